//! Each effect moves the observables in the direction its paper reports; every effect at
//! zero strength reproduces the baseline exactly; truth forms differ from candidate forms.

use trum_core::effects::{Effect, ALL};
use trum_core::{solve, Motor, OperatingPoint, Solution, Status};

/// The baseline motor the effects are switched on in: a frozen TRUM60A without effects
/// (tests/data/motors/trum60a_baseline.toml), independent of the presets' calibration.
fn baseline() -> Motor {
    let text = include_str!("data/motors/trum60a_baseline.toml");
    Motor::from_toml_str(text, "trum60a_baseline.toml").expect("frozen baseline motor")
}

fn with(effect: Effect, params: &[f64]) -> Motor {
    let mut m = baseline();
    m.effects.set(effect, params);
    m
}

fn typical(effect: Effect) -> Motor {
    let mut m = baseline();
    m.effects.set_strength(effect, effect.info().params[0].typical);
    m
}

fn at(m: &Motor, f: f64, t: f64) -> Solution {
    solve(m, &OperatingPoint::new(f, t, 200.0, 43e3))
}

#[test]
fn zero_strength_reproduces_the_baseline_exactly() {
    let base = baseline();
    for e in ALL {
        for (truth, form_b) in [(false, false), (true, false), (true, true)] {
            let mut m = with(e, &[0.0, 0.0]);
            m.effects.set_truth_forms(truth);
            if form_b {
                m.effects.set_truth_form_b(true);
            }
            for (f, t) in [(150.0, 0.0), (250.0, 0.4), (400.0, 0.2)] {
                let mut op = OperatingPoint::new(f, t, 200.0, 43e3);
                op.elapsed_s = 100.0;
                let (a, b) = (solve(&base, &op), solve(&m, &op));
                assert_eq!(a.status, b.status, "{e}");
                for q in trum_core::quantities::QUANTITIES {
                    let (x, y) = ((q.get)(&a), (q.get)(&b));
                    assert!(x == y || (x.is_nan() && y.is_nan()), "{e} truth={truth}: {} {x} vs {y}", q.name);
                }
            }
        }
    }
}

/// the radial-friction paper: radial friction is over half the interface loss at low torque, and
/// neglecting it over-predicts no-load speed and stall torque.
#[test]
fn radial_friction_matches_seed002_claims() {
    let base = baseline();
    let m = typical(Effect::RadialFriction);
    for t in [0.0, 0.2, 0.35] {
        let s = at(&m, 250.0, t);
        assert!(
            s.radial_friction_loss_w > 0.5 * s.friction_loss_w,
            "T={t}: {} of {}",
            s.radial_friction_loss_w,
            s.friction_loss_w
        );
    }
    let (b, r) = (at(&base, 250.0, 0.0), at(&m, 250.0, 0.0));
    assert!(r.speed_rpm < b.speed_rpm - 5.0, "{} vs {}", r.speed_rpm, b.speed_rpm);
    assert!(r.stall_torque_nm < b.stall_torque_nm);
    let bal = r.input_power_w - r.output_power_w - r.total_loss_w();
    assert!(bal.abs() < 1e-6 * r.input_power_w, "power balance {bal}");
}

fn speed_optimal_frequency(m: &Motor, f_n: f64) -> f64 {
    // golden-section search of the no-load speed over 39.5-42.5 kHz
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let speed = |hz: f64| solve(m, &OperatingPoint::new(f_n, 0.0, 200.0, hz)).speed_rpm;
    let (mut a, mut b) = (39_500.0, 42_500.0);
    for _ in 0..60 {
        let (x1, x2) = (b - g * (b - a), a + g * (b - a));
        if speed(x1) > speed(x2) {
            b = x2
        } else {
            a = x1
        }
    }
    0.5 * (a + b)
}

/// Sun et al. 2021 eq. 8/14, the radial-friction paper section 5.3: the contact stiffens the mode, so the
/// speed-optimal frequency moves up with preload (the baseline's does not move).
#[test]
fn preload_stiffening_moves_the_optimal_frequency_up_with_preload() {
    let base = baseline();
    let b = speed_optimal_frequency(&base, 300.0) - speed_optimal_frequency(&base, 100.0);
    let m = typical(Effect::PreloadStiffening);
    let s = speed_optimal_frequency(&m, 300.0) - speed_optimal_frequency(&m, 100.0);
    assert!(b.abs() < 2.0, "baseline shift {b} Hz");
    assert!(s > 10.0, "shift {s} Hz");
    let s1 = at(&m, 250.0, 0.0);
    assert!(s1.modal_stiffness_n_per_m > at(&base, 250.0, 0.0).modal_stiffness_n_per_m);
}

