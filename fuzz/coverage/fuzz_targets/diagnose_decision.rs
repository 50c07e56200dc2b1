//! The diagnosis' decision stage alone (`trum_core::diagnose::fuzzing`, built with
//! `--cfg fuzzing`): the rows of `common/rows.rs` from the input's first 50 bytes, and
//! from the rest the figures fits would give (`fuzzing::case_from_bytes`: the baseline's
//! held-out gap, up to seven single effects and three pairs with their evidence, held-out
//! NRMSE and mean z², each shrink consistent with them, and bootstrap intervals, their
//! held-out predictions, the singles' full-data residuals and signatures). A whole
//! diagnosis reaches this stage a few times a second; here it runs at thousands of inputs
//! a second, and on figures that fits seldom give (ties at the thresholds, intervals
//! straddling zero, pairs worse than their singles).
//! Properties: no panic; the same input decides the same; and `fuzzing::assert_properties`
//! (the verdict's rules whatever the figures).
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::diagnose::fuzzing::{assert_properties, case_from_bytes, decide};
use trum_core::presets;

#[path = "../common/rows.rs"]
mod rows;

fuzz_target!(|data: &[u8]| {
    let motor = presets::find("generic60").expect("preset").motor();
    let split = data.len().min(50);
    let Some(m) = rows::small_rows(&motor, &data[..split]) else { return };
    let bench = trum_core::bench::observations(&m, &motor);
    let (figures, opts) = case_from_bytes(&bench.rows, &data[split..]);
    let Ok(d) = decide(&motor, &bench.rows, &bench.groups, &opts, figures.clone()) else { return };
    assert_properties(&figures, &d);
    let again = decide(&motor, &bench.rows, &bench.groups, &opts, figures).ok();
    assert_eq!(again.as_ref(), Some(&d), "not deterministic");
});
