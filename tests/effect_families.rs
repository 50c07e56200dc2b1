//! Every candidate effect is a family of forms (docs/EFFECTS.md, "Effect families"): its
//! held shape parameters reproduce the baseline at zero strength, meet the candidate's
//! plainest form at their default, and each form does what its physics says.

use trum_core::effects::{Effect, ALL};
use trum_core::{solve, Motor, OperatingPoint, Solution, Status};

/// The frozen TRUM60A without effects (tests/data/motors/trum60a_baseline.toml).
fn baseline() -> Motor {
    let text = include_str!("data/motors/trum60a_baseline.toml");
    Motor::from_toml_str(text, "trum60a_baseline.toml").expect("frozen baseline motor")
}

/// The baseline with `e` at its typical parameters, parameter `i` set to `v`.
fn with_shape(e: Effect, i: usize, v: f64) -> Motor {
    let mut m = baseline();
    let mut vals: Vec<f64> = e.info().params.iter().map(|p| p.typical).collect();
    vals[i] = v;
    m.effects.set(e, &vals);
    m
}

fn op(f: f64, t: f64, elapsed_s: f64) -> OperatingPoint {
    let mut o = OperatingPoint::new(f, t, 200.0, 43e3);
    o.elapsed_s = elapsed_s;
    o
}

/// Every held shape parameter of every effect: (effect, index, a level away from its
/// typical value the scan tries).
fn held_shapes() -> Vec<(Effect, usize, f64)> {
    let mut out = Vec::new();
    for e in ALL {
        for (i, p) in e.info().params.iter().enumerate().filter(|(_, p)| p.held) {
            let level = p.levels.last().copied().unwrap_or(0.05);
            assert!(level != p.typical && (p.min..=p.max).contains(&level), "{e}.{}", p.name);
            out.push((e, i, level));
        }
    }
    out
}

#[test]
fn every_effect_but_preload_stiffening_has_a_held_shape_parameter() {
    let with: Vec<Effect> = held_shapes().iter().map(|s| s.0).collect();
    for e in ALL {
        assert_eq!(with.contains(&e), e != Effect::PreloadStiffening, "{e}");
    }
}

/// At zero strength every form of every family is the baseline, bit for bit.
#[test]
fn every_form_at_zero_strength_reproduces_the_baseline_exactly() {
    let base = baseline();
    for (e, i, level) in held_shapes() {
        let mut vals: Vec<f64> = e.info().params.iter().map(|p| if p.shape { p.typical } else { 0.0 }).collect();
        vals[i] = level;
        let mut m = baseline();
        m.effects.set(e, &vals);
        for (f, t) in [(150.0, 0.0), (250.0, 0.4), (400.0, 0.2)] {
            let o = op(f, t, 100.0);
            let (a, b) = (solve(&base, &o), solve(&m, &o));
            assert_eq!(a.status, b.status, "{e}");
            for q in trum_core::quantities::QUANTITIES {
                let (x, y) = ((q.get)(&a), (q.get)(&b));
                assert!(x == y || (x.is_nan() && y.is_nan()), "{e}[{i}]={level}: {} {x} vs {y}", q.name);
            }
        }
    }
}

/// At its default each held shape gives the candidate's plainest form exactly (a motor file
/// or assignment that leaves it out means the same), and just off the default the family's
/// own formula (its own code: the stick-then-slip saturation and its grading, the knee's
/// quadratic, the two-node rise, the harmonic ripple's five solves) meets it to 1e-6.
#[test]
fn each_family_meets_the_candidate_at_its_default_shape() {
    for (e, i, _) in held_shapes() {
        let p = &e.info().params[i];
        let strength = e.info().params[0].typical;
        let mut plain = baseline();
        plain.effects.parse_assignment(&format!("{}={strength}", e.name())).expect("assignment");
        let at_default = with_shape(e, i, p.typical);
        assert_eq!(plain.effects, at_default.effects, "{e}");
        let near = with_shape(e, i, p.typical + 1e-9 * (1.0 + p.typical.abs()));
        for (f, t) in [(150.0, 0.0), (250.0, 0.3), (400.0, 0.2)] {
            let o = op(f, t, 120.0);
            let (a, b) = (solve(&plain, &o), solve(&near, &o));
            assert_eq!(a.status, b.status, "{e}.{}", p.name);
            for (name, x, y) in [
                ("speed", a.speed_rpm, b.speed_rpm),
                ("amplitude", a.amplitude_m, b.amplitude_m),
                ("electrode voltage", a.electrode_voltage_v, b.electrode_voltage_v),
                ("input power", a.input_power_w, b.input_power_w),
            ] {
                assert!((x - y).abs() <= 1e-6 * x.abs().max(1e-9), "{e}.{} {name}: {x} vs {y}", p.name);
            }
            assert!((a.speed_std_rpm - b.speed_std_rpm).abs() <= 1e-6 * a.speed_std_rpm.max(1.0), "{e}");
        }
    }
}

