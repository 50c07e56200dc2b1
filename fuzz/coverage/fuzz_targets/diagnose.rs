//! The diagnosis on small data (4-8 rows, `common/rows.rs`) of the generic motor.
//! Properties (`common/diagnosis.rs`): no panic; the JSON has every figure of the spec a
//! finite number, a known verdict, and `separating_campaigns` entries from the lead to
//! rivals of a kind that holds.
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::diagnose::{diagnose, DiagnoseOptions};

#[path = "../common/diagnosis.rs"]
mod diagnosis;

fuzz_target!(|data: &[u8]| {
    let Some((motor, bench)) = diagnosis::small_case(data) else { return };
    let opts = DiagnoseOptions { bootstrap: 20, ..DiagnoseOptions::default() };
    if let Ok(d) = diagnose(&motor, &bench.rows, &bench.groups, &opts) {
        diagnosis::checked_json(&motor, &bench, &d);
    }
});
