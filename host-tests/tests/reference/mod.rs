//! An independent, direct-form f64 reimplementation of the motion method,
//! written from the paper (and the project's documented choices), used to
//! check the integer O(N) engine. Nothing here shares code with the engine
//! except the public LCG constants.
#![allow(dead_code)]

use std::f64::consts::PI;

pub const A: u32 = 3_101_517_285;
pub const C: u32 = 672_311;

pub fn lcg(r: u32) -> u32 {
    ((u64::from(A) * u64::from(r) + u64::from(C)) % (1u64 << 32)) as u32
}

fn step(r: u32) -> f64 {
    if r >= 1 << 31 { 1.0 } else { -1.0 }
}

/// Periodic Hann window of W taps.
pub fn hann(w: usize) -> Vec<f64> {
    (0..w)
        .map(|m| 0.5 - 0.5 * (2.0 * PI * m as f64 / w as f64).cos())
        .collect()
}

#[derive(Debug, Clone)]
pub struct RefLoop {
    /// Final loop in degrees, playback order.
    pub final_deg: Vec<f64>,
    /// Split index chosen by the reference.
    pub split: usize,
    pub walk: Vec<f64>,
    pub smoothed: Vec<f64>,
    pub normalized: Vec<f64>,
}

/// The paper's closure: open walk, causal smoothing, normalisation, taper, split.
pub fn paper(seed: u32, n: usize, w: usize, a1: f64, a2: f64) -> RefLoop {
    let mut r = seed;
    let mut u = vec![0.0; n];
    for i in 1..n {
        r = lcg(r);
        u[i] = u[i - 1] + step(r);
    }
    let h = hann(w);
    let s: Vec<f64> = (0..n)
        .map(|i| (0..w).filter(|&m| m <= i).map(|m| h[m] * u[i - m]).sum())
        .collect();
    let (lo, hi) = minmax(&s);
    let x: Vec<f64> = s
        .iter()
        .map(|v| a1 + (v - lo) * (a2 - a1) / (hi - lo))
        .collect();
    let t: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| v * (0.5 - 0.5 * (2.0 * PI * i as f64 / (n - 1) as f64).cos()))
        .collect();
    // Crossings on values rounded to the millidegree (as stored).
    let sign = |v: f64| ((v * 1000.0).round() as i64).signum();
    let crossings: Vec<usize> = (0..n - 1)
        .filter(|&i| sign(t[i + 1]) != sign(t[i]))
        .collect();
    let r_next = lcg(r);
    let pick = (((r_next >> 16) as u64 * crossings.len() as u64) >> 16) as usize;
    let split = crossings.get(pick).copied().unwrap_or(0);
    let mut f = t.clone();
    f.rotate_left(split);
    RefLoop {
        final_deg: f,
        split,
        walk: u,
        smoothed: s.iter().map(|v| v / (w as f64 / 2.0)).collect(),
        normalized: x,
    }
}

/// The seamless closure: periodic walk, circular smoothing, start at a
/// crossing of the zero level (found as the engine finds it), scaled about it.
pub fn seamless(seed: u32, n: usize, w: usize, a1: f64, a2: f64) -> RefLoop {
    let mut r = seed;
    let e: Vec<f64> = (0..n)
        .map(|_| {
            r = lcg(r);
            step(r)
        })
        .collect();
    let mean = e.iter().sum::<f64>() / n as f64;
    let h = hann(w);
    let v: Vec<f64> = (0..n)
        .map(|i| (0..w).map(|m| h[m] * (e[(i + n - m) % n] - mean)).sum())
        .collect();
    let mut j = vec![0.0; n];
    let mut acc = 0.0;
    for i in 0..n {
        acc += v[i];
        j[i] = acc;
    }
    let mut walk = vec![0.0; n];
    let mut uacc = 0.0;
    for i in 0..n {
        uacc += e[i] - mean;
        walk[i] = uacc;
    }
    let (lo, hi) = minmax(&j);
    let level = lo + (-a1) * (hi - lo) / (a2 - a1);
    // The crossing the engine picks: generation order starts at the first
    // full window's output, loop index W−1; the first sample of the grid
    // 0, 16, 32, … off the start's side brackets it, bisection narrows it
    // to two neighbours, and the nearer one is the split.
    let at = |g: usize| j[(w - 1 + g) % n] - level;
    let x0 = at(0);
    let before = |x: f64| if x0 > 0.0 { x > 0.0 } else { x < 0.0 };
    let g = if x0 == 0.0 {
        0
    } else {
        let grid = (1..)
            .map(|k| 16 * k)
            .take_while(|&g| g < n)
            .find(|&g| !before(at(g)));
        let bracket = grid
            .map(|g| (g - 16, g))
            .or_else(|| (1..n).find(|&g| !before(at(g))).map(|g| (g - 1, g)));
        match bracket {
            None => 0,
            Some((mut a, mut b)) => {
                while b - a > 1 {
                    let m = a + (b - a) / 2;
                    if before(at(m)) {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                if at(b).abs() <= at(a).abs() { b } else { a }
            }
        }
    };
    let split = (w - 1 + g) % n;
    let normalized: Vec<f64> = j
        .iter()
        .map(|v| a1 + (v - lo) * (a2 - a1) / (hi - lo))
        .collect();
    let final_deg = scaled_about(&j, split, lo, hi, a1, a2);
    RefLoop {
        final_deg,
        split,
        walk,
        smoothed: j.iter().map(|v| v / (w as f64 / 2.0)).collect(),
        normalized,
    }
}

/// The loop `j` started at `split` and scaled about it into [a1, a2].
pub fn scaled_about(j: &[f64], split: usize, lo: f64, hi: f64, a1: f64, a2: f64) -> Vec<f64> {
    let n = j.len();
    let p = j[split];
    let up = if hi > p { a2 / (hi - p) } else { f64::INFINITY };
    let down = if p > lo {
        -a1 / (p - lo)
    } else {
        f64::INFINITY
    };
    let k = up.min(down);
    (0..n).map(|i| (j[(split + i) % n] - p) * k).collect()
}

pub fn minmax(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}
