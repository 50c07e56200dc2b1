//! The diagnosis on small data (4-8 rows, `common/rows.rs`) of the generic motor.
//! Properties: no panic; the JSON has every figure of the spec a finite number and a
//! known verdict.
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::bench::observations;
use trum_core::diagnose::json::{to_json, Provenance};
use trum_core::diagnose::{diagnose, DiagnoseOptions};
use trum_core::presets;

#[path = "../common/rows.rs"]
mod rows;

fuzz_target!(|data: &[u8]| {
    let motor = presets::find("generic60").expect("preset").motor();
    let Some(m) = rows::small_rows(&motor, data) else { return };
    let bench = observations(&m, &motor);
    let opts = DiagnoseOptions { bootstrap: 20, ..DiagnoseOptions::default() };
    if let Ok(d) = diagnose(&motor, &bench.rows, &bench.groups, &opts) {
        let src = Provenance { motor_name: &motor.name, motor_source: "generic60", data: "fuzz", lines: &bench.lines };
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
});
