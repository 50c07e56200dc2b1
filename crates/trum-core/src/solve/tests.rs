use super::bracket::dip_below_zero;
use super::descent::solve_drive;
use super::fixed_points::{sag_balance, settle, temperature_rise_for_drift};
use super::trial::{sagged_voltage_at, sagged_voltage_v, trial, Drive};
use super::*;
use crate::effects::Effect;
use crate::stator;
use crate::stator::{elastic_detuning, stiffness_crossing};
use rand::{RngExt, SeedableRng};

/// The certificates behind the start points of the amplitude descent: for the Coulomb
/// interface the amplitude map G(W) = Θ·V/|Z(W)| does not rise with the load torque at
/// any W (`solve_in_sweep` starts from the previous point's amplitude), and without
/// stiffening or softening it stays below Θ·V/|k − mω² + iωc| (the cold start). Random
/// amplitudes, preloads, drives and torque pairs through running, stalled and
/// narrow-contact states, with preload stiffening and Hertz softening too.
#[test]
fn amplitude_map_falls_with_the_load_and_stays_below_the_detuned_bound() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(14);
    let (mut stalled, mut moving) = (0, 0);
    for name in crate::presets::PRESETS.iter().map(|p| p.name) {
        for fx in [None, Some(Effect::PreloadStiffening), Some(Effect::HertzSoftening)] {
            let mut m = crate::presets::frozen(name).expect("preset");
            if let Some(e) = fx {
                let typical: Vec<f64> = e.info().params.iter().map(|p| p.typical).collect();
                m.effects.set(e, &typical);
            }
            let p = Prepared::new(&m);
            for _ in 0..1500 {
                let mut op = OperatingPoint::new(
                    rng.random_range(5.0..700.0),
                    0.0,
                    rng.random_range(60.0..320.0),
                    rng.random_range(39e3..45e3),
                );
                let d = Drive::at(&p, &op);
                let w = rng.random_range(0.005..1.0) * p.theta * d.v / (d.omega * d.c);
                let (a, b): (f64, f64) = (rng.random_range(0.0..2.5), rng.random_range(0.0..2.5));
                let mut at = |t: f64| {
                    op.torque_nm = t;
                    trial(&p, &Drive::at(&p, &op), w, None, None)
                };
                let (lo, hi) = (at(a.min(b)), at(a.max(b)));
                assert!(
                    hi.w_next <= lo.w_next * (1.0 + 1e-13),
                    "{name} {fx:?} {op:?} W {w}: G rises with the load, {} -> {}",
                    lo.w_next,
                    hi.w_next
                );
                if fx.is_none() {
                    let bound = p.theta * d.v / (d.ks - p.m * d.omega * d.omega).hypot(d.omega * d.c);
                    assert!(lo.w_next <= bound * (1.0 + 1e-13), "{name} {op:?} W {w}: above the detuned bound");
                }
                if hi.stalled {
                    stalled += 1;
                } else {
                    moving += 1;
                }
            }
        }
    }
    assert!(stalled > 500 && moving > 500, "{stalled} stalled, {moving} moving trials");
}

/// The exact slope of the amplitude residual r(W) = W − G(W) that a baseline trial
/// carries (implicit derivatives of the contact and stick angles) against a central
/// difference of r, at random amplitudes, preloads, drives and torques through
/// partial and full contact, running, stalled and narrow-contact states.
#[test]
fn the_trial_slope_is_the_derivative_of_the_amplitude_residual() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(29);
    let mut seen = [0usize; 4]; // running, stalled, full contact, narrow contact
    for name in crate::presets::PRESETS.iter().map(|p| p.name) {
        let m = crate::presets::frozen(name).expect("preset");
        let p = Prepared::new(&m);
        for _ in 0..2000 {
            let op = OperatingPoint::new(
                rng.random_range(5.0..700.0),
                rng.random_range(0.0..2.5),
                rng.random_range(60.0..320.0),
                rng.random_range(39e3..45e3),
            );
            let d = Drive::at(&p, &op);
            let w = rng.random_range(0.005..1.0) * p.theta * d.v / (d.omega * d.c);
            let t = trial(&p, &d, w, None, None);
            let h = 1e-6 * w;
            let (a, b) = (trial(&p, &d, w - h, None, None), trial(&p, &d, w + h, None, None));
            // a state change inside the difference's span has no derivative to compare
            if a.stalled != b.stalled || a.contact.full != b.contact.full {
                continue;
            }
            let fd = ((b.w - b.w_next) - (a.w - a.w_next)) / (2.0 * h);
            // |G'| is of the order of G/W; the difference's truncation (h²) and
            // rounding (1e-16·W/h) errors are far below 1e-6 of that
            let scale = 1.0 + t.w_next / w;
            assert!(
                (t.slope - fd).abs() <= 1e-6 * scale,
                "{name} {op:?} W {w}: slope {} vs difference {fd} (stalled {}, full {})",
                t.slope,
                t.stalled,
                t.contact.full
            );
            seen[usize::from(t.stalled)] += 1;
            seen[2] += usize::from(t.contact.full);
            seen[3] += usize::from(t.contact.half_angle_rad < 0.5 * PI);
        }
    }
    assert!(seen.iter().all(|&n| n > 150), "running, stalled, full, narrow: {seen:?}");
}

/// Without the stall torque (calibration's passes) a solve is the same solve: every
/// other quantity and the status bit for bit, the stall torque NaN only where the
/// generalised interface would have integrated for it, and no point reported failed for
/// that NaN. Every effect in both forms, through running, stalled and clamped points.
#[test]
fn leaving_out_the_stall_torque_changes_nothing_else() {
    let mut skipped = 0;
    for truth in [false, true] {
        for e in std::iter::once(None).chain(crate::effects::ALL.iter().copied().map(Some)) {
            let mut m = crate::presets::frozen("trum60a").expect("preset");
            if let Some(e) = e {
                let typical: Vec<f64> = e.info().params.iter().map(|p| p.typical).collect();
                m.effects.set(e, &typical);
            }
            m.effects.set_truth_forms(truth);
            let (full, lean) = (Prepared::new(&m), Prepared::new(&m).without_stall_torque());
            for &f in &[60.0, 250.0, 900.0] {
                for &t in &[0.0, 0.5, 1.5] {
                    let mut op = OperatingPoint::new(f, t, 200.0, 43e3);
                    op.elapsed_s = 300.0;
                    let (a, mut b) = (solve_prepared(&full, &m, &op, None), solve_prepared(&lean, &m, &op, None));
                    if b.stall_torque_nm.is_nan() {
                        skipped += 1;
                        b.stall_torque_nm = a.stall_torque_nm;
                    }
                    assert_eq!(format!("{a:?}"), format!("{b:?}"), "{e:?} truth {truth} {op:?}");
                }
            }
        }
    }
    // the generalised interface's running points (radial friction, tangential compliance)
    assert!(skipped >= 8, "{skipped} stall torques left out");
}

/// Where the descent finds the stator clamped, the clamped state's closed form (with the
/// effects' fixed point on it) is that solution: crate::sensitivity carries clamped rows
/// over with it. Every effect at its typical strength, preloads from the clamping edge
/// up, elapsed time on (thermal drift iterates).
#[test]
fn clamped_closed_form_is_the_clamped_solve() {
    let mut clamped = 0;
    for e in std::iter::once(None).chain(crate::effects::ALL.iter().copied().map(Some)) {
        let mut m = crate::presets::frozen("trum60a").expect("preset");
        if let Some(e) = e {
            let typical: Vec<f64> = e.info().params.iter().map(|p| p.typical).collect();
            m.effects.set(e, &typical);
        }
        let p = Prepared::new(&m);
        for &f in &[700.0, 800.0, 1200.0] {
            for &t in &[0.0, 0.4] {
                let mut op = OperatingPoint::new(f, t, 200.0, 43e3);
                op.elapsed_s = 600.0;
                let s = solve_effects(&p, &op, None, &Work::of(&p));
                if s.status != Status::Clamped {
                    continue;
                }
                clamped += 1;
                let c = solve_clamped(&p, &op);
                assert_eq!(c.status, Status::Clamped);
                for q in crate::quantities::QUANTITIES {
                    let (a, b) = ((q.get)(&c), (q.get)(&s));
                    assert!((a - b).abs() <= 1e-10 * b.abs().max(1e-12), "{e:?} {op:?} {}: {a} vs {b}", q.name);
                }
            }
        }
    }
    assert!(clamped >= 30, "{clamped} clamped points");
}

/// The motor `name` with the effect assignments `fx` ("a=1;b:x=2,y=3") in candidate or
/// truth form.
fn motor_with(name: &str, fx: &str, truth: bool) -> Motor {
    let mut m = crate::presets::frozen(name).expect("preset");
    for a in fx.split(';') {
        m.effects.parse_assignment(a).expect("effect");
    }
    m.effects.set_truth_forms(truth);
    m
}

