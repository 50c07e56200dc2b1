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

/// The steady comparison takes the wave's direction: at −90° it is the +90° solution
/// mirrored, with or without load, negative speed and contact torque, and the reversed
/// transient lies as close to it as the forward one to its own; a phase with a standing
/// part has no steady number at all.
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
    // a load brakes either way, so under a load the reversed wave is the mirror image too:
    // contact torque −(T_load + d_r·|Ω|)
    let (fwd_l, back_l) = (at(90.0, 0.1).expect("+90 deg"), at(-90.0, 0.1).expect("-90 deg under load"));
    assert_eq!(fwd_l.status, Status::Ok);
    assert!(fwd_l.speed_rpm > 0.0 && fwd_l.speed_rpm < fwd.speed_rpm, "{fwd_l:?}");
    assert_eq!((back_l.status, back_l.amplitude_m), (fwd_l.status, fwd_l.amplitude_m));
    assert_eq!((back_l.speed_rpm, back_l.contact_torque_nm), (-fwd_l.speed_rpm, -fwd_l.contact_torque_nm));
    let steady_torque = 0.1 + m.rotor.viscous_damping_nms * fwd_l.speed_rpm / crate::solve::RAD_S_TO_RPM;
    assert!(rel(fwd_l.contact_torque_nm, steady_torque) < 1e-12, "{fwd_l:?} vs {steady_torque}");
}

/// The settings of the load tests: [`cfg`] at 64 steps per period, 4 ms.
fn loaded(load: f64, deg: f64) -> TransientConfig {
    TransientConfig { load_torque_nm: load, phase_difference_rad: deg.to_radians(), ..cfg(300.0, 64) }
}

/// +90° under a load: the brake holds the rotor at rest until the contact torque exceeds
/// the load (23 µs), and from then on the rotor turns forwards, where the brake
/// T_load·sign Ω is the constant T_load of eq. 4, so the run is that of a constant load.
/// The reference numbers are the same run with T_load held constant in the rotor kicks
/// (Ω > 0 after the first 35 µs there; before, the constant load turned the resting rotor
/// backwards, to −1.55 rpm, which the brake does not). No load: the same operations,
/// to rounding (1e-12). 0.3 N·m: settled speed, torque and amplitude to 1e-8 relative
/// (measured 2·10⁻¹⁰); the start-up figures, which see the held start, to 1 % (measured:
/// delay −0.10 %, 10-90 % rise +0.68 %, peak +0.04 %, settling +0.005 %).
#[test]
fn forward_rotation_under_a_load_is_the_constant_load_of_eq_4() {
    let free = run(&loaded(0.0, 90.0));
    assert!(rel(free.averages.speed_rpm, 105.7827288805904) < 1e-12, "{}", free.averages.speed_rpm);
    assert!(rel(free.metrics.delay_s.expect("delay"), 1.2063740495696208e-4) < 1e-12);
    assert!(rel(free.metrics.settling_time_s.expect("ts"), 1.5006499909848686e-3) < 1e-12);
    let r = run(&loaded(0.3, 90.0));
    assert!(r.series.speed_rpm.iter().all(|&v| v >= 0.0), "the brake never turns the rotor backwards");
    let a = r.averages;
    for (got, reference) in [
        (a.speed_rpm, 91.45798462522521),
        (a.contact_torque_nm, 0.30478858983630436),
        (a.amplitude_m, 2.183142242967631e-6),
    ] {
        assert!(rel(got, reference) < 1e-8, "{got} vs {reference}");
    }
    let m = r.metrics;
    for (got, reference) in [
        (m.delay_s, 1.335714550654263e-4),
        (m.rise_time_s, 1.1367852036116752e-4),
        (Some(m.peak_speed_rpm), 124.73455409622795),
        (m.overshoot, 0.3638454270270971),
        (m.settling_time_s, 1.4335488602896386e-3),
    ] {
        let got = got.expect("metric");
        assert!(rel(got, reference) < 0.01, "{got} vs {reference}");
    }
    assert_eq!(m.status(), "ok");
}

