//! Per-row time of the measured-input estimator over many rows (docs/PERFORMANCE.md), and
//! a small fixed workload for callgrind's instruction count.
//!
//!     cargo run --release -p trum-core --example estimate_rows [-- ROWS]
//!     valgrind --tool=callgrind target/release/examples/estimate_rows 10000
//!
//! Rows: trum60a at 200 V, 43 kHz, preload 100-400 N × torque 0-0.9 N·m, each with the
//! feedback voltage the solved motor gives (the solves are done before the clock starts).
//! The time is the median over blocks of 1000 rows, so another process scheduled in one
//! block does not move it.
use std::time::Instant;
use trum_core::estimate::{Estimator, MeasuredPoint};
use trum_core::{presets, solve, OperatingPoint};

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(200_000);
    let m = presets::preset("trum60a").expect("preset");
    let e = Estimator::new(&m).expect("estimator");
    let grid: Vec<MeasuredPoint> = (0..1000)
        .map(|i| {
            let op = OperatingPoint::new(100.0 + 10.0 * (i / 33) as f64, 0.9 * (i % 33) as f64 / 32.0, 200.0, 43e3);
            MeasuredPoint {
                preload_n: op.preload_n,
                voltage_v: op.voltage_v,
                frequency_hz: op.frequency_hz,
                torque_nm: op.torque_nm,
                feedback_v: Some(solve(&m, &op).feedback_v),
                speed_rpm: None,
            }
        })
        .collect();
    let mut blocks = Vec::new();
    let mut acc = 0.0;
    for b in 0..n.div_ceil(grid.len()) {
        let t = Instant::now();
        for r in &grid {
            acc += e.estimate(std::hint::black_box(r)).efficiency;
        }
        blocks.push(t.elapsed().as_secs_f64() / grid.len() as f64);
        let _ = b;
    }
    blocks.sort_by(f64::total_cmp);
    println!(
        "{} rows: median {:.3} µs a row, fastest block {:.3} µs (checksum {acc:.6})",
        blocks.len() * grid.len(),
        1e6 * blocks[blocks.len() / 2],
        1e6 * blocks[0]
    );
}
