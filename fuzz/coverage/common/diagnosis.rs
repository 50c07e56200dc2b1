//! The checks the `diagnose` and `diagnose_options` targets share: the diagnosis as its
//! JSON document, with the spec's headline figures finite numbers.
use trum_core::bench::BenchData;
use trum_core::diagnose::json::{to_json, Provenance};
use trum_core::diagnose::Diagnosis;
use trum_core::Motor;

/// The JSON document of `d` (a diagnosis of `motor` on `bench`), after asserting that the
/// gap's figures and every ranked entry's evidence, held-out NRMSE and shrink are finite.
pub fn checked_json(motor: &Motor, bench: &BenchData, d: &Diagnosis) -> serde_json::Value {
    let src = Provenance { motor_name: &motor.name, motor_source: "generic60", data: "fuzz", lines: &bench.lines };
    let doc = to_json(d, &src);
    let finite = |v: &serde_json::Value| v.as_f64().is_some_and(f64::is_finite);
    assert!(finite(&doc["gap"]["baseline_heldout_nrmse"]) && finite(&doc["gap"]["noise_nrmse"]), "{doc}");
    for r in doc["ranking"].as_array().expect("ranking") {
        for k in ["evidence", "heldout_nrmse_after", "shrink"] {
            assert!(finite(&r[k]), "{k}: {doc}");
        }
    }
    doc
}
