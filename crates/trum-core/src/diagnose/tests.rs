//! Tests of the whole diagnosis and of its helpers.

use super::baseline::clipped_second_moment;
use super::candidates::{added_near_zero, fit_params};
use super::context::{noise_scaled, scales, speed_std_clipped};
use super::folds::{approx_cv, predict};
use super::pairs::{first_order_gains, held_out_need, pair_gains, pair_may_beat, worth_pair_fit, PAIR_GAIN};
use super::*;
use crate::calibrate::tests::classic_tolerances;
use crate::calibrate::{residuals, Calibration, FittedParam, ParamRef};
use crate::synth::{synthesize, Campaign, SynthConfig};

pub(super) fn data(m: &Motor, noise: f64, seed: u64) -> (Vec<ObservedRow>, Vec<String>) {
    synthesized(m, &SynthConfig { campaign: Campaign::PreloadTorque, noise, seed, ..SynthConfig::default() })
}

/// The rows and runs of a synthetic campaign of `m`.
fn synthesized(m: &Motor, cfg: &SynthConfig) -> (Vec<ObservedRow>, Vec<String>) {
    let rows = synthesize(m, cfg).expect("synth");
    (rows.iter().map(|r| r.observed()).collect(), rows.iter().map(|r| r.run_id.clone()).collect())
}

pub(super) fn quick(exact_cv: bool) -> DiagnoseOptions {
    DiagnoseOptions {
        candidates: vec![Effect::VoltageSag, Effect::PreloadStiffening],
        try_pairs: false,
        bootstrap: 50,
        exact_cv,
        ..DiagnoseOptions::default()
    }
}

/// The nominal trum60a and seeded preload-torque data of it with voltage sag (300 Ω).
pub(super) fn sag_data() -> (Motor, Vec<ObservedRow>, Vec<String>) {
    let mut m = crate::calibrate::tests::reference_motor();
    m.effects.set_strength(Effect::VoltageSag, 300.0);
    let (rows, groups) = data(&m, 1.0, 11);
    (crate::calibrate::tests::reference_motor(), rows, groups)
}

/// A fold step that overshoots is halved until the training fit improves, not dropped:
/// with the Jacobian four times too small the full step is four times too long, and the
/// damped route still removes the held-out block's influence (predictions as with the
/// right Jacobian), where dropping the step left the full-data fit, predicting the
/// held-out block in-sample.
#[test]
fn an_overshooting_fold_step_is_damped_not_dropped() {
    let (nominal, rows, _) = sag_data();
    let fit = FitOptions::default();
    // (the motor's parameters under their priors; the bench's preload offset and current
    // gain held, whose near-degenerate directions with the sag's can leave a fold's step
    // without a gain at any damping, the route this test is not about)
    let held =
        BTreeMap::from([("bench.preload_offset_n".to_string(), 0.0), ("bench.current_gain_rel".to_string(), 0.0)]);
    let (s0, params) = fit_params(&nominal, &nominal, &rows, &[], false, &held);
    let cal = Calibration::builder(&s0, &rows).params(&params).options(&fit).run().expect("baseline");
    // folds by preload, so each held-out block moves the parameters
    let mut loads: Vec<f64> = rows.iter().map(|r| r.op.preload_n).collect();
    loads.sort_by(f64::total_cmp);
    loads.dedup();
    let folds: Vec<usize> =
        rows.iter().map(|r| loads.iter().position(|&l| l == r.op.preload_n).unwrap_or(0) % 4).collect();
    let right = approx_cv(&cal, &rows, &folds, 4, &fit);
    assert_eq!(right.in_sample, 0);
    let right = right.preds;
    let mut short = cal.clone();
    short.lin.jacobian *= 0.25;
    let damped = approx_cv(&short, &rows, &folds, 4, &fit);
    assert_eq!(damped.in_sample, 0);
    let damped = damped.preds;
    let all: Vec<&ObservedRow> = rows.iter().collect();
    let in_sample = predict(&cal.motor, &all);
    // largest difference in units of the readings' σ
    let sigmas: Vec<f64> = rows.iter().flat_map(|r| r.readings.iter().map(|x| x.2)).collect();
    let gap = |a: &[Vec<f64>], b: &[Vec<f64>]| {
        let d = a.iter().flatten().zip(b.iter().flatten()).zip(&sigmas).map(|((x, y), s)| ((x - y) / s).abs());
        d.fold(0.0, f64::max)
    };
    let moved = gap(&right, &in_sample);
    assert!(moved > 0.3, "the held-out blocks do not move the fit: {moved} σ");
    assert!(gap(&damped, &right) < 0.2 * moved, "damped {} vs held-out shift {moved}", gap(&damped, &right));
    // 64 times too long: even a quarter of it overshoots, and the stuck folds are
    // refitted on their training rows, which predicts their blocks held out (as the right
    // steps do), not in-sample
    short.lin.jacobian *= 1.0 / 16.0;
    let stuck = approx_cv(&short, &rows, &folds, 4, &fit);
    assert_eq!(stuck.in_sample, 0);
    assert!(gap(&stuck.preds, &in_sample) > 0.5 * moved, "{} vs {moved}", gap(&stuck.preds, &in_sample));
    assert!(
        gap(&stuck.preds, &right) < 0.2 * moved,
        "refitted {} vs held-out shift {moved}",
        gap(&stuck.preds, &right)
    );
}