/// `radial_friction`'s preload exponent: ρ is the ratio at 100 N, and ρ·(F_N/100 N)^q at
/// 400 N with q = 0.5 is the plain candidate with 2ρ.
#[test]
fn radial_friction_ratio_grows_with_preload_by_its_exponent() {
    let rf = Effect::RadialFriction;
    let grown = |rho: f64, q: f64| {
        let mut m = baseline();
        m.effects.set(rf, &[rho, q]);
        m
    };
    let (a, b) = (solve(&grown(0.5, 0.5), &op(400.0, 0.2, 0.0)), solve(&grown(1.0, 0.0), &op(400.0, 0.2, 0.0)));
    assert!((a.speed_rpm - b.speed_rpm).abs() <= 1e-12 * b.speed_rpm, "{} vs {}", a.speed_rpm, b.speed_rpm);
    assert_eq!(
        solve(&grown(0.5, 1.0), &op(100.0, 0.1, 0.0)).speed_rpm,
        solve(&grown(0.5, 0.0), &op(100.0, 0.1, 0.0)).speed_rpm
    );
    // a ratio growing with the preload: at 200 N the same as a flat one of 0.3, at 400 N
    // twice that, which costs speed there
    let (mid, hi) = (op(200.0, 0.1, 0.0), op(400.0, 0.1, 0.0));
    let (flat, steep) = (grown(0.3, 0.0), grown(0.15, 1.0));
    let (a, b) = (solve(&steep, &mid), solve(&flat, &mid));
    assert!((a.speed_rpm - b.speed_rpm).abs() <= 1e-12 * b.speed_rpm, "{} vs {}", a.speed_rpm, b.speed_rpm);
    assert_eq!(solve(&steep, &hi).status, Status::Ok);
    assert!(solve(&steep, &hi).speed_rpm < solve(&flat, &hi).speed_rpm);
}

/// `hertz_softening`'s preload exponent: 2β·((1 + gF)/2)² is the plain candidate with
/// β' = β·(1 + gF)/2 at that preload.
#[test]
fn hertz_softening_exponent_is_a_power_of_the_preload_growth() {
    let hs = Effect::HertzSoftening;
    let (beta, g, f) = (1e18, 0.004, 250.0);
    let mut a = baseline();
    a.effects.set(hs, &[beta, g, 2.0]);
    let mut b = baseline();
    b.effects.set(hs, &[beta * (1.0 + g * f) / 2.0, g, 1.0]);
    for t in [0.0, 0.3] {
        let (x, y) = (solve(&a, &op(f, t, 0.0)), solve(&b, &op(f, t, 0.0)));
        assert!((x.speed_rpm - y.speed_rpm).abs() <= 1e-9 * y.speed_rpm, "{} vs {}", x.speed_rpm, y.speed_rpm);
        assert!((x.modal_stiffness_n_per_m / y.modal_stiffness_n_per_m - 1.0).abs() < 1e-12);
    }
}

/// `hertz_softening`'s falling member: at n = −1 the cubic coefficient is 4β/(1 + gF), the
/// plain candidate's with β' = 4β/(1 + gF)² at that preload, so it softens less the harder
/// the contact is pressed (a Hertzian contact expanded about its preloaded compression).
#[test]
fn hertz_softening_falls_with_the_preload_at_a_negative_exponent() {
    let hs = Effect::HertzSoftening;
    let (beta, g) = (1e18, 0.004);
    let mut falling = baseline();
    falling.effects.set(hs, &[beta, g, -1.0]);
    for f in [100.0, 250.0, 400.0] {
        let mut plain = baseline();
        plain.effects.set(hs, &[4.0 * beta / (1.0 + g * f).powi(2), g, 1.0]);
        for t in [0.0, 0.3] {
            let (x, y) = (solve(&falling, &op(f, t, 0.0)), solve(&plain, &op(f, t, 0.0)));
            assert!(
                (x.speed_rpm - y.speed_rpm).abs() <= 1e-9 * y.speed_rpm,
                "{f} N: {} vs {}",
                x.speed_rpm,
                y.speed_rpm
            );
            assert!((x.modal_stiffness_n_per_m / y.modal_stiffness_n_per_m - 1.0).abs() < 1e-12);
        }
    }
    // the same β softens the stator less at 400 N than at 100 N: the resonance's drop
    // below the effect-free motor's shrinks as the contact is pressed
    let shift = |f: f64| {
        let (x, y) = (solve(&falling, &op(f, 0.0, 0.0)), solve(&baseline(), &op(f, 0.0, 0.0)));
        (y.modal_stiffness_n_per_m - x.modal_stiffness_n_per_m) / y.modal_stiffness_n_per_m
    };
    assert!(shift(100.0) > 0.0 && shift(400.0) < shift(100.0), "{} {}", shift(100.0), shift(400.0));
}