/// the Hertzian driving-circuit paper (2022): the softening cubic term lowers the resonance, more at higher voltage.
#[test]
fn hertz_softening_shifts_resonance_down_with_amplitude() {
    let base = baseline();
    let m = typical(Effect::HertzSoftening);
    let fb = speed_optimal_frequency(&base, 200.0);
    let fs = speed_optimal_frequency(&m, 200.0);
    assert!(fs < fb - 50.0, "{fs} vs {fb}");
    let lo = solve(&m, &OperatingPoint::new(200.0, 0.0, 100.0, 43e3)).modal_stiffness_n_per_m;
    let hi = solve(&m, &OperatingPoint::new(200.0, 0.0, 250.0, 43e3)).modal_stiffness_n_per_m;
    assert!(hi < lo, "softening grows with voltage: {hi} vs {lo}");
}

/// the Hertzian driving-circuit paper (2022) section 3: a softening stator has a band below its linear resonance where
/// three steady amplitudes coexist (the middle one unstable); the band widens towards
/// lower frequencies with the drive voltage; outside it, and without the effect, there is
/// one. The solver's amplitude is always one of the stable branches.
#[test]
fn hertz_softening_has_a_multivalued_band_with_jump_frequencies() {
    use trum_core::solve::{amplitude_branches, jump_frequencies_hz};
    let m = with(Effect::HertzSoftening, &[1e18, 0.004]);
    let op = |v: f64, f: f64| OperatingPoint::new(250.0, 0.0, v, f);
    let b = amplitude_branches(&m, &op(200.0, 37e3));
    assert_eq!(b.len(), 3, "{b:?}");
    assert_eq!(b.iter().map(|x| x.stable).collect::<Vec<_>>(), [true, false, true]);
    assert!(b[0].amplitude_m < b[1].amplitude_m && b[1].amplitude_m < b[2].amplitude_m);
    for f in [37e3, 41e3, 44e3] {
        let s = solve(&m, &op(200.0, f));
        let stable: Vec<f64> =
            amplitude_branches(&m, &op(200.0, f)).iter().filter(|x| x.stable).map(|x| x.amplitude_m).collect();
        assert!(
            stable.iter().any(|w| (w - s.amplitude_m).abs() <= 1e-8 * w),
            "{f} Hz: solver {} not on a stable branch {stable:?}",
            s.amplitude_m
        );
    }
    assert_eq!(amplitude_branches(&m, &op(200.0, 41e3)).len(), 1);
    // The band lies below the linear resonance (40.75 kHz) and its upper edge (jump-up)
    // moves down with voltage. Its lower edge lies below the scan: the cubic term keeps
    // the upper branch alive as long as ¾βW² can cancel k − mω² (docs/EFFECTS.md).
    let fr = m.stator.resonance_frequency_hz;
    let (down2, up2) = jump_frequencies_hz(&m, &op(200.0, 0.0), 30e3, 46e3, 160).expect("a band at 200 V");
    let (_, up1) = jump_frequencies_hz(&m, &op(100.0, 0.0), 30e3, 46e3, 160).expect("a band at 100 V");
    assert!(down2 == 30e3 && up2 < fr, "{down2} {up2} {fr}");
    assert!(up2 < up1 - 500.0, "jump-up at 200 V {up2} vs 100 V {up1}");
    // at the edge the count of stable branches changes
    let stable_at = |f: f64| amplitude_branches(&m, &op(200.0, f)).iter().filter(|x| x.stable).count();
    assert_eq!((stable_at(up2 - 1.0), stable_at(up2 + 1.0)), (2, 1));
    // no softening, no band
    let base = baseline();
    assert_eq!(jump_frequencies_hz(&base, &op(200.0, 0.0), 30e3, 46e3, 160), None);
}

