//! The diagnosis on small data (4-8 rows, `common/rows.rs`) of the generic motor, in a
//! configuration the input chooses (its byte `data[1]`, which the rows do not read): one
//! or two candidate effects of the seven, or none (bits 0-2 and 3-5: an effect's index, 7
//! for none; the same effect twice is one), pairs tried or not (bit 6), 0 or 2 bootstrap
//! draws (bit 7), two folds. Every other option is the default's, so each stage of the
//! diagnosis runs as `trum diagnose` runs it: the baseline and its cross-validation, the
//! candidates' fits and scores, the pair fits (where two candidates and bit 6 ask for
//! them), the verdict, where the gap lies.
//! Properties: those of the `diagnose` target (no panic; the JSON's headline figures
//! finite, the verdict a known word), and the ranking and the verdict name only the
//! candidates asked for.
//!
//! Why a configuration: the `diagnose` target, with all seven candidates, four folds and
//! 20 bootstrap draws, takes 0.3-1 s an input; the fits of a diagnosis are each
//! candidate's and each fold's, so one or two candidates on two folds reach the same code
//! for about a tenth of the cost (docs/RELIABILITY.md, "Where 10^6 is out of reach").
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::diagnose::{diagnose, DiagnoseOptions};
use trum_core::effects::ALL;

#[path = "../common/diagnosis.rs"]
mod diagnosis;

fuzz_target!(|data: &[u8]| {
    let Some((motor, bench)) = diagnosis::small_case(data) else { return };
    let config = data[1];
    let mut candidates = Vec::new();
    for i in [config & 7, (config >> 3) & 7] {
        if let Some(&e) = ALL.get(usize::from(i)) {
            if !candidates.contains(&e) {
                candidates.push(e);
            }
        }
    }
    let opts = DiagnoseOptions {
        folds: 2,
        candidates: candidates.clone(),
        try_pairs: config & 64 != 0,
        bootstrap: if config & 128 != 0 { 2 } else { 0 },
        ..DiagnoseOptions::default()
    };
    if let Ok(d) = diagnose(&motor, &bench.rows, &bench.groups, &opts) {
        let doc = diagnosis::checked_json(&motor, &bench, &d);
        for r in doc["ranking"].as_array().expect("ranking") {
            let name = r["effect"].as_str().expect("effect");
            assert!(
                name.split('+').all(|e| candidates.iter().any(|c| c.name() == e)),
                "{name} not among {candidates:?}"
            );
        }
        let v = d.verdict.as_str();
        assert!(
            v == "none" || v == "unexplained" || v.split('+').all(|e| candidates.iter().any(|c| c.name() == e)),
            "{v} not among {candidates:?}"
        );
    }
});
