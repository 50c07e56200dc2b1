//! KNOWN BUGS: inputs for which trum does not yet do what it should. Each test fails
//! until the bug is fixed; then delete the file's line in
//! tests/data/bad/motor/known_bugs.txt (so the normal corpus tests cover it) and the test
//! here (or keep it as a regression test). See docs/RELIABILITY.md, "Bugs found".

use std::path::Path;
use trum_core::Motor;

fn corpus_file(name: &str) -> (String, String) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad/motor").join(name);
    let text = std::fs::read_to_string(&p).expect("corpus file");
    let exp = std::fs::read_to_string(p.with_extension("expected")).expect("expected file");
    (text, exp.trim_end_matches('\n').replace("{source}", "bad.toml"))
}

fn check(name: &str) {
    let (text, expected) = corpus_file(name);
    let got = Motor::from_toml_str_with_sweep(&text, "bad.toml").err().map(|e| e.to_string()).unwrap_or_default();
    assert_eq!(got, expected, "{name}");
}

/// params.rs, `Motor::from_toml_str`: for an unknown section header `[statr]` the key is
/// qualified with the "section above it", which is the header's own `[` → key '.statr'.
#[test]
fn known_bug_unknown_section_key_has_a_leading_dot() {
    check("unknown_section.toml");
}

/// params.rs, `AxisSpec` (`#[serde(untagged)]`): a `[sweep]` axis that is neither a
/// number nor `[start, stop, n]` reports "data did not match any variant of untagged
/// enum AxisSpec": a Rust type name, and no key.
#[test]
fn known_bug_sweep_axis_of_the_wrong_shape_leaks_a_type_name() {
    check("sweep_axis_two_numbers.toml");
    check("sweep_axis_string.toml");
}

// ------------------------------------------------------------------ solver

use proptest::prelude::*;
use trum_core::presets::PRESETS;

use trum_core::quantities::QUANTITIES;
use trum_core::solve::{solve_prepared, Prepared};
use trum_core::sweep::{solve_range, Axis, Grid};
use trum_core::{solve, OperatingPoint, Status};

#[path = "support/frozen.rs"]
mod frozen;
use frozen::preset;

/// solve.rs `solve_drive`: a warm start (what `trum map` and `trum.map` use) from the
/// previous grid point lands on the clamped branch although the point has a running
/// solution. `trum map --motor trum60a --preload-n 10:600:60 --torque-nm 0:2:41
/// --voltage-v 88 --frequency-hz 41300` writes `280,0,88,41300,clamped,0,...` while
/// `trum point --motor trum60a --preload-n 280 --voltage-v 88 --frequency-hz 41300` says
/// ok, 149.4 rpm. The baseline amplitude map has more than one fixed point here (W = 0
/// and the running branch), so starting below the middle one descends to W = 0.
#[test]
fn known_bug_warm_start_reports_clamped_where_the_motor_runs() {
    let m = preset("trum60a").expect("preset");
    let p = Prepared::new(&m);
    let prev = solve(&m, &OperatingPoint::new(270.0, 2.0, 88.0, 41_300.0));
    let op = OperatingPoint::new(280.0, 0.0, 88.0, 41_300.0);
    let cold = solve(&m, &op);
    let warm = solve_prepared(&p, &m, &op, Some(&prev));
    assert_eq!(cold.status, Status::Ok);
    assert_eq!(warm.status, cold.status, "warm {} cold {} ({} rpm)", warm.status, cold.status, cold.speed_rpm);
}