/// Chen et al. 2020 eq. 11 and section 4.2: the motor warms over a run and the speed drifts down.
#[test]
fn thermal_drift_makes_speed_fall_over_a_run() {
    let m = typical(Effect::ThermalDrift);
    let mut prev = f64::INFINITY;
    for t in [0.0, 30.0, 120.0, 600.0] {
        let mut op = OperatingPoint::new(250.0, 0.3, 200.0, 43e3);
        op.elapsed_s = t;
        let s = solve(&m, &op);
        assert!(s.speed_rpm < prev || t == 0.0, "t={t}: {} after {prev}", s.speed_rpm);
        prev = s.speed_rpm;
        if t > 0.0 {
            assert!(s.temperature_rise_at_elapsed_k > 0.0);
        }
    }
}

/// `thermal_drift`'s damping term: a stator whose damping grows as it warms (its
/// mechanical quality factor falls) loses amplitude, so more damping loss per amplitude²
/// and a lower speed late in a run; each of the three coefficients acts on its own.
#[test]
fn thermal_drift_damping_grows_with_temperature_and_slows_the_rotor() {
    let run = |coefs: &[f64], t: f64| {
        let mut m = baseline();
        m.effects.set(Effect::ThermalDrift, coefs);
        let mut op = OperatingPoint::new(250.0, 0.3, 200.0, 43e3);
        op.elapsed_s = t;
        solve(&m, &op)
    };
    let (cold, warm) = (run(&[0.0, 0.0, 5e-3], 0.0), run(&[0.0, 0.0, 5e-3], 600.0));
    assert!(warm.temperature_rise_at_elapsed_k > 1.0, "{}", warm.temperature_rise_at_elapsed_k);
    assert!(warm.amplitude_m < cold.amplitude_m && warm.speed_rpm < cold.speed_rpm);
    // damping loss = c·ω²·W²: the effective damping coefficient rose by the linear law
    let c_eff = |s: &Solution| s.damping_loss_w / s.amplitude_m.powi(2);
    let expected = 1.0 + 5e-3 * warm.temperature_rise_at_elapsed_k;
    assert!(
        (c_eff(&warm) / c_eff(&cold) / expected - 1.0).abs() < 1e-9,
        "{} vs {expected}",
        c_eff(&warm) / c_eff(&cold)
    );
    // each coefficient alone moves the warm point; together they differ from any one
    let alone: Vec<f64> =
        [[-4e-4, 0.0, 0.0], [0.0, -2e-3, 0.0], [0.0, 0.0, 2e-3]].iter().map(|c| run(c, 600.0).speed_rpm).collect();
    let base = run(&[0.0, 0.0, 0.0], 600.0).speed_rpm;
    for s in &alone {
        assert!((s - base).abs() > 1e-3 * base, "{alone:?} vs {base}");
    }
}

/// Sun et al. 2021 section 3.1: the electrode voltage falls as the load current grows with
/// preload and torque.
#[test]
fn voltage_sag_grows_with_preload_and_torque() {
    let m = typical(Effect::VoltageSag);
    let a = at(&m, 100.0, 0.0);
    let b = at(&m, 350.0, 0.0);
    let c = at(&m, 350.0, 0.4);
    assert!(a.electrode_voltage_v < 200.0);
    assert!(b.electrode_voltage_v < a.electrode_voltage_v, "{} vs {}", b.electrode_voltage_v, a.electrode_voltage_v);
    assert!(c.electrode_voltage_v < b.electrode_voltage_v);
    assert!(at(&m, 250.0, 0.3).speed_rpm < at(&baseline(), 250.0, 0.3).speed_rpm);
}

/// Chen et al. 2020 section 4.3: an eccentric rotor makes the speed fluctuate once per revolution;
/// the fluctuation grows with the runout.
#[test]
fn eccentricity_makes_speed_fluctuate() {
    let base = at(&baseline(), 250.0, 0.2);
    assert_eq!(base.speed_std_rpm, 0.0);
    let s1 = at(&with(Effect::Eccentricity, &[10e-6]), 250.0, 0.2);
    let s2 = at(&with(Effect::Eccentricity, &[40e-6]), 250.0, 0.2);
    assert!(s1.speed_std_rpm > 0.0 && s2.speed_std_rpm > 2.0 * s1.speed_std_rpm);
    assert!((s1.speed_rpm - base.speed_rpm).abs() < 0.05 * base.speed_rpm);
    let bal = s2.input_power_w - s2.output_power_w - s2.total_loss_w();
    assert!(bal.abs() < 1e-8 * s2.input_power_w);
}

