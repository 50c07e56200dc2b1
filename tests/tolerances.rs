//! The `[tolerances]` table of a motor file: the baseline calibration's priors
//! (docs/MOTOR_FILE.md, docs/DIAGNOSIS.md).

use trum_core::params::{tolerances_from_pairs, tolerances_from_toml_str};
use trum_core::Motor;

const MOTOR: &str = include_str!("data/motors/ring60.toml");

#[test]
fn dotted_keys_and_sub_tables_are_read_and_the_motor_still_reads() {
    let text = format!(
        "{MOTOR}\n[tolerances]\n\"geometry.neutral_plane_distance_m\" = 0.02\n\"stator.resonance_frequency_hz\" = 0\n\
         \"friction_layer.youngs_modulus_pa\" = inf\n[tolerances.electrical]\ndielectric_loss_tangent = 0.2\n"
    );
    let t = tolerances_from_toml_str(&text, "m.toml").expect("valid table");
    assert_eq!(t.get("geometry.neutral_plane_distance_m"), Some(&0.02));
    assert_eq!(t.get("stator.resonance_frequency_hz"), Some(&0.0));
    assert_eq!(t.get("friction_layer.youngs_modulus_pa"), Some(&f64::INFINITY));
    assert_eq!(t.get("electrical.dielectric_loss_tangent"), Some(&0.2));
    // the motor reader accepts the table (it ignores it)
    let m = Motor::from_toml_str(&text, "m.toml").expect("motor");
    assert_eq!(m, Motor::from_toml_str(MOTOR, "m.toml").expect("motor"));
    // without a table: no overrides
    assert!(tolerances_from_toml_str(MOTOR, "m.toml").expect("no table").is_empty());
}

#[test]
fn a_tolerance_on_a_parameter_that_is_not_fitted_or_negative_is_an_error_naming_it() {
    let unknown = format!("{MOTOR}\n[tolerances]\n\"rotor.mass_kg\" = 0.1\n");
    let e = tolerances_from_toml_str(&unknown, "m.toml").expect_err("rotor mass is not calibrated").to_string();
    assert!(e.contains("m.toml") && e.contains("tolerances.rotor.mass_kg") && e.contains("valid keys"), "{e}");
    // the line of a quoted dotted key (the form docs/MOTOR_FILE.md shows)
    let line = MOTOR.lines().count() + 3;
    assert!(e.starts_with(&format!("m.toml: line {line}, key ")), "{e}");
    let negative = format!("{MOTOR}\n[tolerances]\n\"geometry.mean_radius_m\" = -0.1\n");
    let e = tolerances_from_toml_str(&negative, "m.toml").expect_err("negative").to_string();
    assert!(e.contains("tolerances.geometry.mean_radius_m") && e.contains(">= 0"), "{e}");
}

#[test]
fn a_zero_tolerance_holds_the_parameter_and_others_keep_their_priors() {
    use trum_core::calibrate::{baseline_params, baseline_params_with, Observable, ObservedRow};
    let m = Motor::from_toml_str(MOTOR, "m.toml").expect("motor");
    let rows: Vec<ObservedRow> = (0..4)
        .map(|i| ObservedRow {
            op: trum_core::OperatingPoint::new(100.0 + 50.0 * i as f64, 0.0, 200.0, 43e3),
            readings: vec![(Observable::SpeedRpm, 100.0, 1.0)],
            ambient_c: 25.0,
            speed_std_clipped: false,
        })
        .collect();
    let all = baseline_params(&m, &rows);
    let held: std::collections::BTreeMap<String, f64> =
        [("stator.resonance_frequency_hz".to_string(), 0.0)].into_iter().collect();
    let fewer = baseline_params_with(&m, &rows, &held);
    assert_eq!(fewer.len() + 1, all.len());
    assert!(!fewer.iter().any(|p| p.param.name() == "stator.resonance_frequency_hz"));
    assert!(fewer.iter().all(|p| p.prior.is_some()));
}

#[test]
fn the_torque_offset_width_comes_from_the_table_and_zero_removes_it() {
    use trum_core::calibrate::{baseline_params_with, Observable, ObservedRow};
    let m = Motor::from_toml_str(MOTOR, "m.toml").expect("motor");
    // a load sweep whose smallest reading is not a tared zero
    let rows: Vec<ObservedRow> = (0..8)
        .map(|i| ObservedRow {
            op: trum_core::OperatingPoint::new(200.0, 0.002 + 0.04 * i as f64, 200.0, 43e3),
            readings: vec![(Observable::SpeedRpm, 100.0, 1.0)],
            ambient_c: 25.0,
            speed_std_clipped: false,
        })
        .collect();
    let offset = |t: &std::collections::BTreeMap<String, f64>| {
        baseline_params_with(&m, &rows, t).into_iter().find(|p| p.param.name() == "bench.torque_offset_nm")
    };
    let default = offset(&Default::default()).expect("an offset on a load sweep");
    // 1 % of the largest reading (0.282 N·m), bounded above by the smallest reading
    assert!((default.prior.expect("prior").sd - 0.00282).abs() < 1e-9, "{default:?}");
    assert!((default.hi - 0.002).abs() < 1e-12 && default.lo < -0.01, "{default:?}");
    let text = format!("{MOTOR}\n[tolerances]\n\"bench.torque_offset_nm\" = 0.001\n");
    let t = tolerances_from_toml_str(&text, "m.toml").expect("valid key");
    assert_eq!(offset(&t).expect("offset").prior.expect("prior").sd, 0.001);
    let held = tolerances_from_toml_str(&format!("{MOTOR}\n[tolerances]\n\"bench.torque_offset_nm\" = 0\n"), "m.toml")
        .expect("valid key");
    assert!(offset(&held).is_none());
}

#[test]
fn pairs_are_checked_as_the_tables_entries_are() {
    let ok = [("geometry.mean_radius_m".to_string(), 0.01), ("bench.speed_std_floor_rpm".to_string(), 0.0)];
    let t = tolerances_from_pairs(&ok, "tolerances").expect("valid pairs");
    assert_eq!(t.get("geometry.mean_radius_m"), Some(&0.01));
    assert_eq!(t.get("bench.speed_std_floor_rpm"), Some(&0.0));
    let e = tolerances_from_pairs(&[("rotor.mass_kg".into(), 0.1)], "tolerances").expect_err("unknown").to_string();
    assert!(e.starts_with("tolerances, key 'tolerances.rotor.mass_kg'") && e.contains("valid keys"), "{e}");
    let e = tolerances_from_pairs(&[("geometry.mean_radius_m".into(), f64::NAN)], "t").expect_err("nan").to_string();
    assert!(e.contains(">= 0"), "{e}");
}
