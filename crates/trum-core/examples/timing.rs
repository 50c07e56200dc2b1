//! Per-point solve times and work counts (docs/PERFORMANCE.md).
//!
//! `cargo run --release -p trum-core --example timing`            all effect sets, cold
//! `cargo run --release -p trum-core --example timing -- baseline` baseline only: cold
//!     points, then the same grid as a warm-started sweep, then the Python comparison's
//!     grid as a sweep (for callgrind too)
//!
//! Times are medians over rows of 25 points (one preload, torque 0-0.96 N·m), so one
//! slow row (another process scheduled) does not move them.
use std::time::Instant;
use trum_core::solve::{solve_prepared, Prepared};
use trum_core::sweep::{solve_range, Axis, Grid};
use trum_core::*;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let baseline_only = std::env::args().any(|a| a == "baseline");
    let sets: &[&str] = if baseline_only {
        &["none"]
    } else {
        &[
            "none",
            "radial_friction=1",
            "tangential_compliance=1",
            "thermal_drift=-4e-4",
            "voltage_sag=150",
            "eccentricity=2e-5",
            "preload_stiffening=0.05",
            "hertz_softening=1e18",
        ]
    };
    let rows = if baseline_only { 400 } else { 40 };
    for fx in sets {
        let mut m = presets::preset("trum60a").expect("preset");
        m.effects.parse_assignment(fx).expect("effect");
        let (mut it, mut n, mut per_row) = (0u64, 0u64, Vec::new());
        for i in 0..rows {
            let t0 = Instant::now();
            for j in 0..25 {
                let mut op =
                    OperatingPoint::new(100.0 + 200.0 * i as f64 / rows as f64, j as f64 / 25.0, 200.0, 43000.0);
                op.elapsed_s = 60.0;
                let s = solve(&m, &op);
                it += s.iterations as u64;
                n += 1;
            }
            per_row.push(t0.elapsed().as_secs_f64() / 25.0);
        }
        println!(
            "{fx:26} cold  {:.3} us/point (median), mean evals {:.2}",
            median(per_row) * 1e6,
            it as f64 / n as f64
        );
    }
    if baseline_only {
        let m = presets::preset("trum60a").expect("preset");
        let p = Prepared::new(&m);
        // Warm: the same points as a sweep (torque fastest), each started from its neighbour.
        let g = Grid {
            preload_n: Axis::linspace(100.0, 300.0, rows),
            voltage_v: Axis::fixed(200.0),
            frequency_hz: Axis::fixed(43e3),
            torque_nm: Axis::linspace(0.0, 0.96, 25),
        };
        let (mut it, mut per_row) = (0u64, Vec::new());
        for r in 0..rows as u64 {
            let t0 = Instant::now();
            solve_range(&m, &p, &g, r * 25..(r + 1) * 25, |_, _, s| it += s.iterations as u64);
            per_row.push(t0.elapsed().as_secs_f64() / 25.0);
        }
        println!(
            "{:26} sweep {:.3} us/point (median), mean evals {:.2}",
            "none",
            median(per_row) * 1e6,
            it as f64 / g.len() as f64
        );
        // The Python comparison's grid (benches/compare_python.py: 200 preloads × 100
        // torques over 0-1.2 N·m) as rows of torque sweeps: what `trum.map` solves there,
        // without the Python layer. Best of five passes.
        let g = Grid {
            preload_n: Axis::linspace(100.0, 500.0, 200),
            voltage_v: Axis::fixed(200.0),
            frequency_hz: Axis::fixed(43e3),
            torque_nm: Axis::linspace(0.0, 1.2, 100),
        };
        let (mut best, mut it) = (f64::INFINITY, 0u64);
        for _ in 0..5 {
            it = 0;
            let t0 = Instant::now();
            for r in 0..200u64 {
                solve_range(&m, &p, &g, r * 100..(r + 1) * 100, |_, _, s| it += s.iterations as u64);
            }
            best = best.min(t0.elapsed().as_secs_f64());
        }
        println!(
            "{:26} sweep, Python comparison grid {:.3} us/point, mean evals {:.2}",
            "none",
            best / g.len() as f64 * 1e6,
            it as f64 / g.len() as f64
        );
        // Prepared once, no neighbour: the solver alone, without Prepared::new.
        let mut per_row = Vec::new();
        for i in 0..rows {
            let t0 = Instant::now();
            for j in 0..25 {
                let op = OperatingPoint::new(100.0 + 200.0 * i as f64 / rows as f64, j as f64 / 25.0, 200.0, 43000.0);
                std::hint::black_box(solve_prepared(&p, &m, &op, None));
            }
            per_row.push(t0.elapsed().as_secs_f64() / 25.0);
        }
        println!("{:26} cold, prepared once {:.3} us/point (median)", "none", median(per_row) * 1e6);
        // The floor: what the sin_cos calls alone cost (callgrind counts ~40 per point).
        let n = 10_000_000;
        let t0 = Instant::now();
        let mut acc = 0.0;
        for i in 0..n {
            let (s, c) = std::hint::black_box(0.3 + 1e-7 * i as f64).sin_cos();
            acc += s + c;
        }
        std::hint::black_box(acc);
        println!("sin_cos on [0.3, 1.3]: {:.1} ns/call", t0.elapsed().as_secs_f64() / n as f64 * 1e9);
    }
}
