//! Criterion benchmarks of the steady-state solver: one operating point cold, a sweep
//! with warm starts (points per second), an effect-laden point, and `trum map` to CSV. Reference problems come from the presets so tests and
//! benches share them. `bash benches/quick.sh` is the short CI-sized run.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use trum_core::presets::preset;
use trum_core::solve::{solve_prepared, Prepared};
use trum_core::sweep::{solve_range, Axis, Grid};
use trum_core::{solve, OperatingPoint};

fn one_point(c: &mut Criterion) {
    let m = preset("trum60a").expect("preset");
    let op = OperatingPoint::new(250.0, 0.3, 200.0, 43e3);
    let mut g = c.benchmark_group("solve");
    g.throughput(Throughput::Elements(1));
    g.bench_function("cold/trum60a", |b| b.iter(|| solve(black_box(&m), black_box(&op))));
    let p = Prepared::new(&m);
    g.bench_function("cold_prepared/trum60a", |b| b.iter(|| solve_prepared(black_box(&p), &m, black_box(&op), None)));
    let guess = solve(&m, &OperatingPoint::new(249.0, 0.29, 200.0, 43e3));
    g.bench_function("warm/trum60a", |b| b.iter(|| solve_prepared(black_box(&p), &m, black_box(&op), Some(&guess))));
    // The preset as shipped carries its calibrated preload_stiffening (a multi-branch
    // descent); the effect-free motor is the baseline, and each effect below is alone on it.
    let mut bare = m.clone();
    bare.effects.parse_assignment("none").expect("effect");
    g.bench_function("cold/trum60a-no-effects", |b| b.iter(|| solve(black_box(&bare), black_box(&op))));
    let mut r = m.clone();
    r.effects.parse_assignment("radial_friction=1").expect("effect");
    g.bench_function("cold/trum60a+radial_friction", |b| b.iter(|| solve(black_box(&r), black_box(&op))));
    let mut sag = bare.clone();
    sag.effects.parse_assignment("voltage_sag=150").expect("effect");
    g.bench_function("cold/trum60a-no-effects+voltage_sag", |b| b.iter(|| solve(black_box(&sag), black_box(&op))));
    g.finish();
}

fn sweep(c: &mut Criterion) {
    let shipped = preset("trum60a").expect("preset");
    // the effect-free motor (the baseline's warm sweep) and the preset as shipped, whose
    // multi-branch stator a sweep cannot warm-start (docs/PERFORMANCE.md)
    let mut bare = shipped.clone();
    bare.effects.parse_assignment("none").expect("effect");
    let mut g = c.benchmark_group("sweep");
    for (name, m) in [("preload_x_torque-no-effects", &bare), ("preload_x_torque", &shipped)] {
        let p = Prepared::new(m);
        for n in [1_000u64, 10_000] {
            let side = (n as f64).sqrt() as usize;
            let grid = Grid {
                preload_n: Axis::linspace(100.0, 500.0, side),
                voltage_v: Axis::fixed(200.0),
                frequency_hz: Axis::fixed(43e3),
                torque_nm: Axis::linspace(0.0, 1.2, side),
            };
            g.throughput(Throughput::Elements(grid.len()));
            g.bench_with_input(BenchmarkId::new(name, grid.len()), &grid, |b, grid| {
                b.iter(|| {
                    let mut acc = 0.0;
                    solve_range(m, &p, grid, 0..grid.len(), |_, _, s| acc += s.speed_rpm);
                    black_box(acc)
                })
            });
        }
    }
    g.finish();
}

fn map_csv(c: &mut Criterion) {
    // `trum map` in-process to memory: solving, CSV formatting and the parallel pipeline
    // (all columns; `-o -` writes to the given buffer).
    let mut g = c.benchmark_group("map");
    g.sample_size(10);
    g.throughput(Throughput::Elements(100 * 100));
    let mut out = Vec::with_capacity(8 << 20);
    g.bench_function("csv_all_columns/10000", |b| {
        b.iter(|| {
            out.clear();
            let args = [
                "trum",
                "map",
                "--motor",
                "trum60a",
                "--preload-n",
                "100:500:100",
                "--torque-nm",
                "0:1.2:100",
                "-q",
                "-o",
                "-",
            ];
            let code = trum_cli::run_with_io(args, &mut out, &mut std::io::sink());
            assert_eq!(code, 0);
            black_box(out.len())
        })
    });
    g.finish();
}

criterion_group!(benches, one_point, sweep, map_csv);
criterion_main!(benches);
