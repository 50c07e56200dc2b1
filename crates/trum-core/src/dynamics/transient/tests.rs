use super::*;
use crate::presets::frozen as preset;
use crate::solve::{solve, OperatingPoint, Status};

fn motor() -> Motor {
    preset("trum60a").expect("preset")
}

/// Short, coarse run used by most tests (64 nodes, 3-4 ms).
fn cfg(ratio: f64, spp: usize) -> TransientConfig {
    TransientConfig {
        duration_s: 4e-3,
        steps_per_period: spp,
        nodes_per_wavelength: 64,
        tangential_stiffness_ratio: ratio,
        record_every: 8,
        ..TransientConfig::default()
    }
}

fn run(c: &TransientConfig) -> StepResponse {
    step_response(&motor(), c).expect("run")
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The transient model converges to the rigid-Coulomb steady model as the layer's
/// tangential stiffness k_t → ∞, with error ∝ k_t^(-1/2) (stick bands of width
/// ∝ √(μ·k_f/k_t) at the two stick points). Checked with and without load.
#[test]
fn settles_on_the_steady_solution_as_the_layer_stiffens() {
    for load in [0.0, 0.3] {
        let op = OperatingPoint::new(260.0, load, 200.0, 43e3);
        let s = solve(&motor(), &op);
        assert_eq!(s.status, Status::Ok);
        let soft = run(&TransientConfig { load_torque_nm: load, ..cfg(300.0, 128) }).averages;
        let stiff = run(&TransientConfig { load_torque_nm: load, ..cfg(1200.0, 256) }).averages;
        let (e_soft, e_stiff) = (rel(soft.speed_rpm, s.speed_rpm), rel(stiff.speed_rpm, s.speed_rpm));
        // direct agreement of the stiff layer: 5 % on speed and amplitude
        assert!(e_stiff < 0.05, "load {load}: speed {} vs steady {}", stiff.speed_rpm, s.speed_rpm);
        assert!(rel(stiff.amplitude_m, s.amplitude_m) < 0.05, "{} vs {}", stiff.amplitude_m, s.amplitude_m);
        // the error halves when k_t is quadrupled (k_t^(-1/2)) ...
        let ratio = e_soft / e_stiff;
        assert!((1.5..2.6).contains(&ratio), "load {load}: error ratio {ratio}");
        // ... so the extrapolated rigid limit 2·v(4k) − v(k) matches the steady model to 1.5 %
        let limit = 2.0 * stiff.speed_rpm - soft.speed_rpm;
        assert!(rel(limit, s.speed_rpm) < 0.015, "load {load}: limit {limit} vs {}", s.speed_rpm);
        // the contact's mean torque balances load + rotor viscous torque of the steady speed
        let steady_torque = load + motor().rotor.viscous_damping_nms * s.speed_rad_s;
        assert!(rel(stiff.contact_torque_nm, steady_torque) < 0.05, "{} vs {steady_torque}", stiff.contact_torque_nm);
        // axial equilibrium: mean contact force = preload (+ k_sp·Δz, < 0.1 %)
        assert!(rel(stiff.axial_force_n, 260.0) < 2e-3, "{}", stiff.axial_force_n);
    }
}

/// Time-step and node-count study at the default stiffness ratio: halving h or doubling
/// the node count moves the settled speed by < 0.5 %.
#[test]
fn converges_in_time_step_and_node_count() {
    let base = run(&cfg(300.0, 128)).averages.speed_rpm;
    let fine_t = run(&cfg(300.0, 256)).averages.speed_rpm;
    let fine_x = run(&TransientConfig { nodes_per_wavelength: 128, ..cfg(300.0, 128) }).averages.speed_rpm;
    assert!(rel(fine_t, base) < 5e-3, "{fine_t} vs {base}");
    assert!(rel(fine_x, base) < 5e-3, "{fine_x} vs {base}");
}

/// 0° phase difference drives a standing wave: no net rotation (the bar-type transient paper, section III.C);
/// −90° reverses the rotor.
#[test]
fn standing_wave_does_not_turn_the_rotor_and_minus_90_reverses() {
    let fwd = run(&TransientConfig { duration_s: 3e-3, ..cfg(300.0, 64) });
    let standing = run(&TransientConfig { duration_s: 3e-3, phase_difference_rad: 0.0, ..cfg(300.0, 64) });
    let back =
        run(&TransientConfig { duration_s: 3e-3, phase_difference_rad: -0.5 * std::f64::consts::PI, ..cfg(300.0, 64) });
    let v = fwd.averages.speed_rpm;
    assert!(v > 50.0, "{v}");
    let peak = standing.series.speed_rpm.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    assert!(peak < 1e-3 * v, "standing wave moved the rotor: peak {peak} rpm");
    assert!(standing.averages.amplitude_m > 0.5 * fwd.averages.amplitude_m, "the stator still vibrates");
    assert!(rel(-back.averages.speed_rpm, v) < 1e-6, "{} vs {v}", back.averages.speed_rpm);
    assert!(standing.metrics.delay_s.is_none());
    assert_eq!(standing.metrics.status(), "not_moving");
    // the reversed wave is motion the other way, with the forward run's step figures
    assert_eq!(back.metrics.status(), fwd.metrics.status());
    assert!(back.metrics.final_speed_rpm < -50.0 && back.metrics.peak_speed_rpm < back.metrics.final_speed_rpm);
    let (d_back, d_fwd) = (back.metrics.delay_s.expect("delay"), fwd.metrics.delay_s.expect("delay"));
    assert!((d_back - d_fwd).abs() < 1e-3 * d_fwd, "{d_back} vs {d_fwd}");
}

/// The steady comparison takes the wave's direction: at −90° (no load) it is the +90°
/// solution mirrored, negative speed and contact torque, and the reversed transient lies
/// as close to it as the forward one to its own; a phase with a standing part, or a load
/// under the reversed wave, has no steady number at all.
#[test]
fn steady_comparison_follows_the_wave_and_leaves_out_what_it_does_not_describe() {
    use std::f64::consts::FRAC_PI_2;
    let m = motor();
    let c = TransientConfig { duration_s: 3e-3, ..cfg(300.0, 64) };
    let fwd = steady_comparison(&m, &c).expect("+90 deg is a travelling wave");
    let at = |deg: f64, load: f64| {
        steady_comparison(
            &m,
            &TransientConfig { phase_difference_rad: deg.to_radians(), load_torque_nm: load, ..c.clone() },
        )
    };
    let back = at(-90.0, 0.0).expect("-90 deg is a travelling wave");
    assert_eq!(fwd.status, Status::Ok);
    assert!(fwd.speed_rpm > 50.0 && fwd.contact_torque_nm > 0.0, "{fwd:?}");
    // the mirror image, exactly
    assert_eq!(back.status, fwd.status);
    assert_eq!(back.speed_rpm, -fwd.speed_rpm);
    assert_eq!(back.contact_torque_nm, -fwd.contact_torque_nm);
    assert_eq!(back.amplitude_m, fwd.amplitude_m);
    // -90 deg given in radians directly, and as +270 deg, is the same reversed wave
    let direct = steady_comparison(&m, &TransientConfig { phase_difference_rad: -FRAC_PI_2, ..c.clone() });
    assert_eq!(direct, Ok(back));
    assert_eq!(at(270.0, 0.0), Ok(back));
    // the transient runs settle on the same side of it: final/steady - 1 equal to 1e-6
    let (tf, tb) = (run(&c), run(&TransientConfig { phase_difference_rad: -FRAC_PI_2, ..c.clone() }));
    let (df, db) = (tf.averages.speed_rpm / fwd.speed_rpm - 1.0, tb.averages.speed_rpm / back.speed_rpm - 1.0);
    assert!(df > 0.0 && df < 0.15, "{df}");
    assert!((db - df).abs() < 1e-6, "reversed {db} vs forward {df}");
    let (qf, qb) =
        (tf.averages.contact_torque_nm / fwd.contact_torque_nm, tb.averages.contact_torque_nm / back.contact_torque_nm);
    assert!((qb - qf).abs() < 1e-6 && (qf - 1.0).abs() < 0.15, "{qb} vs {qf}");
    // a standing part (anything but +-90 deg) is outside the steady model
    for deg in [0.0, 45.0, -45.0, 89.0, 180.0] {
        match at(deg, 0.0) {
            Err(SteadyGap::StandingPart { phase_difference_deg: d }) => assert!((d - deg).abs() < 1e-9, "{d} vs {deg}"),
            other => panic!("{deg} deg: {other:?}"),
        }
    }
    // so is a load under the reversed wave (it turns with the rotor); +90 deg takes it
    assert_eq!(at(-90.0, 0.1), Err(SteadyGap::LoadAlongReversedRotation { load_torque_nm: 0.1 }));
    assert_eq!(at(90.0, 0.1).map(|s| s.status), Ok(Status::Ok));
}

/// Trends of the bar-type transient paper Fig. 3-5: speed grows with voltage and near resonance; the
/// response is a lightly damped second-order-like step with overshoot, settling in a few ms.
#[test]
fn step_metrics_follow_voltage_and_frequency() {
    let c = TransientConfig { duration_s: 5e-3, ..cfg(300.0, 64) };
    let base = run(&c);
    let m = base.metrics;
    let (delay, rise, over, settle) = (
        m.delay_s.expect("delay"),
        m.rise_time_s.expect("rise"),
        m.overshoot.expect("os"),
        m.settling_time_s.expect("ts"),
    );
    assert!(delay > 0.0 && delay < 1e-3, "{delay}");
    assert!(rise > 0.0 && rise < 1e-3, "{rise}");
    assert!(over > 0.05, "{over}");
    assert!(settle > delay && settle < 4e-3, "{settle}");
    let low_v = run(&TransientConfig { voltage_v: 150.0, ..c.clone() });
    assert!(low_v.averages.speed_rpm < 0.9 * base.averages.speed_rpm);
    let near = run(&TransientConfig { frequency_hz: 42.5e3, ..c.clone() });
    assert!(near.averages.speed_rpm > base.averages.speed_rpm);
    // each final speed lies above its own steady solution by the layer-compliance error
    // (k_t = 300·k_f: 6 % at 200 V, 13 % at 150 V where the stick bands are wider), < 15 %
    for (r, v, f) in [(&base, 200.0, 43e3), (&low_v, 150.0, 43e3), (&near, 200.0, 42.5e3)] {
        let s = solve(&motor(), &OperatingPoint::new(260.0, 0.0, v, f));
        let e = r.averages.speed_rpm / s.speed_rpm - 1.0;
        assert!(e > 0.0 && e < 0.15, "{v} V {f} Hz: {} vs {}", r.averages.speed_rpm, s.speed_rpm);
    }
}

/// Snapshots: full contact right after the step, stick/slip/no-contact zones once running,
/// Coulomb's bound everywhere, and the pressure integrates to the axial force.
#[test]
fn snapshots_show_the_contact_zones() {
    let c = TransientConfig { duration_s: 3e-3, snapshot_times_s: vec![2.9e-3, 0.02e-3], ..cfg(300.0, 64) };
    let r = run(&c);
    assert_eq!(r.snapshots.len(), 2);
    let (early, late) = (&r.snapshots[1], &r.snapshots[0]);
    assert!((early.requested_time_s - 0.02e-3).abs() < 1e-12);
    assert!((early.time_s - 0.02e-3).abs() <= 0.5 * r.time_step_s + 1e-15);
    assert_eq!(early.counts().0, 0, "full contact at start-up");
    let (nc, st, sl) = late.counts();
    assert!(nc > 0 && st > 0 && sl > 0, "{nc} {st} {sl}");
    let m = motor();
    let mu = m.friction_layer.friction_coefficient;
    let dx = late.nodes[1].position_m - late.nodes[0].position_m;
    let mut fz = 0.0;
    for n in &late.nodes {
        let bound = mu * n.pressure_n_per_m;
        assert!(n.tangential_force_n_per_m.abs() <= bound * (1.0 + 1e-9) + 1e-9, "{n:?}");
        match n.state {
            NodeState::NoContact => assert_eq!(n.pressure_n_per_m, 0.0),
            NodeState::Slip => {
                assert!(rel(n.tangential_force_n_per_m.abs(), bound) < 1e-9);
                // the friction force on the rotor follows the slip v_s − v_r (the bar-type transient paper eq. 1);
                // within one step of a slip reversal the node re-sticks first, so a mismatch
                // is only possible at slip speeds below |d(slip)/dt|·h ≈ 5 mm/s
                let agrees = n.tangential_force_n_per_m * n.slip_speed_m_s >= 0.0;
                assert!(agrees || n.slip_speed_m_s.abs() < 5e-3, "{n:?}");
            }
            NodeState::Stick => {}
        }
        fz += n.pressure_n_per_m * dx;
    }
    fz *= m.geometry.wave_number;
    assert!(rel(fz, 260.0) < 0.01, "{fz}");
}

#[test]
fn invalid_configurations_are_errors_not_panics() {
    let m = motor();
    let bad = [
        TransientConfig { voltage_v: -1.0, ..TransientConfig::default() },
        TransientConfig { frequency_hz: f64::NAN, ..TransientConfig::default() },
        TransientConfig { steps_per_period: 4, ..TransientConfig::default() },
        TransientConfig { nodes_per_wavelength: 2, ..TransientConfig::default() },
        TransientConfig { record_every: 0, ..TransientConfig::default() },
        TransientConfig { snapshot_times_s: vec![1.0], ..TransientConfig::default() },
        TransientConfig { preload_n: 0.0, ..TransientConfig::default() },
        TransientConfig { load_torque_nm: -0.1, ..TransientConfig::default() },
        TransientConfig { duration_s: 0.0, ..TransientConfig::default() },
        TransientConfig { tangential_stiffness_ratio: 0.0, ..TransientConfig::default() },
    ];
    for c in bad {
        assert!(matches!(step_response(&m, &c), Err(TransientError::InvalidConfig { .. })), "{c:?}");
    }
    let stiff = TransientConfig { tangential_stiffness_ratio: 1e5, ..TransientConfig::default() };
    assert!(matches!(step_response(&m, &stiff), Err(TransientError::StepTooLarge { .. })));
    // (a stiffness that would need more than MAX_STEP_REFINEMENT times the steps is refused)
    assert!(matches!(step_response_stable(&m, &stiff), Err(TransientError::StepTooLarge { .. })));
    // left to the tool, the step is refined until the scheme is stable: the run then
    // equals an explicit run at the steps it chose, which the coarser step refused
    let stiffer = TransientConfig { tangential_stiffness_ratio: 1e3, ..TransientConfig::default() };
    assert!(matches!(step_response(&m, &stiffer), Err(TransientError::StepTooLarge { .. })));
    let short = TransientConfig { duration_s: 2e-4, ..stiffer.clone() };
    let (auto, steps) = step_response_stable(&m, &short).expect("a stable step");
    assert!(steps > short.steps_per_period && steps % 16 == 0, "{steps}");
    let explicit = step_response(&m, &TransientConfig { steps_per_period: steps, ..short.clone() }).expect("explicit");
    assert_eq!(auto.series.speed_rpm, explicit.series.speed_rpm);
    let (_, same) =
        step_response_stable(&m, &TransientConfig { duration_s: 2e-4, ..TransientConfig::default() }).expect("run");
    assert_eq!(same, 64);
    let long = TransientConfig { duration_s: 1e4, ..TransientConfig::default() };
    assert!(matches!(step_response(&m, &long), Err(TransientError::TooManySteps { .. })));
    let mut bad_motor = m.clone();
    bad_motor.rotor.mass_kg = -1.0;
    assert!(matches!(step_response(&bad_motor, &TransientConfig::default()), Err(TransientError::InvalidMotor(_))));
}

/// Metrics against the closed forms of an underdamped second-order step
/// y = 1 − e^{−ζω t}/√(1−ζ²)·sin(ω_d t + acos ζ).
#[test]
fn metrics_match_second_order_closed_forms() {
    let (zeta, wn) = (0.3f64, 2.0e3f64);
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let t: Vec<f64> = (0..200_000).map(|i| i as f64 * 1e-7).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| 100.0 * (1.0 - (-zeta * wn * t).exp() / (1.0 - zeta * zeta).sqrt() * (wd * t + zeta.acos()).sin()))
        .collect();
    let m = step_metrics(&t, &y, 100.0);
    let os = (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
    assert!((m.overshoot.expect("os") - os).abs() < 1e-6, "{:?} vs {os}", m.overshoot);
    // delay: y(t_d) = 50
    let td = m.delay_s.expect("delay");
    let yd = 1.0 - (-zeta * wn * td).exp() / (1.0 - zeta * zeta).sqrt() * (wd * td + zeta.acos()).sin();
    assert!((yd - 0.5).abs() < 1e-6, "{yd}");
    // settling: the envelope bound 4/(ζω_n) is an upper bound; the true 2 % time lies below it
    let ts = m.settling_time_s.expect("ts");
    assert!(ts < 4.0 / (zeta * wn) && ts > 2.0 / (zeta * wn), "{ts}");
    assert!(m.rise_time_s.expect("rise") > 0.0);
    // 0-100 % rise t_r = (π − acos ζ)/ω_d and peak time t_p = π/ω_d (Ogata §5-3)
    let tr = (std::f64::consts::PI - zeta.acos()) / wd;
    assert!((m.rise_to_final_s.expect("tr") - tr).abs() < 2e-7, "{:?} vs {tr}", m.rise_to_final_s);
    let tp = std::f64::consts::PI / wd;
    assert!((m.peak_time_s.expect("tp") - tp).abs() < 2e-7, "{:?} vs {tp}", m.peak_time_s);
    // the mirrored history (a rotor turning backwards) has the same figures and a negative peak
    let neg: Vec<f64> = y.iter().map(|v| -v).collect();
    let b = step_metrics(&t, &neg, -100.0);
    assert_eq!(
        (b.delay_s, b.rise_time_s, b.rise_to_final_s, b.peak_time_s),
        (m.delay_s, m.rise_time_s, m.rise_to_final_s, m.peak_time_s)
    );
    assert_eq!(b.overshoot, m.overshoot);
    assert_eq!((b.final_speed_rpm, b.peak_speed_rpm), (-100.0, -m.peak_speed_rpm));
    assert_eq!(b.status(), "ok");
    let none = step_metrics(&t, &y, 0.0);
    assert!(none.delay_s.is_none() && none.settling_time_s.is_none() && none.overshoot.is_none());
    assert!(step_metrics(&[], &[], 1.0).delay_s.is_none());
}