/// The residual moments of a reading clipped at zero, against direct integration over
/// the normal density.
#[test]
fn clipped_noise_moments_are_those_of_the_clipped_normal() {
    let phi = |z: f64| (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
    for x in [-3.0f64, -1.0, -0.2, 0.0, 0.7, 2.0, 6.0] {
        // Y = max(0, x + Z): zero below z = −x
        let zero = (-x).max(-12.0);
        let below = crate::quad::integral(phi, -12.0, zero);
        let m1 = crate::quad::integral(|z| (x + z) * phi(z), zero, 12.0);
        let m2 = crate::quad::integral(|z| (x + z) * (x + z) * phi(z), zero, 12.0);
        let about_m = m2 - 2.0 * x * m1 + x * x * (below + crate::quad::integral(phi, zero, 12.0));
        let var = m2 - m1 * m1;
        assert!(
            (clipped_second_moment(x, false) - about_m).abs() < 1e-9,
            "x {x}: {} vs {about_m}",
            clipped_second_moment(x, false)
        );
        assert!(
            (clipped_second_moment(x, true) - var).abs() < 1e-9,
            "x {x}: {} vs {var}",
            clipped_second_moment(x, true)
        );
    }
    assert!((clipped_second_moment(0.0, true) - (0.5 - 0.5 / std::f64::consts::PI)).abs() < 1e-15);
}

/// On data without any effect a model without error scores the noise alone: the
/// reported noise NRMSE is the baseline's held-out NRMSE within their scatter (over six
/// seeds 0.91-1.13 in the preload-torque campaign and 0.98-1.20 in the combined one;
/// the weights' upper-bound levels give 1.5-1.8 and 3.3-4.1), and never above the
/// weights' level.
#[test]
fn the_noise_nrmse_is_what_a_model_without_error_scores() {
    let m = crate::calibrate::tests::reference_motor();
    let opts = DiagnoseOptions {
        candidates: vec![Effect::VoltageSag],
        try_pairs: false,
        bootstrap: 20,
        ..DiagnoseOptions::default()
    };
    for campaign in [Campaign::PreloadTorque, Campaign::Combined] {
        for seed in [1, 2, 3] {
            let cfg = SynthConfig { campaign, noise: 1.0, seed, ..SynthConfig::default() };
            let (rows, groups) = synthesized(&m, &cfg);
            let d = diagnose(&m, &rows, &groups, &opts).expect("diagnosis");
            let ratio = d.noise_nrmse / d.baseline_heldout_nrmse;
            assert!(
                (0.8..1.3).contains(&ratio),
                "{campaign:?} seed {seed}: noise {} vs baseline {}",
                d.noise_nrmse,
                d.baseline_heldout_nrmse
            );
            assert!(d.noise_nrmse <= d.noise_nrmse_weights, "{} > {}", d.noise_nrmse, d.noise_nrmse_weights);
            assert_eq!(d.verdict, "none");
        }
    }
}

#[test]
fn approximate_and_exact_block_cross_validation_agree() {
    let (nominal, rows, groups) = sag_data();
    let a = diagnose(&nominal, &rows, &groups, &quick(false)).expect("approximate");
    let e = diagnose(&nominal, &rows, &groups, &quick(true)).expect("exact");
    // the refit step is first-order: held-out errors within 10 %, same verdict
    let rel = (a.baseline_heldout_nrmse / e.baseline_heldout_nrmse - 1.0).abs();
    assert!(rel < 0.1, "baseline held-out NRMSE {} vs {}", a.baseline_heldout_nrmse, e.baseline_heldout_nrmse);
    assert_eq!(a.verdict, e.verdict);
    assert_eq!(a.verdict, "voltage_sag");
    let sag = |d: &Diagnosis| d.ranking.iter().find(|r| r.effect == "voltage_sag").map(|r| r.shrink).unwrap_or(0.0);
    assert!((sag(&a) - sag(&e)).abs() < 0.1, "shrink {} vs {}", sag(&a), sag(&e));
}

#[test]
fn noisier_bench_than_assumed_is_not_mistaken_for_an_effect() {
    // three times the nominal bench noise: the stated noise levels are too small, the
    // estimate from the data rescales them, and nothing is claimed
    let m = crate::calibrate::tests::reference_motor();
    let (rows, groups) = data(&m, 3.0, 5);
    let d = diagnose(&m, &rows, &groups, &quick(false)).expect("diagnosis");
    assert_eq!(d.verdict, "none", "{:?}", d.ranking);
    let speed = d.noise_scale.iter().find(|(q, _, _)| q == "speed_rpm").expect("speed noise estimated");
    assert!(speed.1 > 1.0, "{speed:?}");
}

/// The pair screen's first-order gains are what a refit removes, in both held-out
/// measures' terms: on noise-free data of moderate radial friction (0.6: the calibrated
/// baseline's Huber weights go down to 0.45, and they are taken back out), at the
/// calibrated baseline, against the refit with the effect; and the pair screen's bars
/// on them.
#[test]
fn first_order_gains_are_what_the_refit_removes() {
    let nominal = crate::calibrate::tests::reference_motor();
    let mut truth = nominal.clone();
    truth.effects.set(Effect::RadialFriction, &[0.6]);
    let loads = [100.0, 175.0, 250.0, 325.0, 400.0];
    let rows = crate::calibrate::tests::rows_on_grid(&truth, &loads, &[0.0, 0.15, 0.3, 0.45]);
    let fit = FitOptions::default();
    let (s0, params) = fit_params(&nominal, &nominal, &rows, &[], false, &classic_tolerances());
    let base = Calibration::builder(&s0, &rows).params(&params).options(&fit).run().expect("baseline");
    let sig = signature::signature(&base, &rows, Effect::RadialFriction).expect("signature");
    let sc = scales(&rows);
    let (d_chi2, d_e2) = first_order_gains(&base, &rows, &sig, &sc);
    let (s1, params) =
        fit_params(&nominal, &base.motor, &rows, &[Effect::RadialFriction], false, &classic_tolerances());
    let with = Calibration::builder(&s1, &rows)
        .params(&params)
        .options(&fit)
        .adding(&[Effect::RadialFriction])
        .run()
        .expect("refit");
    assert!(!with.abandoned);
    // Σ z² and Σ e² of a motor's residuals
    let sums = |m: &Motor| {
        let z = residuals(m, &rows);
        let scale = rows.iter().flat_map(|r| r.readings.iter().map(|&(o, _, s)| s / sc[&o]));
        z.iter().zip(scale).fold((0.0, 0.0), |a, (z, k)| (a.0 + z * z, a.1 + (z * k).powi(2)))
    };
    let (b, a) = (sums(&base.motor), sums(&with.motor));
    assert!(a.0 < 1e-2 * b.0, "the refit removes the gap: {} -> {}", b.0, a.0);
    let (r_chi2, r_e2) = (d_chi2 / (b.0 - a.0), d_e2 / (b.1 - a.1));
    assert!((0.8..=1.05).contains(&r_chi2), "χ²: first order {d_chi2} vs refit {}", b.0 - a.0);
    assert!((0.8..=1.05).contains(&r_e2), "Σe²: first order {d_e2} vs refit {}", b.1 - a.1);

    // the screen on these gains: a quarter of what is needed in either held-out measure
    let worth = |held| worth_pair_fit(Some(&base), &rows, Effect::RadialFriction, 10.0, held, &sc).0;
    assert!(worth(None));
    assert!(worth(Some((3.9 * d_chi2, f64::INFINITY))) && worth(Some((0.0, 3.9 * d_e2))));
    assert!(!worth(Some((4.1 * d_chi2, 4.1 * d_e2))));
    // nothing to remove beyond the noise: no pair can beat the lead
    assert!(!worth(Some((0.0, 0.0))));
    // the evidence bar still holds on its own
    let (worth_it, why) =
        worth_pair_fit(Some(&base), &rows, Effect::RadialFriction, 4.1 * sig.linear_chi2_drop, None, &sc);
    assert!(!worth_it && why.starts_with("score Δχ²"), "{why}");
    // a failed held-out bar says so, with its numbers
    let (worth_it, why) =
        worth_pair_fit(Some(&base), &rows, Effect::RadialFriction, 10.0, Some((4.1 * d_chi2, 4.1 * d_e2)), &sc);
    assert!(!worth_it && why.starts_with("Σz² ") && why.contains(" and Σe² "), "{why}");
    // a measure without a need is not named
    let (worth_it, why) =
        worth_pair_fit(Some(&base), &rows, Effect::RadialFriction, 10.0, Some((0.0, 4.1 * d_e2)), &sc);
    assert!(!worth_it && why.starts_with("Σe² ") && !why.contains("Σz²"), "{why}");

    // the screen of pairs that lead nothing, with the baseline as the first effect's fit
    // (evidence 0): the pair must remove 2·best + ln n + 10 to beat a best single of
    // evidence `best`; fitted when the first-order gain is a quarter of that
    let ln_n = (rows.iter().map(|r| r.readings.len()).sum::<usize>() as f64).ln();
    let may = |need_over_gain: f64| {
        let best = 0.5 * (need_over_gain * d_chi2 - ln_n - 10.0);
        pair_may_beat(&base, 0.0, best, &rows, Effect::RadialFriction, &sc)
    };
    assert_eq!(may(3.9), Some(true));
    assert_eq!(may(4.1), Some(false));
    // an effect the fit already carries has no signature: nothing to screen on
    assert_eq!(pair_may_beat(&with, 0.0, 1e9, &rows, Effect::RadialFriction, &sc), None);
}

/// An effect that moves no prediction of the rows (thermal drift without a time series)
/// is ranked with the baseline's fit and its parameter penalty, not fitted; the other
/// candidate is.
#[test]
fn an_effect_the_data_cannot_see_is_not_fitted() {
    let (nominal, rows, groups) = sag_data();
    let opts = DiagnoseOptions { candidates: vec![Effect::VoltageSag, Effect::ThermalDrift], ..quick(false) };
    let d = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    let entry = |name: &str| d.ranking.iter().find(|r| r.effect == name).expect("ranked");
    let thermal = entry("thermal_drift");
    // (the fitted parameters: a held shape parameter is not one)
    let fitted = Effect::ThermalDrift.info().params.iter().filter(|p| !p.held).count();
    let penalty = 0.5 * fitted as f64 * (d.n_readings as f64).ln();
    assert!(thermal.params.is_empty() && thermal.shrink == 0.0, "{thermal:?}");
    assert!((thermal.evidence + penalty).abs() < 1e-9 * penalty, "{} vs −{penalty}", thermal.evidence);
    assert!(thermal.signature_match.is_none());
    let sag = entry("voltage_sag");
    assert!(!sag.params.is_empty() && sag.evidence > 5.0 && sag.signature_match.is_some(), "{sag:?}");
    assert!(d.notes.iter().any(|n| n.contains("thermal_drift cannot act")));
    // when the nominal motor already carries it, it is part of the baseline, not a candidate
    let mut carrying = nominal.clone();
    let typical: Vec<f64> = Effect::ThermalDrift.info().params.iter().map(|p| p.typical).collect();
    carrying.effects.set(Effect::ThermalDrift, &typical);
    let d = diagnose(&carrying, &rows, &groups, &opts).expect("diagnosis");
    assert!(d.ranking.iter().all(|r| r.effect != "thermal_drift"), "{:?}", d.ranking);
    assert!(
        d.notes.iter().any(|n| n.contains("own effects (thermal_drift) are part of the baseline")),
        "{:?}",
        d.notes
    );
}

/// An effect the nominal motor carries (a preset's calibrated stiffening or sag) is part
/// of the motor: the baseline refits its strength under a prior, so data whose only
/// difference from the nominal is that strength (300 Ω where the file says 150 Ω) give
/// `none`, with the fitted strength near the true one, and the effect is not a candidate.
#[test]
fn the_motors_own_effect_is_refitted_in_the_baseline_not_named() {
    let mut nominal = crate::calibrate::tests::reference_motor();
    nominal.effects.set_strength(Effect::VoltageSag, 150.0);
    let mut truth = nominal.clone();
    truth.effects.set_strength(Effect::VoltageSag, 300.0);
    let cfg = SynthConfig {
        campaign: Campaign::PreloadTorque,
        noise: 1.0,
        seed: 11,
        truth_forms: false,
        ..SynthConfig::default()
    };
    let (rows, groups) = synthesized(&truth, &cfg);
    let d = diagnose(&nominal, &rows, &groups, &quick(false)).expect("diagnosis");
    assert_eq!(d.verdict, "none", "{:?}", d.ranking);
    assert!(d.ranking.iter().all(|r| r.effect != "voltage_sag"));
    let (_, r) = d
        .baseline_params
        .iter()
        .find(|(k, _)| k == "effects.voltage_sag.source_resistance_ohm")
        .expect("the sag is a baseline parameter");
    assert!((r / 300.0 - 1.0).abs() < 0.2, "fitted {r} Ω against 300 Ω");
}

/// One motor (`motor_seed` = `seed`) measured in a run of `campaign` at each drive
/// voltage, noise seeds `seed`, `seed` + 1, ...; run ids prefixed with the voltage.
fn one_motor(truth: &Motor, campaign: Campaign, seed: u64, voltages: &[f64]) -> (Vec<ObservedRow>, Vec<String>) {
    let (mut rows, mut groups) = (Vec::new(), Vec::new());
    for (i, &v) in voltages.iter().enumerate() {
        let cfg = SynthConfig {
            campaign,
            seed: seed + i as u64,
            motor_seed: Some(seed),
            voltage_v: v,
            ..SynthConfig::default()
        };
        for r in synthesize(truth, &cfg).expect("synth") {
            rows.push(r.observed());
            groups.push(format!("v{v}-{}", r.run_id));
        }
    }
    (rows, groups)
}

/// `trum60a` with `effect` at `strength` (truth forms), synthesised on `campaign` at
/// `noise` with `seed`, diagnosed with single `candidates` only (no pairs).
fn diagnosed_single(
    effect: Effect,
    strength: f64,
    campaign: Campaign,
    noise: f64,
    seed: u64,
    candidates: &[Effect],
) -> Diagnosis {
    let nominal = crate::calibrate::tests::reference_motor();
    let mut truth = nominal.clone();
    truth.effects.set_strength(effect, strength);
    let cfg = SynthConfig { campaign, noise, seed, ..SynthConfig::default() };
    let (rows, groups) = synthesized(&truth, &cfg);
    let opts = DiagnoseOptions {
        candidates: candidates.to_vec(),
        try_pairs: false,
        bootstrap: 200,
        // (mechanism tests written on the classic baseline)
        tolerances: classic_tolerances(),
        ..DiagnoseOptions::default()
    };
    diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis")
}

/// On a `combined` campaign the weights' noise levels put most of the held-out NRMSE of
/// the baseline inside the noise, where noise alone gives a small fraction of it. The
/// test "half of the NRMSE beyond the noise is gone" measured against the weights'
/// level would then hold for almost any supported effect, and a `radial_friction` closing
/// a fifth of a preload-stiffening gap would pass for the whole answer. Against the best
/// noise estimate it closes only part: named, as the best partial explanation among the
/// candidates (the truth is left out of them), with `complete: false`.
#[test]
fn a_gap_inside_the_weights_noise_is_not_closed_by_every_effect() {
    let d = diagnosed_single(Effect::PreloadStiffening, 0.05, Campaign::Combined, 0.5, 136, &[Effect::RadialFriction]);
    // the premise: the weights' noise is most of the baseline's gap, the best estimate far below
    assert!(
        d.noise_nrmse_weights > 0.7 * d.baseline_heldout_nrmse && d.noise_nrmse_weights > 3.0 * d.noise_nrmse,
        "{} vs {} and {}",
        d.noise_nrmse_weights,
        d.baseline_heldout_nrmse,
        d.noise_nrmse
    );
    assert!(d.noise_nrmse < 0.5 * d.baseline_heldout_nrmse, "{} vs {}", d.noise_nrmse, d.baseline_heldout_nrmse);
    let rf = d.ranking.iter().find(|r| r.effect == "radial_friction").expect("ranked");
    assert!(rf.evidence > 5.0 && rf.shrink_interval.0 > 0.0, "radial friction no longer supported: {rf:?}");
    assert!(rf.shrink < 0.5 && rf.heldout_chi2_after > 2.0, "{rf:?}");
    assert_eq!(d.verdict, "radial_friction");
    assert!(!d.complete, "a remaining gap is reported");
    assert!(d.notes.iter().any(|n| n.starts_with("radial_friction closes") && n.contains("not all")), "{:?}", d.notes);
}

/// A strong `radial_friction` (ρ = 3) stalls the rotor from 200 N on. A baseline
/// calibration can end with the rotor at rest at every reading, the turning ones too,
/// where six of the seven candidates move no prediction; probed at the nominal motor as
/// well, they stay testable, and the strong-effect starts find ρ.
#[test]
fn a_strong_radial_friction_that_stalls_the_rotor_is_found() {
    let candidates = [Effect::RadialFriction, Effect::ThermalDrift, Effect::TangentialCompliance];
    let d = diagnosed_single(Effect::RadialFriction, 3.0, Campaign::PreloadTorque, 0.5, 1201, &candidates);
    assert_eq!(d.verdict, "radial_friction");
    let rf = d.ranking.iter().find(|r| r.effect == "radial_friction").expect("ranked");
    let rho = rf.params.first().map(|p| p.1).unwrap_or(0.0);
    // (the stalled rows make the held-out blocks hard to predict: refitting every fold
    // exactly gives a shrink of 0.63 on this seed)
    assert!((rho / 3.0 - 1.0).abs() < 0.05 && rf.shrink > 0.6, "{rf:?}");
    // thermal_drift without a time series is still untestable: not fitted
    let td = d.ranking.iter().find(|r| r.effect == "thermal_drift").expect("ranked");
    assert!(td.params.is_empty(), "{td:?}");
}

/// Just above the weights' noise level the "half beyond the noise" test measured against
/// that level would let almost any shrink close the gap: with the truth left out of the
/// candidates, an effect closing a sliver of a `voltage_sag` or `radial_friction` gap
/// (held-out χ² far above the noise left) must be no verdict. Against the best noise
/// estimate none closes it, and a sliver is no material part either.
#[test]
fn an_effect_that_closes_a_sliver_of_the_gap_is_no_verdict() {
    let cases = [
        (Effect::VoltageSag, 150.0, Campaign::Combined, 1.0, 158, [Effect::RadialFriction, Effect::ThermalDrift]),
        (
            Effect::RadialFriction,
            0.3,
            Campaign::PreloadTorque,
            0.5,
            101,
            [Effect::HertzSoftening, Effect::PreloadStiffening],
        ),
    ];
    for (truth_effect, strength, campaign, noise, seed, candidates) in cases {
        let d = diagnosed_single(truth_effect, strength, campaign, noise, seed, &candidates);
        let best = &d.ranking[0];
        // (a sliver: under a fifth of the NRMSE gone, the held-out z² left beyond the
        // noise's 2)
        assert!(best.shrink < 0.2 && best.heldout_chi2_after > 2.5, "{truth_effect:?}: {best:?}");
        assert_eq!(d.verdict, "unexplained", "{truth_effect:?}: {:?}", d.ranking);
    }
}

/// One motor measured at four drive voltages (preload-torque runs, radial friction in its
/// truth form): calibrated from the nominal motor, the baseline presses the modal damping
/// onto its upper bound, where the logistic transform holds it (a radial-friction fit
/// started there stays in that valley, held-out χ² 108 per reading, without the second
/// start from the nominal motor). Refitted from its own end, the baseline leaves
/// the bound at a fraction of the χ²; `Calibrate::refit_bounds` and so the diagnosis
/// do that, and the diagnosis finds radial friction at its truth.
#[test]
fn a_baseline_left_on_a_bound_is_refitted_from_its_end() {
    let nominal = crate::calibrate::tests::reference_motor();
    let mut truth = nominal.clone();
    truth.effects.set_strength(Effect::RadialFriction, 1.0);
    let (rows, groups) = one_motor(&truth, Campaign::PreloadTorque, 31, &[165.0, 185.0, 205.0, 225.0]);
    let opts = DiagnoseOptions {
        candidates: vec![Effect::RadialFriction],
        try_pairs: false,
        bootstrap: 50,
        tolerances: classic_tolerances(),
        ..DiagnoseOptions::default()
    };
    // (the rows as the diagnosis fits them: σ scaled by the estimated noise levels)
    let scaled = noise_scaled(&rows, &crate::noise::estimate(&rows, &groups));
    let (s0, bp) = fit_params(&nominal, &nominal, &scaled, &[], false, &classic_tolerances());
    let on_damping_bound =
        |c: &Calibration| c.params.iter().any(|p| p.name.ends_with("modal_damping_ns_per_m") && p.at_bound);
    let first = Calibration::builder(&s0, &scaled).params(&bp).options(&opts.fit).run().expect("baseline");
    assert!(on_damping_bound(&first), "the baseline no longer ends on the damping bound: the test needs new data");
    let again = Calibration::builder(&first.motor, &scaled).params(&bp).options(&opts.fit).run().expect("refit");
    assert!(!on_damping_bound(&again));
    // (χ² 1.74e5 → 6.3e4 when written)
    assert!(again.chi2 < 0.5 * first.chi2, "χ² {} → {}", first.chi2, again.chi2);
    // what `trum calibrate` and the diagnosis call does both
    let refitted =
        Calibration::builder(&s0, &scaled).params(&bp).options(&opts.fit).refit_bounds(true).run().expect("refitting");
    assert_eq!(refitted.chi2, again.chi2);
    assert_eq!(refitted.motor, again.motor);
    let d = diagnose(&nominal, &rows, &groups, &opts).expect("diagnose");
    let damping = d.baseline_params.iter().find(|p| p.0.ends_with("modal_damping_ns_per_m")).expect("damping").1;
    assert!(damping < 49.0, "the diagnosis's baseline damping {damping}");
    let rf = d.ranking.iter().find(|r| r.effect == "radial_friction").expect("ranked");
    assert_eq!(d.verdict, "radial_friction");
    assert!(rf.heldout_chi2_after < 5.0, "held-out χ² per reading {}", rf.heldout_chi2_after);
    let rho = rf.params[0].1;
    assert!((rho - 1.0).abs() < 0.1, "ρ {rho}");
}

/// A motor without eccentricity measured in eight stability runs (64 readings of the
/// speed standard deviation, true value near zero): the readings are the non-negative
/// part of the noise, biased upwards in every row alike. Compared with the model's
/// expected reading (`Observable::expected_reading`) that bias is no gap; compared with
/// the model value itself, eccentricity fitted it (evidence 10.2, verdict
/// `eccentricity`).
#[test]
fn the_positive_bias_of_speed_std_readings_is_not_eccentricity() {
    let nominal = crate::calibrate::tests::reference_motor();
    let voltages = [165.0, 175.0, 185.0, 195.0, 205.0, 215.0, 225.0, 235.0];
    let (rows, groups) = one_motor(&nominal, Campaign::Stability, 41, &voltages);
    let zeros = rows.iter().flat_map(|r| &r.readings).filter(|x| x.0 == Observable::SpeedStdRpm && x.1 == 0.0);
    assert!(zeros.count() >= 16, "the readings are no longer clipped noise: the test needs new data");
    let opts = DiagnoseOptions {
        candidates: vec![Effect::Eccentricity],
        try_pairs: false,
        bootstrap: 50,
        ..DiagnoseOptions::default()
    };
    // (the data clip and estimate; one run of the same data estimates no noise level)
    let est = crate::noise::estimate(&rows, &groups);
    assert!(speed_std_clipped(&rows, est.contains_key(&Observable::SpeedStdRpm)));
    let one_run: Vec<usize> = (0..rows.len()).filter(|&i| groups[i].starts_with("v165")).collect();
    let (rows1, groups1): (Vec<ObservedRow>, Vec<String>) =
        one_run.iter().map(|&i| (rows[i].clone(), groups[i].clone())).unzip();
    assert!(!crate::noise::estimate(&rows1, &groups1).contains_key(&Observable::SpeedStdRpm));
    assert!(!speed_std_clipped(&rows1, false));
    let d = diagnose(&nominal, &rows, &groups, &opts).expect("diagnose");
    let ecc = d.ranking.iter().find(|r| r.effect == "eccentricity").expect("ranked");
    assert_eq!(d.verdict, "none", "evidence {}", ecc.evidence);
    assert!(ecc.evidence < 3.0, "evidence {}", ecc.evidence);
}

/// A supported ranking entry with the given held-out χ² per reading and NRMSE.
pub(super) fn ranked(effect: &str, chi2: f64, nrmse: f64) -> RankEntry {
    RankEntry {
        effect: effect.into(),
        evidence: 100.0,
        heldout_nrmse_after: nrmse,
        heldout_chi2_after: chi2,
        shrink: 0.5,
        shrink_interval: (0.4, 0.6),
        z2_shrink_interval: (0.4, 0.6),
        lone_row_shares: (1.0, 1.0),
        params: Vec::new(),
        signature_match: None,
        linear_chi2_drop: None,
        signature_overlap: None,
        heldout_in_sample_folds: 0,
    }
}

/// The held-out need is the pair that gains exactly PAIR_GAIN of the single's excess in
/// `pair_beats_single`'s terms: √(χ² − 1) and √(NRMSE² − noise²) per reading.
#[test]
fn the_held_out_need_is_a_pair_gain_of_exactly_a_third() {
    let (n, noise) = (1000, 0.12);
    let single = ranked("radial_friction", 40.0, 0.2);
    let (chi2, e2) = held_out_need(&single, n, noise);
    let pair = RankEntry {
        effect: "radial_friction+voltage_sag".into(),
        heldout_chi2_after: single.heldout_chi2_after - chi2 / n as f64,
        heldout_nrmse_after: (single.heldout_nrmse_after.powi(2) - e2 / n as f64).sqrt(),
        ..single.clone()
    };
    let (g_nrmse, g_chi2) = pair_gains(&single, &pair, n, noise);
    assert!((g_chi2 - PAIR_GAIN).abs() < 1e-12 && (g_nrmse - PAIR_GAIN).abs() < 1e-12, "{g_chi2} {g_nrmse}");
    // at the noise level nothing is left to gain
    let quiet = RankEntry { heldout_chi2_after: 0.8, heldout_nrmse_after: 0.1, ..single.clone() };
    assert_eq!(held_out_need(&quiet, n, noise), (0.0, 0.0));
    // nor within two standard errors of the noise's mean z² (2·√(2/1000) = 0.089)
    let close = RankEntry { heldout_chi2_after: 1.085, heldout_nrmse_after: 0.1, ..single.clone() };
    assert_eq!(held_out_need(&close, n, noise), (0.0, 0.0));
    let beyond = RankEntry { heldout_chi2_after: 1.095, heldout_nrmse_after: 0.1, ..single.clone() };
    assert!(held_out_need(&beyond, n, noise).0 > 0.0);
}

/// `pair_beats_single`'s gains: a single within the noise tolerance leaves nothing to gain
/// in χ², however far below it the pair goes (the blind `hertz_softening` at 3 × typical,
/// 1.03 per reading at 679 readings, and `voltage_sag` polishing it to 0.90), while the
/// pair's own excess is never zeroed: a pair ending at 1.03 removes √0.03 less than all
/// of a single's excess of 2 (χ² 5). And the NRMSE gain is of the part beyond the noise.
#[test]
fn a_pair_gains_nothing_on_a_single_within_the_noise() {
    let entry = ranked;
    let n = 679;
    let within = entry("hertz_softening", 1.03, 0.05);
    let polished = entry("hertz_softening+voltage_sag", 0.90, 0.05);
    assert_eq!(pair_gains(&within, &polished, n, 0.05).1, 0.0);
    let far = entry("hertz_softening", 5.0, 0.05);
    let g = pair_gains(&far, &entry("hertz_softening+voltage_sag", 1.03, 0.05), n, 0.05).1;
    assert!((g - (1.0 - 0.03f64.sqrt() / 2.0)).abs() < 1e-12, "{g}");
    // NRMSE: 0.05 beyond a noise of 0.03 is an excess of 0.04; a pair at 0.0427 (excess
    // 0.0222) removes 0.445 of it
    let (gn, _) = pair_gains(&entry("a", 2.0, 0.05), &entry("a+b", 2.0, 0.0427), n, 0.03);
    let expect = 1.0 - (0.0427f64.powi(2) - 0.0009).sqrt() / 0.04;
    assert!((gn - expect).abs() < 1e-12, "{gn} vs {expect}");
    // nothing beyond the noise: nothing to gain
    assert_eq!(pair_gains(&entry("a", 2.0, 0.02), &entry("a+b", 2.0, 0.01), n, 0.03).0, 0.0);
}

#[test]
fn a_pair_refits_both_effects_and_starts_from_the_lead_fit() {
    let nominal = crate::calibrate::tests::reference_motor();
    let (rows, _) = data(&nominal, 1.0, 3);
    let mut lead = nominal.clone();
    lead.effects.set_strength(Effect::RadialFriction, 0.8);
    let (m, params) =
        fit_params(&nominal, &lead, &rows, &[Effect::RadialFriction, Effect::VoltageSag], false, &BTreeMap::new());
    let names: Vec<String> = params.iter().map(|p| p.param.name()).collect();
    for e in [Effect::RadialFriction, Effect::VoltageSag] {
        assert!(names.iter().any(|n| n.starts_with(&format!("effects.{}.", e.name()))), "{e:?} not fitted: {names:?}");
    }
    // the lead keeps its fitted strength; the new effect starts at half its typical one
    assert_eq!(m.effects.value(Effect::RadialFriction, 0), 0.8);
    let typical = Effect::VoltageSag.info().params[0].typical;
    assert_eq!(m.effects.value(Effect::VoltageSag, 0), 0.5 * typical);
}

/// A fit that ends with an added effect within 1 % of zero counts as collapsed for the
/// second start (`added_near_zero`): the rule on fitted values, and fits of
/// `tangential_compliance` to data without it (ending at or next to zero) and with it.
#[test]
fn an_effect_fitted_to_next_to_zero_counts_as_collapsed() {
    let tc = Effect::TangentialCompliance;
    let nominal = crate::calibrate::tests::reference_motor();
    let grid =
        |m: &Motor| crate::calibrate::tests::rows_on_grid(m, &[100.0, 200.0, 300.0, 400.0], &[0.0, 0.2, 0.4, 0.6]);
    let rows = grid(&nominal);
    let (start, params) = fit_params(&nominal, &nominal, &rows, &[tc], false, &BTreeMap::new());
    let hi = params.iter().find(|fp| fp.param == ParamRef::Effect(tc, 0)).expect("strength").hi;
    let fitted = |v: f64| {
        params
            .iter()
            .map(|fp| FittedParam {
                name: fp.param.name(),
                value: if fp.param == ParamRef::Effect(tc, 0) { v } else { fp.lo },
                std_error: 0.0,
                at_bound: false,
                identifiable: true,
                prior_rel_sd: None,
            })
            .collect::<Vec<_>>()
    };
    assert!(added_near_zero(&params, &fitted(0.009 * hi), &[tc]));
    assert!(!added_near_zero(&params, &fitted(0.011 * hi), &[tc]));
    // only an added effect's strength counts (for a pair, the lead's is not added)
    assert!(!added_near_zero(&params, &fitted(0.0), &[Effect::RadialFriction]));
    let opts = FitOptions { huber_k: 3.0, irls_passes: 1, max_evaluations: 300, ..FitOptions::default() };
    let without = Calibration::builder(&start, &rows).params(&params).options(&opts).adding(&[tc]).run().expect("fit");
    // (not abandoned when written: 0.3 % of the range, on its bound by the 0.5 % rule)
    assert!(without.abandoned || added_near_zero(&params, &without.params, &[tc]), "{:?}", without.params);
    let mut truth = nominal.clone();
    truth.effects.set(tc, &[tc.info().params[0].typical]);
    let with =
        Calibration::builder(&start, &grid(&truth)).params(&params).options(&opts).adding(&[tc]).run().expect("fit");
    assert!(!with.abandoned && !added_near_zero(&params, &with.params, &[tc]), "{:?}", with.params);
}

/// A current-limited driver (a knee at the median phase current, a steep sag above it) is
/// diagnosed as `voltage_sag` and the fit closes the held-out gap to near the noise. (On
/// preload-torque data at one voltage the plain resistive source already does: the
/// phase current is mostly capacitive, so the knee's drop, in phase with it, moves the
/// electrode voltage much as a larger resistance does; the fit reaches the noise and the
/// scan has nothing left to explain. A knee the scan moves is reported with the effect's
/// parameters, within its range.)
#[test]
fn a_current_limited_driver_is_diagnosed_as_voltage_sag() {
    let nominal = crate::calibrate::tests::reference_motor();
    let (probe_rows, _) = data(&nominal, 1.0, 13);
    let mut amps: Vec<f64> = probe_rows.iter().map(|r| crate::solve::solve(&nominal, &r.op).current_a).collect();
    amps.sort_by(f64::total_cmp);
    let knee = amps[amps.len() / 2];
    let mut truth = nominal.clone();
    truth.effects.set(Effect::VoltageSag, &[2000.0, knee]);
    let (rows, groups) = data(&truth, 1.0, 13);
    let opts = DiagnoseOptions { candidates: vec![Effect::VoltageSag, Effect::RadialFriction], ..quick(false) };
    let d = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    let sag = d.ranking.iter().find(|r| r.effect == "voltage_sag").expect("ranked");
    assert_eq!(d.verdict, "voltage_sag");
    assert!(sag.shrink > 0.8 && sag.heldout_chi2_after < 2.0, "{sag:?}");
    let p = &Effect::VoltageSag.info().params[1];
    for (name, v) in &sag.params {
        if name.ends_with(p.name) {
            assert!(*v > p.min && *v <= p.max, "{name} = {v}");
        }
    }
}

/// A stator temperature sensor that lags the warm-up by 40 s (a sheathed thermocouple
/// bonded to the stator) is a bench nuisance, not a gap: a warm-up of the reference motor
/// with nothing else added is diagnosed `none`, and the fitted lag comes back within 5 s.
/// Without the lag parameter (its tolerance 0) the same data leave a gap in the early
/// temperature readings (a held-out mean z² above 2) that no candidate explains; a sensor
/// offset cannot stand in for a lag that fades as the warm-up settles.
#[test]
fn a_lagging_temperature_sensor_is_the_benchs_not_a_gap() {
    let artefacts = crate::synth::Artefacts { temperature_lag_s: 40.0, ..Default::default() };
    let (d, held) = warm_up_through_a_sensor(artefacts, 1, "bench.temperature_lag_s");
    assert_eq!(d.verdict, "none", "{:?}", d.ranking);
    let (_, got) = d.baseline_params.iter().find(|(k, _)| k == "bench.temperature_lag_s").expect("the lag is fitted");
    assert!((got - 40.0).abs() < 5.0, "fitted lag {got} s against 40 s");
    assert!(held.baseline_params.iter().all(|(k, _)| k != "bench.temperature_lag_s"));
    assert_sensor_misses_without(&d, &held);
}

/// A strong `radial_friction` stalls the rotor at half the preloads of a speed-stability
/// run: the baseline's calibration from the nominal motor stops in a valley of its own
/// parameters, and every candidate's fit (refitting those parameters from other starts)
/// gains ½ΔBIC ≈ 100 over it with no held-out shrink, so that the one candidate with a
/// little shrink, `eccentricity`, would be named. The baseline is every candidate at zero
/// strength: it is refitted from the best candidate fit with its effect taken out, the
/// spurious evidence goes, and no wrong effect is named. The valley is that of a baseline
/// whose power meter reads exact (`bench.power_phase_rad` held at zero); with the meter's
/// phase error free the baseline's own fit leaves it, to the same end.
#[test]
fn a_baseline_stuck_in_its_own_valley_is_refitted_from_a_candidates_fit() {
    let nominal = crate::calibrate::tests::reference_motor();
    let mut truth = nominal.clone();
    truth.effects.set_strength(Effect::RadialFriction, 2.0);
    let cfg = SynthConfig {
        campaign: Campaign::Stability,
        noise: 1.0,
        seed: 95,
        artefacts: crate::synth::Artefacts { readback_rel: 0.004, speed_std_floor_rpm: 0.3, ..Default::default() },
        ..SynthConfig::default()
    };
    let (rows, groups) = synthesized(&truth, &cfg);
    // (the power meter's phase error held: free, it gives this baseline a way out of the
    // valley by itself, and the refit this test is about is not needed)
    let held = BTreeMap::from([("bench.power_phase_rad".to_string(), 0.0)]);
    let opts = DiagnoseOptions { bootstrap: 50, tolerances: held, ..DiagnoseOptions::default() };
    let d = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    assert!(d.notes.iter().any(|n| n.starts_with("the baseline was refitted from a candidate's fit")), "{:?}", d.notes);
    assert!(d.verdict == "radial_friction" || d.verdict == "unexplained", "{} {:?}", d.verdict, d.ranking);
    assert_eq!(d.ranking[0].effect, "radial_friction", "{:?}", d.ranking);
    // no candidate keeps the valley's evidence
    assert!(d.ranking.iter().all(|r| r.evidence < 20.0), "{:?}", d.ranking);
    // with the meter's phase free the baseline leaves the valley without the refit, to the
    // same end
    let free = DiagnoseOptions { bootstrap: 50, ..DiagnoseOptions::default() };
    let d = diagnose(&nominal, &rows, &groups, &free).expect("diagnosis");
    assert!(d.verdict == "radial_friction" || d.verdict == "unexplained", "{} {:?}", d.verdict, d.ranking);
    assert_eq!(d.ranking[0].effect, "radial_friction", "{:?}", d.ranking);
    assert!(d.ranking.iter().all(|r| r.evidence < 20.0), "{:?}", d.ranking);
}

/// A single effect that leaves the held-out data at the noise needs no partner: with
/// pairs allowed, the current-limited driver's data are `voltage_sag` alone, no pair is
/// fitted, and a note says why (a second effect there would only polish the first one's
/// form).
#[test]
fn a_single_at_the_noise_is_given_no_partner() {
    let nominal = crate::calibrate::tests::reference_motor();
    let mut truth = nominal.clone();
    truth.effects.set(Effect::VoltageSag, &[300.0, 0.0]);
    let (rows, groups) = data(&truth, 1.0, 13);
    let opts = DiagnoseOptions {
        candidates: vec![Effect::VoltageSag, Effect::RadialFriction, Effect::PreloadStiffening],
        try_pairs: true,
        ..quick(false)
    };
    let d = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    let sag = d.ranking.iter().find(|r| r.effect == "voltage_sag").expect("ranked");
    assert_eq!(d.verdict, "voltage_sag");
    assert!(d.complete && sag.heldout_chi2_after <= 2.0, "{sag:?}");
    assert!(d.ranking.iter().all(|r| !r.effect.contains('+')), "{:?}", d.ranking);
    assert!(d.notes.iter().any(|n| n.starts_with("no pair of effects tried: voltage_sag alone")), "{:?}", d.notes);
}

/// A stator temperature sensor that reads 1.5 K high (a thermocouple within its class-1
/// tolerance) is a bench nuisance, not a gap: a warm-up of the reference motor with nothing
/// else added is diagnosed `none`, and the fitted offset comes back within 0.4 K. Without the
/// offset parameter (its tolerance 0) the same data leave a gap in the temperature readings
/// (a held-out mean z² above 2), which no candidate explains.
#[test]
fn a_temperature_sensor_offset_is_the_benchs_not_a_gap() {
    let artefacts = crate::synth::Artefacts { temperature_offset_k: 1.5, ..Default::default() };
    let (d, held) = warm_up_through_a_sensor(artefacts, 7204, "bench.temperature_offset_k");
    assert_eq!(d.verdict, "none", "{:?}", d.ranking);
    let (_, got) =
        d.baseline_params.iter().find(|(k, _)| k == "bench.temperature_offset_k").expect("the offset is fitted");
    assert!((got - 1.5).abs() < 0.4, "fitted offset {got} K against 1.5 K");
    assert!(held.baseline_params.iter().all(|(k, _)| k != "bench.temperature_offset_k"));
    assert_sensor_misses_without(&d, &held);
}

/// A preload-torque campaign of the reference motor with nothing added, its preload read
/// 10 N high and its current 5 % high (besides the development half's artefacts): both
/// are the bench's. Fitted, they come back near their values and the verdict is `none`;
/// held at zero (tolerance 0), the baseline cannot follow them and a candidate is fitted
/// to the bench (on this seed `radial_friction`, with evidence 31, to the shifted preload
/// axis) with more evidence than any has with them.
#[test]
fn a_preload_offset_and_a_current_gain_are_the_benchs_not_an_effect() {
    let nominal = crate::calibrate::tests::reference_motor();
    let cfg = SynthConfig {
        campaign: Campaign::PreloadTorque,
        noise: 1.0,
        seed: 7301,
        artefacts: crate::synth::Artefacts::parse(
            "readback_rel=0.004,speed_std_floor_rpm=0.3,preload_offset_n=10,current_gain_rel=0.05",
        )
        .expect("artefacts"),
        ..SynthConfig::default()
    };
    let (rows, groups) = synthesized(&nominal, &cfg);
    let opts = DiagnoseOptions {
        candidates: vec![Effect::RadialFriction, Effect::VoltageSag, Effect::PreloadStiffening, Effect::Eccentricity],
        try_pairs: false,
        bootstrap: 50,
        ..DiagnoseOptions::default()
    };
    let d = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    assert_eq!(d.verdict, "none", "{:?}", d.ranking);
    let got = |k: &str| d.baseline_params.iter().find(|(n, _)| n == k).map(|(_, v)| *v);
    let offset = got("bench.preload_offset_n").expect("the preload offset is fitted");
    assert!((offset - 10.0).abs() < 4.0, "fitted preload offset {offset} N against 10 N");
    let gain = got("bench.current_gain_rel").expect("the current gain is fitted");
    assert!((gain - 0.05).abs() < 0.015, "fitted current gain {gain} against 0.05");
    let held_at_zero =
        BTreeMap::from([("bench.preload_offset_n".to_string(), 0.0), ("bench.current_gain_rel".to_string(), 0.0)]);
    let held =
        diagnose(&nominal, &rows, &groups, &DiagnoseOptions { tolerances: held_at_zero, ..opts }).expect("diagnosis");
    let best = |x: &Diagnosis| x.ranking.iter().map(|r| r.evidence).fold(f64::NEG_INFINITY, f64::max);
    assert!(best(&held) > 5.0 && best(&held) > best(&d) + 5.0, "{} vs {}", best(&held), best(&d));
}

/// Without the sensor's nuisance parameter (`held`) the warm-up's baseline misses the
/// held-out temperatures beyond twice the noise variance, and by more than half again
/// what it misses with it (`fitted`). (Whether that gap is called real also depends on how
/// well some thirty temperature residuals fix the noise level: docs/DIAGNOSIS.md.)
fn assert_sensor_misses_without(fitted: &Diagnosis, held: &Diagnosis) {
    let (with, without) = (fitted.baseline_heldout_chi2_per_reading, held.baseline_heldout_chi2_per_reading);
    assert!(without > 2.0 && without > 1.5 * with, "held-out mean z² {without} without the parameter, {with} with it");
}

/// A warm-up of the reference motor with nothing added, read through a temperature sensor
/// with `artefacts` (noise seed `seed`), diagnosed with the sensor's nuisance parameter
/// `key` fitted and with it held at zero (its tolerance 0).
fn warm_up_through_a_sensor(artefacts: crate::synth::Artefacts, seed: u64, key: &str) -> (Diagnosis, Diagnosis) {
    let nominal = crate::calibrate::tests::reference_motor();
    let cfg = SynthConfig { campaign: Campaign::WarmUp, noise: 1.0, seed, artefacts, ..SynthConfig::default() };
    let (rows, groups) = synthesized(&nominal, &cfg);
    let opts = DiagnoseOptions { bootstrap: 50, try_pairs: false, ..DiagnoseOptions::default() };
    let fitted = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    let opts = DiagnoseOptions { tolerances: BTreeMap::from([(key.to_string(), 0.0)]), ..opts };
    let held = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    (fitted, held)
}

/// A `tangential_compliance` at twice its typical strength, in its first truth form, on a
/// combined campaign with the development half's bench artefacts: the fit from the
/// calibrated baseline collapses onto zero strength (the baseline's parameters bent to
/// mimic part of the effect), the scan's valley of the effect's own from the nominal motor
/// reaches it, and that fit, started with the calibrated bench nuisances (not a speed-std
/// floor on its bound), predicts the held-out regions: the verdict, closing most of the
/// gap.
#[test]
fn a_strong_compliance_is_reached_from_its_own_valley() {
    let nominal = crate::calibrate::tests::reference_motor();
    let mut truth = nominal.clone();
    truth.effects.set_strength(Effect::TangentialCompliance, 2.0);
    let cfg = SynthConfig {
        campaign: Campaign::Combined,
        noise: 1.0,
        seed: 8113,
        artefacts: crate::synth::Artefacts::parse("readback_rel=0.004,speed_std_floor_rpm=0.3,outlier_fraction=0.01")
            .expect("artefacts"),
        ..SynthConfig::default()
    };
    let (rows, groups) = synthesized(&truth, &cfg);
    let opts = DiagnoseOptions {
        candidates: vec![Effect::TangentialCompliance, Effect::VoltageSag, Effect::ThermalDrift],
        try_pairs: false,
        bootstrap: 50,
        ..DiagnoseOptions::default()
    };
    let d = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    assert_eq!(d.verdict, "tangential_compliance", "{:?}", d.ranking);
    let tc = d.ranking.iter().find(|r| r.effect == "tangential_compliance").expect("ranked");
    assert!(tc.shrink > 0.5, "shrink {}", tc.shrink);
    let (_, s) = tc.params.iter().find(|(k, _)| k.ends_with("shear_compliance_ratio")).expect("strength");
    assert!((1.5..3.0).contains(s), "fitted strength {s}");
}

/// The diagnosis names the baseline parameters its data leave at their priors, as
/// calibration does: every one of them a calibrated parameter with a prior; no more of the
/// motor's on a whole campaign than on a handful of its rows (more readings narrow as many
/// parameters or more), and on the whole campaign not the resonance frequency, which every reading
/// of a drive near resonance pins down.
#[test]
fn the_parameters_the_data_leave_at_their_priors_are_named() {
    let nominal = crate::calibrate::tests::reference_motor();
    let (rows, groups) = data(&nominal, 1.0, 21);
    let opts = DiagnoseOptions { candidates: vec![Effect::VoltageSag], ..quick(false) };
    let full = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    let few: Vec<usize> = (0..rows.len()).step_by(rows.len() / 8).collect();
    let (rows8, groups8): (Vec<ObservedRow>, Vec<String>) =
        few.iter().map(|&i| (rows[i].clone(), groups[i].clone())).unzip();
    let small = diagnose(&nominal, &rows8, &groups8, &opts).expect("diagnosis");
    for d in [&full, &small] {
        for n in &d.baseline_held_near_prior {
            assert!(d.baseline_params.iter().any(|(k, _)| k == n), "{n} is not a calibrated parameter");
            assert!(!n.starts_with("effects."), "{n}");
        }
    }
    // (the motor's parameters: the bench's nuisances are fitted only where the data have
    // enough readings of theirs)
    let motor_held = |d: &Diagnosis| d.baseline_held_near_prior.iter().filter(|n| !n.starts_with("bench.")).count();
    assert!(
        motor_held(&full) <= motor_held(&small),
        "{:?} vs {:?}",
        full.baseline_held_near_prior,
        small.baseline_held_near_prior
    );
    assert!(!full.baseline_held_near_prior.iter().any(|n| n == "stator.resonance_frequency_hz"));
}

/// A sensor noise level the user states replaces the default and the estimate from the
/// data: the note says so with the data's own estimate beside it, the stated quantity
/// leaves the list of estimated factors, and a level four times the default lowers the
/// baseline's held-out z² (each of the quantity's readings weighs a sixteenth as much).
#[test]
fn a_stated_sensor_noise_level_replaces_the_estimate() {
    let (nominal, rows, groups) = sag_data();
    let opts =
        DiagnoseOptions { candidates: vec![Effect::VoltageSag], try_pairs: false, bootstrap: 20, ..quick(false) };
    let plain = diagnose(&nominal, &rows, &groups, &opts).expect("diagnosis");
    let speed_sd = |v: f64| 4.0 * Observable::SpeedRpm.default_sigma(v);
    let stated = DiagnoseOptions {
        stated_noise: BTreeMap::from([(Observable::SpeedRpm, (speed_sd(0.0), 0.04))]),
        ..opts.clone()
    };
    let d = diagnose(&nominal, &rows, &groups, &stated).expect("diagnosis");
    let note = d.notes.iter().find(|n| n.starts_with("noise levels as stated")).expect("stated note");
    assert!(note.contains("speed_rpm σ = 2 + 0.04 × reading") && note.contains("its stated level"), "{note}");
    assert!(d.noise_scale.iter().all(|(q, _, _)| q != "speed_rpm"), "{:?}", d.noise_scale);
    assert!(plain.noise_scale.iter().any(|(q, _, _)| q == "speed_rpm"));
    assert!(
        d.baseline_heldout_chi2_per_reading < plain.baseline_heldout_chi2_per_reading,
        "{} against {}",
        d.baseline_heldout_chi2_per_reading,
        plain.baseline_heldout_chi2_per_reading
    );
    // a level out of range is refused with the quantity's name
    let zero = DiagnoseOptions { stated_noise: BTreeMap::from([(Observable::CurrentA, (0.0, 0.01))]), ..opts };
    let e = diagnose(&nominal, &rows, &groups, &zero).expect_err("refused").to_string();
    assert!(e.contains("current_a") && e.contains("> 0"), "{e}");
}

/// The texts of `--sensor-noise` (and Python's `sensor_noise`): `COLUMN=SD` or
/// `COLUMN=SD,REL`; errors name the text and list the valid columns.
#[test]
fn stated_sensor_noise_texts_are_read_or_refused_with_the_reason() {
    let t =
        |xs: &[&str]| stated_noise_from_texts(&xs.iter().map(|x| x.to_string()).collect::<Vec<_>>(), "--sensor-noise");
    let ok = t(&["speed_rpm=0.3,0.005", "current_a = 0.002"]).expect("read");
    assert_eq!(ok[&Observable::SpeedRpm], (0.3, 0.005));
    assert_eq!(ok[&Observable::CurrentA], (0.002, 0.0));
    let err = |xs: &[&str]| t(xs).expect_err("refused").to_string();
    let e = err(&["speed=1"]);
    assert!(e.contains("'speed=1'") && e.contains("speed_rpm, input_power_w"), "{e}");
    assert!(err(&["speed_rpm"]).contains("COLUMN=SD"));
    assert!(err(&["speed_rpm=fast"]).contains("'fast' is not a number"));
    assert!(err(&["speed_rpm=1,2,3"]).contains("COLUMN=SD,REL"));
    assert!(err(&["speed_rpm=0"]).contains("> 0"));
    assert!(err(&["speed_rpm=1,-0.1"]).contains(">= 0"));
    assert!(err(&["speed_rpm=inf"]).contains("finite"));
    assert!(err(&["speed_rpm=1", "speed_rpm=2"]).contains("stated twice"));
    assert!(t(&[]).expect("none").is_empty());
}

/// The rivals whose separation from the lead is reported: every confounded effect, then
/// the supported single effect with the most evidence after the lead's where it is
/// within CLOSE_EVIDENCE of it; pairs, unsupported and distant effects never.
#[test]
fn a_rival_is_confounded_or_the_next_supported_single_close_in_evidence() {
    use separation::{rivals, Rival, CLOSE_EVIDENCE};
    let with = |e: &str, evidence: f64| RankEntry { evidence, ..ranked(e, 1.0, 0.1) };
    let ranking = vec![
        with("voltage_sag+eccentricity", 60.0),
        with("voltage_sag", 50.0),
        with("thermal_drift", 47.5),
        with("radial_friction", 48.0),
        with("eccentricity", 49.9),
    ];
    assert_eq!(
        rivals(&ranking, "voltage_sag", &["eccentricity".to_string()]),
        vec![("eccentricity".to_string(), Rival::Confounded), ("radial_friction".to_string(), Rival::CloseInEvidence)]
    );
    let pair = |behind: f64| vec![with("voltage_sag", 50.0), with("radial_friction", 50.0 - behind)];
    assert_eq!(rivals(&pair(CLOSE_EVIDENCE - 0.01), "voltage_sag", &[]).len(), 1);
    assert!(rivals(&pair(CLOSE_EVIDENCE), "voltage_sag", &[]).is_empty());
    // not supported, however close
    let weak = vec![with("voltage_sag", 1.0), with("radial_friction", -0.5)];
    assert!(rivals(&weak, "voltage_sag", &[]).is_empty());
    // a pair verdict has none either, whatever trails it
    assert!(rivals(&ranking, "voltage_sag+eccentricity", &[]).is_empty());
    // a lead the ranking does not hold has no rivals
    assert!(rivals(&ranking, "hertz_softening", &["eccentricity".to_string()]).is_empty());
}

/// Noise correlated along each run (a first-order autoregression in row order with
/// coefficient 0.95 and each reading's default noise level as its standard deviation:
/// nearly an offset per run) on a noise-free preload-torque campaign of the nominal motor.
/// The levels estimated along the runs see a fraction of it, so the calibrated baseline
/// misses held-out data by more than they allow; the misses do not repeat from run to run,
/// and the verdict is `none`, with the note that says why. The same draws without the
/// correlation (white noise) need no such note.
#[test]
fn noise_correlated_along_runs_is_scatter_of_the_runs_not_a_gap() {
    let m = crate::calibrate::tests::reference_motor();
    let (clean, groups) = data(&m, 0.0, 5);
    let noisy = |phi: f64| -> Vec<ObservedRow> {
        let mut state = rand::SeedableRng::seed_from_u64(2024);
        let mut rows = clean.clone();
        let mut e: BTreeMap<(String, Observable), f64> = BTreeMap::new();
        for (r, g) in rows.iter_mut().zip(&groups) {
            for x in r.readings.iter_mut() {
                let prev = e.get(&(g.clone(), x.0)).copied();
                let fresh = super::repeatability::tests::normal(&mut state);
                let now = match prev {
                    Some(p) => phi * p + (1.0 - phi * phi).sqrt() * fresh,
                    None => fresh,
                };
                e.insert((g.clone(), x.0), now);
                x.1 = (x.1 + x.2 * now).max(0.0);
            }
        }
        rows
    };
    let opts = DiagnoseOptions::default();
    let d = diagnose(&m, &noisy(0.95), &groups, &opts).expect("diagnosis");
    assert!(
        d.baseline_heldout_chi2_per_reading > 2.0,
        "no gap by the levels along the runs: {}",
        d.baseline_heldout_chi2_per_reading
    );
    assert_eq!(d.verdict, "none", "{:?}", d.notes);
    assert!(d.notes.iter().any(|n| n.contains("do not repeat from run to run")), "{:?}", d.notes);
    let white = diagnose(&m, &noisy(0.0), &groups, &opts).expect("diagnosis");
    assert_eq!(white.verdict, "none", "{:?}", white.notes);
    assert!(!white.notes.iter().any(|n| n.contains("run to run")), "{:?}", white.notes);
}