/// `voltage_sag`'s current-limited driver: below its knee it holds the set voltage exactly
/// (the baseline's state); above it the electrode voltage satisfies its own balance
/// V_set = |V_e + R·(|I| − I_k)·Y/|Y|| and sags less than the resistive source's.
#[test]
fn a_current_limited_driver_holds_its_voltage_up_to_the_knee() {
    let vs = Effect::VoltageSag;
    let o = op(300.0, 0.3, 0.0);
    let base = solve(&baseline(), &o);
    let r = 300.0;
    let driver = |knee: f64| {
        let mut m = baseline();
        m.effects.set(vs, &[r, knee]);
        solve(&m, &o)
    };
    let above = driver(1.5 * base.current_a);
    assert_eq!(above.electrode_voltage_v, 200.0);
    assert_eq!(above.speed_rpm, base.speed_rpm);
    let (resistive, knee) = (driver(0.0), driver(0.5 * base.current_a));
    assert!(resistive.electrode_voltage_v < knee.electrode_voltage_v && knee.electrode_voltage_v < 200.0);
    assert!(resistive.speed_rpm < knee.speed_rpm && knee.speed_rpm < base.speed_rpm);
    let (ve, ik) = (knee.electrode_voltage_v, 0.5 * base.current_a);
    let (yr, yi) = (knee.current_in_phase_a / ve, knee.current_quadrature_a / ve);
    let y = yr.hypot(yi);
    let drop = r * (y * ve - ik) / y;
    let v_set = (ve + drop * yr).hypot(drop * yi);
    assert!((v_set - 200.0).abs() < 1e-6 * 200.0, "balance {v_set}");
    assert!((knee.current_a - y * ve).abs() < 1e-9 * knee.current_a);
}

/// `tangential_compliance`'s stick-then-slip layer, S = tanh(xⁿ)^(1/n): a form of its own
/// (n = 4 moves the speed by more than 0.1 % from tanh's at every load), the Coulomb
/// baseline as the layer stiffens (σ → 0), and the energy balance.
#[test]
fn a_stick_then_slip_layer_is_its_own_form_and_stiffens_to_coulomb() {
    let tc = Effect::TangentialCompliance;
    let base = baseline();
    let layer = |kappa: f64, n: f64| {
        let mut m = baseline();
        m.effects.set(tc, &[kappa, n]);
        m
    };
    for t in [0.0, 0.2, 0.4] {
        let o = op(250.0, t, 0.0);
        let v: Vec<f64> = [1.0, 4.0].iter().map(|&n| solve(&layer(1.0, n), &o).speed_rpm).collect();
        assert!((v[1] - v[0]).abs() > 1e-3 * v[0], "T={t}: {v:?}");
        let b = solve(&base, &o).speed_rpm;
        let stiff = solve(&layer(1e-4, 4.0), &o).speed_rpm;
        assert!((stiff - b).abs() < 1e-3 * b && (stiff - b).abs() < (v[1] - b).abs(), "T={t}: {stiff} vs {b}");
        let s = solve(&layer(1.0, 4.0), &o);
        assert_eq!(s.status, Status::Ok, "T={t}");
        let bal = s.input_power_w - s.output_power_w - s.total_loss_w();
        assert!(bal.abs() < 1e-6 * s.input_power_w, "T={t}: power balance {bal}");
    }
}

/// `thermal_drift`'s fast interface node: early in a run the interface share warms at ten
/// times the rate; after many time constants both laws reach the same rise.
#[test]
fn a_fast_interface_node_warms_first_and_ends_at_the_same_rise() {
    let td = Effect::ThermalDrift;
    let m = baseline();
    let tau =
        m.thermal.heat_capacity_j_per_k / (m.thermal.heat_transfer_coefficient_w_per_m2k * m.thermal.surface_area_m2);
    let run = |f: f64, t: f64| solve(&with_shape(td, 3, f), &op(250.0, 0.3, t));
    let (one, two) = (run(0.0, 0.05 * tau), run(0.8, 0.05 * tau));
    assert!(
        two.temperature_rise_at_elapsed_k > 2.0 * one.temperature_rise_at_elapsed_k,
        "{} vs {}",
        two.temperature_rise_at_elapsed_k,
        one.temperature_rise_at_elapsed_k
    );
    assert!(two.speed_rpm < one.speed_rpm);
    let (one, two) = (run(0.0, 40.0 * tau), run(0.8, 40.0 * tau));
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(rel(two.temperature_rise_at_elapsed_k, one.temperature_rise_at_elapsed_k) < 1e-9);
    assert!(rel(two.speed_rpm, one.speed_rpm) < 1e-9);
}

