//! The seamless closure's wrap correction E fits `i32`, for every window and
//! every loop length.
//!
//! The engine sums E (`crates/core/src/motion/engine/sweep.rs`, `initial_window`) in
//! wrapping `i32` arithmetic and forms the detrend from it in 32-bit steps
//! (`seamless.rs`); both are exact only if |E| < 2²⁴ (the bound its docs
//! state). E is a sum over the first W−1 steps of b(k)·term(k),
//! b(k) ∈ {0, 1}, where term(k) depends only on W and N mod W. This test
//! bounds |E| for every W ≤ 511 and every N mod W by the worst choice of
//! steps (all positive or all negative terms taken), computed in `i64`
//! straight from the definition:
//!
//! ```text
//! term(k) = T[k]·SA(k) + T[(k+N) mod W]·SB(k)
//! SA(k) = Σ_{n=W−1}^{k+W−1} T[n mod W],  SB(k) = Σ_{n=k+N}^{N+W−2} T[n mod W]
//! ```

use idle_head_core::motion::{HannKernel, MAX_WINDOW, MIN_WINDOW};

#[test]
fn wrap_correction_is_far_inside_i32() {
    let mut worst = (0i64, 0usize, 0usize);
    for window in MIN_WINDOW..=MAX_WINDOW {
        let kernel = HannKernel::new(window).unwrap();
        let t: Vec<(i64, i64)> = kernel
            .table()
            .iter()
            .map(|&(c, s)| (i64::from(c), i64::from(s)))
            .collect();
        let w = usize::from(window);
        let dot = |a: (i64, i64), b: (i64, i64)| a.0 * b.0 + a.1 * b.1;
        for r in 0..w {
            // SA(0) = T[W−1]; SB(0) = Σ_{i=0}^{W−2} T[(i + r) mod W].
            let mut sa = t[w - 1];
            let mut sb = (0..w - 1).fold((0, 0), |s, i| {
                let e = t[(i + r) % w];
                (s.0 + e.0, s.1 + e.1)
            });
            let (mut pos, mut neg) = (0i64, 0i64);
            for k in 0..w - 1 {
                let (early, late) = (t[k], t[(k + r) % w]);
                let term = dot(early, sa) + dot(late, sb);
                if term > 0 {
                    pos += term;
                } else {
                    neg -= term;
                }
                sa = (sa.0 + early.0, sa.1 + early.1);
                sb = (sb.0 - late.0, sb.1 - late.1);
            }
            let bound = pos.max(neg);
            if bound > worst.0 {
                worst = (bound, w, r);
            }
        }
    }
    println!(
        "largest |E| over all steps: {} (W = {}, N mod W = {})",
        worst.0, worst.1, worst.2
    );
    assert!(worst.0 < 1 << 24, "|E| may reach {}", worst.0);
}
