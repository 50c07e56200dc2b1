//! A diagnosis must not depend on how a file lists its rows: data without `run_id`, in a
//! random order (as a designed experiment runs its points), say what the same data with
//! their runs named say. The bench model infers runs from the set points' levels and keeps
//! a sweep whose rows show no trend in file order (docs/DIAGNOSIS.md, "The bench model").

use trum_core::calibrate::ObservedRow;
use trum_core::diagnose::{diagnose, DiagnoseOptions};
use trum_core::synth::{synthesize, Artefacts, Campaign, SynthConfig};

#[path = "support/blind.rs"]
mod blind;

/// Null data of the combined campaign with read-back set points: rows with their runs
/// named, and the same rows without names in a fixed pseudo-random order.
fn null_data(seed: u64) -> (Vec<ObservedRow>, Vec<String>, Vec<ObservedRow>) {
    let cfg = SynthConfig {
        campaign: Campaign::from_name("combined").expect("campaign"),
        noise: 1.0,
        seed,
        artefacts: Artefacts::parse("readback_rel=0.004,speed_std_floor_rpm=0.3").expect("artefacts"),
        ..SynthConfig::default()
    };
    let rows = synthesize(&blind::nominal(), &cfg).expect("synth");
    let observed: Vec<ObservedRow> = rows.iter().map(|r| r.observed()).collect();
    let groups: Vec<String> = rows.iter().map(|r| r.run_id.clone()).collect();
    let n = observed.len();
    // 37 is prime to every campaign size here: a permutation that interleaves all runs
    let shuffled: Vec<ObservedRow> = (0..n).map(|i| observed[(i * 37 + 11) % n].clone()).collect();
    (observed, groups, shuffled)
}

fn verdict_and_gap(rows: &[ObservedRow], groups: &[String]) -> (String, f64) {
    let opts = DiagnoseOptions { bootstrap: 50, ..DiagnoseOptions::default() };
    let d = diagnose(&blind::nominal(), rows, groups, &opts).expect("diagnosis");
    (d.verdict, d.baseline_heldout_chi2_per_reading)
}

#[test]
fn null_data_without_runs_in_random_order_need_no_effect() {
    let (named, groups, shuffled) = null_data(11);
    let (v_named, z_named) = verdict_and_gap(&named, &groups);
    let (v_bare, z_bare) = verdict_and_gap(&shuffled, &vec![String::new(); shuffled.len()]);
    assert_eq!(v_named, "none");
    assert_eq!(v_bare, "none", "held-out χ² per reading {z_bare} (named runs: {z_named})");
    // the same data: the baseline's held-out misfit within 30 % of the named runs'
    assert!((z_bare / z_named - 1.0).abs() < 0.3, "{z_bare} vs {z_named}");
}