/// Storck and Wallaschek / the bar-type transient paper: shear compliance lets the contact slip partially
/// around the stick points, lowering the speed at every load and rounding the
/// speed–torque curve (no corner at stall).
#[test]
fn tangential_compliance_lowers_the_speed_torque_curve() {
    let base = baseline();
    let m = typical(Effect::TangentialCompliance);
    for t in [0.0, 0.3, 0.6] {
        let (b, c) = (at(&base, 250.0, t), at(&m, 250.0, t));
        assert!(c.speed_rpm < b.speed_rpm, "T={t}");
        assert!(c.status == Status::Ok || c.status == Status::Stall);
    }
    let s = at(&m, 250.0, 0.0);
    let bal = s.input_power_w - s.output_power_w - s.total_loss_w();
    assert!(bal.abs() < 1e-6 * s.input_power_w);
}

/// Load torque at which the speed at preload `f` falls to `frac` of its no-load value.
fn torque_at_speed_fraction(m: &Motor, f: f64, frac: f64) -> f64 {
    let v0 = at(m, f, 0.0).speed_rpm;
    let (mut lo, mut hi) = (0.0, 3.0);
    for _ in 0..60 {
        let t = 0.5 * (lo + hi);
        if at(m, f, t).speed_rpm > frac * v0 {
            lo = t;
        } else {
            hi = t;
        }
    }
    0.5 * (lo + hi)
}

/// The corner at stall: with Coulomb friction the whole contact drives once the stick
/// point leaves it, the torque stops rising as the rotor slows, and the last part of the
/// speed falls over a sliver of torque (only the rotor's viscous drag sets it). Shear
/// compliance keeps the traction rising as slip grows, so the curve runs into stall
/// more gradually. Measure: torque span of the last 10 % of speed over that of a 10 %
/// step in mid-curve (1 for a straight line, near 0 for a sharp corner). At 100 N the
/// contact is narrow and the baseline corner sharp (0.15); at high preload the contact
/// is wide and there is no corner to round, with or without compliance.
#[test]
fn tangential_compliance_rounds_the_stall_corner() {
    let corner = |m: &Motor| {
        let t = |frac| torque_at_speed_fraction(m, 100.0, frac);
        (t(1e-3) - t(0.1)) / (t(0.5) - t(0.6))
    };
    let compliant = |k: f64| {
        let mut m = baseline();
        m.effects.set_strength(Effect::TangentialCompliance, k);
        corner(&m)
    };
    let base = corner(&baseline());
    let (c1, c2) = (compliant(1.0), compliant(2.0));
    assert!(base < 0.25, "baseline corner ratio {base}");
    assert!(c1 > 2.0 * base, "typical compliance {c1} vs baseline {base}");
    assert!(c2 > c1, "more compliance, rounder corner: {c2} vs {c1}");
}

#[test]
fn truth_forms_differ_from_candidate_forms() {
    for e in ALL {
        let mut m = typical(e);
        let mut op = OperatingPoint::new(250.0, 0.3, 200.0, 43e3);
        op.elapsed_s = 120.0;
        let cand = solve(&m, &op);
        m.effects.set_truth_forms(true);
        let truth = solve(&m, &op);
        m.effects.set_truth_form_b(true);
        let truth_b = solve(&m, &op);
        let differs = |a: &Solution, b: &Solution| {
            (a.speed_rpm - b.speed_rpm).abs() > 1e-6 * a.speed_rpm
                || (a.speed_std_rpm - b.speed_std_rpm).abs() > 1e-9
                || (a.electrode_voltage_v - b.electrode_voltage_v).abs() > 1e-9
        };
        assert!(differs(&cand, &truth), "{e}: truth form equals candidate form");
        assert!(differs(&cand, &truth_b), "{e}: second truth form equals candidate form");
        assert!(differs(&truth, &truth_b), "{e}: second truth form equals the first");
    }
}

/// The second truth forms are a motor-file setting too, and read back.
#[test]
fn the_second_truth_forms_read_back_from_a_motor_file() {
    let mut m = typical(Effect::VoltageSag);
    m.effects.set_truth_form_b(true);
    let text = m.to_toml();
    assert!(text.contains("form = \"truth-b\""), "{text}");
    let back = Motor::from_toml_str(&text, "m.toml").expect("reads back");
    assert!(back.effects.truth_form_b());
    assert_eq!(back.effects, m.effects);
}
