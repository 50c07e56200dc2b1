//! Criterion benchmark of the measured-input estimator (`trum_core::estimate`): one
//! measurement row, the on-line use of Sun et al. 2021's model. No amplitude is solved:
//! one contact and one stick-angle solve a row.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use trum_core::estimate::{Estimator, MeasuredPoint};
use trum_core::presets::preset;
use trum_core::{solve, OperatingPoint};

fn one_row(c: &mut Criterion) {
    let mut g = c.benchmark_group("estimate");
    g.throughput(Throughput::Elements(1));
    for name in ["trum60a", "generic60"] {
        let m = preset(name).expect("preset");
        let e = Estimator::new(&m).expect("estimator");
        let op = OperatingPoint::new(250.0, 0.3, 200.0, 43e3);
        // a feedback voltage the motor gives at this point, as a bench would read it
        let row = MeasuredPoint {
            preload_n: op.preload_n,
            voltage_v: op.voltage_v,
            frequency_hz: op.frequency_hz,
            torque_nm: op.torque_nm,
            feedback_v: Some(solve(&m, &op).feedback_v),
            speed_rpm: Some(100.0),
        };
        g.bench_function(format!("row/{name}"), |b| b.iter(|| e.estimate(black_box(&row))));
    }
    g.finish();
}

criterion_group!(benches, one_row);
criterion_main!(benches);