/// Checks a cold solve at `op` against `amplitude_branches`: the reported amplitude
/// is a fixed point of the map with none above it, and clamped only where the scan
/// finds none. Returns (problem, solution, branch count).
fn largest_fixed_point_problem(m: &Motor, op: &OperatingPoint) -> (Option<String>, Solution, usize) {
    let p = Prepared::new(m);
    let s = solve(m, op);
    let branches = amplitude_branches(m, op);
    let w = s.amplitude_m;
    let problem = match s.status {
        Status::Clamped => branches.last().map(|b| format!("clamped, but a fixed point at {:.6e} m", b.amplitude_m)),
        Status::Ok | Status::Stall => {
            let t = trial(&p, &Drive::at(&p, op), w, None, None);
            if (t.w - t.w_next).abs() > 1e-9 * w {
                Some(format!("{w:.6e} m is not a fixed point (G = {:.6e} m)", t.w_next))
            } else {
                branches
                    .iter()
                    .find(|b| b.amplitude_m > w * (1.0 + 1e-6))
                    .map(|b| format!("{w:.6e} m, but a fixed point above at {:.6e} m", b.amplitude_m))
            }
        }
        other => Some(format!("status {other:?}")),
    };
    (problem, s, branches.len())
}

/// [`largest_fixed_point_problem`] at `n` random drives, preloads and torques per
/// (preset, effects, truth form). Returns (problems, points, multi-branch points,
/// clamped points, mean evaluations).
fn largest_fixed_point_check(
    configs: &[(&str, &str, bool)],
    n: usize,
    seed: u64,
) -> (Vec<String>, usize, usize, usize, f64) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (mut checked, mut multi, mut clamped, mut wrong, mut evals) = (0, 0, 0, Vec::new(), 0u64);
    for &(name, fx, truth) in configs {
        let m = motor_with(name, fx, truth);
        for _ in 0..n {
            let op = OperatingPoint::new(
                rng.random_range(20.0..600.0),
                rng.random_range(0.0..1.5),
                rng.random_range(80.0..300.0),
                rng.random_range(38e3..45e3),
            );
            let (problem, s, branches) = largest_fixed_point_problem(&m, &op);
            evals += u64::from(s.iterations);
            multi += usize::from(branches > 1);
            clamped += usize::from(s.status == Status::Clamped);
            checked += 1;
            if let Some(why) = problem {
                wrong.push(format!("{name} {fx} truth={truth} {op:?}: {why} ({branches} branches)"));
            }
        }
    }
    (wrong, checked, multi, clamped, evals as f64 / checked as f64)
}

/// `stiffness_crossing`, which both the solver's spike probe and `amplitude_branches`'
/// dense scan rely on, checked on its own: where it reports an amplitude the elastic
/// detuning Re Z (friction left out) changes sign within 1e-6 of it in W, or is there
/// within the search's stop, 1e-8 of m·ω² (Re Z carries rounding of ~10 N/m; where Re Z
/// is flat that stop is a few 1e-6 in W: 1.5e-6 at trum60a, truth-form stiffening and
/// softening, 435 N, 147 V, 44.92 kHz), and where it reports none
/// Re Z keeps one sign over a fine scan of (1e-9·top, top). Every configuration of
/// the multi-branch test, random drives and preloads.
#[test]
fn stiffness_crossing_is_where_the_elastic_detuning_changes_sign() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
    let (mut found, mut none) = (0, 0);
    for &(name, fx, truth) in &MULTI_BRANCH_CONFIGS {
        let m = motor_with(name, fx, truth);
        let p = Prepared::new(&m);
        for _ in 0..60 {
            let op = OperatingPoint::new(
                rng.random_range(20.0..600.0),
                0.0,
                rng.random_range(80.0..300.0),
                rng.random_range(38e3..45e3),
            );
            let d = Drive::at(&p, &op);
            let top = p.theta * d.v / (d.omega * d.c);
            match stiffness_crossing(&p, &d, top) {
                Some(w) => {
                    found += 1;
                    let (a, b) =
                        (elastic_detuning(&p, &d, w * (1.0 - 1e-6)), elastic_detuning(&p, &d, w * (1.0 + 1e-6)));
                    let at = elastic_detuning(&p, &d, w).abs() <= 1e-8 * p.m * d.omega * d.omega;
                    assert!((a >= 0.0 && b <= 0.0) || at, "{name} {fx} {op:?}: Re Z {a:e}, {b:e} about {w:e} m");
                }
                None => {
                    none += 1;
                    let signs: Vec<bool> = (0..=2000)
                        .map(|i| elastic_detuning(&p, &d, top * 1e-9f64.powf(i as f64 / 2000.0)) > 0.0)
                        .collect();
                    assert!(signs.iter().all(|&x| x == signs[0]), "{name} {fx} {op:?}: a crossing was missed");
                }
            }
        }
    }
    assert!(found >= 100 && none >= 100, "{found} crossings, {none} without");
}

/// Preload stiffening by the modal projection of the radial-friction paper (`modal_fraction
/// = 1`) at strength 3.3046, where the descent needs the spike probe of the stiffness
/// crossing to reach the upper branch (generic60).
const MODAL_3_3: &str = "preload_stiffening:stiffness_scale=3.3046,modal_fraction=1";
/// The same projection at strength 1.
const MODAL_1: &str = "preload_stiffening:stiffness_scale=1,modal_fraction=1";

#[test]
fn points_near_the_fold_reach_the_upper_branch() {
    for (name, fx, op) in [
        ("generic60", MODAL_3_3, OperatingPoint::new(476.2, 0.8427, 112.15, 44467.8)),
        (
            "trum60-qut",
            "hertz_softening:beta_n_per_m3=1.089e18,preload_gain_per_n=0",
            OperatingPoint::new(211.79, 0.4035, 252.59, 39479.3),
        ),
    ] {
        let m = motor_with(name, fx, !fx.starts_with("preload"));
        let (problem, s, _) = largest_fixed_point_problem(&m, &op);
        assert!(problem.is_none(), "{name} {fx}: {problem:?}");
        assert!(s.status.is_valid(), "{name}: {:?}", s.status);
        // the stable upper branch: 10.12 µm; at the fold, 0.9997 of the
        // stiffness crossing (5.96 µm; the log scan alone saw only 0.546 µm)
        let expected = if name == "generic60" { 10.12e-6 } else { 5.96e-6 };
        assert!((s.amplitude_m / expected - 1.0).abs() < 2e-3, "{name}: {:e} m", s.amplitude_m);
        let top = amplitude_branches(&m, &op).last().map(|b| b.amplitude_m);
        assert_eq!(top.map(|w| (w / s.amplitude_m - 1.0).abs() < 1e-6), Some(true), "{top:?}");
    }
}

/// Points whose largest root lies in a window of r < 0 that the descent does not reach
/// first (from a random run and a 200 000-point census), which `highest_window` finds:
/// - above the stiffness crossing (friction damping falls with W, so |Z| keeps falling
///   past it), where searching the fold window below the crossing first would end on the
///   lower branch (the first point: 0.478 µm instead of 2.18 µm), or the descent's capped
///   steps go over a window 0.7-3 % wide and it would end clamped;
/// - below it, where the fold window's search finds the lower branch's window and not the
///   one above it (the first of those: 1.24 µm instead of 2.26 µm).
#[test]
fn windows_the_descent_steps_over_still_hold_the_largest_root() {
    const BOTH: &str = "preload_stiffening=1;hertz_softening=1e18";
    for (name, fx, truth, op, above) in [
        ("trum60a", BOTH, true, OperatingPoint::new(567.718, 0.31575, 182.80, 44258.0), true),
        ("trum60a", BOTH, true, OperatingPoint::new(253.091, 0.518637, 83.9513, 44758.1), true),
        ("trum60a", "hertz_softening=1e18", false, OperatingPoint::new(578.123, 0.402540, 186.353, 40313.1), true),
        ("trum60a", "hertz_softening=1e18", false, OperatingPoint::new(492.619, 0.701395, 162.961, 40361.9), true),
        ("trum60a", "hertz_softening=1e18", false, OperatingPoint::new(598.512, 0.555832, 170.570, 38155.7), true),
        ("trum60a", BOTH, true, OperatingPoint::new(596.554, 0.228730, 168.347, 42206.1), true),
        // a window 0.4 % wide at 1.047 of the crossing (a reference scan that ends at
        // 1.02 of the crossing misses it and accepts the clamped-like 1.98e-8 m)
        ("trum60a", BOTH, true, OperatingPoint::new(488.149312, 0.6318092, 154.291230, 43570.8501), true),
        // r < 0 at the crossing itself, and a higher window above it than the one the
        // bracket [crossing, top] would converge in (the second 12-25× the crossing)
        (
            "trum60a",
            "hertz_softening=1e18",
            false,
            OperatingPoint::new(488.145028, 0.54623495, 160.640349, 40590.465),
            true,
        ),
        (
            "trum60a",
            "hertz_softening=1e18",
            false,
            OperatingPoint::new(310.906458, 0.28872648, 100.388775, 40749.024),
            true,
        ),
        // (the modal projection of the radial-friction paper: the candidate at λ = 1)
        ("trum60a", MODAL_1, false, OperatingPoint::new(194.551, 1.386416, 80.8638, 44049.04), false),
        // (truth form; at 53.06 N its cubic coefficient is 1.39862e18 N/m³)
        (
            "trum60-qut",
            "hertz_softening=3.4832193326664e17",
            true,
            OperatingPoint::new(53.0628, 0.541305, 182.991, 40875.43),
            false,
        ),
    ] {
        let m = motor_with(name, fx, truth);
        let (problem, s, branches) = largest_fixed_point_problem(&m, &op);
        assert!(problem.is_none(), "{name} {fx} {op:?}: {problem:?}");
        assert!(branches >= 2, "{name} {fx} {op:?}: {branches} branches");
        let p = Prepared::new(&m);
        let d = Drive::at(&p, &op);
        let crossing = stiffness_crossing(&p, &d, p.theta * d.v / (d.omega * d.c)).expect("a crossing");
        assert_eq!(s.amplitude_m > crossing, above, "{fx} {op:?}: {:e} m, crossing {crossing:e} m", s.amplitude_m);
    }
}

