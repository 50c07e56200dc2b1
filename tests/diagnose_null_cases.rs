//! Data with no effect in them are `none`, also where the motor runs near an edge of its
//! behaviour and the bench's artefacts push a few readings across it, and where a fit of
//! the baseline from the nominal motor alone stops in another valley of its parameters
//! (docs/DIAGNOSIS.md, "The diagnosis, step by step").

use trum_core::diagnose::{diagnose, DiagnoseOptions, Diagnosis};

/// The diagnosis of `tests/data/diagnose/<file>` against the effect-free `trum60-qut` motor
/// file with the `[tolerances]` of `tolerances` (dotted key, prior standard deviation), with
/// its ranking as (effect, evidence, shrink) for the messages.
fn diagnosed(file: &str, tolerances: &[(&str, f64)]) -> (Diagnosis, Vec<(String, f64, f64)>) {
    diagnosed_against("trum60-qut_baseline.toml", file, tolerances)
}

/// [`diagnosed`] against `tests/data/motors/<motor_file>`.
fn diagnosed_against(motor_file: &str, file: &str, tolerances: &[(&str, f64)]) -> (Diagnosis, Vec<(String, f64, f64)>) {
    let root = env!("CARGO_MANIFEST_DIR");
    let path = format!("{root}/tests/data/diagnose/{file}");
    let bytes = std::fs::read(&path).expect("test data");
    let m = trum_core::measurements::parse_measurements(&bytes, &path).expect("measurements");
    let motor_path = format!("{root}/tests/data/motors/{motor_file}");
    let text = std::fs::read_to_string(&motor_path).expect("motor file");
    let motor = trum_core::Motor::from_toml_str(&text, &motor_path).expect("motor");
    let bench = trum_core::bench::observations(&m, &motor);
    let opts = DiagnoseOptions {
        bootstrap: 50,
        tolerances: tolerances.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
        ..DiagnoseOptions::default()
    };
    let d = diagnose(&motor, &bench.rows, &bench.groups, &opts).expect("diagnosis");
    let ranked = d.ranking.iter().map(|r| (r.effect.clone(), r.evidence, r.shrink)).collect();
    (d, ranked)
}

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
    let (d, ranked) = diagnosed("trum60-qut_null_combined.csv", &[]);
    assert_eq!(d.verdict, "none", "ranking {ranked:?}");
    assert!(d.baseline_heldout_chi2_per_reading <= 1.0, "{}", d.baseline_heldout_chi2_per_reading);
}

/// Preload-torque campaigns of two `trum60-qut` motors (parameters perturbed by 3 %, seeds
/// 14152 and 17451) at its paper's drive: `tests/data/diagnose/trum60-qut_null_preload_torque_<seed>.csv`,
/// written by `trum synth --motor tests/data/motors/trum60-qut_baseline.toml --campaign
/// preload-torque --noise 1 --seed <seed> --artefacts readback_rel=0.004,speed_std_floor_rpm=0.3
/// --voltage-v 150 --frequency-hz 42000`. From the nominal motor a fit of the baseline stops
/// at 20-110 times the χ² the true motor's parameters reach (its resonance on the far side
/// of where the data put it), every candidate effect then gains evidence 150-240 by moving
/// the baseline out of that valley, and one was named with a held-out shrink of 0.01. The
/// calibration's search for starts (`Calibrate::search_starts`) reaches the true motor's
/// valley: the baseline predicts the held-out data at the noise and the verdict is `none`.
#[test]
fn a_baseline_that_a_plain_fit_leaves_in_another_valley_names_no_effect() {
    for seed in [14_152, 17_451] {
        let (d, ranked) = diagnosed(&format!("trum60-qut_null_preload_torque_{seed}.csv"), &[]);
        assert_eq!(d.verdict, "none", "seed {seed}: ranking {ranked:?}");
        assert!(d.baseline_heldout_chi2_per_reading < 2.0, "seed {seed}: {}", d.baseline_heldout_chi2_per_reading);
        // no candidate gains evidence by moving the baseline
        assert!(ranked.iter().all(|r| r.1 < 20.0), "seed {seed}: ranking {ranked:?}");
    }
}

