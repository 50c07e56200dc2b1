//! Criterion benchmarks of the steady-state solver: one operating point cold, a sweep
//! with warm starts (points per second), and an effect-laden point. Reference problems
//! come from the presets so tests and benches share them.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use trum_core::presets::preset;
use trum_core::solve::{solve_prepared, Prepared};
use trum_core::sweep::{solve_range, Axis, Grid};
use trum_core::{solve, OperatingPoint};

fn one_point(c: &mut Criterion) {
    let m = preset("trum60a").expect("preset");
    let op = OperatingPoint::new(250.0, 0.3, 200.0, 43e3);
    c.bench_function("solve/cold/trum60a", |b| b.iter(|| solve(black_box(&m), black_box(&op))));
    let p = Prepared::new(&m);
    let guess = solve(&m, &OperatingPoint::new(249.0, 0.29, 200.0, 43e3));
    c.bench_function("solve/warm/trum60a", |b| {
        b.iter(|| solve_prepared(black_box(&p), &m, black_box(&op), Some(&guess)))
    });
    let mut r = m.clone();
    r.effects.parse_assignment("radial_friction=1").expect("effect");
    c.bench_function("solve/cold/trum60a+radial_friction", |b| b.iter(|| solve(black_box(&r), black_box(&op))));
}

fn sweep(c: &mut Criterion) {
    let m = preset("trum60a").expect("preset");
    let p = Prepared::new(&m);
    let mut g = c.benchmark_group("sweep");
    for n in [1_000u64, 10_000] {
        let side = (n as f64).sqrt() as usize;
        let grid = Grid {
            preload_n: Axis::linspace(100.0, 500.0, side),
            voltage_v: Axis::fixed(200.0),
            frequency_hz: Axis::fixed(43e3),
            torque_nm: Axis::linspace(0.0, 1.2, side),
        };
        g.throughput(Throughput::Elements(grid.len()));
        g.bench_with_input(BenchmarkId::new("preload_x_torque", grid.len()), &grid, |b, grid| {
            b.iter(|| {
                let mut acc = 0.0;
                solve_range(&m, &p, grid, 0..grid.len(), |_, _, s| acc += s.speed_rpm);
                black_box(acc)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, one_point, sweep);
criterion_main!(benches);