/// The load brakes either way: a reversed wave (−90°) under 0.3 N·m is the mirror image
/// of the forward run (speed, contact torque and the step figures negated or equal to
/// 1e-9 relative; measured 4·10⁻¹⁶), slower than the unloaded reversed rotor, and the
/// mirrored steady comparison is as far from it as the forward one from its own (1e-6).
#[test]
fn reversed_wave_under_a_load_mirrors_the_forward_run() {
    let (fwd, back) = (run(&loaded(0.3, 90.0)), run(&loaded(0.3, -90.0)));
    let (f, b) = (fwd.averages, back.averages);
    assert!(f.speed_rpm > 50.0, "{f:?}");
    assert!(rel(-b.speed_rpm, f.speed_rpm) < 1e-9, "{} vs {}", b.speed_rpm, f.speed_rpm);
    assert!(rel(-b.contact_torque_nm, f.contact_torque_nm) < 1e-9, "{b:?} vs {f:?}");
    assert!(rel(b.amplitude_m, f.amplitude_m) < 1e-9 && rel(b.axial_force_n, f.axial_force_n) < 1e-9);
    let unloaded_back = run(&loaded(0.0, -90.0)).averages.speed_rpm;
    assert!(b.speed_rpm < 0.0 && b.speed_rpm > 0.95 * unloaded_back, "{} vs {unloaded_back}", b.speed_rpm);
    assert!(back.series.speed_rpm.iter().all(|&v| v <= 0.0), "the reversed rotor never turns forwards");
    let (mf, mb) = (fwd.metrics, back.metrics);
    assert_eq!(mb.status(), "ok");
    assert!(rel(-mb.peak_speed_rpm, mf.peak_speed_rpm) < 1e-9);
    for (x, y) in [
        (mb.delay_s, mf.delay_s),
        (mb.rise_time_s, mf.rise_time_s),
        (mb.overshoot, mf.overshoot),
        (mb.settling_time_s, mf.settling_time_s),
    ] {
        let (x, y) = (x.expect("metric"), y.expect("metric"));
        assert!(rel(x, y) < 1e-9, "{x} vs {y}");
    }
    let m = motor();
    let (sf, sb) = (
        steady_comparison(&m, &loaded(0.3, 90.0)).expect("+90"),
        steady_comparison(&m, &loaded(0.3, -90.0)).expect("-90 under load"),
    );
    assert_eq!((sb.speed_rpm, sb.contact_torque_nm), (-sf.speed_rpm, -sf.contact_torque_nm));
    let (df, db) = (f.speed_rpm / sf.speed_rpm - 1.0, b.speed_rpm / sb.speed_rpm - 1.0);
    assert!(df > 0.0 && df < 0.15 && (db - df).abs() < 1e-6, "reversed {db} vs forward {df}");
}

/// A load above the stall torque holds a rotor that starts at rest: 2 N·m against the
/// largest contact torque of the held rotor, 1.65 N·m (mean 1.38 N·m, the transient's stall
/// torque at 200 V; the steady solver's rotor does not turn at 2 N·m either). Every step's
/// speed is exactly 0, either way round (no creep, no chatter), and the contact torque
/// stays within the brake's hold |T_c| ≤ T_load throughout.
#[test]
fn load_above_the_stall_torque_holds_the_rotor_at_rest() {
    let load = 2.0;
    let s = solve(&motor(), &OperatingPoint::new(260.0, load, 200.0, 43e3));
    assert!(!(s.status == Status::Ok && s.speed_rpm > 0.0), "steady: {:?} {}", s.status, s.speed_rpm);
    for deg in [90.0, -90.0] {
        let r = run(&TransientConfig { record_every: 1, ..loaded(load, deg) });
        assert!(r.series.speed_rpm.iter().all(|&v| v == 0.0), "{deg} deg: the rotor moved");
        assert_eq!(r.averages.speed_rpm, 0.0);
        assert_eq!(r.metrics.status(), "not_moving");
        let peak = r.series.torque_nm.iter().fold(0.0f64, |m, t| m.max(t.abs()));
        assert!(peak <= load && peak > 0.5 * load, "{deg} deg: peak contact torque {peak}");
        // the drive pushes the held rotor the wave's way
        assert!(r.averages.contact_torque_nm * deg > 0.0, "{deg} deg: {}", r.averages.contact_torque_nm);
    }
}

/// A rotor coasting at 1000 rpm with the drive off (zero voltage): the stator at rest,
/// every node in contact slips at μ·p against the rotor, so J_r·Ω̇ = −μ·R0·F_N − T_load
/// − d_r·Ω, which stops it at t = (J_r/d_r)·ln(1 + d_r·Ω₀/(μ·R0·F_N + T_load)) (closed
/// form 0.3177 ms; the run within 0.5 %, measured 0.09 %, one time step). The contact
/// springs, loaded to μ·R0·F_N > T_load, then swing the rotor back, the swing shortened by
/// the brake, until their torque is within its hold (measured: at rest from 0.324 ms on,
/// with T_c = 0.289 N·m): from 0.4 ms to the end of the 2 ms run the speed is exactly 0 at
/// every step and |T_c| ≤ T_load.
#[test]
fn coasting_rotor_stops_and_stays_at_rest() {
    let m = motor();
    let load = 0.3;
    let c = TransientConfig { duration_s: 2e-3, record_every: 1, ..loaded(load, 90.0) };
    let mut plant = sim::ring_plant(&m, &c);
    plant.drive_force_n = 0.0;
    let om0 = 1000.0 / crate::solve::RAD_S_TO_RPM;
    plant.initial_rotor_speed_rad_s = om0;
    let out = sim::run(&plant).expect("run");
    let (j, d) = (m.rotor.inertia_kg_m2, m.rotor.viscous_damping_nms);
    let friction = m.friction_layer.friction_coefficient * m.geometry.mean_radius_m * 260.0;
    let t_stop = j / d * (1.0 + d * om0 / (friction + load)).ln();
    let (t, v, tc) = (&out.series.time_s, &out.series.speed_rpm, &out.series.torque_nm);
    let first = v.iter().position(|&v| v <= 0.0).expect("the rotor stops");
    assert!(rel(t[first], t_stop) < 5e-3, "stopped at {} s, closed form {t_stop} s", t[first]);
    // held at rest from 0.4 ms to the end
    let last_moving = v.iter().rposition(|&v| v != 0.0).expect("it moved");
    assert!(t[last_moving] < 0.4e-3, "still moving at {} s", t[last_moving]);
    assert!(tc[last_moving + 1..].iter().all(|&x| x.abs() <= load), "contact torque beyond the hold");
    assert!(tc[tc.len() - 1] != 0.0, "the springs keep a residual torque the brake holds");
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