/// A stator clamped under weak preload stiffening (the strength a 1000-row diagnosis
/// fits): below 1e-3 of the top the map is G ≈ κ·W with κ just below 1, where steps of a
/// tenth of W took about 130 trials to reach the clamping threshold (about 180 in all;
/// 0.3 of a diagnosis's trials). A decade a step there: the same clamped answer, which
/// the dense branch scan confirms, in under 100. The fold window's early stop took
/// them from 75-88 to 58-73; ruling out a window of r < 0 above the stiffness crossing
/// (`highest_window`) costs up to 11 more (58-84): under 90.
#[test]
fn a_clamped_multi_branch_descent_takes_decade_steps_near_zero() {
    let m = motor_with("trum60a", "preload_stiffening=0.06", false);
    for (preload, freq) in [(400.0, 43e3), (400.0, 44e3), (500.0, 41.5e3), (500.0, 43e3), (500.0, 44e3)] {
        let op = OperatingPoint::new(preload, 0.0, 120.0, freq);
        let (problem, s, _) = largest_fixed_point_problem(&m, &op);
        assert!(problem.is_none(), "{op:?}: {problem:?}");
        assert_eq!(s.status, Status::Clamped, "{op:?}");
        assert!(s.iterations < 90, "{op:?}: {} amplitude evaluations", s.iterations);
    }
}

/// trum60a with `voltage_sag` 150 Ω and the nominal `thermal_drift` coefficients.
fn sag_and_drift_trum60a() -> (Motor, Prepared) {
    let th = "thermal_drift:stiffness_coefficient_per_k=-0.0004,friction_coefficient_per_k=-0.002,\
              damping_coefficient_per_k=0.002";
    let m = motor_with("trum60a", &format!("voltage_sag=150;{th}"), false);
    let p = Prepared::new(&m);
    (m, p)
}

/// `voltage_sag` with `thermal_drift`: where the joint passes cycle (here between a
/// running and a stalled state: they do not settle in 100 passes), the nested fallback
/// finds the state that is its own fixed point in both: the temperature rise its losses
/// produce, the electrode voltage its current leaves.
#[test]
fn sag_with_thermal_drift_settles_where_the_joint_passes_cycle() {
    let (m, p) = sag_and_drift_trum60a();
    let mut op = OperatingPoint::new(301.77607641416205, 0.7886468900037416, 227.28717512048937, 40163.644478763854);
    op.elapsed_s = 170.56565919703655;
    let work = Work::of(&p);
    let direct = |d: &Drive, _: f64, g: Option<&Solution>| solve_drive(&p, d, &op, g, &work);
    let (_, _, joint) = settle(&p, &op, None, (true, true), 0.0, &work, &direct);
    assert!(!joint, "the joint passes settle here: the test no longer reaches the fallback");
    let s = solve(&m, &op);
    assert_eq!(s.status, Status::Ok);
    let rise = temperature_rise_for_drift(&p, s.total_loss_w(), op.elapsed_s);
    assert!((rise - s.temperature_rise_at_elapsed_k).abs() <= 1e-9 * rise, "{rise} K vs {s:?}");
    let v = sagged_voltage_v(&p, &op, &s);
    assert!((v - s.electrode_voltage_v).abs() <= 1e-12 * op.voltage_v, "{v} V vs {s:?}");
    // a moving stator, hot (53.4 K) and sagged (116.8 V of 227.3 V)
    assert!(s.amplitude_m > 6e-6 && (53.0..54.0).contains(&rise) && (116.0..118.0).contains(&v), "{s:?}");
}

/// Near the clamping fold of a sagging drive the amplitude solve resolves W only to
/// ~1e-10 (r(W) has a tiny slope there), so the electrode voltage's residual stays a few
/// 1e-12 of the voltage however the sign change shrinks. That is settled, not a jump of
/// G: this point, started from its neighbour in a map row, ended as no convergence at
/// a bracket 1e-12 wide with residuals of ±3e-12 (a jump has ±3e-2). The warm and cold
/// solves agree, and the state is its own fixed point.
#[test]
fn a_sag_fixed_point_at_a_fold_settles_within_the_amplitude_solves_noise() {
    let mut m = crate::presets::frozen("trum60-qut").expect("preset");
    m.effects.parse_assignment("voltage_sag=150").expect("effect");
    let p = Prepared::new(&m);
    let prev = solve_prepared(&p, &m, &OperatingPoint::new(640.0, 0.05, 194.0, 41562.5), None);
    let op = OperatingPoint::new(640.0, 0.075, 194.0, 41562.5);
    let cold = solve_prepared(&p, &m, &op, None);
    let warm = solve_prepared(&p, &m, &op, Some(&prev));
    for s in [&cold, &warm] {
        assert_eq!(s.status, Status::Ok, "{s:?}");
        let v = sagged_voltage_v(&p, &op, s);
        assert!((v - s.electrode_voltage_v).abs() <= 1e-10 * op.voltage_v, "{v} V vs {s:?}");
    }
    assert!((warm.amplitude_m - cold.amplitude_m).abs() <= 1e-9 * cold.amplitude_m, "{warm:?} vs {cold:?}");
    // near clamping: 1.9 µm of a 2.6 µm neighbour, 184 V of 194 V on the electrode
    assert!((1.8e-6..2.0e-6).contains(&cold.amplitude_m) && (183.0..185.0).contains(&cold.electrode_voltage_v));
}

/// Under load near the fold of the running branch a sagging drive has no running steady
/// state (its current sags the electrode voltage below the fold) but a stalled one (its
/// smaller current lets the voltage recover, and the rotor at rest stays at rest): the
/// point is a stall, a lower fixed point of the amplitude map at its own sagged
/// voltage. Without the lower-branch search these three end `no_convergence`.
#[test]
fn a_sagging_drive_stalls_where_its_running_state_sags_past_the_fold() {
    let m = motor_with("trum60a", "voltage_sag=10", false);
    let p = Prepared::new(&m);
    for (f, t) in [(480.0, 1.3), (490.0, 1.2), (500.0, 1.1)] {
        let op = OperatingPoint::new(f, t, 165.0, 41_000.0);
        let s = solve(&m, &op);
        assert_eq!(s.status, Status::Stall, "{op:?}: {s:?}");
        // its own electrode voltage
        let v = sagged_voltage_v(&p, &op, &s);
        assert!((v - s.electrode_voltage_v).abs() <= 1e-9 * op.voltage_v, "{op:?}: {v} V vs {s:?}");
        // a fixed point of the amplitude map at that voltage, stalled, and held there
        let mut d = Drive::at(&p, &op);
        d.v = s.electrode_voltage_v;
        let tr = trial(&p, &d, s.amplitude_m, None, None);
        assert!(tr.stalled && (tr.w - tr.w_next).abs() <= 1e-9 * tr.w, "{op:?}: {tr:?}");
        assert!(s.stall_torque_nm < t, "{op:?}: blocking torque {} N·m", s.stall_torque_nm);
        // a lower one: the descent from the top finds a running state at this voltage,
        // whose current sags the voltage by more than a volt below it
        let top = solve_drive(&p, &d, &op, None, &Work::of(&p));
        assert_eq!(top.status, Status::Ok, "{op:?}: {top:?}");
        assert!(top.amplitude_m > 2.0 * s.amplitude_m, "{op:?}: {top:?} vs {s:?}");
        assert!(sagged_voltage_v(&p, &op, &top) < s.electrode_voltage_v - 1.0, "{op:?}: {top:?}");
    }
}

