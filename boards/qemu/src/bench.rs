//! Boot-precompute benchmark on the emulated Cortex-M0: instruction counts of
//! the motion engine against a direct-form f32 implementation of the paper's
//! smoothing (the costly stage it names), on the same core.
//!
//! Run with `cargo xtask bench`, or `cargo run --release --bin bench` in
//! boards/qemu/ (QEMU `-icount shift=0`: one instruction is one nanosecond of
//! virtual time, SysTick counts 12.5 MHz, so one count is 80 instructions,
//! the same every run). Each row measures three axes (pitch,
//! roll, yaw) of the paper's Table 2 set with N and W as given:
//!
//! ```text
//! bench row=<label> n=<N> w=<W> engine=<insns> direct=<insns>
//! ```
//!
//! `engine` is the whole pipeline (walk, smoothing, scaling, loop closure,
//! for three axes); `direct` is only the direct-form smoothing
//! s(n) = Σₘ h(m)·u(n−m) of three walks in f32 (N·W multiply-adds each).
//!
//! Then the frame benchmark (`frame_bench.rs`): the instructions of every
//! frame update of a whole loop with a join, counted exactly, and of
//! generating the next loop set of the never-repeating stream.
#![no_std]
#![no_main]

mod exit;
mod frame_bench;
#[allow(dead_code)] // the time driver half is the smoke image's
mod systick;

use cortex_m_rt::entry;
use defmt_semihosting as _;
use idle_head_core::motion::{DEFAULT_HEAD, HeadConfig, HeadTrajectories, Integral16, Lcg};
use static_cell::ConstStaticCell;

/// One row of the table: label, N, W.
struct Row {
    label: &'static str,
    n: usize,
    w: u16,
}

const ROWS: [Row; 7] = [
    Row {
        label: "default",
        n: 900,
        w: 59,
    },
    Row {
        label: "w15",
        n: 900,
        w: 15,
    },
    Row {
        label: "w59",
        n: 900,
        w: 59,
    },
    Row {
        label: "w239",
        n: 900,
        w: 239,
    },
    Row {
        label: "n450",
        n: 450,
        w: 59,
    },
    Row {
        label: "n900",
        n: 900,
        w: 59,
    },
    Row {
        label: "n1800",
        n: 1800,
        w: 59,
    },
];

static mut H450: HeadTrajectories<Integral16, 450> = HeadTrajectories::new();
static mut H900: HeadTrajectories<Integral16, 900> = HeadTrajectories::new();
static mut H1800: HeadTrajectories<Integral16, 1800> = HeadTrajectories::new();
static mut WALK: [f32; 1800] = [0.0; 1800];
static mut SMOOTH: [f32; 1800] = [0.0; 1800];
static mut HANN: [f32; 512] = [0.0; 512];
/// Loop sets 0 and 1 of the default stream, for the frame benchmark.
static SETS: ConstStaticCell<[frame_bench::Set; 2]> =
    ConstStaticCell::new([frame_bench::Set::new(), frame_bench::Set::new()]);

/// The default set with window `w`.
fn config(w: u16) -> HeadConfig {
    let mut c = DEFAULT_HEAD;
    c.pitch.window = w;
    c.roll.window = w;
    c.yaw.window = w;
    c
}

/// The paper's smoothing in direct form, f32: walk, Hann taps, N·W
/// multiply-adds (causal, u(n−m) = 0 before the start).
fn direct(
    seed: u32,
    n: usize,
    w: usize,
    walk: &mut [f32],
    out: &mut [f32],
    hann: &mut [f32],
) -> f32 {
    let mut g = Lcg::new(seed);
    let mut u = 0.0f32;
    for (i, x) in walk.iter_mut().take(n).enumerate() {
        if i > 0 {
            u += if g.next_step_bit() == 1 { 1.0 } else { -1.0 };
        }
        *x = u;
    }
    for (m, h) in hann.iter_mut().take(w).enumerate() {
        *h = 0.5 - 0.5 * libm::cosf(2.0 * core::f32::consts::PI * m as f32 / w as f32);
    }
    let mut check = 0.0;
    for i in 0..n {
        let mut s = 0.0f32;
        for m in 0..w.min(i + 1) {
            s += hann[m] * walk[i - m];
        }
        out[i] = s;
        check += s;
    }
    check
}

#[entry]
fn main() -> ! {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        exit::exit(false)
    };
    // Note(unsafe): single-threaded `main`, no interrupt touches these
    // buffers, and each is borrowed once, here.
    let (h450, h900, h1800, walk, smooth, hann) = unsafe {
        (
            &mut *core::ptr::addr_of_mut!(H450),
            &mut *core::ptr::addr_of_mut!(H900),
            &mut *core::ptr::addr_of_mut!(H1800),
            &mut *core::ptr::addr_of_mut!(WALK),
            &mut *core::ptr::addr_of_mut!(SMOOTH),
            &mut *core::ptr::addr_of_mut!(HANN),
        )
    };
    let mut ok = true;
    let mut default_checksum = None;
    for row in &ROWS {
        let cfg = config(row.w);
        let (result, engine) = systick::stopwatch(&mut core.SYST, || match row.n {
            450 => h450.generate(&cfg).map(|_| ()),
            900 => h900.generate(&cfg).map(|_| ()),
            _ => h1800.generate(&cfg).map(|_| ()),
        });
        if let Err(e) = result {
            defmt::error!("row {=str}: {}", row.label, e);
            ok = false;
        }
        let (check, direct_counts) = systick::stopwatch(&mut core.SYST, || {
            let mut check = 0.0;
            for seed in [cfg.pitch.seed, cfg.roll.seed, cfg.yaw.seed] {
                check += direct(seed, row.n, usize::from(row.w), walk, smooth, hann);
            }
            check
        });
        if row.label == "default" {
            default_checksum = Some(h900.checksum());
        }
        defmt::info!(
            "bench row={=str} n={=usize} w={=u16} engine={=u64} direct={=u64} ({=f32})",
            row.label,
            row.n,
            row.w,
            engine * systick::INSNS_PER_COUNT,
            direct_counts * systick::INSNS_PER_COUNT,
            check
        );
    }
    // Last: it switches the clock the rows above are counted with. The
    // default row's checksum is the one loop set 0 must have.
    let sets = SETS.take();
    ok &= default_checksum.is_some_and(|sum| frame_bench::run(&mut core.SYST, sets, sum));
    exit::exit(ok)
}