/// `eccentricity`'s harmonics: a tilt or lobes change the speed's fluctuation at the same
/// peak runout, keep the mean preload (so the mean speed moves by little) and the energy
/// balance.
#[test]
fn runout_harmonics_change_the_fluctuation_at_the_same_peak() {
    let ec = Effect::Eccentricity;
    let o = op(250.0, 0.2, 0.0);
    let once = solve(&with_shape(ec, 0, 40e-6), &o);
    for i in [1, 2] {
        let mut m = with_shape(ec, i, 0.7);
        *m.effects.value_mut(ec, 0) = 40e-6;
        let s = solve(&m, &o);
        assert!(
            s.speed_std_rpm > 0.0 && (s.speed_std_rpm - once.speed_std_rpm).abs() > 0.01 * once.speed_std_rpm.max(1e-3),
            "[{i}] {} vs {}",
            s.speed_std_rpm,
            once.speed_std_rpm
        );
        assert!((s.speed_rpm - once.speed_rpm).abs() < 0.05 * once.speed_rpm);
        let bal = s.input_power_w - s.output_power_w - s.total_loss_w();
        assert!(bal.abs() < 1e-8 * s.input_power_w, "[{i}] balance {bal}");
    }
}

/// Shape keys read from a motor file and an assignment, round-trip, and are validated with
/// errors that name the key and list the effect's parameters.
#[test]
fn shape_keys_read_validate_and_round_trip() {
    let text = |effects: &str| {
        let s = baseline().to_toml();
        let header = "[effects]  # none switched on; see `trum effects`";
        assert!(s.contains(header), "{s}");
        s.replacen(header, &format!("[effects]\n{effects}"), 1)
    };
    let m = Motor::from_toml_str(
        &text("voltage_sag = { source_resistance_ohm = 100, knee_current_a = 0.2 }\ntangential_compliance = { shear_compliance_ratio = 1, stick_sharpness = 3 }"),
        "m.toml",
    )
    .expect("shape keys read");
    assert_eq!(m.effects.get(Effect::VoltageSag), Some(&[100.0, 0.2][..]));
    assert_eq!(m.effects.get(Effect::TangentialCompliance), Some(&[1.0, 3.0][..]));
    let back = Motor::from_toml_str(&m.to_toml(), "back.toml").expect("round trip");
    assert_eq!(back.effects, m.effects);
    // a shape key left out keeps the candidate's plainest form
    let m =
        Motor::from_toml_str(&text("hertz_softening = { beta_n_per_m3 = 1e18, preload_gain_per_n = 0.004 }"), "m.toml")
            .expect("reads");
    assert_eq!(m.effects.get(Effect::HertzSoftening), Some(&[1e18, 0.004, 1.0][..]));
    let err = Motor::from_toml_str(&text("voltage_sag = { source_resistance_ohm = 100, knee_a = 0.2 }"), "m.toml")
        .expect_err("unknown key")
        .to_string();
    assert!(err.contains("knee_a") && err.contains("knee_current_a") && err.contains("source_resistance_ohm"), "{err}");
    let err = Motor::from_toml_str(
        &text("tangential_compliance = { shear_compliance_ratio = 1, stick_sharpness = 0.5 }"),
        "m.toml",
    )
    .expect_err("out of range")
    .to_string();
    assert!(err.contains("effects.tangential_compliance.stick_sharpness") && err.contains("[1, 4]"), "{err}");
    let mut fx = trum_core::effects::Effects::none();
    fx.parse_assignment("eccentricity:runout_m=2e-5,third_harmonic_fraction=0.4").expect("assignment");
    assert_eq!(fx.get(Effect::Eccentricity), Some(&[2e-5, 0.0, 0.4][..]));
    let err = fx.parse_assignment("radial_friction:radial_velocity_ratio=1,exponent=1").expect_err("unknown");
    assert!(err.contains("preload_exponent"), "{err}");
    // solved without trouble at a strong form
    let s: Solution = solve(&with_shape(Effect::TangentialCompliance, 1, 4.0), &op(400.0, 0.6, 0.0));
    assert!(matches!(s.status, Status::Ok | Status::Stall));
}