/// At the clamping edge of a sagging drive: the moving stator's current sags the
/// voltage to where it clamps (about 60 V of 120 V set, 150 Ω), the clamped one's
/// small capacitive current leaves 117.4 V, where the stator moves if it is moving but
/// a small amplitude dies away. The point is clamped, at its own sagged voltage (it was
/// `no_convergence`).
#[test]
fn a_sagging_drive_stays_clamped_where_its_moving_state_sags_below_clamping() {
    let (p, op, s) = sagging_trum60a(150.0, OperatingPoint::new(380.0, 0.2, 120.0, 41_000.0));
    assert_eq!(s.status, Status::Clamped, "{s:?}");
    assert!(fixed_point_problem(&p, &op, &s).is_none(), "{:?}", fixed_point_problem(&p, &op, &s));
    let v = s.electrode_voltage_v;
    assert!((117.0..118.0).contains(&v), "{v} V");
    let mut d = Drive::at(&p, &op);
    d.v = v;
    for w in [1e-12, 1e-9] {
        let t = trial(&p, &d, w, None, None);
        assert!(t.w_next < t.w, "W = {w} m grows to {} m", t.w_next);
    }
    let top = solve_drive(&p, &d, &op, None, &Work::of(&p));
    assert_eq!(top.status, Status::Ok, "{top:?}");
    assert!(sagged_voltage_v(&p, &op, &top) < 0.6 * v, "{top:?}");
}

/// Where the clamped stator would start at its own voltage, a stall sits just above
/// W = 0 (it was `no_convergence`; reporting it clamped would not be a steady state).
#[test]
fn a_sagging_drive_stalls_just_above_clamping_where_a_clamped_stator_would_start() {
    let (p, op, s) = sagging_trum60a(10.0, OperatingPoint::new(490.0, 0.95, 155.0, 41_000.0));
    assert_eq!(s.status, Status::Stall, "{s:?}");
    assert!(s.amplitude_m > 0.0 && s.amplitude_m < 1e-7, "{s:?}");
    assert!(fixed_point_problem(&p, &op, &s).is_none(), "{:?}", fixed_point_problem(&p, &op, &s));
    // W = 0 is not one: a small amplitude grows at that voltage
    let mut d = Drive::at(&p, &op);
    d.v = s.electrode_voltage_v;
    let t = trial(&p, &d, 1e-3 * s.amplitude_m, None, None);
    assert!(t.w_next > t.w, "{t:?}");
}

/// Where the electrode voltage's passes hunt between states (150 Ω, 380 N, 0.2 N·m,
/// 150 V, 41 kHz), the sagging drive's steady state is the middle
/// root of the amplitude map at its own voltage: unstable with the voltage held there
/// (a slightly larger amplitude grows towards the upper root, which the descent from the
/// top takes), stable with the sag acting (that larger amplitude draws the voltage down
/// until it shrinks back). The electrode voltage's passes alone end `no_convergence`.
#[test]
fn a_sagging_drive_settles_on_the_middle_root_where_its_passes_hunt() {
    let (p, op, s) = sagging_trum60a(150.0, OperatingPoint::new(380.0, 0.2, 150.0, 41_000.0));
    assert_eq!(s.status, Status::Ok, "{s:?}");
    assert!(fixed_point_problem(&p, &op, &s).is_none(), "{:?}", fixed_point_problem(&p, &op, &s));
    assert!((145.0..155.0).contains(&s.speed_rpm) && (97.0..100.0).contains(&s.electrode_voltage_v), "{s:?}");
    let mut d = Drive::at(&p, &op);
    d.v = s.electrode_voltage_v;
    let up = 1.01 * s.amplitude_m;
    let t = trial(&p, &d, up, None, None);
    assert!(t.w_next > up, "at a fixed voltage W = {up} m should grow: {t:?}");
    let top = solve_drive(&p, &d, &op, None, &Work::of(&p));
    assert!(top.amplitude_m > 1.1 * s.amplitude_m, "{top:?}");
    // with the sag acting, the larger amplitude's current leaves a lower voltage, at
    // which it shrinks
    let (ire, iim) = stator::phase_current_a(d.v, d.omega, p.c0, p.tan_d, p.theta, t.z);
    let ve = sagged_voltage_at(&p, &op, (ire / d.v, iim / d.v));
    assert!(t.w_next * ve / d.v < up, "W = {up} m at {ve} V maps to {} m", t.w_next * ve / d.v);
}

/// Where the passes find no state, a sagging drive takes the largest root of its balance
/// h(W) = W − Θ·V_e(W)/|Z(W)| (the upper-branch convention). A point of the trum60a map
/// at 150 Ω and 41 kHz (grid 300-560 N × 120-180 V: 458.6 N, 0 N·m, 166.7 V): there h
/// dips below zero at 3.45 µm over less than one step ×0.8, so a scan in such steps
/// passes over it to a root at 1.35 µm, 31.9 rpm, where its neighbours at lower preload
/// run at 174-227 rpm. A dense scan (×0.999) finds no root above the answer.
#[test]
fn a_sagging_drive_takes_the_largest_root_of_its_balance() {
    let op = OperatingPoint::new(300.0 + 260.0 * 36.0 / 59.0, 0.0, 120.0 + 60.0 * 7.0 / 9.0, 41_000.0);
    let (p, op, s) = sagging_trum60a(150.0, op);
    assert_eq!(s.status, Status::Ok, "{s:?}");
    assert!((145.0..157.0).contains(&s.speed_rpm), "{s:?}");
    assert!(fixed_point_problem(&p, &op, &s).is_none(), "{:?}", fixed_point_problem(&p, &op, &s));
    let d = Drive::at(&p, &op);
    let work = Work::of(&p);
    let h = |w: f64| sag_balance(&p, &d, &op, w, &work).0;
    assert!(h(s.amplitude_m).abs() < 1e-6 * s.amplitude_m, "h = {} m at the answer", h(s.amplitude_m));
    let mut w = p.theta * d.v / (d.omega * d.c);
    while w > 1.0005 * s.amplitude_m {
        assert!(h(w) > 0.0, "a root above the answer {} m: h({w}) = {}", s.amplitude_m, h(w));
        w *= 0.999;
    }
}

/// The dip search on known functions. h = 1 − 1.2·exp(−((w − 2)/0.02)²) is below zero only
/// within 2 ± 0.0085, narrower than the triple's spacing (1.9, 1.98, 2.15): the search
/// moves its bracket (two probes that miss) before it lands in the dip, and brackets the
/// top root. With 0.8 in place of 1.2 there is no root: none. A dip away from the
/// triple's least point, narrower than the probes near it, is not found
/// (1 + 10(w − 1.99)² − 1.5·exp(−((w − 2.045)/0.004)²) about the sample at 2.0).
/// A non-finite value is an error.
#[test]
fn the_dip_search_brackets_the_top_root_of_a_narrow_dip() {
    let gauss = |depth: f64| move |w: f64| (1.0 - depth * (-((w - 2.0) / 0.02).powi(2)).exp(), ());
    let at = |h: &dyn Fn(f64) -> (f64, ()), w: f64| (w, h(w).0);
    let calls = std::cell::Cell::new(0);
    let h = gauss(1.2);
    let counted = |w: f64| {
        calls.set(calls.get() + 1);
        h(w)
    };
    let dip = dip_below_zero(counted, at(&h, 1.9), at(&h, 1.98), at(&h, 2.15)).expect("finite");
    let ((neg, (hn, ())), (pos, hp)) = dip.expect("a dip below zero");
    let root = 2.0 + 0.02 * 1.2f64.ln().sqrt();
    assert!(hn <= 0.0 && hp > 0.0 && neg < root && root < pos, "[{neg}, {pos}] around {root}");
    assert!(calls.get() >= 3, "the bracket never moved: {} probes", calls.get());
    let shallow = gauss(0.8);
    let none = dip_below_zero(shallow, at(&shallow, 1.9), at(&shallow, 1.98), at(&shallow, 2.15));
    assert!(matches!(none, Ok(None)));
    let aside = |w: f64| (1.0 + 10.0 * (w - 1.99).powi(2) - 1.5 * (-((w - 2.045) / 0.004).powi(2)).exp(), ());
    assert!(aside(2.045).0 < 0.0);
    let missed = dip_below_zero(aside, at(&aside, 1.94), at(&aside, 2.0), at(&aside, 2.06));
    assert!(matches!(missed, Ok(None)), "the documented limit moved: {missed:?}");
    let nan = |w: f64| (if w > 2.0 { f64::NAN } else { 1.0 + (w - 1.95).powi(2) }, ());
    assert!(dip_below_zero(nan, (1.9, 1.0025), (1.95, 1.0), (2.15, 1.04)).is_err());
}