/// A preload-torque campaign of a `trum60-qut` motor (parameters perturbed by 3 %, seed
/// 7152) at its paper's drive, written as those above with `--seed 7152`:
/// `tests/data/diagnose/trum60-qut_null_preload_torque_7152.csv`. Most rows are stalled;
/// one (line 50) turns at 61 rpm where one fold's baseline fit, not having seen it,
/// predicts the rotor at rest, and that single row is most of the baseline's held-out
/// NRMSE. A `radial_friction` fit (evidence 7.9) predicts it turning and took the NRMSE's
/// shrink to 0.53, nearly all of it from that row: a gain one operating point carries
/// supports no effect, and the verdict is `none`.
#[test]
fn a_held_out_gain_that_one_row_carries_names_no_effect() {
    let (d, ranked) = diagnosed("trum60-qut_null_preload_torque_7152.csv", &[]);
    assert_eq!(d.verdict, "none", "ranking {ranked:?}");
    // the premise: an effect's held-out shrink is large, and one row carries it
    let lead = d.ranking.iter().max_by(|a, b| a.shrink.total_cmp(&b.shrink)).expect("ranked");
    assert!(lead.shrink > 0.3 && lead.lone_row_shares.0 < 0.2, "{lead:?}");
}

/// A preload-torque campaign of the effect-free `trum60-qut` motor file at its paper's
/// drive whose power reading is 1 W high, a constant offset that no candidate's form has:
/// `tests/data/diagnose/trum60-qut_null_power_offset_1w.csv`, written by `trum synth --motor
/// tests/data/motors/trum60-qut_baseline.toml --campaign preload-torque --voltage-v 150
/// --frequency-hz 42000 --noise 1 --seed 3` with 1 W added to every `input_power_w`. At one
/// drive setting the power meter's phase error (`bench.power_phase_rad`) shifts the power
/// reading by δ·Q, nearly a constant there (Q ≈ 27 var, 0.48 W a degree), so the bench
/// model takes the offset as about 2° of phase error and the verdict is `none`. With the
/// meter held exact (a tolerance of 0) the same data are a gap that no candidate closes,
/// `unexplained`.
#[test]
fn a_power_reading_offset_is_the_meters_and_names_no_effect() {
    let file = "trum60-qut_null_power_offset_1w.csv";
    let (d, ranked) = diagnosed(file, &[]);
    assert_eq!(d.verdict, "none", "ranking {ranked:?}");
    let phase = d.baseline_params.iter().find(|p| p.0 == "bench.power_phase_rad").expect("the meter's phase").1;
    // 1 W over 27 var is 0.037 rad, the whole offset; the loss tangent, whose dielectric
    // loss moves the power as Q_c·δ does, takes its share within its prior
    assert!((0.01..0.045).contains(&phase), "phase {phase} rad");
    let (held, ranked) = diagnosed(file, &[("bench.power_phase_rad", 0.0)]);
    assert_eq!(held.verdict, "unexplained", "ranking {ranked:?}");
    assert!(held.baseline_params.iter().all(|p| p.0 != "bench.power_phase_rad"));
}

/// A preload-torque campaign of a `trum60a` motor whose parameters are perturbed by 6 %
/// (seed 9334), diagnosed against the effect-free `trum60a` motor file:
/// `tests/data/diagnose/trum60a_null_preload_torque_9334.csv`, written by `trum synth
/// --motor tests/data/motors/trum60a_baseline.toml --campaign preload-torque --noise 1
/// --seed 9334 --perturbation 0.06 --artefacts readback_rel=0.004,speed_std_floor_rpm=0.3`.
/// The power meter's phase error shifts every power reading by nearly one constant, which
/// the damping's loss can also supply; searched with the motor's parameters, a start that
/// moves it slides to its bound with the damping a tenth of its value, a valley that every
/// effect then leaves by being named (here `hertz_softening+preload_stiffening`). The
/// baseline's search runs without it and it joins from the motor's valley: the verdict is
/// `none`, the baseline predicts the held-out data at the noise, and the damping stays
/// within its prior.
#[test]
fn the_power_meters_phase_joins_the_baseline_from_the_motors_valley() {
    let (d, ranked) = diagnosed_against("trum60a_baseline.toml", "trum60a_null_preload_torque_9334.csv", &[]);
    assert_eq!(d.verdict, "none", "ranking {ranked:?}");
    assert!(d.baseline_heldout_chi2_per_reading < 1.5, "{}", d.baseline_heldout_chi2_per_reading);
    let get = |k: &str| d.baseline_params.iter().find(|p| p.0 == k).map(|p| p.1).expect(k);
    let phase = get("bench.power_phase_rad");
    assert!(phase.abs() < 0.035, "phase {phase} rad, two degrees or more");
    let nominal = 10.0; // stator.modal_damping_ns_per_m of trum60a_baseline.toml
    let damping = get("stator.modal_damping_ns_per_m");
    assert!((damping / nominal).ln().abs() < 0.5, "damping {damping} N·s/m");
}