/// Same function: warm start ends in `no_convergence` where the cold solve converges
/// (`trum map --motor trum60a --preload-n 10:600:60 --torque-nm 0:2:41 --voltage-v 150
/// --frequency-hz 42000` has `440,0,150,42000,no_convergence`; `trum point` there: ok,
/// 29.0 rpm). And the reverse: the cold solve does not converge where the warm one finds
/// a stall (`trum point --motor generic60 --preload-n 470 --torque-nm 1.35 --voltage-v
/// 150 --frequency-hz 42000`: no_convergence after 82 evaluations; the map: stall).
/// Checks every point of four 60 x 41 maps against cold solves.
#[test]
fn known_bug_maps_and_points_disagree() {
    let mut bad = Vec::new();
    for name in trum_core::presets::PRESETS.iter().map(|p| p.name) {
        let m = preset(name).expect("preset");
        let p = Prepared::new(&m);
        for (hz, v) in [(41_300.0, 88.0), (40_750.0, 200.0), (43_000.0, 200.0), (42_000.0, 150.0)] {
            let g = Grid {
                preload_n: Axis::linspace(10.0, 600.0, 60),
                voltage_v: Axis::fixed(v),
                frequency_hz: Axis::fixed(hz),
                torque_nm: Axis::linspace(0.0, 2.0, 41),
            };
            solve_range(&m, &p, &g, 0..g.len(), |_, op, s| {
                let c = solve(&m, op);
                let same = c.status == s.status
                    || (c.status.is_valid()
                        && s.status.is_valid()
                        && (c.speed_rpm - s.speed_rpm).abs() <= 1e-6 * c.speed_rpm.abs().max(1.0));
                if !same {
                    bad.push(format!(
                        "{name} F={} T={} V={v} f={hz}: map {} cold {}",
                        op.preload_n, op.torque_nm, s.status, c.status
                    ));
                }
            });
        }
    }
    assert!(bad.is_empty(), "{} map points differ from `trum point`:\n{}", bad.len(), bad.join("\n"));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, failure_persistence: None, .. ProptestConfig::default() })]

    /// Warm starts give the cold answer (the solver's documented contract: "the result
    /// does not depend on the guess beyond the tolerance"), presets scaled 0.5-2x.
    /// Fails within a few hundred cases: no_convergence or another branch when warm.
    #[test]
    fn known_bug_warm_start_gives_another_answer(
        i in 0..PRESETS.len(),
        scale in proptest::collection::vec(-1.0f64..1.0, 4),
        f in 5.0f64..600.0, t in 0.0f64..2.0, v in 30.0f64..300.0, rel in 0.97f64..1.5,
        dt in 0.0f64..0.3, df in 0.95f64..1.05,
    ) {
        let mut m = PRESETS[i].motor();
        for (k, e) in ["geometry.neutral_plane_distance_m", "friction_layer.friction_coefficient",
                       "stator.force_factor_n_per_v", "stator.modal_damping_ns_per_m"].iter().zip(scale) {
            *m.param_mut(k).expect("key") *= 2f64.powf(e);
        }
        let op = OperatingPoint::new(f, t, v, m.stator.resonance_frequency_hz * rel);
        let cold = solve(&m, &op);
        let mut nb = op;
        nb.torque_nm += dt;
        nb.preload_n *= df;
        let p = Prepared::new(&m);
        let guess = solve_prepared(&p, &m, &nb, None);
        prop_assume!(guess.status.is_valid() && cold.status.is_valid());
        let warm = solve_prepared(&p, &m, &op, Some(&guess));
        prop_assert!(warm.status == cold.status, "warm {} cold {} at {:?} (guess at {:?}) of\n{}", warm.status, cold.status, op, nb, m.to_toml());
        let rel = (warm.speed_rpm - cold.speed_rpm).abs() / cold.speed_rpm.abs().max(1e-6);
        prop_assert!(rel <= 1e-6, "warm {} cold {} rpm at {:?}", warm.speed_rpm, cold.speed_rpm, op);
    }
}