/// Every point of a sagging trum60a near resonance has a steady state that is a fixed
/// point of both maps: 150 Ω, 41 kHz, 360-520 N, 0-1.4 N·m, 120-165 V. Without the
/// amplitude-root route (`settle_on_amplitude`) 73 of these 288 points end
/// `no_convergence`.
#[test]
fn a_sagging_drive_near_resonance_has_a_steady_state_everywhere() {
    let m = motor_with("trum60a", "voltage_sag=150", false);
    let p = Prepared::new(&m);
    let mut bad = Vec::new();
    let mut seen = std::collections::BTreeMap::new();
    for i in 0..9 {
        for j in 0..8 {
            for k in 0..4 {
                let op =
                    OperatingPoint::new(360.0 + 20.0 * i as f64, 0.2 * j as f64, 120.0 + 15.0 * k as f64, 41_000.0);
                let s = solve(&m, &op);
                *seen.entry(s.status.as_str()).or_insert(0) += 1;
                match s.status.is_valid() {
                    true => bad.extend(fixed_point_problem(&p, &op, &s).map(|why| format!("{op:?}: {why}"))),
                    false => bad.push(format!("{op:?}: {}", s.status)),
                }
            }
        }
    }
    assert!(bad.is_empty(), "{} of 288 ({seen:?}):\n{}", bad.len(), bad.join("\n"));
    assert!(["ok", "stall", "clamped"].iter().all(|k| seen.get(k).is_some_and(|&n| n >= 15)), "{seen:?}");
}

/// trum60a with a `voltage_sag` of `ohm` [Ω], prepared, and its solution at `op`.
fn sagging_trum60a(ohm: f64, op: OperatingPoint) -> (Prepared, OperatingPoint, Solution) {
    let m = motor_with("trum60a", &format!("voltage_sag={ohm}"), false);
    let s = solve(&m, &op);
    (Prepared::new(&m), op, s)
}

/// Why a sagging point's state is not its own steady state, if it is not: the electrode
/// voltage its current leaves, and the amplitude map at that voltage (a root for a
/// running or stalled state, a small amplitude dying away for a clamped one).
fn fixed_point_problem(p: &Prepared, op: &OperatingPoint, s: &Solution) -> Option<String> {
    let v = sagged_voltage_v(p, op, s);
    if (v - s.electrode_voltage_v).abs() > 1e-9 * op.voltage_v {
        return Some(format!("sagged voltage {v} V, reported {} V", s.electrode_voltage_v));
    }
    let mut d = Drive::at(p, op);
    d.v = s.electrode_voltage_v;
    if s.status == Status::Clamped {
        let w = d.clamp_floor(p.theta);
        let t = trial(p, &d, w, None, None);
        return (t.w_next > t.w).then(|| format!("clamped, but W = {w} m grows to {} m", t.w_next));
    }
    let t = trial(p, &d, s.amplitude_m, None, None);
    ((t.w - t.w_next).abs() > 1e-9 * t.w).then(|| format!("W = {} m maps to {} m", t.w, t.w_next))
}

/// Random sagging points over the three presets (5-600 N, 0-2 N·m, 30-300 V, 39-46 kHz,
/// 10-1000 Ω): every valid state is a fixed point of both the sag and the amplitude map
/// (tests/solver_convergence.rs checks the sag alone, over scaled presets). A clamped
/// state from the lower-branch search that a small amplitude would leave fails here.
#[test]
fn every_sagging_state_is_a_fixed_point_of_both_maps() {
    let mut x: u64 = 0x51ed_270b_27a1_c3f5;
    let mut rnd = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut bad = Vec::new();
    let mut seen = std::collections::BTreeMap::new();
    for _ in 0..1500 {
        let name = ["trum60a", "generic60", "trum60-qut"][(rnd() * 3.0) as usize];
        let z = 10f64.powf(1.0 + 2.0 * rnd());
        let m = motor_with(name, &format!("voltage_sag={z}"), false);
        let p = Prepared::new(&m);
        let op = OperatingPoint::new(5.0 + 595.0 * rnd(), 2.0 * rnd(), 30.0 + 270.0 * rnd(), 39e3 + 7e3 * rnd());
        let s = solve(&m, &op);
        *seen.entry(s.status.as_str()).or_insert(0) += 1;
        if s.status.is_valid() {
            if let Some(why) = fixed_point_problem(&p, &op, &s) {
                bad.push(format!("{name} {z} Ω {op:?} {}: {why}", s.status));
            }
        }
    }
    assert!(bad.is_empty(), "{} of 1500 ({seen:?}):\n{}", bad.len(), bad.join("\n"));
    assert!(seen.values().all(|&n| n > 0) && seen.len() >= 3, "{seen:?}");
}

/// Just past a fold, where r has a minimum a hair above zero, the descent goes on down
/// instead of crawling on noisy secants: this drive (a rise of 40 K and 131.064 V on the
/// electrode, reached inside the sag and thermal fixed point) takes 64 trials with the
/// secant's noise floor (the stretched steps double from r = 2.6e-18 m); without it, 82
/// trials and no convergence.
#[test]
fn the_descent_does_not_crawl_just_past_a_fold() {
    let (_, p) = sag_and_drift_trum60a();
    let mut op = OperatingPoint::new(400.6711409395973, 0.789261744966443, 173.7, 39935.4);
    op.elapsed_s = 611.0;
    let mut d = Drive::at(&p, &op);
    d.warm(&p, 40.0);
    d.v = 131.06413114605616;
    let s = solve_drive(&p, &d, &op, None, &Work::of(&p));
    assert!(s.status.is_valid() && s.iterations <= 72, "{:?} after {} trials", s.status, s.iterations);
    // below the fold's amplitude (2.94 µm): the running state there has folded away
    assert!(s.amplitude_m < 2.9e-6, "{s:?}");
}

const MULTI_BRANCH_CONFIGS: [(&str, &str, bool); 12] = [
    ("generic60", "preload_stiffening=0.504", false),
    ("trum60a", "preload_stiffening=1", false),
    // the candidate's other forms: the radial-friction paper's projection, and a blend
    ("generic60", MODAL_3_3, false),
    ("trum60a", "preload_stiffening:stiffness_scale=1,modal_fraction=0.5", false),
    ("trum60a", "hertz_softening=1e18", false),
    ("generic60", "hertz_softening=3e17", false),
    ("generic60", "preload_stiffening=3.3", true),
    ("trum60a", "preload_stiffening=1", true),
    ("trum60-qut", "hertz_softening=1.089e18", true),
    ("generic60", "hertz_softening=3e17", true),
    ("generic60", "preload_stiffening=0.504;hertz_softening=3e17", false),
    ("trum60a", "preload_stiffening=1;hertz_softening=1e18", true),
];

/// Where G(W) is not monotonic (preload stiffening, Hertz softening, candidate and
/// truth forms, alone and together) the cold solve still reports the largest fixed
/// point, the state reached from above; 1000 random points per configuration, each
/// with its own seed (≈ 15 s in release, mostly the reference's dense scan;
/// `-- --nocapture` prints the census with the mean amplitude evaluations). Without the
/// capped descent and the softening spike probe, 118 of 600 candidate-form points end on
/// a lower branch or clamped; without the truth-form crossing and the fold search, 26 of
/// 4000 truth-form points, and about 8 % with both effects on.
#[test]
fn multi_branch_stators_report_the_largest_fixed_point() {
    let mut all = Vec::new();
    for (i, c) in MULTI_BRANCH_CONFIGS.iter().enumerate() {
        let (wrong, checked, multi, clamped, mean) = largest_fixed_point_check(&[*c], 1000, 100 + i as u64);
        println!("{c:?}: {} wrong of {checked}, {multi} multi, {clamped} clamped, {mean:.2} evals", wrong.len());
        // the sample reaches the cases that matter
        assert!(multi >= 50 && clamped >= 1, "{c:?}: {multi} multi-branch, {clamped} clamped of {checked}");
        all.extend(wrong);
    }
    assert!(all.is_empty(), "{} points:\n{}", all.len(), all.join("\n"));
}

