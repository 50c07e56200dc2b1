//! The diagnosis on small data (4-8 rows, `common/rows.rs`) of the generic motor.
//! Properties: no panic; the JSON has every figure of the spec a finite number and a
//! known verdict.
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::bench::observations;
use trum_core::diagnose::{diagnose, DiagnoseOptions};
use trum_core::presets;

#[path = "../common/diagnosis.rs"]
mod diagnosis;
#[path = "../common/rows.rs"]
mod rows;

fuzz_target!(|data: &[u8]| {
    let motor = presets::find("generic60").expect("preset").motor();
    let Some(m) = rows::small_rows(&motor, data) else { return };
    let bench = observations(&m, &motor);
    let opts = DiagnoseOptions { bootstrap: 20, ..DiagnoseOptions::default() };
    if let Ok(d) = diagnose(&motor, &bench.rows, &bench.groups, &opts) {
        let doc = diagnosis::checked_json(&motor, &bench, &d);
        let v = doc["verdict"].as_str().expect("verdict");
        assert!(
            v == "none" || v == "unexplained" || v.split('+').all(|e| trum_core::Effect::from_name(e).is_ok()),
            "{v}"
        );
    }
});
