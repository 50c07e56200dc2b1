//! What the `diagnose` and `diagnose_options` targets share: their input (small data of
//! the generic motor, `rows.rs`) and their checks of the diagnosis as its JSON document.
use trum_core::bench::{observations, BenchData};
use trum_core::diagnose::json::{to_json, Provenance};
use trum_core::diagnose::Diagnosis;
use trum_core::{presets, Effect, Motor};

#[path = "rows.rs"]
mod rows;

/// The generic motor and the bench data `data` encodes (`rows::small_rows`), or `None`
/// where the input encodes no rows.
pub fn small_case(data: &[u8]) -> Option<(Motor, BenchData)> {
    let motor = presets::find("generic60").expect("preset").motor();
    let m = rows::small_rows(&motor, data)?;
    let bench = observations(&m, &motor);
    Some((motor, bench))
}

/// The JSON document of `d` (a diagnosis of `motor` on `bench`), after asserting that the
/// gap's figures and every ranked entry's evidence, held-out NRMSE and shrink are finite,
/// that the verdict is `none`, `unexplained` or known effects joined by `+`, and that
/// every `separating_campaigns` entry starts from the lead (the single-effect verdict, or
/// `partial` with `unexplained`) and is of a rival kind that holds.
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
    let v = d.verdict.as_str();
    assert!(v == "none" || v == "unexplained" || v.split('+').all(|e| Effect::from_name(e).is_ok()), "{v}");
    let lead = if v == "unexplained" { d.partial.as_deref().unwrap_or(v) } else { v };
    for s in &d.separating_campaigns {
        assert_eq!(s.effects.0, lead, "{doc}");
        let rival = &s.effects.1;
        let confounded = d.confounded_with.contains(rival);
        match s.rival {
            trum_core::diagnose::separation::Rival::Confounded => assert!(confounded, "{doc}"),
            trum_core::diagnose::separation::Rival::CloseInEvidence => {
                assert!(!confounded && !rival.contains('+'), "{doc}")
            }
        }
    }
    doc
}