/// The effect-free stators too, whose cold descent takes Newton steps on the trial's
/// exact slope of r = W − G(W) from the top down (`first_step`, `unbracketed_step`):
/// random drives from far below to far above the resonance reach points with several
/// fixed points (W = 0, a middle and the running one) and clamped ones, and every
/// reported amplitude is the largest fixed point of the dense scan.
#[test]
fn effect_free_stators_report_the_largest_fixed_point() {
    let configs: Vec<(&str, &str, bool)> =
        ["trum60a", "generic60", "trum60-qut"].iter().map(|&name| (name, "none", false)).collect();
    let (wrong, checked, multi, clamped, mean) = largest_fixed_point_check(&configs, 3000, 31);
    println!("effect-free: {} wrong of {checked}, {multi} multi, {clamped} clamped, {mean:.2} evals", wrong.len());
    assert!(multi >= 20 && clamped >= 1, "{multi} multi-branch, {clamped} clamped of {checked}");
    assert!(wrong.is_empty(), "{} points:\n{}", wrong.len(), wrong.join("\n"));
}

/// Every motor parameter over many decades (each alone, ×10^-6 to ×10^6 where the motor
/// stays valid), at running, loaded and low-drive points: a point reported `clamped` is
/// clamped for real — an amplitude of a thousandth of the static deflection Θ·V/k (no
/// damping in it) dies away, G(W) ≤ W — and a running or stalled point is a fixed point
/// of the amplitude map. A clamp threshold relative to the undamped bound Θ·V/(ω·c) grew
/// without limit as the damping fell and failed the first (generic60 at c = 1e-7 N·s/m:
/// `clamped` at every point, 86 rpm from 1e-6 N·s/m up).
#[test]
fn clamped_points_are_clamped_over_many_decades_of_every_parameter() {
    let ops = [
        OperatingPoint::new(250.0, 0.0, 200.0, 43_000.0),
        OperatingPoint::new(250.0, 0.05, 150.0, 42_000.0),
        OperatingPoint::new(26.87, 0.0, 6.63, 40_456.6),
    ];
    let (mut checked, mut clamped) = (0, 0);
    for name in ["generic60", "trum60a"] {
        let base = crate::presets::frozen(name).expect("preset");
        for key in Motor::all_keys() {
            let dotted = format!("{}.{}", key.section, key.key);
            for decade in (-6..=6).step_by(2) {
                let mut m = base.clone();
                let Some(v) = m.param_mut(&dotted) else { continue };
                if *v == 0.0 || dotted.contains("wave_number") {
                    continue;
                }
                *v *= 10f64.powi(decade);
                if m.validate("t", None).is_err() {
                    continue;
                }
                let p = Prepared::new(&m);
                for op in &ops {
                    let s = solve_prepared(&p, &m, op, None);
                    let d = Drive::at(&p, op);
                    // (the effects' fixed points move the drive; the frozen presets have none)
                    let plain = iterated(&p, op) == (false, false) && p.runout_m == 0.0;
                    match s.status {
                        Status::Clamped if plain => {
                            clamped += 1;
                            let w = 1e-3 * p.theta * d.v / d.ks;
                            let t = trial(&p, &d, w, None, None);
                            assert!(
                                t.w_next <= w * (1.0 + 1e-9),
                                "{name}, {dotted} ×1e{decade} at {op:?}: clamped, but W = {w:e} m grows to {:e} m",
                                t.w_next
                            );
                        }
                        Status::Ok | Status::Stall if plain => {
                            let t = trial(&p, &d, s.amplitude_m, None, None);
                            assert!(
                                (t.w - t.w_next).abs() <= 1e-6 * t.w,
                                "{name}, {dotted} ×1e{decade} at {op:?}: {:?} at W = {:e} m maps to {:e} m",
                                s.status,
                                t.w,
                                t.w_next
                            );
                        }
                        _ => {}
                    }
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 500 && clamped > 10, "{checked} points, {clamped} clamped");
}

/// The scaled complementary error function of the diffusive truth-form warm-up agrees
/// with libm's e^(z²)·erfc(z) to 2e-7 relative on [0, 5], and falls as 1/(z·√π).
#[test]
fn scaled_erfc_agrees_with_libm() {
    for i in 0..=500 {
        let z = 0.01 * i as f64;
        let want = (z * z).exp() * libm::erfc(z);
        assert!((super::fixed_points::erfcx(z) / want - 1.0).abs() < 2e-7, "z = {z}");
    }
    let z = 300.0;
    assert!((super::fixed_points::erfcx(z) * z * std::f64::consts::PI.sqrt() - 1.0).abs() < 1e-5);
}

/// The truth forms' warm-ups (docs/EFFECTS.md) have the shapes that keep them out of
/// `thermal_drift`'s two-node family: the series capacities start flat (rise ∝ t², where
/// every member rises ∝ t), the diffusive one as √t; both reach the same steady rise as
/// the candidate, the diffusive one slowly (1 − 1/√(πx)).
#[test]
fn truth_form_warm_ups_have_their_shapes() {
    use super::fixed_points::temperature_rise_for_drift as rise;
    let mut m = motor_with("trum60a", "thermal_drift=-4e-4", false);
    let cand = Prepared::new(&m);
    m.effects.set_truth_forms(true);
    let series = Prepared::new(&m);
    m.effects.set_truth_form_b(true);
    let diffusive = Prepared::new(&m);
    let (loss, tau) = (10.0, cand.heat_cap / cand.alpha_s);
    let ss = loss / cand.alpha_s;
    // early: the ratio of the rises at t and 2t (2 for ∝ t, 4 for ∝ t², √2 for ∝ √t)
    let t = 1e-4 * tau;
    let ratio = |p: &Prepared| rise(p, loss, 2.0 * t) / rise(p, loss, t);
    assert!((ratio(&cand) - 2.0).abs() < 1e-3, "{}", ratio(&cand));
    assert!((ratio(&series) - 4.0).abs() < 1e-2, "{}", ratio(&series));
    assert!((ratio(&diffusive) - 2f64.sqrt()).abs() < 1e-2, "{}", ratio(&diffusive));
    // late: all at the steady rise; the diffusive one within 1/√(πx) of it
    for p in [&cand, &series] {
        assert!((rise(p, loss, 40.0 * tau) / ss - 1.0).abs() < 1e-9);
    }
    let x = 400.0;
    let left = 1.0 - rise(&diffusive, loss, x * tau) / ss;
    assert!((left * (std::f64::consts::PI * x).sqrt() - 1.0).abs() < 1e-2, "{left}");
}

/// The multi-branch descent with the bound on G that needs no interface integral (the
/// top it rules out from the cold bound, `descent::Split::Bounded`, secant steps inside
/// the bracket) against the descent without it (the cold top's trial, midpoint splits,
/// regula falsi; `descent::REFERENCE_DESCENT`) on `trum60a` as shipped (radial friction
/// and preload stiffening, the mode below the drive) over preload × voltage × frequency ×
/// torque: the same status and amplitude to 1e-9 relative at every point (both converge
/// to 1e-10 on r, so they differ by the solve's tolerance alone), at many points where
/// the amplitude map has several fixed points, in fewer trials.
#[test]
fn the_bounded_descent_finds_the_reference_descents_root() {
    let m = crate::presets::preset("trum60a").expect("preset");
    let set_reference = |on: bool| super::descent::REFERENCE_DESCENT.with(|c| c.set(on));
    let (mut points, mut multi, mut evals_ref, mut evals_bounded) = (0, 0, 0u64, 0u64);
    let mut differ = Vec::new();
    for f_n in [120.0, 180.0, 240.0, 300.0, 360.0] {
        for v in [120.0, 160.0, 200.0, 240.0, 280.0] {
            for f in [41.0e3, 41.8e3, 42.5e3, 43.0e3, 43.7e3, 44.5e3] {
                for t in [0.0, 0.3, 0.6, 0.9] {
                    let op = OperatingPoint::new(f_n, t, v, f);
                    set_reference(true);
                    let a = solve(&m, &op);
                    set_reference(false);
                    let b = solve(&m, &op);
                    points += 1;
                    evals_ref += u64::from(a.iterations);
                    evals_bounded += u64::from(b.iterations);
                    multi += usize::from(amplitude_branches(&m, &op).len() > 1);
                    let rel = (a.amplitude_m - b.amplitude_m).abs() / a.amplitude_m.abs().max(f64::MIN_POSITIVE);
                    if a.status != b.status || !(rel <= 1e-9 || a.amplitude_m == b.amplitude_m) {
                        differ.push(format!(
                            "{op:?}: reference {:?} {:e} m, bounded {:?} {:e} m",
                            a.status, a.amplitude_m, b.status, b.amplitude_m
                        ));
                    }
                }
            }
        }
    }
    println!(
        "{points} points, {multi} with several fixed points, trials {evals_ref} reference, {evals_bounded} bounded"
    );
    assert!(differ.is_empty(), "{} of {points} points differ:\n{}", differ.len(), differ.join("\n"));
    assert!(multi >= 100, "only {multi} of {points} points have several fixed points");
    assert!(evals_bounded < evals_ref, "{evals_bounded} trials bounded, {evals_ref} reference");
}

/// The speed solve of the generalised interface (`interface::general_interface`) against
/// its plain-Newton reference (`REFERENCE_SPEED_SOLVE`: from the guess, Newton steps, a
/// step carried only after two): its faster route starts a trial after a stalled one with
/// the rotor at rest, takes Halley steps where the node sums give ∂²torque/∂u² and judges
/// the carried step by it. Both solve the same unique root of a falling torque(u) to 1e-14,
/// so every point must come out with the same status and every quantity within 1e-9
/// relative (of the value, or of 1e-3 of the quantity's largest value over the motor's
/// points where the value is smaller: just below stall the speed is a difference of nearly
/// equal torques), with fewer integrals. Random points through running and stalled states
/// of `radial_friction` (small to large ρ, candidate and truth forms), `tangential_compliance`
/// (tanh and the sharper saturation, which has no second derivative and keeps Newton's
/// steps), both together, and `trum60a` as shipped.
#[test]
fn faster_speed_solves_give_the_plain_newton_solves_points() {
    use crate::interface::{REFERENCE_SPEED_SOLVE, SPEED_SOLVE_INTEGRALS};
    use crate::quantities::{values, QUANTITIES};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(20_261_129);
    let sets: [(&str, &[&str], bool); 10] = [
        ("trum60a as shipped", &[], false),
        ("radial_friction=0.05", &["none", "radial_friction=0.05"], false),
        ("radial_friction=1", &["none", "radial_friction=1"], false),
        ("radial_friction=2.5", &["none", "radial_friction=2.5"], false),
        ("radial_friction=0.5 truth", &["none", "radial_friction=0.5"], true),
        ("tangential_compliance=1", &["none", "tangential_compliance=1"], false),
        ("tangential_compliance=0.1", &["none", "tangential_compliance=0.1"], false),
        (
            "tangential_compliance sharp",
            &["none", "tangential_compliance:shear_compliance_ratio=1,stick_sharpness=3"],
            false,
        ),
        ("both", &["none", "radial_friction=0.5", "tangential_compliance=1"], false),
        ("tangential_compliance=1 truth", &["none", "tangential_compliance=1"], true),
    ];
    let integrals = |f: &mut dyn FnMut() -> Solution| {
        let before = SPEED_SOLVE_INTEGRALS.with(std::cell::Cell::get);
        let s = f();
        (s, SPEED_SOLVE_INTEGRALS.with(std::cell::Cell::get) - before)
    };
    let mut differ = Vec::new();
    let (mut n_ref, mut n_fast, mut worst) = (0u64, 0u64, 0.0f64);
    for (label, assignments, truth) in sets {
        let mut m = crate::presets::preset("trum60a").expect("preset");
        for a in assignments {
            m.effects.parse_assignment(a).expect("assignment");
        }
        if truth {
            m.effects.set_truth_forms(true);
        }
        let mut pairs = Vec::new();
        let (mut stalled, mut running) = (0, 0);
        for _ in 0..250 {
            let op = OperatingPoint::new(
                rng.random_range(60.0..400.0),
                rng.random_range(0.0..1.4),
                rng.random_range(100.0..300.0),
                rng.random_range(41e3..45e3),
            );
            REFERENCE_SPEED_SOLVE.with(|c| c.set(true));
            let (a, ia) = integrals(&mut || solve(&m, &op));
            REFERENCE_SPEED_SOLVE.with(|c| c.set(false));
            let (b, ib) = integrals(&mut || solve(&m, &op));
            (n_ref, n_fast) = (n_ref + ia, n_fast + ib);
            match a.status {
                Status::Stall => stalled += 1,
                Status::Ok => running += 1,
                _ => {}
            }
            pairs.push((op, a, b));
        }
        println!("{label}: {stalled} stalled, {running} running points");
        assert!(stalled >= 10 && running >= 10, "{label}: {stalled} stalled, {running} running points");
        let largest: Vec<f64> = (0..QUANTITIES.len())
            .map(|i| pairs.iter().map(|(_, a, _)| values(a)[i].abs()).filter(|v| v.is_finite()).fold(0.0, f64::max))
            .collect();
        for (op, a, b) in &pairs {
            if a.status != b.status {
                differ.push(format!("{label} {op:?}: status {:?} reference, {:?} fast", a.status, b.status));
                continue;
            }
            for (i, (x, y)) in values(a).iter().zip(values(b)).enumerate() {
                let scale = x.abs().max(1e-3 * largest[i]);
                let same = x == &y || (x.is_nan() && y.is_nan()) || (x - y).abs() <= 1e-9 * scale;
                if x != &y && x.is_finite() {
                    worst = worst.max((x - y).abs() / scale);
                }
                if !same {
                    differ.push(format!("{label} {op:?}: {} {x:e} reference, {y:e} fast", QUANTITIES[i].name));
                }
            }
        }
    }
    println!("interface integrals: {n_ref} reference, {n_fast} fast; largest difference {worst:.1e} of the scale");
    assert!(differ.is_empty(), "{} differences:\n{}", differ.len(), differ.join("\n"));
    assert!(n_fast * 10 < n_ref * 9, "{n_fast} integrals fast, {n_ref} reference");
}

/// The motors of the work-bound census: every preset with no effect, each of the seven
/// effects alone at its typical strength, and all seven together, each in candidate and
/// truth form.
fn work_census_motors() -> Vec<(String, crate::params::Motor)> {
    let mut out = Vec::new();
    for preset in crate::presets::PRESETS.iter().map(|p| p.name) {
        for set in 0..=crate::effects::ALL.len() + 1 {
            for truth in [false, true] {
                let mut m = crate::presets::preset(preset).expect("preset");
                m.effects.parse_assignment("none").expect("none");
                let label = match set {
                    0 => "none".to_string(),
                    s if s <= crate::effects::ALL.len() => crate::effects::ALL[s - 1].name().to_string(),
                    _ => "all seven".to_string(),
                };
                for (i, e) in crate::effects::ALL.iter().enumerate() {
                    if set == i + 1 || set == crate::effects::ALL.len() + 1 {
                        m.effects.set_strength(*e, e.info().params[0].typical);
                    }
                }
                m.effects.set_truth_forms(truth);
                m.validate("census", None).expect("a valid motor");
                out.push((format!("{preset} {label} truth={truth}"), m));
            }
        }
    }
    out
}

/// Every converging point of a broad set (each preset with no effect, each effect alone and
/// all seven together, candidate and truth forms, at ordinary and loaded operating points,
/// cold and along warm-started torque sweeps) spends less than a twentieth of the default
/// work bound, so the bound changes none of their answers; and none reports the bound.
#[test]
fn converging_points_stay_far_inside_the_work_bound() {
    let ops = [(250.0, 0.3, 200.0, 43e3, 60.0), (400.0, 1.0, 250.0, 41.5e3, 600.0), (100.0, 0.1, 120.0, 44e3, 0.0)];
    let (mut most, mut at, mut converged) = (0u64, String::new(), 0);
    for (label, m) in work_census_motors() {
        let p = Prepared::new(&m);
        for &(f, t, v, hz, el) in &ops {
            let mut op = OperatingPoint::new(f, t, v, hz);
            op.elapsed_s = el;
            let (s, spent) = solve_prepared_counted(&p, &m, &op, None);
            assert!(!s.work_bound_reached, "{label} {op:?}: {spent} units");
            if s.status.is_valid() {
                converged += 1;
                if spent > most {
                    (most, at) = (spent, format!("{label} {op:?}"));
                }
            }
        }
        // a warm-started torque line, as maps solve them: the same answers as without a
        // bound at all
        let unbounded = Prepared::new(&m).with_work_bound(u64::MAX);
        let grid = crate::sweep::Grid {
            preload_n: crate::axis::Axis::fixed(250.0),
            voltage_v: crate::axis::Axis::fixed(200.0),
            frequency_hz: crate::axis::Axis::fixed(43e3),
            torque_nm: crate::axis::Axis::linspace(0.0, 1.2, 7),
        };
        let mut line = Vec::new();
        crate::sweep::solve_range(&m, &p, &grid, 0..7, |_, _, s| line.push(s.clone()));
        let mut free = Vec::new();
        crate::sweep::solve_range(&m, &unbounded, &grid, 0..7, |_, _, s| free.push(s.clone()));
        // (Debug text: bit for bit, NaN included)
        assert_eq!(format!("{line:?}"), format!("{free:?}"), "{label}");
        assert!(line.iter().all(|s| !s.work_bound_reached), "{label}");
    }
    println!("{converged} converging points; the most work {most} units ({at})");
    assert_eq!(converged, 162);
    assert!(most * 20 < WORK_BOUND, "{most} units at {at}");
}

/// generic60 with all seven effects in truth form, `thermal_drift` at the top of its
/// stiffness range and an interface fraction of 4140 (outside its valid range: the motor
/// fails validation, but the fuzzer solves it), at 300 N, 0.5 N·m, 250 V, 43.5 kHz, 120 s:
/// about 4·10⁸ units of work without a bound (483 000 amplitude trials, 13 s). Under a
/// bound of 2·10⁷ units it ends as `no_convergence` with the bound as its reason, past the
/// bound by less than one trial's work.
#[test]
fn a_slow_input_ends_at_the_work_bound() {
    let mut m = crate::presets::preset("generic60").expect("preset");
    m.effects.set(Effect::RadialFriction, &[1.0, 0.0]);
    m.effects.set(Effect::VoltageSag, &[150.0, 0.0]);
    m.effects.set(Effect::Eccentricity, &[2e-5, 0.0, 0.0]);
    m.effects.set(Effect::ThermalDrift, &[0.05, -0.002, 0.0, 4140.0]);
    m.effects.set(Effect::TangentialCompliance, &[1.0, 0.0]);
    m.effects.set(Effect::PreloadStiffening, &[0.05, 0.0]);
    m.effects.set(Effect::HertzSoftening, &[1e18, 0.004, 0.0]);
    m.effects.set_truth_forms(true);
    assert!(m.validate("slow", None).is_err());
    let mut op = OperatingPoint::new(300.0, 0.5, 250.0, 43_500.0);
    op.elapsed_s = 120.0;
    let bound = 20_000_000;
    let p = Prepared::new(&m).with_work_bound(bound);
    let (s, spent) = solve_prepared_counted(&p, &m, &op, None);
    println!("{} after {spent} units", s.status);
    assert_eq!(s.status, Status::NoConvergence);
    assert!(s.work_bound_reached);
    assert!((bound..bound + 200_000).contains(&spent), "{spent} units");
    // the public entry point says the same
    let again = solve_prepared(&p, &m, &op, None);
    assert_eq!((again.status, again.work_bound_reached), (Status::NoConvergence, true));
}

/// A tiny bound makes an ordinary point report the bound, never a wrong answer: cold, with
/// each effect that nests routes, and along a warm-started sweep. A bound just at the work
/// the point needs leaves its answer bit for bit.
#[test]
fn a_tiny_work_bound_reports_the_bound_rather_than_an_answer() {
    let op = OperatingPoint::new(250.0, 0.3, 200.0, 43e3);
    for fx in ["none", "voltage_sag=150", "eccentricity=2e-5", "thermal_drift=-4e-4", "tangential_compliance=1"] {
        let mut m = crate::presets::preset("trum60a").expect("preset");
        m.effects.parse_assignment(fx).expect("assignment");
        let p = Prepared::new(&m);
        let mut o = op;
        o.elapsed_s = 600.0;
        let (full, need) = solve_prepared_counted(&p, &m, &o, None);
        assert!(full.status.is_valid() && !full.work_bound_reached, "{fx}: {full:?}");
        for bound in [0, 1, 10, 25, need / 2, need - 1] {
            let s = solve_prepared(&Prepared::new(&m).with_work_bound(bound), &m, &o, None);
            assert_eq!((s.status, s.work_bound_reached), (Status::NoConvergence, true), "{fx}: bound {bound}");
            assert!(s.warnings.is_empty(), "{fx}: {:?}", s.warnings);
        }
        let just = solve_prepared(&Prepared::new(&m).with_work_bound(need + 1), &m, &o, None);
        assert_eq!(format!("{just:?}"), format!("{full:?}"), "{fx}");
    }
    let m = crate::presets::preset("trum60a").expect("preset");
    let grid = crate::sweep::Grid {
        preload_n: crate::axis::Axis::fixed(250.0),
        voltage_v: crate::axis::Axis::fixed(200.0),
        frequency_hz: crate::axis::Axis::fixed(43e3),
        torque_nm: crate::axis::Axis::linspace(0.0, 1.2, 7),
    };
    let tiny = Prepared::new(&m).with_work_bound(25);
    let mut n = 0;
    crate::sweep::solve_range(&m, &tiny, &grid, 0..7, |_, _, s| {
        assert_eq!((s.status, s.work_bound_reached), (Status::NoConvergence, true), "{s:?}");
        n += 1;
    });
    assert_eq!(n, 7);
}

/// A ring motor as a diagnosis calibrated it against data of a strongly sagging drive,
/// with a 900 Ω source and strong preload stiffening: under load its electrode
/// voltage's passes swing between a clamped and a moving stator about a jump of the
/// pass map.
const SWINGING_SAG_MOTOR: &str = r#"
name = "ring60-calibrated"
[geometry]
wave_number = 9
mean_radius_m = 0.02599493161218265
contact_width_m = 0.0032
neutral_plane_distance_m = 0.0021054903555125216
[friction_layer]
youngs_modulus_pa = 170631147.21030605
thickness_m = 0.0005
friction_coefficient = 0.36951947704277416
[stator]
modal_mass_kg = 0.006987676702230779
resonance_frequency_hz = 41548.148739236334
modal_damping_ns_per_m = 13.974463279727196
force_factor_n_per_v = 0.2739861178837353
[electrical]
clamped_capacitance_f = 3.2127671102799357e-9
dielectric_loss_tangent = 0.0017972394578689539
feedback_gain_v_per_m = 35707266.34000827
[rotor]
viscous_damping_nms = 0.0005
inertia_kg_m2 = 7.2e-6
mass_kg = 0.03
[thermal]
heat_transfer_coefficient_w_per_m2k = 9.542412518315741
surface_area_m2 = 0.02366
heat_capacity_j_per_k = 157.37908912109012
ambient_c = 28.0
[assembly]
axial_spring_stiffness_n_per_m = 200000.0
[effects]
preload_stiffening = { stiffness_scale = 0.2396248775337372, modal_fraction = 0.9999950218379732 }
voltage_sag = { source_resistance_ohm = 899.5436597886236 }
"#;

/// Passes that swing across a jump of the electrode voltage's pass map switch to the
/// bracket at once, bisect it while its ends are states of different kinds and stop once
/// it proves the jump, so the lower-branch search that finds the stall starts after a
/// fraction of the passes: the solve stays under 30 000 units of work (22 330). The state
/// is the stall, a fixed point of both maps.
#[test]
fn passes_that_swing_across_a_jump_stop_early_and_still_find_the_stall() {
    let m = Motor::from_toml_str(SWINGING_SAG_MOTOR, "swinging").expect("motor");
    let p = Prepared::new(&m);
    let op = OperatingPoint::new(240.0, 0.36, 200.0, 43_000.0);
    let (s, work) = solve_prepared_counted(&p, &m, &op, None);
    assert_eq!(s.status, Status::Stall, "{s:?}");
    assert!(fixed_point_problem(&p, &op, &s).is_none(), "{:?}", fixed_point_problem(&p, &op, &s));
    assert!((s.amplitude_m / 1.320030386394708e-7 - 1.0).abs() < 1e-9, "{s:?}");
    assert!((s.electrode_voltage_v - 152.15097061063776).abs() < 1e-7, "{s:?}");
    assert!(work < 30_000, "work {work}");
}

/// The finiteness check of every solved point: a NaN or an infinity in any quantity fails
/// it, except a stall torque that a solve without the stall torque leaves NaN (and only
/// there: where the solve computes it, a NaN stall torque fails too).
#[test]
fn the_finiteness_check_skips_only_an_uncomputed_stall_torque() {
    use crate::quantities::{QUANTITIES, STALL_TORQUE_INDEX};
    assert_eq!(QUANTITIES[STALL_TORQUE_INDEX].name, "stall_torque_nm");
    let m = crate::presets::frozen("trum60a").expect("preset");
    let (full, lean) = (Prepared::new(&m), Prepared::new(&m).without_stall_torque());
    let s = solve_prepared(&full, &m, &OperatingPoint::new(250.0, 0.3, 200.0, 43e3), None);
    assert!(full.all_finite(&s) && lean.all_finite(&s));
    let no_stall = Solution { stall_torque_nm: f64::NAN, ..s.clone() };
    assert!(lean.all_finite(&no_stall) && !full.all_finite(&no_stall));
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let inf_stall = Solution { stall_torque_nm: bad, ..s.clone() };
        assert_eq!(lean.all_finite(&inf_stall), bad.is_nan(), "stall torque {bad}");
        let others = [
            Solution { speed_rpm: bad, ..no_stall.clone() },
            Solution { efficiency: bad, ..no_stall.clone() },
            Solution { input_power_w: bad, ..no_stall.clone() },
            Solution { feedback_v: bad, ..no_stall.clone() },
            Solution { amplitude_m: bad, ..no_stall.clone() },
            Solution { friction_loss_w: bad, ..no_stall.clone() },
        ];
        for t in &others {
            assert!(!lean.all_finite(t) && !full.all_finite(t), "{bad} in {t:?}");
        }
    }
}
