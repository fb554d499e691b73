//! The paper's pseudo-random source: a linear congruential generator.
//!
//! r(n+1) = (a·r(n) + c) mod m with a = 3101517285, c = 672311, m = 2³², r(0) = seed,
//! exact in wrapping `u32` arithmetic.
//!
//! The low bits of a power-of-two-modulus LCG are short-period (bit 0 simply
//! alternates), so every decision this crate draws from it uses the **top** bits:
//! a walk step is up when r(n) ≥ 2³¹, and a choice among `k` candidates takes the
//! top 16 bits scaled by `k`.

/// Multiplier `a` (paper, section 3).
pub const A: u32 = 3_101_517_285;
/// Increment `c` (paper, section 3).
pub const C: u32 = 672_311;

/// The paper's LCG, positioned at r(n); [`Lcg::next_value`] returns r(n+1).
///
/// ```
/// use idle_head_core::motion::Lcg;
/// let mut g = Lcg::new(127);
/// // r(1) = (3101517285 · 127 + 672311) mod 2³²
/// assert_eq!(g.next_value(), ((3_101_517_285u64 * 127 + 672_311) % (1 << 32)) as u32);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lcg {
    state: u32,
}

impl Lcg {
    /// A generator whose current value is r(0) = `seed`.
    #[must_use]
    pub const fn new(seed: u32) -> Self {
        Self { state: seed }
    }

    /// The current value r(n).
    #[must_use]
    pub const fn value(&self) -> u32 {
        self.state
    }

    /// Advances to r(n+1) and returns it.
    #[inline]
    pub fn next_value(&mut self) -> u32 {
        self.state = self.state.wrapping_mul(A).wrapping_add(C);
        self.state
    }

    /// Advances and returns the next walk step as a bit: `1` for +δ (r ≥ 2³¹), `0` for −δ.
    #[inline]
    pub fn next_step_bit(&mut self) -> u32 {
        self.next_value() >> 31
    }

    /// Advances and draws an index in `0..count` from the top 16 bits
    /// (`count` ≤ 65536; returns 0 for `count` = 0).
    #[must_use]
    pub fn next_index(&mut self, count: u32) -> u32 {
        ((self.next_value() >> 16) * count.min(1 << 16)) >> 16
    }
}

/// The walk step encoded by an LCG value: +1 when r ≥ 2³¹, else −1.
#[must_use]
pub const fn step_of(r: u32) -> i32 {
    if r >> 31 == 1 { 1 } else { -1 }
}