/// solve.rs `finish`: a valid status (ok, stall, clamped) with NaN or infinite numbers,
/// for a motor that passes `Motor::validate` and a valid operating point. Nothing checks
/// the outputs are finite before the status is set; extreme inputs overflow or underflow.
/// `trum point --motor trum60a --preload-n 250 --voltage-v 1e-300` prints "status ok"
/// and exits 0 with input_power_w and current_a "-"; `trum map` writes status ok with
/// empty cells. Found by the fuzzer (fuzz/, target solver) and reduced by hand.
#[test]
fn known_bug_valid_status_with_non_finite_numbers() {
    let cases: &[(&str, &str, f64, OperatingPoint)] = &[
        ("trum60a", "", 0.0, OperatingPoint::new(250.0, 0.0, 1e-300, 43_000.0)),
        ("trum60a", "", 0.0, OperatingPoint::new(250.0, 0.3, 1e-300, 43_000.0)),
        ("trum60a", "", 0.0, OperatingPoint::new(250.0, 0.0, 1e200, 43_000.0)),
        ("trum60a", "", 0.0, OperatingPoint::new(250.0, 0.0, 1e308, 43_000.0)),
        ("trum60a", "stator.force_factor_n_per_v", 1e-300, OperatingPoint::new(250.0, 0.0, 200.0, 43_000.0)),
        ("trum60a", "stator.resonance_frequency_hz", 1e200, OperatingPoint::new(250.0, 0.0, 200.0, 43_000.0)),
        ("trum60a", "electrical.dielectric_loss_tangent", 1e308, OperatingPoint::new(250.0, 0.0, 200.0, 43_000.0)),
        ("trum60a", "geometry.mean_radius_m", 1e300, OperatingPoint::new(250.0, 0.0, 200.0, 43_000.0)),
        (
            "trum60a",
            "thermal.heat_transfer_coefficient_w_per_m2k",
            1e-320,
            OperatingPoint::new(250.0, 0.0, 200.0, 43_000.0),
        ),
    ];
    let mut bad = Vec::new();
    for (name, key, value, op) in cases {
        let mut m = preset(name).expect("preset");
        if !key.is_empty() {
            *m.param_mut(key).expect("key") = *value;
        }
        assert!(m.validate("x", None).is_ok() && op.invalid_reason().is_none());
        let s = solve(&m, op);
        let nonfinite: Vec<String> = QUANTITIES
            .iter()
            .filter(|q| !(q.get)(&s).is_finite())
            .map(|q| format!("{}={}", q.name, (q.get)(&s)))
            .collect();
        if s.status.is_valid() && !nonfinite.is_empty() {
            bad.push(format!("{name} {key}={value:e} at {op:?}: status {} with {}", s.status, nonfinite.join(" ")));
        }
    }
    assert!(bad.is_empty(), "{} case(s):\n{}", bad.len(), bad.join("\n"));
}

/// solve.rs `solve_effects` (candidate form of `thermal_drift`): μ·(1 + b·ΔT) and
/// k·(1 + a·ΔT) are not kept positive. With b = -0.05 /K (inside the effect's valid range
/// [-0.05, 0.05]) the friction coefficient turns negative past 20 K of heating, and the
/// solver reports status `stall` (valid) with a negative stall torque at zero load:
/// `trum point --motor trum60a --effect
/// thermal_drift:stiffness_coefficient_per_k=-0.0004,friction_coefficient_per_k=-0.05
/// --preload-n 250 --voltage-v 400 --elapsed-s 3600` prints stall, stall_torque_nm
/// -2.42349, temperature rise 46.2 K, exit 0. Found by
/// `effects_keep_status_and_numbers_consistent` (tests/reliability_props.rs).
#[test]
fn known_bug_thermal_drift_makes_friction_negative() {
    let mut m = preset("trum60a").expect("preset");
    m.effects.set(trum_core::Effect::ThermalDrift, &[-0.0004, -0.05]);
    assert!(m.validate("x", None).is_ok());
    let mut op = OperatingPoint::new(250.0, 0.0, 400.0, 43_000.0);
    op.elapsed_s = 3600.0;
    let s = solve(&m, &op);
    assert!(
        !s.status.is_valid() || s.stall_torque_nm >= 0.0,
        "status {} with stall torque {} N·m (temperature rise {} K)",
        s.status,
        s.stall_torque_nm,
        s.temperature_rise_at_elapsed_k
    );
}
