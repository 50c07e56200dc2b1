//! Calibration and the diagnosis on small data (4-8 rows) decoded from the bytes: set
//! points inside the plausible ranges, readings the generic motor's own with a
//! byte-sized error (so fits start near a solution, as on a bench), or any plausible
//! value. Properties: no panic; a calibration's parameters and χ² are finite; a
//! diagnosis's JSON has every figure of the spec a finite number and a known verdict.
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::bench::observations;
use trum_core::calibrate::{baseline_params_with, calibrate_refitting_bounds, FitOptions};
use trum_core::diagnose::json::{to_json, Provenance};
use trum_core::diagnose::{diagnose, DiagnoseOptions};
use trum_core::measurements::{Column, Measurements, Row};
use trum_core::{presets, solve, OperatingPoint};

fn unit(b: u8) -> f64 {
    f64::from(b) / 255.0
}

fuzz_target!(|data: &[u8]| {
    if data.len() < 6 {
        return;
    }
    let motor = presets::find("generic60").expect("preset").motor();
    let n = 4 + usize::from(data[0] % 5);
    let mut builder = Measurements::builder().column(Column::CurrentA);
    let mut chunks = data[2..].chunks(6);
    for i in 0..n {
        let c: Vec<u8> = chunks.next().map_or_else(|| vec![i as u8; 6], <[u8]>::to_vec);
        let c = |k: usize| c.get(k).copied().unwrap_or(0);
        let op = OperatingPoint::new(
            100.0 + 400.0 * unit(c(0)),
            0.8 * unit(c(1)),
            120.0 + 120.0 * unit(c(2)),
            41_000.0 + 4000.0 * unit(c(3)),
        );
        let s = solve(&motor, &op);
        let err = (f64::from(c(4)) - 128.0) / 128.0;
        let speed = if c(5) > 250 { 9999.0 * unit(c(4)) } else { (s.speed_rpm * (1.0 + 0.2 * err)).clamp(0.0, 9999.0) };
        let current = if s.current_a.is_finite() { Some(s.current_a.abs()) } else { None };
        let mut row = Row::new(
            op.preload_n,
            op.voltage_v,
            op.frequency_hz,
            op.torque_nm,
            if speed.is_finite() { speed } else { 0.0 },
        );
        if let Some(a) = current.filter(|a| a.is_finite() && *a <= 1e3) {
            row = row.with_current_a(a);
        }
        builder = builder.row(row);
    }
    let Ok(m) = builder.build() else { return };
    let bench = observations(&m, &motor);
    if data[1] & 1 == 0 {
        let params = baseline_params_with(&motor, &bench.rows, &Default::default());
        if let Ok(cal) = calibrate_refitting_bounds(&motor, &bench.rows, &params, &FitOptions::default()) {
            assert!(cal.chi2.is_finite() || cal.chi2 == f64::INFINITY, "{}", cal.chi2);
            for p in &cal.params {
                assert!(p.value.is_finite(), "{} = {}", p.name, p.value);
            }
        }
    } else {
        let opts = DiagnoseOptions { bootstrap: 20, ..DiagnoseOptions::default() };
        if let Ok(d) = diagnose(&motor, &bench.rows, &bench.groups, &opts) {
            let src =
                Provenance { motor_name: &motor.name, motor_source: "generic60", data: "fuzz", lines: &bench.lines };
            let doc = to_json(&d, &src);
            let finite = |v: &serde_json::Value| v.as_f64().is_some_and(f64::is_finite);
            assert!(finite(&doc["gap"]["baseline_heldout_nrmse"]) && finite(&doc["gap"]["noise_nrmse"]), "{doc}");
            for r in doc["ranking"].as_array().expect("ranking") {
                for k in ["evidence", "heldout_nrmse_after", "shrink"] {
                    assert!(finite(&r[k]), "{k}: {doc}");
                }
            }
            let v = doc["verdict"].as_str().expect("verdict");
            assert!(
                v == "none" || v == "unexplained" || v.split('+').all(|e| trum_core::Effect::from_name(e).is_ok()),
                "{v}"
            );
        }
    }
});
