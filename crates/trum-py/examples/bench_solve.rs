//! Rust baseline of `bench/bench_solve.py`: the same N operating points solved cold and
//! written into one column per quantity, serially and rayon-parallel in 1024-point chunks
//! (what `Motor.solve` does). Prints one JSON line with the best of `repeats` timings.
//! Usage: cargo run --release -p trum-py --example bench_solve -- [N] [repeats]
use rayon::prelude::*;
use std::time::Instant;
use trum_core::quantities::QUANTITIES;
use trum_core::solve::{solve_prepared, OperatingPoint, Prepared};

/// The bench's inputs: preload 100-400 N × torque 0-0.3 N·m at 200 V, 43 kHz.
fn point(i: usize, n: usize) -> OperatingPoint {
    let rows = 1000.min(n).max(1);
    let cols = n.div_ceil(rows);
    let (r, c) = (i / cols, i % cols);
    let f = 100.0 + 300.0 * r as f64 / (rows.max(2) - 1) as f64;
    let t = 0.3 * c as f64 / (cols.max(2) - 1) as f64;
    OperatingPoint::new(f, t, 200.0, 43e3)
}

fn solve_chunk(p: &Prepared, m: &trum_core::Motor, start: usize, n: usize, out: &mut [Vec<f64>]) {
    for (j, _) in (0..out[0].len()).enumerate() {
        let s = solve_prepared(p, m, &point(start + j, n), None);
        for (col, q) in out.iter_mut().zip(QUANTITIES) {
            col[j] = (q.get)(&s);
        }
    }
}

fn main() {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let n = args.first().copied().unwrap_or(1_000_000);
    let repeats = args.get(1).copied().unwrap_or(3).max(1);
    let Ok(m) = trum_core::presets::preset("trum60a") else { return };
    let p = Prepared::new(&m);
    let nq = QUANTITIES.len();
    let mut best = [f64::INFINITY; 2];
    let mut checksum = 0.0;
    for _ in 0..repeats {
        for (k, parallel) in [false, true].into_iter().enumerate() {
            let t0 = Instant::now();
            let chunks: Vec<usize> = (0..n).step_by(1024).collect();
            let work = |&start: &usize| {
                let len = 1024.min(n - start);
                let mut out = vec![vec![0.0; len]; nq];
                solve_chunk(&p, &m, start, n, &mut out);
                out[0].iter().sum::<f64>()
            };
            let sum: f64 = if parallel { chunks.par_iter().map(work).sum() } else { chunks.iter().map(work).sum() };
            best[k] = best[k].min(t0.elapsed().as_secs_f64());
            checksum = sum;
        }
    }
    println!(
        "{{\"n\": {n}, \"serial_s\": {:.6}, \"parallel_s\": {:.6}, \"threads\": {}, \"speed_rpm_sum\": {checksum}}}",
        best[0],
        best[1],
        rayon::current_num_threads()
    );
}
