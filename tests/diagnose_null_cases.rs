//! Data with no effect in them are `none`, also where the motor runs near an edge of its
//! behaviour and the bench's artefacts push a few readings across it (docs/DIAGNOSIS.md,
//! "The diagnosis, step by step").

use trum_core::diagnose::{diagnose, DiagnoseOptions};

/// A combined campaign of the effect-free `trum60-qut` motor file at its paper's drive,
/// whose stiff friction layer keeps the stator near clamping:
/// `tests/data/diagnose/trum60-qut_null_combined.csv`, written by `trum synth --motor
/// tests/data/motors/trum60-qut_baseline.toml --campaign combined --noise 1 --seed 515
/// --motor-seed 515 --artefacts readback_rel=0.004,speed_std_floor_rpm=0.3 --voltage-v 150
/// --frequency-hz 42000`. A few rows, their read-back set points taken at the run's mean,
/// fall on the other side of the edge from the motor that ran: a compliance fit follows
/// them (evidence in the thousands from those readings) and moves the held-out NRMSE by a
/// tenth, while the baseline's held-out mean z² is below one. No gap is shown in σ, and
/// the verdict is `none`.
#[test]
fn a_null_campaign_near_the_clamping_edge_is_none() {
    let root = env!("CARGO_MANIFEST_DIR");
    let path = format!("{root}/tests/data/diagnose/trum60-qut_null_combined.csv");
    let bytes = std::fs::read(&path).expect("test data");
    let m = trum_core::measurements::parse_measurements(&bytes, &path).expect("measurements");
    let motor_path = format!("{root}/tests/data/motors/trum60-qut_baseline.toml");
    let text = std::fs::read_to_string(&motor_path).expect("motor file");
    let motor = trum_core::Motor::from_toml_str(&text, &motor_path).expect("motor");
    let bench = trum_core::bench::observations(&m, &motor);
    let opts = DiagnoseOptions { bootstrap: 50, ..DiagnoseOptions::default() };
    let d = diagnose(&motor, &bench.rows, &bench.groups, &opts).expect("diagnosis");
    let ranked: Vec<(&str, f64, f64)> = d.ranking.iter().map(|r| (r.effect.as_str(), r.evidence, r.shrink)).collect();
    assert_eq!(d.verdict, "none", "ranking {ranked:?}");
    assert!(d.baseline_heldout_chi2_per_reading <= 1.0, "{}", d.baseline_heldout_chi2_per_reading);
}
