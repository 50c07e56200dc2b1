//! The sim-to-real gap diagnosis (`shared/spec/diagnose.md`): where the calibrated
//! baseline misses, which unmodelled effect causes it, and how far the gap shrinks on
//! held-out operating regions once that effect is added.
//!
//! Method (docs/DIAGNOSIS.md):
//! 1. Rows are grouped into operating regions (run, preload level, frequency band, time
//!    window); regions are dealt round-robin into K folds — block cross-validation, never
//!    random rows, so a held-out block is an operating region the fit never saw.
//! 2. The baseline is calibrated on each training set and predicts its held-out block;
//!    the held-out normalised error is compared with the noise level.
//! 3. Every candidate effect is refitted together with the baseline parameters the same
//!    way and scored by its held-out error and by the BIC of the full-data fit (evidence =
//!    ½·ΔBIC, a log Bayes factor: > 3 strong, > 5 very strong). Pairs of the best
//!    candidates follow when no single one closes the gap or when two are supported, and
//!    win only by beating the best single on held-out data as well as in evidence.
//!    Each candidate's sensitivity signature (`signature`) is compared with the baseline's
//!    residual pattern (a score test) and with the verdict's signature: effects whose
//!    signatures the data see as one shape are reported as confounded; at the lead effect's
//!    fit the same test screens which second effects are worth a pair fit.
//! 4. Where: baseline residuals grouped by quantity and region; a group is reported when
//!    its mean normalised residual is more than 3.5 standard errors from zero (z-test;
//!    3.5 keeps the family-wise false-alarm rate near 1 % over ~50 groups).

mod bench;
pub mod json;
mod scan;
mod signature;

use crate::calibrate::{
    baseline_params_with, calibrate, calibrate_adding, calibrate_nested, calibrate_refitting_bounds,
    calibrate_weighted, effect_params, prior_residuals, residuals, with_prior_rows, Calibration, FitOptions, FitParam,
    FittedParam, Observable, ObservedRow, ParamRef, Start, IRLS_START_RTOL,
};
use crate::effects::{Effect, ALL};
use crate::error::TrumError;
use crate::params::Motor;
use crate::solve::{solve_prepared, Prepared, Status};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Options of a diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub struct DiagnoseOptions {
    /// Number of cross-validation folds (≥ 2).
    pub folds: usize,
    /// Candidate effects (all seven by default).
    pub candidates: Vec<Effect>,
    /// Try pairs of the best candidates when no single effect closes the gap.
    pub try_pairs: bool,
    /// Bootstrap resamples for the shrink interval.
    pub bootstrap: usize,
    /// Seed of the bootstrap.
    pub seed: u64,
    /// Calibration settings.
    pub fit: FitOptions,
    /// Refit every model on every training fold (slow) instead of the approximate
    /// leave-block-out refit from the full-data optimum (the default; docs/DIAGNOSIS.md).
    pub exact_cv: bool,
    /// Relative tolerances of baseline parameters in place of the defaults
    /// ([`crate::calibrate::baseline_params_with`]): dotted key → prior standard deviation
    /// of the logarithm (0 holds a parameter at its nominal value).
    pub tolerances: BTreeMap<String, f64>,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            folds: 4,
            candidates: ALL.to_vec(),
            try_pairs: true,
            bootstrap: 200,
            seed: 7,
            fit: FitOptions { huber_k: 3.0, irls_passes: 1, max_evaluations: 300, ..FitOptions::default() },
            exact_cv: false,
            tolerances: BTreeMap::new(),
        }
    }
}

/// A region where the baseline misses.
#[derive(Clone, Debug, PartialEq)]
pub struct GapRegion {
    /// Measured quantity (column name).
    pub quantity: String,
    /// Region in words, e.g. `torque_nm < 0.3`.
    pub region: String,
    /// Mean residual measured − model, in the quantity's unit.
    pub mean_residual: f64,
    /// Readings in the region.
    pub n: usize,
    /// z statistic of the mean normalised residual.
    pub z: f64,
}

/// One candidate's score.
#[derive(Clone, Debug, PartialEq)]
pub struct RankEntry {
    /// Effect name, or two names joined with `+`.
    pub effect: String,
    /// ½·(BIC_baseline − BIC_effect) on the full data (larger = stronger).
    pub evidence: f64,
    /// Held-out NRMSE with the effect added.
    pub heldout_nrmse_after: f64,
    /// Held-out mean squared normalised residual with the effect added (1 = noise level).
    pub heldout_chi2_after: f64,
    /// 1 − after/before on the held-out readings.
    pub shrink: f64,
    /// Bootstrap 90 % interval of the shrink.
    pub shrink_interval: (f64, f64),
    /// Fitted effect parameters on the full data (name, value).
    pub params: Vec<(String, f64)>,
    /// Score test at the calibrated baseline (single effects): cos of the angle between
    /// the baseline's residual and the effect's signature, signed so that +1 means the
    /// effect, raised from zero, moves the model exactly towards the data.
    pub signature_match: Option<f64>,
    /// Score test at the calibrated baseline: the χ² the effect removes to first order.
    pub linear_chi2_drop: Option<f64>,
    /// |cos| between this effect's signature and the verdict's (1: the data see one shape).
    pub signature_overlap: Option<f64>,
    /// Cross-validation folds whose refit could not be moved off this fit's full-data
    /// optimum, so their held-out blocks were predicted in-sample (the held-out figures are
    /// then optimistic; 0 with exact CV, and for an entry its nested model stands in for).
    pub heldout_in_sample_folds: usize,
}

/// The diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnosis {
    /// One effect, several joined with `+`, `none` or `unexplained`.
    pub verdict: String,
    /// True when the verdict leaves no held-out gap beyond the noise (`none`, or an effect
    /// that closes the gap); false for `unexplained` and for an effect named because it
    /// closes a material part of the gap but not all of it.
    pub complete: bool,
    /// Effects that explain the data about as well as the verdict.
    pub confounded_with: Vec<String>,
    /// With an `unexplained` verdict, the supported effect that explains part of the gap
    /// (the strongest; its ranking entry says how much): present, but not all that is
    /// missing. `None` for every other verdict, and when no effect is supported.
    pub partial: Option<String>,
    /// Held-out NRMSE of the calibrated baseline.
    pub baseline_heldout_nrmse: f64,
    /// Held-out NRMSE the measurement noise alone would give, with the best noise levels
    /// (`noise_nrmse_best`): what a model without error would score.
    pub noise_nrmse: f64,
    /// The same with the noise levels the fits weigh readings by (upper bounds: the
    /// verdict's tests beyond the noise use these).
    pub noise_nrmse_weights: f64,
    /// Held-out mean squared normalised residual of the baseline (1 = at noise level).
    pub baseline_heldout_chi2_per_reading: f64,
    /// Noise levels estimated from the data (crate::noise): quantity, factor applied to
    /// the stated noise levels, line residuals it rests on.
    pub noise_scale: Vec<(String, f64, usize)>,
    /// Where the gap lies.
    pub gap_where: Vec<GapRegion>,
    /// Every candidate tried, strongest first.
    pub ranking: Vec<RankEntry>,
    /// What the data can and cannot support.
    pub notes: Vec<String>,
    /// Rows, readings, regions and folds used.
    pub n_rows: usize,
    /// Readings used.
    pub n_readings: usize,
    /// Folds used.
    pub folds: usize,
    /// Baseline parameters calibrated on all data (name, value).
    pub baseline_params: Vec<(String, f64)>,
    /// Per held-out reading: (row index, observable, measured, baseline prediction,
    /// prediction with the verdict's effects) — for plots.
    pub heldout: Vec<HeldOut>,
}

/// One held-out reading with its predictions.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldOut {
    /// Row index in the input.
    pub row: usize,
    /// What was measured.
    pub observable: Observable,
    /// Measured value.
    pub measured: f64,
    /// Baseline prediction (trained without this row's region).
    pub baseline: f64,
    /// Prediction with the verdict's effect(s) (equal to baseline for `none`).
    pub after: f64,
}

/// Region key of a row: run, preload level (25 N bins), frequency band (500 Hz), time
/// window (120 s).
fn region_key(r: &ObservedRow, group: &str) -> String {
    let t = if r.op.elapsed_s > 0.0 { (r.op.elapsed_s / 120.0).floor() as i64 } else { -1 };
    format!("{group}|{}|{}|{}", (r.op.preload_n / 25.0).round() as i64, (r.op.frequency_hz / 500.0).round() as i64, t)
}

/// Scale of each observable for the NRMSE: the spread (standard deviation) of its
/// measured values, floored by its noise level.
fn scales(rows: &[ObservedRow]) -> BTreeMap<Observable, f64> {
    let mut acc: BTreeMap<Observable, Vec<(f64, f64)>> = BTreeMap::new();
    for r in rows {
        for &(o, v, s) in &r.readings {
            acc.entry(o).or_default().push((v, s));
        }
    }
    acc.into_iter()
        .map(|(o, vs)| {
            let n = vs.len() as f64;
            let mean = vs.iter().map(|x| x.0).sum::<f64>() / n;
            let sd = (vs.iter().map(|x| (x.0 - mean).powi(2)).sum::<f64>() / n).sqrt();
            let noise = vs.iter().map(|x| x.1).sum::<f64>() / n;
            (o, sd.max(noise).max(1e-12))
        })
        .collect()
}

/// The quantity scales of the held-out NRMSEs a diagnosis of `rows` (runs `groups`)
/// reports ([`scales`] with the noise levels it estimates from the data): for outside
/// figures on the same scale, such as the blind benchmark's model without error.
pub fn nrmse_scales(rows: &[ObservedRow], groups: &[String]) -> BTreeMap<Observable, f64> {
    let rows = bench_model(rows, groups).0;
    scales(&noise_scaled(&rows, &crate::noise::estimate(&rows, groups)))
}

/// The rows as the diagnosis fits them, after the bench model (`bench`): set points read
/// back with noise at their run's mean, quantised readings with their rounding error; and
/// the notes saying what was done.
fn bench_model(rows: &[ObservedRow], groups: &[String]) -> (Vec<ObservedRow>, Vec<String>) {
    let (snapped, snap_note) = bench::snap_set_points(rows, groups);
    let (out, quantum_note) = bench::account_for_quantisation(&snapped);
    (out, snap_note.into_iter().chain(quantum_note).collect())
}

/// Noise factors per quantity (`noise::estimate`), each the smaller of two estimates:
/// from the readings themselves (`raw`, as estimated), and from their residuals from the nominal motor's
/// predictions. Both are biased upwards only by what the lines through neighbouring
/// readings cannot follow; the model follows most of the curvature (stall knee, efficiency
/// peak, resonance) that dominates that bias on coarse grids, the raw readings follow what
/// the nominal model gets wrong in shape (a temperature time series).
fn noise_estimate(
    motor: &Motor,
    rows: &[ObservedRow],
    groups: &[String],
    raw: &BTreeMap<Observable, crate::noise::NoiseScale>,
) -> BTreeMap<Observable, crate::noise::NoiseScale> {
    let refs: Vec<&ObservedRow> = rows.iter().collect();
    // (a speed std keeps its readings: whether one is clipped is a property of the reading,
    // and a residual from a model that predicts a spread is ≤ 0 half the time)
    let detrended: Vec<ObservedRow> = rows
        .iter()
        .zip(predict(motor, &refs))
        .map(|(r, p)| {
            let mut r = r.clone();
            for (x, y) in r.readings.iter_mut().zip(p) {
                if x.0 != Observable::SpeedStdRpm {
                    x.1 -= y;
                }
            }
            r
        })
        .collect();
    let model = crate::noise::estimate(&detrended, groups);
    raw.iter()
        .map(|(&o, &n)| match model.get(&o) {
            Some(&m) if m.factor < n.factor => (o, m),
            _ => (o, n),
        })
        .collect()
}

/// Mean squared residual, over σ², of a reading max(0, m + σZ) (Z standard normal, x = m/σ)
/// that the bench clips at zero (a speed standard deviation): about its mean when the
/// reading is compared with the expected clipped reading (`centred`), else about m.
fn clipped_second_moment(x: f64, centred: bool) -> f64 {
    let (cdf, upper, pdf) = (crate::noise::normal_cdf(x), crate::noise::normal_cdf(-x), crate::noise::normal_pdf(x));
    // E[(Y/σ − x)²] = Φ(x) − xφ(x) + x²(1 − Φ(x)); the mean of Y/σ − x is φ(x) − x(1 − Φ(x))
    let about_m = cdf - x * pdf + x * x * upper;
    let bias = pdf - x * upper;
    if centred {
        (about_m - bias * bias).max(0.0)
    } else {
        about_m
    }
}

/// The held-out NRMSE that noise alone gives, with the best noise levels (`noise_estimate`):
/// each reading's σ rescaled from the weights' factor `est` to `best`. A speed std is
/// clipped at zero, its noise taken about the model's value `pred` (or about the expected
/// clipped reading where it is compared with that). A quantity without an
/// estimate of its own (fewer than `noise::MIN_TRIPLES` line residuals: the speed std of
/// one stability run) takes the speed's factor if it is the speed std (the same sensor),
/// and counts with the smaller of that noise and the baseline's own mean squared residual
/// for it, both upper bounds of its noise (the default levels are 2.5× the synthetic
/// bench's for the speed std, whose eight readings then outweighed the rest of the noise).
fn noise_nrmse_best(
    rows: &[ObservedRow],
    est: &BTreeMap<Observable, crate::noise::NoiseScale>,
    best: &BTreeMap<Observable, crate::noise::NoiseScale>,
    pred: &[Vec<f64>],
    sc: &BTreeMap<Observable, f64>,
) -> f64 {
    let best_factor = |o: Observable| {
        let same_sensor = o == Observable::SpeedStdRpm && !best.contains_key(&o);
        applied_factor(best, if same_sensor { Observable::SpeedRpm } else { o })
    };
    // per quantity: Σ noise²/sc², Σ residual²/sc²
    let mut acc: BTreeMap<Observable, (f64, f64)> = BTreeMap::new();
    let mut n = 0usize;
    for (r, p) in rows.iter().zip(pred) {
        for (&(o, y, s), &m) in r.readings.iter().zip(p) {
            let sigma = s / applied_factor(est, o) * best_factor(o);
            let var = if o == Observable::SpeedStdRpm && sigma > 0.0 {
                let x = if m.is_finite() { m / sigma } else { 0.0 };
                sigma * sigma * clipped_second_moment(x, r.speed_std_clipped)
            } else {
                sigma * sigma
            };
            let e = acc.entry(o).or_default();
            e.0 += var / sc[&o].powi(2);
            e.1 += if m.is_finite() { (m - y).powi(2) / sc[&o].powi(2) } else { f64::INFINITY };
            n += 1;
        }
    }
    let total: f64 =
        acc.iter().map(|(o, &(noise, res))| if best.contains_key(o) { noise } else { noise.min(res) }).sum();
    (total / n.max(1) as f64).sqrt()
}

/// The factor applied to the stated noise levels of quantity `o`: its estimate clamped to
/// [1/4, 4], or 1 without one.
fn applied_factor(est: &BTreeMap<Observable, crate::noise::NoiseScale>, o: Observable) -> f64 {
    est.get(&o).map_or(1.0, |n| n.factor.clamp(0.25, 4.0))
}

/// The rows with each reading's σ scaled by the noise factor estimated for its quantity
/// (clamped to [1/4, 4]), marked clipped where `speed_std_clipped` says so.
fn noise_scaled(rows: &[ObservedRow], est: &BTreeMap<Observable, crate::noise::NoiseScale>) -> Vec<ObservedRow> {
    let scaled: Vec<ObservedRow> = rows
        .iter()
        .map(|r| {
            let mut r = r.clone();
            for x in r.readings.iter_mut() {
                x.2 *= applied_factor(est, x.0);
            }
            r
        })
        .collect();
    let clipped = speed_std_clipped(&scaled, est.contains_key(&Observable::SpeedStdRpm));
    scaled.into_iter().map(|r| ObservedRow { speed_std_clipped: clipped, ..r }).collect()
}

/// Whether the speed-std readings of `rows` are compared with the expected reading of
/// clipped noise (`ObservedRow::speed_std_clipped`): some read exactly zero (the bench
/// clips at zero) and their noise level was `estimated` from the data. With the stated
/// (default) level, 2.5-5× the synthetic bench's, that expectation would overshoot; exact
/// data (the blind benchmark's reference fits) have no noise to clip.
fn speed_std_clipped(rows: &[ObservedRow], estimated: bool) -> bool {
    estimated && rows.iter().flat_map(|r| &r.readings).any(|x| crate::noise::clipped_reading(x.0, x.1))
}

/// Predictions of `motor` for `rows` (NaN where the model has no solution).
fn predict(motor: &Motor, rows: &[&ObservedRow]) -> Vec<Vec<f64>> {
    let p = Prepared::new(motor).without_stall_torque();
    // in parallel: the baseline's held-out predictions are made while nothing else runs
    rows.par_iter()
        .map(|r| {
            let s = solve_prepared(&p, motor, &r.op, None);
            r.readings
                .iter()
                .map(|&(o, _, sigma)| {
                    if s.status.is_valid() {
                        crate::calibrate::expected(o, r, &s, motor.effects.instrument(), sigma)
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect()
}

struct CvResult {
    /// held-out predictions aligned with rows/readings
    preds: Vec<Vec<f64>>,
    /// folds whose fit could not be moved off the full-data fit (approximate CV: even the
    /// damped first step raised the training χ²), so their held-out blocks were predicted
    /// in-sample
    in_sample: usize,
}

/// Approximate leave-block-out refits. From the full-data optimum û (where the gradient
/// of the full χ² vanishes), simplified Gauss–Newton steps on the training readings with
/// the full-data Jacobian, u ← u − (J_Tᵀ J_T)⁺ J_Tᵀ r_T(u), remove the held-out block's
/// influence on the parameters — to first order after one step (exact for a model linear
/// in u; the approximate leave-out estimators of Beirami et al. 2017 and Rad & Maleki
/// 2020 rest on the same step), closer after the second, which uses the training
/// residuals at the new point. The held-out block is then predicted with the nonlinear
/// model. Cost: about two passes over the data per model instead of one full fit per
/// fold. `DiagnoseOptions::exact_cv` refits instead; a test checks the two agree.
///
/// When the held-out block moves the parameters far (a step beyond 0.3 in the logistic
/// coordinates, about 7 % of a parameter's range near mid-range: the linearisation is no
/// longer trusted), the fold is refitted, starting from the stepped point, on the same
/// weighted problem the steps linearise: the full-data fit's Huber weights kept on the
/// training readings (a refit that reweighted from scratch would be another estimator, and
/// on the 1000-row benchmark took 59 model passes where this takes 6).
fn approx_cv(cal: &Calibration, rows: &[ObservedRow], folds: &[usize], k: usize, fit: &FitOptions) -> CvResult {
    let lin = &cal.lin;
    let mut offset = vec![0usize];
    for r in rows {
        offset.push(offset.last().copied().unwrap_or(0) + r.readings.len());
    }
    let mut preds: Vec<Vec<f64>> = rows.iter().map(|r| vec![f64::NAN; r.readings.len()]).collect();
    let mut in_sample = 0;
    for f in 0..k {
        let test: Vec<usize> = (0..rows.len()).filter(|&i| folds[i] == f).collect();
        if test.is_empty() {
            continue;
        }
        let train: Vec<usize> = (0..rows.len()).filter(|&i| folds[i] != f).collect();
        let idx: Vec<usize> = train.iter().flat_map(|&i| offset[i]..offset[i + 1]).collect();
        // (the priors' rows belong to every training set)
        let jt = with_prior_rows(lin.jacobian.select_rows(idx.iter()), &lin.params, &lin.u);
        let w: Vec<f64> = idx.iter().map(|&j| lin.weights[j]).collect();
        let train_rows: Vec<ObservedRow> = train.iter().map(|&i| rows[i].clone()).collect();
        let hinv = pseudo_inverse(&(jt.transpose() * &jt));
        let weighted = |u: &DVector<f64>| -> DVector<f64> {
            let r = residuals(&lin.motor_at(u), &train_rows);
            let prior = prior_residuals(&lin.params, u);
            DVector::from_iterator(r.len() + prior.len(), r.iter().zip(&w).map(|(x, w)| x * w).chain(prior))
        };
        let prior0 = prior_residuals(&lin.params, &lin.u);
        let mut r =
            DVector::from_iterator(idx.len() + prior0.len(), idx.iter().map(|&j| lin.residuals[j]).chain(prior0));
        let mut best = (lin.u.clone(), r.norm_squared());
        for iteration in 0..2 {
            let step = &hinv * (jt.transpose() * &r);
            // a step that leaves the region where the linearisation holds is cut back
            let big = step.amax();
            let full = if big > 2.0 { step * (2.0 / big) } else { step };
            // Damped: a step whose actual gain on the training χ² is below a quarter of what
            // the linear model predicts for it (it overshoots, or crosses a row's change of
            // status, moving to clamped) is halved, up to twice (the trust-region
            // acceptance ratio ρ ≥ ¼). Undamped, a failed step left the fold with the
            // full-data fit, and its held-out block was predicted in-sample.
            let taken = (0..3).find_map(|h| {
                let du = &full * 0.5f64.powi(h);
                let ut = &best.0 - &du;
                let rt = weighted(&ut);
                let predicted = best.1 - (&r - &jt * &du).norm_squared();
                let actual = best.1 - rt.norm_squared();
                (actual > 0.0 && actual >= 0.25 * predicted).then_some((ut, rt))
            });
            let Some((ut, rt)) = taken else {
                // stuck at the full-data fit, though the held-out block moves the training
                // optimum (the first step promised a gain a fit would not stop short of)
                let promised = best.1 - (&r - &jt * &full).norm_squared();
                if iteration == 0 && promised >= crate::calibrate::FIT_DECREMENT_TOL {
                    in_sample += 1;
                }
                break;
            };
            best = (ut, rt.norm_squared());
            r = rt;
        }
        let moved = (&best.0 - &lin.u).amax();
        let fitted = if moved > 0.3 {
            let stepped = lin.motor_at(&best.0);
            calibrate_weighted(&stepped, &train_rows, &lin.params, fit, w.clone()).map(|c| c.motor).unwrap_or(stepped)
        } else {
            lin.motor_at(&best.0)
        };
        let test_rows: Vec<&ObservedRow> = test.iter().map(|&i| &rows[i]).collect();
        for (i, p) in test.iter().zip(predict(&fitted, &test_rows)) {
            preds[*i] = p;
        }
    }
    CvResult { preds, in_sample }
}

/// The excess beyond the noise of a held-out χ² per reading `x` over `n` readings of a
/// model a pair would have to beat, √(x − 1); 0 where x − 1 is within 2·√(2/n): noise
/// alone gives a mean z² of 1 with a standard error of √(2/n), and a model within two of
/// them leaves nothing a second effect could be shown to remove. (Blind case
/// `hertz_softening` at 3 × typical, 679 readings: the single left 1.03, its form error;
/// `voltage_sag` at 30 Ω polished that to 0.90 and was named as a second effect.) The
/// pair's own excess is the plain √(x − 1): the threshold decides only whether there is
/// anything to remove, so it never makes a pair easier to accept.
fn chi2_excess(x: f64, n: usize) -> f64 {
    if x - 1.0 <= 2.0 * (2.0 / n.max(1) as f64).sqrt() {
        0.0
    } else {
        (x - 1.0).sqrt()
    }
}

/// The fraction of what the single effect's entry `single` leaves beyond the noise on
/// held-out data that the pair's entry `pair` removes: (in NRMSE, excess √(NRMSE² −
/// noise²); in χ² per reading, the single's excess [`chi2_excess`] against the pair's plain
/// √(χ² − 1)); 0 where the single leaves nothing beyond the noise. `pair_beats_single`
/// asks for PAIR_GAIN in either.
fn pair_gains(single: &RankEntry, pair: &RankEntry, n_read: usize, noise_nrmse: f64) -> (f64, f64) {
    let excess = |x: f64| (x * x - noise_nrmse * noise_nrmse).max(0.0).sqrt();
    let gain = |s: f64, p: f64| if s > 1e-12 { 1.0 - p / s } else { 0.0 };
    (
        gain(excess(single.heldout_nrmse_after), excess(pair.heldout_nrmse_after)),
        gain(chi2_excess(single.heldout_chi2_after, n_read), (pair.heldout_chi2_after - 1.0).max(0.0).sqrt()),
    )
}

/// What a pair must remove, summed over the readings, to beat the single `b` on held-out
/// data by PAIR_GAIN of its excess beyond the noise (`pair_beats_single`): in Σ z² (the
/// excess [`chi2_excess`] per reading) and in Σ e² (the excess √(NRMSE² − noise²)), each
/// 1 − (1 − PAIR_GAIN)² of n times the squared excess.
fn held_out_need(b: &RankEntry, n_read: usize, noise_nrmse: f64) -> (f64, f64) {
    let part = n_read as f64 * (1.0 - (1.0 - PAIR_GAIN) * (1.0 - PAIR_GAIN));
    (
        part * chi2_excess(b.heldout_chi2_after, n_read).powi(2),
        part * (b.heldout_nrmse_after.powi(2) - noise_nrmse.powi(2)).max(0.0),
    )
}

/// `x` to about three significant digits, for notes.
fn rounded(x: f64) -> String {
    match x.abs() {
        a if a >= 100.0 => format!("{x:.0}"),
        a if a >= 10.0 => format!("{x:.1}"),
        _ => format!("{x:.2}"),
    }
}

/// Whether `e` is worth a pair fit as a second effect to the lead fitted in `lead_fit`: its
/// score test there removes at least a quarter of `chi2_needed` (what the pair needs in
/// evidence), and, when the lead closes the gap (`held_needed`: the Σ z² and Σ e² a pair
/// must remove on held-out data to beat it), its first-order gain reaches a quarter of
/// either. Without a lead fit or a signature there is nothing to screen on: worth it.
/// When not worth it, the second value says which bar failed, with its numbers.
fn worth_pair_fit(
    lead_fit: Option<&Calibration>,
    rows: &[ObservedRow],
    e: Effect,
    chi2_needed: f64,
    held_needed: Option<(f64, f64)>,
    sc: &BTreeMap<Observable, f64>,
) -> (bool, String) {
    let Some((c, s)) = lead_fit.and_then(|c| signature::signature(c, rows, e).map(|s| (c, s))) else {
        return (true, String::new());
    };
    if s.linear_chi2_drop < 0.25 * chi2_needed {
        let why = format!("score Δχ² {} < {}", rounded(s.linear_chi2_drop), rounded(0.25 * chi2_needed));
        return (false, why);
    }
    match held_needed {
        Some((chi2, e2)) => {
            let (d_chi2, d_e2) = first_order_gains(c, rows, &s, sc);
            let worth = (chi2 > 0.0 && d_chi2 >= 0.25 * chi2) || (e2 > 0.0 && d_e2 >= 0.25 * e2);
            let why = format!(
                "Σz² {} < {} and Σe² {} < {}",
                rounded(d_chi2),
                rounded(0.25 * chi2),
                rounded(d_e2),
                rounded(0.25 * e2)
            );
            (worth, if worth { String::new() } else { why })
        }
        None => (true, String::new()),
    }
}

/// Whether a pair of two candidates that lead nothing may beat the best single effect
/// (evidence `best`) in evidence, to first order (the screen in `diagnose`): the unweighted
/// score gain of `b` at the fit `fit_a` of the other effect (evidence `ev_a`) reaches a
/// quarter of 2·(best − ev_a) + k_b·ln n + 10, the χ² the pair must remove from that fit to
/// lead the best single by ½ΔBIC > 5. None when `b` has no signature there.
fn pair_may_beat(
    fit_a: &Calibration,
    ev_a: f64,
    best: f64,
    rows: &[ObservedRow],
    b: Effect,
    sc: &BTreeMap<Observable, f64>,
) -> Option<bool> {
    let n_read: usize = rows.iter().map(|r| r.readings.len()).sum();
    let need = 2.0 * (best - ev_a) + b.info().params.len() as f64 * (n_read as f64).ln() + 10.0;
    let sig = signature::signature(fit_a, rows, b)?;
    Some(first_order_gains(fit_a, rows, &sig, sc).0 >= 0.25 * need)
}

/// The first-order in-sample gains of adding the effect of `sig` to the fit `cal`, in the
/// two held-out measures' terms: the drop of Σ z² (unweighted normalised residuals, as in
/// the held-out χ²) and of Σ e² (errors over each quantity's scale, as in the NRMSE). The
/// signature's change is of the Huber-weighted residuals; each reading's weight is taken
/// back out (weights are positive).
fn first_order_gains(
    cal: &Calibration,
    rows: &[ObservedRow],
    sig: &signature::Signature,
    sc: &BTreeMap<Observable, f64>,
) -> (f64, f64) {
    let lin = &cal.lin;
    let (mut chi2, mut e2) = (0.0, 0.0);
    let readings = rows.iter().flat_map(|r| r.readings.iter());
    for (k, &(o, _, sigma)) in readings.enumerate() {
        let w = lin.weights[k];
        let (z, dz) = (lin.residuals[k] / w, sig.linear_change[k] / w);
        let gain = z * z - (z + dz) * (z + dz);
        chi2 += gain;
        e2 += gain * (sigma / sc[&o]).powi(2);
    }
    (chi2, e2)
}

/// Moore–Penrose inverse of a small symmetric normal matrix; directions the training data
/// do not determine (singular values below 1e-10 of the largest) are left unchanged.
fn pseudo_inverse(h: &DMatrix<f64>) -> DMatrix<f64> {
    let zero = || DMatrix::zeros(h.nrows(), h.ncols());
    if !h.iter().all(|x| x.is_finite()) {
        return zero();
    }
    match h.clone().try_svd(true, true, 1e-15, 500) {
        Some(svd) => {
            let smax = svd.singular_values.max();
            svd.pseudo_inverse(smax * 1e-10).unwrap_or_else(|_| zero())
        }
        None => zero(),
    }
}

/// True when a fit ended with an added effect's primary strength within 1 % of its range
/// above zero: the data pulled it there from the nested model's fit, as in a fit abandoned
/// as collapsing (which is tested at 1e-3 of the range, where the logistic transform
/// freezes the strength; a fit that stops on the decrement just above that has the same
/// answer). Such a fit gets no second start: on the 1000-row benchmark with seeds 21-28,
/// `tangential_compliance` ended at 0.13 % of its range, and its second start spent 41
/// passes (a fifth of the run's CPU) refitting the baseline before collapsing too.
fn added_near_zero(params: &[FitParam], fitted: &[FittedParam], added: &[Effect]) -> bool {
    params.iter().zip(fitted).any(|(fp, p)| {
        matches!(fp.param, ParamRef::Effect(e, 0) if added.contains(&e)) && fp.lo == 0.0 && p.value <= 0.01 * fp.hi
    })
}

/// The fraction of the nominal motor's χ² a strong-effect probe must leave at most to
/// start a fit (docs/DIAGNOSIS.md, step 4). Not a test of the effect: a wrong
/// `voltage_sag` at 8 × typical left 7.7-9.1 % in a stop-33 review (its refits ended
/// worse than the fits they would have replaced, which they therefore do not replace),
/// and 6 % lost the true `radial_friction` of a 3 × blind case. A refit that does not end
/// below the fit costs only its time.
const PROBE_LEFT: f64 = 0.1;

/// The nominal `motor` with `effects` at `times` × their typical strengths (every
/// strength; a shape parameter mid-range), each kept a twentieth of its fit range inside
/// its bounds in `params`:
/// the starts probed for a strong effect in the diagnosis.
fn strong_start(motor: &Motor, effects: &[Effect], params: &[FitParam], times: f64) -> Motor {
    let mut m = motor.clone();
    for &e in effects {
        let v: Vec<f64> = e
            .info()
            .params
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let x = if p.shape { p.start() } else { times * p.typical };
                match params.iter().find(|fp| matches!(fp.param, ParamRef::Effect(f, j) if f == e && j == i)) {
                    Some(fp) => {
                        let margin = 0.05 * (fp.hi - fp.lo);
                        if fp.hi - fp.lo > 0.0 {
                            x.clamp(fp.lo + margin, fp.hi - margin)
                        } else {
                            x
                        }
                    }
                    None => x,
                }
            })
            .collect();
        m.effects.set(e, &v);
    }
    m
}

/// `start` with the shape parameters of the `added` effects at their typical values, or
/// `None` when none has a shape parameter away from it.
fn at_typical_shape(start: &Motor, added: &[Effect]) -> Option<Motor> {
    let mut m = start.clone();
    let mut moved = false;
    for &e in added {
        for (i, p) in e.info().params.iter().enumerate().filter(|(_, p)| p.shape) {
            if m.effects.value(e, i) != p.typical {
                *m.effects.value_mut(e, i) = p.typical;
                moved = true;
            }
        }
    }
    moved.then_some(m)
}

/// True when `fp` is a shape parameter of one of the `added` effects.
fn is_shape_of(fp: &FitParam, added: &[Effect]) -> bool {
    matches!(fp.param, ParamRef::Effect(e, i) if added.contains(&e) && e.info().params[i].shape)
}

/// Start point and parameters of a fit: bounds around the nominal `motor`, starting from
/// `start` (the full-data baseline calibration, which saves most LM iterations).
fn fit_params(
    motor: &Motor,
    start: &Motor,
    rows: &[ObservedRow],
    effects: &[Effect],
    reduced: bool,
    tolerances: &BTreeMap<String, f64>,
) -> (Motor, Vec<FitParam>) {
    let mut m = start.clone();
    // (with few readings too: the priors hold what the data cannot determine)
    let _ = reduced;
    let mut params = baseline_params_with(motor, rows, tolerances);
    // an instrument floor starts mid-range (at zero it would sit on its bound, where the
    // transformed gradient vanishes)
    for fp in params.iter().filter(|fp| matches!(fp.param, ParamRef::Instrument(_))) {
        if m.effects.instrument().speed_std_floor_rpm == 0.0 {
            m.effects.instrument_mut().speed_std_floor_rpm = 0.5 * (fp.lo + fp.hi);
        }
    }
    let already = start.effects.active();
    for &e in effects {
        // Start inside the range (a strength of exactly 0 sits on the bound, where the
        // transformed gradient vanishes). An effect the start already carries (the lead
        // effect of a pair, fitted alone) starts from its fitted strength; every effect's
        // parameters are fitted.
        if !already.contains(&e) {
            let info = e.info();
            m.effects.set(e, &info.with_primary(info.fit_start * info.params[0].typical));
        }
        params.extend(effect_params(e));
    }
    (m, params)
}

#[allow(clippy::too_many_arguments)]
fn cross_validate(
    motor: &Motor,
    start: &Motor,
    rows: &[ObservedRow],
    folds: &[usize],
    k: usize,
    effects: &[Effect],
    opts: &DiagnoseOptions,
    reduced: bool,
) -> CvResult {
    let mut preds: Vec<Vec<f64>> = rows.iter().map(|r| vec![f64::NAN; r.readings.len()]).collect();
    for f in 0..k {
        let train: Vec<ObservedRow> = rows.iter().zip(folds).filter(|(_, &g)| g != f).map(|(r, _)| r.clone()).collect();
        let test_idx: Vec<usize> = (0..rows.len()).filter(|&i| folds[i] == f).collect();
        if test_idx.is_empty() {
            continue;
        }
        let (s0, params) = fit_params(motor, start, &train, effects, reduced, &opts.tolerances);
        let mut fitted = calibrate(&s0, &train, &params, &opts.fit).ok();
        if !effects.is_empty() {
            // Nested models: the effect at zero strength is the baseline, so a fit that ends
            // worse than the baseline's is a local minimum; use the baseline fit instead.
            let (b0, bp) = fit_params(motor, start, &train, &[], reduced, &opts.tolerances);
            let base = calibrate(&b0, &train, &bp, &opts.fit).ok();
            if let Some(b) = base {
                if fitted.as_ref().is_none_or(|f| f.chi2 > b.chi2) {
                    fitted = Some(b);
                }
            }
        }
        let fitted = fitted.map(|c| c.motor).unwrap_or(s0);
        let test: Vec<&ObservedRow> = test_idx.iter().map(|&i| &rows[i]).collect();
        for (i, p) in test_idx.iter().zip(predict(&fitted, &test)) {
            preds[*i] = p;
        }
    }
    CvResult { preds, in_sample: 0 }
}

/// A reading's squared normalised residual counts at most this much in the held-out mean
/// z² (a 4σ miss): single gross outliers, which a real bench records now and then, then
/// move the mean by at most 16/n. Noise alone gives a mean of 0.9997 instead of 1.
pub const OUTLIER_Z2: f64 = 16.0;

/// Normalised held-out errors: (NRMSE with the quantity scales, mean squared residual in σ
/// with each reading's clipped at [`OUTLIER_Z2`], per-reading squared scaled residuals,
/// per-reading squared residuals in σ). The NRMSE is not clipped: the spec's shrink is
/// measured on it, and a baseline's large misses are the gap itself.
fn errors(rows: &[ObservedRow], preds: &[Vec<f64>], sc: &BTreeMap<Observable, f64>) -> (f64, f64, Vec<f64>, Vec<f64>) {
    let mut e2 = Vec::new();
    let mut z2 = Vec::new();
    for (r, p) in rows.iter().zip(preds) {
        for (&(o, v, s), &y) in r.readings.iter().zip(p) {
            let y = if y.is_finite() { y } else { 0.0 };
            let d = y - v;
            e2.push((d / sc[&o]).powi(2));
            z2.push((d / s).powi(2));
        }
    }
    let n = e2.len().max(1) as f64;
    // the mean z² with each reading's clipped at OUTLIER_Z2, so that a few gross outliers
    // (a bench artefact) do not make a gap
    let clipped = z2.iter().map(|x| x.min(OUTLIER_Z2)).sum::<f64>() / n;
    ((e2.iter().sum::<f64>() / n).sqrt(), clipped, e2, z2)
}

/// Diagnoses `rows` (with `groups[i]` the run of row i; empty strings are fine) against
/// `motor`. Errors on data that cannot support any held-out test.
pub fn diagnose(
    motor: &Motor,
    rows: &[ObservedRow],
    groups: &[String],
    opts: &DiagnoseOptions,
) -> Result<Diagnosis, TrumError> {
    let n_read: usize = rows.iter().map(|r| r.readings.len()).sum();
    // The bench model first: set points read back with noise are taken at their run's
    // mean, quantised readings carry their rounding error (`bench`).
    let (bench_rows, bench_notes) = bench_model(rows, groups);
    let rows = &bench_rows[..];
    // Noise levels from the data, so that χ² and the evidence are on the scale of the
    // actual noise; clamped to [1/4, 4] × the stated levels.
    let est = crate::noise::estimate(rows, groups);
    let scaled = noise_scaled(rows, &est);
    let unscaled_rows = rows;
    let rows = &scaled[..];
    let noise_scale: Vec<(String, f64, usize)> =
        est.iter().map(|(&o, n)| (o.column().to_string(), applied_factor(&est, o), n.residuals)).collect();
    if rows.len() < 4 {
        return Err(TrumError::input(format!(
            "{} rows are too few to diagnose anything; need at least 4 operating points",
            rows.len()
        )));
    }
    // regions → folds
    let keys: Vec<String> = rows
        .iter()
        .zip(groups.iter().chain(std::iter::repeat(&String::new())))
        .map(|(r, g)| region_key(r, g))
        .collect();
    let mut uniq: Vec<&String> = keys.iter().collect();
    uniq.sort();
    uniq.dedup();
    if uniq.len() < 2 {
        return Err(TrumError::input(
            "all rows lie in one operating region (same run, preload, frequency and time window): no held-out block is possible",
        ));
    }
    let k = opts.folds.clamp(2, uniq.len());
    let fold_of: BTreeMap<&String, usize> = uniq.iter().enumerate().map(|(i, key)| (*key, i % k)).collect();
    let folds: Vec<usize> = keys.iter().map(|key| fold_of[key]).collect();
    let mut notes: Vec<String> = bench_notes;
    if !noise_scale.is_empty() {
        let list: Vec<String> = noise_scale.iter().map(|(q, f, n)| format!("{q} ×{f:.2} ({n})")).collect();
        notes.push(format!(
            "noise levels estimated from the data (residuals from lines through neighbouring readings within runs; \
             factor on the default levels, residuals used): {}",
            list.join(", ")
        ));
    }
    let n_base = baseline_params_with(motor, rows, &opts.tolerances).len();
    let reduced = n_read < 4 * (n_base + 2);
    if reduced {
        notes.push(format!(
            "only {n_read} readings: the baseline's parameters rest largely on their priors, the held-out \
             figures come from exact refits, and no effect can be confirmed with confidence"
        ));
    }
    // With few readings the fit is far from linear over a fold's influence: refit exactly
    // (cheap at this size).
    let opts = &DiagnoseOptions { exact_cv: opts.exact_cv || reduced, ..opts.clone() };
    let sc = scales(rows);
    // noise level as NRMSE, with the weights' noise levels
    let noise_weights = {
        let mut acc = 0.0;
        for r in rows {
            for &(o, _, s) in &r.readings {
                acc += (s / sc[&o]).powi(2);
            }
        }
        (acc / n_read as f64).sqrt()
    };
    // full-data baseline fit (the start of every other fit; "where", BIC, reported parameters)
    let (start0, bparams) = fit_params(motor, motor, rows, &[], reduced, &opts.tolerances);
    // A baseline that ends with a parameter on a bound is refitted from its own end
    // (`calibrate_refitting_bounds`). (1000-row benchmark, seeds 31-38: every single fit,
    // started from the baseline left on the damping bound, first refitted the baseline
    // whatever its effect.)
    let base_cal = calibrate_refitting_bounds(&start0, rows, &bparams, &opts.fit)?;
    let start = base_cal.motor.clone();
    let base_cv = if opts.exact_cv {
        cross_validate(motor, &start, rows, &folds, k, &[], opts, reduced)
    } else {
        approx_cv(&base_cal, rows, &folds, k, &opts.fit)
    };
    let (base_nrmse, base_z2, base_e2, _) = errors(rows, &base_cv.preds, &sc);
    // The noise NRMSE reported (the spec's `noise_nrmse`) is the best estimate of what noise
    // alone gives; the tests beyond the noise below keep the weights' levels, upper bounds
    // consistent with the χ² the fits minimise (with the best levels in those tests the
    // blind benchmark lost 3 of its 45 correct verdicts: docs/DIAGNOSIS.md).
    let noise_best = {
        // the model's own values, not expected clipped readings
        let plain: Vec<ObservedRow> =
            rows.iter().map(|r| ObservedRow { speed_std_clipped: false, ..r.clone() }).collect();
        let refs: Vec<&ObservedRow> = plain.iter().collect();
        let best = noise_estimate(motor, unscaled_rows, groups, &est);
        noise_nrmse_best(rows, &est, &best, &predict(&base_cal.motor, &refs), &sc)
    };
    let bic = |chi2: f64, kpar: usize| chi2 + kpar as f64 * (n_read as f64).ln();
    let base_bic = bic(base_cal.chi2, bparams.len());

    // what the data can see
    let varies = |f: &dyn Fn(&ObservedRow) -> f64| {
        let v: Vec<f64> = rows.iter().map(f).collect();
        let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| (a.0.min(x), a.1.max(x)));
        hi - lo > 1e-9 * hi.abs().max(1.0)
    };
    let has = |o: Observable| rows.iter().any(|r| r.readings.iter().any(|x| x.0 == o));
    if !varies(&|r| r.op.frequency_hz) {
        notes.push("frequency never varies: preload_stiffening and hertz_softening show only through amplitude and speed, not through a resonance shift".into());
    }
    if !varies(&|r| r.op.elapsed_s) {
        notes.push("no time series (elapsed_s): thermal_drift cannot act and is not testable".into());
    }
    if !has(Observable::SpeedStdRpm) {
        notes.push("no speed_std_rpm column: eccentricity shows only through the mean speed".into());
    }
    if !has(Observable::InputPowerW) && !has(Observable::CurrentA) {
        notes.push(
            "no electrical readings (input_power_w, current_a): voltage_sag and the losses are weakly constrained"
                .into(),
        );
    }
    if !varies(&|r| r.op.torque_nm) {
        notes.push(
            "load torque never varies: the speed-torque curve (radial_friction, tangential_compliance) is not observed"
                .into(),
        );
    }

    // candidates in parallel; each returns its entry and its held-out predictions
    // An effect that moves no prediction of these rows (thermal_drift without a time
    // series) cannot be tested: it is ranked with the baseline's fit and its parameter
    // penalty, not fitted, and joins no pair.
    // Score tests at the calibrated baseline: each candidate's signature against the
    // baseline's residual (one model pass per effect parameter). Its probe is also the test
    // of whether the effect moves any prediction at all: all columns exactly zero.
    let probed: Vec<(Effect, Option<signature::Signature>)> =
        opts.candidates.par_iter().map(|&e| (e, signature::signature(&base_cal, rows, e))).collect();
    // (an effect the motor already carries has no probe: switched off instead)
    // (each computed once, when a probe first needs it)
    let (base_res, nominal_res) = (std::cell::OnceCell::new(), std::cell::OnceCell::new());
    let untestable: Vec<Effect> = probed
        .iter()
        .filter(|(e, s)| match s {
            // (and at the nominal motor with the effect at its typical strength: a baseline
            // fit with the rotor at rest everywhere gives every rotor effect a zero probe)
            Some(s) => {
                s.columns.iter().all(|&x| x == 0.0) && {
                    let mut on = motor.clone();
                    on.effects.set(*e, &e.info().with_primary(e.info().params[0].typical));
                    &residuals(&on, rows) == nominal_res.get_or_init(|| residuals(motor, rows))
                }
            }
            None if start.effects.is_on(*e) => {
                let mut off = start.clone();
                off.effects.clear(*e);
                &residuals(&off, rows) == base_res.get_or_init(|| residuals(&start, rows))
            }
            None => false,
        })
        .map(|(e, _)| *e)
        .collect();
    // A baseline fit with the rotor at rest wherever it was measured turning leaves the
    // effects that act through the turning rotor nothing to move at that fit (blind
    // benchmark, `radial_friction` at 3 ×, preload-torque, seed 1201: the fit ends with
    // every reading clamped or stalled, and six of the seven candidates had a zero probe
    // there; they were ranked untestable and the verdict was `unexplained`, where the true
    // motor shrinks the gap by 0.97). Said in a note; the untestable rule above also
    // probes the nominal motor, so they are fitted.
    let turning: Vec<&ObservedRow> = rows
        .iter()
        .filter(|r| r.readings.iter().any(|&(o, v, sd)| o == Observable::SpeedRpm && v > 3.0 * sd))
        .collect();
    if !turning.is_empty() {
        let pb = Prepared::new(&base_cal.motor);
        let at_rest = turning
            .iter()
            .filter(|r| {
                matches!(solve_prepared(&pb, &base_cal.motor, &r.op, None).status, Status::Stall | Status::Clamped)
            })
            .count();
        if at_rest == turning.len() {
            notes.push(format!(
                "the calibrated baseline has the rotor at rest (clamped or stalled) at all {at_rest} operating \
                 points where it was measured turning, so the effects that act through the turning rotor \
                 move none of its predictions: they are tested from the nominal motor instead (the \
                 strong-effect starts), and the baseline's own figures describe a stator that does not run"
            ));
        }
    }
    // (a zero probe, of an effect testable only at the nominal motor, is no signature: its
    // match, score and overlap are not reported as zeros)
    let base_sigs: BTreeMap<Effect, signature::Signature> = probed
        .into_iter()
        .filter(|(e, _)| !untestable.contains(e))
        .filter_map(|(e, s)| s.filter(|s| s.columns.iter().any(|&x| x != 0.0)).map(|s| (e, s)))
        .collect();
    let single_sig = |effects: &[Effect]| match effects {
        [e] => base_sigs.get(e),
        _ => None,
    };
    // `from`: the start of the fit (the calibrated baseline; for a pair, the lead effect's
    // own fit, so the pair starts where the single ended). `nested`: the χ² and held-out
    // predictions of the fitted model this one nests (the lead effect's fit for a pair; the
    // baseline when None), which stand in when the fit ends worse than it.
    // χ² of the nominal motor itself, for the strong-effect probes below (once, if needed)
    let nominal_chi2 = std::sync::OnceLock::<f64>::new();
    // fits whose starts ended in different valleys (reported in the notes)
    let start_notes = std::sync::Mutex::new(Vec::<String>::new());
    type Scored = (RankEntry, Vec<Vec<f64>>, Option<Calibration>);
    type Nested = Option<(f64, Vec<Vec<f64>>, Vec<FittedParam>)>;
    let score = |effects: &[Effect], from: &Motor, nested: &Nested| -> Scored {
        let (nested_chi2, nested_preds, nested_params) =
            nested.as_ref().map(|(c, p, q)| (*c, p, &q[..])).unwrap_or((base_cal.chi2, &base_cv.preds, &[]));
        // Two starts: the calibrated baseline with the effect weak (`EffectInfo::fit_start`),
        // and the nominal motor with the effect at its typical strength. The baseline calibration may have bent
        // its parameters to mimic part of the effect, a valley the first start can stay in.
        let (s0, params) = fit_params(motor, from, rows, effects, reduced, &opts.tolerances);
        let kpar = params.len();
        let name = effects.iter().map(|e| e.name()).collect::<Vec<_>>().join("+");
        if effects.iter().any(|e| untestable.contains(e)) {
            let entry = RankEntry {
                effect: name,
                evidence: 0.5 * (base_bic - bic(base_cal.chi2, kpar)),
                heldout_nrmse_after: base_nrmse,
                heldout_chi2_after: base_z2,
                shrink: 0.0,
                shrink_interval: (0.0, 0.0),
                params: Vec::new(),
                signature_match: None,
                linear_chi2_drop: None,
                signature_overlap: None,
                heldout_in_sample_folds: 0,
            };
            return (entry, base_cv.preds.clone(), None);
        }
        // the effects this fit adds to the model it nests (a pair not led by a fitted single,
        // one of the three strongest when none closes the gap, nests the baseline: both its
        // effects count as added, and a collapse of either lets the baseline stand in, not the
        // other single; such a pair cannot win over that single anyway)
        let added = if nested.is_some() { &effects[1..] } else { effects };
        // a pair led by a fitted single starts at that fit's optimum (a parameter within
        // 1e-3 of a bound moved to 1e-3 from it, `calibrate::fit`)
        let first = |s: &Motor| {
            if nested.is_some() {
                calibrate_nested(s, rows, &params, &opts.fit, added, Start::Extending(IRLS_START_RTOL))
            } else {
                calibrate_adding(s, rows, &params, &opts.fit, added)
            }
        };
        let mut cal = first(&s0);
        // An added effect with a shape parameter is fitted from a second first start too,
        // the shape at its typical value (on its bound: `preload_stiffening` by Sun et al. 2021
        // eq. 8 alone, moved just inside by the fit), and the better fit is kept. From the
        // shape's middle alone, fits of a wrong stiffening were pushed onto zero strength
        // where the typical shape finds a valley (1000-row radial-friction benchmark: evidence
        // 26 453 from the typical shape, collapsed from the middle), and a shape the data
        // want away from the typical one is reached from the middle (blind benchmark).
        if let Some(typical_shape) = at_typical_shape(&s0, added) {
            // the shape held (not fitted: a free shape column on its bound still changed the
            // path enough to collapse), then freed from that fit's optimum
            let held: Vec<FitParam> = params.iter().filter(|fp| !is_shape_of(fp, added)).cloned().collect();
            let alt = match calibrate_adding(&typical_shape, rows, &held, &opts.fit, added) {
                Ok(c) if !c.abandoned => {
                    calibrate_nested(&c.motor, rows, &params, &opts.fit, added, Start::Extending(IRLS_START_RTOL))
                }
                other => other,
            };
            let fitted = |c: &Result<Calibration, _>| c.as_ref().ok().filter(|c| !c.abandoned).map(|c| c.chi2);
            if fitted(&alt).is_some_and(|a| fitted(&cal).is_none_or(|c| a < c)) {
                cal = alt;
            }
        }
        // The second start is needed only when the first did not reach the noise level and
        // found no clear evidence (a supported effect is not rejected for a shallower valley).
        // A first fit that collapsed onto the nested model (or ended next to it,
        // `added_near_zero`) has its answer: from the calibrated baseline the data pull the
        // effect to zero. (In the blind benchmark no second start
        // after a collapse gained evidence; on the 1000-row benchmark they cost 7 CPU-s.)
        let first_ev = cal.as_ref().map(|c| 0.5 * (base_bic - bic(c.chi2, kpar))).unwrap_or(f64::NEG_INFINITY);
        let at_noise = cal.as_ref().is_ok_and(|c| c.chi2 <= 1.5 * n_read as f64);
        let collapsed = cal.as_ref().is_ok_and(|c| c.abandoned || added_near_zero(&params, &c.params, added));
        let on_bound =
            cal.as_ref().is_ok_and(|c| c.params.iter().any(|p| p.at_bound && !p.name.starts_with("effects.")));
        let second_start = !at_noise && (first_ev <= 5.0 || on_bound) && !collapsed;
        if second_start {
            let mut s1 = motor.clone();
            for &e in effects {
                s1.effects.set(e, &e.info().with_primary(e.info().params[0].typical));
            }
            if let Ok(c1) = calibrate_nested(&s1, rows, &params, &opts.fit, added, Start::Restart) {
                if !c1.abandoned && !cal.as_ref().is_ok_and(|c| !c.abandoned && c1.chi2 >= c.chi2) {
                    cal = Ok(c1);
                }
            }
        }
        // A strong effect: both starts above can end in a valley far from it, the baseline's
        // parameters pressed against their bounds to mimic part of the effect (blind cases at
        // 3 × typical: `radial_friction` fitted at 0.3-0.5 for a truth of 3, χ² 100-1000 ×
        // the noise; from the nominal motor with the effect at 4 × typical the fit reaches
        // the noise). Where the better of them did not reach the noise, the objective is
        // probed (one pass each, nothing fitted) at the nominal motor with the effect 1, 2, 4
        // and 8 × as strong as typical. A probe that removes nine tenths of the nominal
        // motor's own χ² lies in a valley of the effect's own, and the fit restarts from
        // it. (Not a probe below the fit's χ²: a probe has nothing calibrated and stays far
        // above even a wrong fit. On the blind cases at 3 × the true effect's best probe
        // left 1-5 % of the nominal χ², the others 8-140 %.)
        if nested.is_none() && !effects.is_empty() {
            let fit_chi2 = match &cal {
                Ok(c) if !c.abandoned => c.chi2,
                _ => base_cal.chi2,
            };
            if fit_chi2 > 1.5 * n_read as f64 {
                let chi2_of = |m: &Motor| residuals(m, rows).iter().map(|z| z * z).sum::<f64>();
                let nominal = *nominal_chi2.get_or_init(|| chi2_of(motor));
                // (1 × is the second start's motor when that ran; a start clamped to the
                // same strengths as the one before it is not probed again)
                let mut starts: Vec<Motor> = Vec::new();
                for x in [1.0, 2.0, 4.0, 8.0] {
                    let m = strong_start(motor, effects, &params, x);
                    let seen = starts.last().is_some_and(|l| l.effects.to_string() == m.effects.to_string());
                    if !(seen || (x == 1.0 && second_start)) {
                        starts.push(m);
                    }
                }
                let probe = starts.into_iter().map(|m| (chi2_of(&m), m)).min_by(|a, b| a.0.total_cmp(&b.0));
                if let Some((_, m)) = probe.filter(|p| p.0 < PROBE_LEFT * nominal) {
                    if let Ok(c2) = calibrate_nested(&m, rows, &params, &opts.fit, added, Start::Restart) {
                        if !c2.abandoned && c2.chi2 < fit_chi2 {
                            cal = Ok(c2);
                        }
                    }
                }
            }
        }
        // The search over the effect's whole documented range: a coarse scan of its
        // strength (and shape), from the calibrated baseline and from the nominal motor,
        // on a subsample of the rows. A valley the fits above did not reach — beyond their
        // bounds, or simply lower on the scan's rows than where they ended — is fitted
        // from, with the bounds widened to hold it (`scan`).
        // (a fit already at the noise has nothing left for another valley to explain)
        let at_noise_now = cal.as_ref().is_ok_and(|c| !c.abandoned && c.chi2 <= 1.5 * n_read as f64);
        if nested.is_none() && effects.len() == 1 && !at_noise_now {
            let fit_motor = match &cal {
                Ok(c) if !c.abandoned => c.motor.clone(),
                _ => start.clone(),
            };
            let valleys = scan::valleys(&[&start, motor], &fit_motor, rows, effects[0]);
            let mut disagree = Vec::new();
            for v in valleys {
                let mut wide = params.clone();
                scan::widen(&mut wide, effects[0], &v.values);
                let mut s2 = v.base.clone();
                s2.effects.set(effects[0], &v.values);
                if let Ok(c2) = calibrate_nested(&s2, rows, &wide, &opts.fit, added, Start::Restart) {
                    let current = match &cal {
                        Ok(c) if !c.abandoned => c.chi2,
                        _ => f64::INFINITY,
                    };
                    if !c2.abandoned {
                        if (c2.chi2 - current).abs() > 10.0 && current.is_finite() {
                            disagree.push(format!(
                                "χ² {:.0} from {} = {:.3e} against {:.0}",
                                c2.chi2,
                                effects[0].info().params[0].name,
                                v.values[0],
                                current
                            ));
                        }
                        if c2.chi2 < current {
                            cal = Ok(c2);
                        }
                    }
                }
            }
            if !disagree.is_empty() {
                start_notes
                    .lock()
                    .map(|mut n| n.push(format!("{}: starts disagree ({})", effects[0], disagree.join("; "))))
                    .ok();
            }
        }
        let mut in_sample = 0;
        let (evidence, fitted, preds, fitted_motor) = match cal {
            // Nested models: the effect at zero strength is the baseline, so a fit that ends
            // worse than the baseline's χ² is a local minimum; the baseline stands in for it.
            // (Not the lead's χ² for a pair: the two are Huber-reweighted fits, and a pair can
            // end a little above its lead in unweighted χ² and still predict held-out data
            // better.) A fit abandoned as collapsing onto its nested model (for a pair, the
            // lead's fit) is that model.
            Ok(c) if !c.abandoned && (c.chi2 <= base_cal.chi2 || opts.exact_cv) => {
                let cv = if opts.exact_cv {
                    cross_validate(motor, &start, rows, &folds, k, effects, opts, reduced)
                } else {
                    approx_cv(&c, rows, &folds, k, &opts.fit)
                };
                in_sample = cv.in_sample;
                (0.5 * (base_bic - bic(c.chi2.min(base_cal.chi2), kpar)), c.params.clone(), cv.preds, Some(c))
            }
            Ok(c) if !c.abandoned => {
                let zero = c.params.into_iter().map(|p| FittedParam { value: 0.0, ..p }).collect();
                (0.5 * (base_bic - bic(base_cal.chi2, kpar)), zero, base_cv.preds.clone(), None)
            }
            Ok(c) => {
                // the nested model's values: zero for the added effect, the lead's own for a pair
                let nested_value = |name: &str| nested_params.iter().find(|q| q.name == name).map(|q| q.value);
                let zero = c
                    .params
                    .into_iter()
                    .map(|p| FittedParam { value: nested_value(&p.name).unwrap_or(0.0), ..p })
                    .collect();
                (0.5 * (base_bic - bic(nested_chi2, kpar)), zero, nested_preds.clone(), None)
            }
            Err(_) => (f64::NEG_INFINITY, Vec::new(), base_cv.preds.clone(), None),
        };
        let (after, chi2_after, e2, _) = errors(rows, &preds, &sc);
        let shrink = 1.0 - after / base_nrmse.max(1e-300);
        let interval = bootstrap_shrink(&base_e2, &e2, opts.bootstrap, opts.seed);
        let entry = RankEntry {
            effect: name,
            evidence,
            heldout_nrmse_after: after,
            heldout_chi2_after: chi2_after,
            shrink,
            shrink_interval: interval,
            params: fitted.into_iter().filter(|p| p.name.starts_with("effects.")).map(|p| (p.name, p.value)).collect(),
            signature_match: single_sig(effects).map(|s| s.matched),
            linear_chi2_drop: single_sig(effects).map(|s| s.linear_chi2_drop),
            signature_overlap: None,
            heldout_in_sample_folds: in_sample,
        };
        (entry, preds, fitted_motor)
    };
    let mut cv_preds: BTreeMap<String, Vec<Vec<f64>>> = BTreeMap::new();
    let mut fits: BTreeMap<String, Calibration> = BTreeMap::new();
    let collect = |cv_preds: &mut BTreeMap<String, Vec<Vec<f64>>>,
                   fits: &mut BTreeMap<String, Calibration>,
                   scored: Vec<Scored>|
     -> Vec<RankEntry> {
        scored
            .into_iter()
            .map(|(e, p, m)| {
                cv_preds.insert(e.effect.clone(), p);
                if let Some(m) = m {
                    fits.insert(e.effect.clone(), m);
                }
                e
            })
            .collect()
    };
    let mut ranking: Vec<RankEntry> =
        collect(&mut cv_preds, &mut fits, opts.candidates.par_iter().map(|&e| score(&[e], &start, &None)).collect());
    sort_ranking(&mut ranking);

    // A candidate is supported when the full-data evidence is very strong (½ΔBIC > 5)
    // and its held-out improvement is real (the bootstrap 5 % bound of the shrink is
    // above zero). It closes the gap when the held-out residual is back near the noise
    // (mean squared normalised residual ≤ 2), or at least half of the held-out NRMSE is
    // gone, or at least half of the part of it beyond the noise, √(NRMSE² − noise²) (the
    // truth may differ in form from the candidate and leave a remainder; and a gap only a
    // little above the noise can never lose half of its total NRMSE).
    let supported = |r: &RankEntry| r.evidence > 5.0 && r.shrink > 0.0 && r.shrink_interval.0 > 0.0;
    // The noise of that last test is the best estimate of what noise alone gives
    // (`noise_best`, the reported `noise_nrmse`), not the weights' level: on `combined`
    // campaigns that is 3-4 × higher, often above the baseline's whole held-out NRMSE, and
    // then there was no gap "beyond the noise" for half of it to go. Every supported effect
    // closed it: a `radial_friction` that closed 18 % with χ² 4.2 per reading left was the
    // verdict for a truth of preload stiffening (blind benchmark, seed 136). Just above that
    // level the same test let a 1.4 % shrink close (a review's `thermal_drift` on
    // `voltage_sag` data, χ² 8.1 left), so no switch between the two levels will do.
    let gap_noise = noise_best;
    let beyond = |x: f64| (x * x - gap_noise * gap_noise).max(0.0).sqrt();
    // the fraction of the held-out gap beyond the noise an entry closes
    let excess_shrink = |r: &RankEntry| {
        let before = beyond(base_nrmse);
        if before > 0.0 {
            1.0 - beyond(r.heldout_nrmse_after) / before
        } else {
            0.0
        }
    };
    // A material part of the gap: a fifth of the held-out NRMSE or a quarter of its part
    // beyond the noise (with the supported test's bootstrap bound above zero).
    let material = |r: &RankEntry| supported(r) && (r.shrink >= 0.2 || excess_shrink(r) >= 0.25);
    // An entry closes the gap when it removes a material part of it and what it leaves is
    // at the noise level (held-out mean z² ≤ 2), or it removes half of the NRMSE or half of
    // its part beyond the noise. (A held-out mean z² ≤ 2 alone is no closing: a baseline
    // already at the noise passes it with any supported polish.)
    let closes = |r: &RankEntry| {
        let before = beyond(base_nrmse);
        material(r)
            && (r.heldout_chi2_after <= 2.0
                || r.shrink >= 0.5
                || (before > 0.0 && beyond(r.heldout_nrmse_after) <= 0.5 * before))
    };
    // The gap is real when the baseline misses held-out data beyond twice the noise
    // variance, or when some effect closes a material part of it (a small, consistent gap).
    let gap = base_z2 > 2.0 || ranking.iter().any(material);
    let mut verdict = String::from("none");
    let mut confounded = Vec::new();
    let mut partial = None;
    let mut complete = true;
    let mut screened_note = None;
    if gap {
        let best_single = ranking.iter().find(|r| supported(r)).cloned();
        let single_closes = best_single.as_ref().is_some_and(closes);
        // Pairs are tried when no single effect closes the gap, and also when one does: it
        // may close the gap on average yet leave another effect's signature in one quantity
        // or corner of the data, and that second effect need not be supported on its own
        // (the first one's gap dominates its single fit). Which second effects are worth a
        // pair fit is screened below by their score test at the lead's fit.
        let mut best_pair: Option<RankEntry> = None;
        if opts.try_pairs && ranking.len() >= 2 {
            // Forward selection: the best single joined with every other candidate (a
            // second effect can have no evidence on its own while the first one's gap
            // dominates the fit), plus pairs of the three strongest when no single closes.
            let names: Vec<Effect> = ranking
                .iter()
                .filter_map(|r| Effect::from_name(&r.effect).ok())
                .filter(|e| !untestable.contains(e))
                .collect();
            let mut pairs: Vec<[Effect; 2]> = Vec::new();
            let mut push = |a: Effect, b: Effect| {
                if a != b && !pairs.iter().any(|p| (p[0] == a && p[1] == b) || (p[0] == b && p[1] == a)) {
                    pairs.push([a, b]);
                }
            };
            // (no testable candidate at all: no lead, no pairs)
            let lead = best_single.as_ref().and_then(|b| Effect::from_name(&b.effect).ok()).or(names.first().copied());
            // When no single effect closes the gap, the candidate with the most evidence
            // leads a forward selection too: a large in-sample gain whose held-out shrink
            // fails is what a missing partner looks like (its fit extrapolates into a region
            // the other effect governs; blind slice pair case: radial friction alone
            // predicts a clamped stator at 400 N where sag keeps it moving).
            let mut leads: Vec<Effect> = lead.into_iter().collect();
            if let (false, Some(&top)) = (single_closes, names.first()) {
                if !leads.contains(&top) {
                    leads.push(top);
                }
            }
            // Screening: at the lead's own fit, a second effect whose score test (the χ² it
            // removes to first order) is below a quarter of what a pair needs to beat the
            // single (½ΔBIC > 5: Δχ² > 10 + k·ln n) is not worth a pair fit.
            let needed = |e: Effect| 10.0 + e.info().params.len() as f64 * (n_read as f64).ln();
            // A lead that closes the gap is beaten only by a pair that also removes PAIR_GAIN
            // of what it leaves beyond the noise on held-out data, in held-out χ² or in NRMSE
            // (`pair_beats_single`): Σ over readings of at least 1 − (1 − PAIR_GAIN)² of the
            // excess. A second effect whose first-order in-sample gain at the lead's fit is
            // below a quarter of that in both measures is not worth a pair fit either. The
            // bound is empirical: held-out gains are in-sample gains less what the fit
            // overfits, where the held-out excess is of the in-sample one's order (here 39
            // against 29 per reading); the quarter allows for that and the first-order
            // error. (Not so for a lead that does not close the gap: its fit can extrapolate
            // badly where a missing partner governs, and the partner's held-out gain then
            // exceeds its in-sample one.) On the 1000-row benchmark (radial friction closing
            // with held-out χ² 39 per reading) the score test let three second effects
            // through whose pair fits took 45 % of the run and none of which beat the lead:
            // preload stiffening and thermal drift gain under 1.5 % of what they need,
            // eccentricity 23 % in NRMSE terms (its pair fit collapsed onto the lead).
            let held_need = |lead: Effect| {
                best_single
                    .as_ref()
                    .filter(|b| single_closes && b.effect == lead.name())
                    .map(|b| held_out_need(b, n_read, noise_weights))
            };
            let mut lead_starts: Vec<(Effect, Motor)> = Vec::new();
            let mut skipped_notes: Vec<String> = Vec::new();
            for &lead in &leads {
                let lead_fit = fits.get(lead.name());
                let need = held_need(lead);
                let second: Vec<(Effect, (bool, String))> = names
                    .par_iter()
                    .filter(|&&e| e != lead)
                    .map(|&e| (e, worth_pair_fit(lead_fit, rows, e, needed(e), need, &sc)))
                    .collect();
                for (e, (worth, _)) in &second {
                    if *worth {
                        push(lead, *e);
                    }
                }
                let skipped: Vec<String> =
                    second.iter().filter(|x| !x.1 .0).map(|(e, (_, why))| format!("{e} ({why})")).collect();
                if !skipped.is_empty() {
                    let held = if need.is_some() {
                        ", or a third of the held-out gap it leaves beyond the noise (Σz², Σe²)"
                    } else {
                        ""
                    };
                    skipped_notes.push(format!(
                        "not fitted as a second effect to {lead} (first-order gain at its fit below a quarter of what a pair needs: ½ΔBIC > 5 (score Δχ²){held}): {}",
                        skipped.join(", ")
                    ));
                }
                lead_starts.push((lead, lead_fit.map(|c| c.motor.clone()).unwrap_or_else(|| start.clone())));
            }
            if !single_closes {
                // A pair of two candidates that lead nothing can be the verdict only by
                // beating the best single effect by ½ΔBIC > 5 (`pair_beats_single`): from a's
                // fit it must remove 2·(evidence of the best − a's) + k_b·ln n + 10 of χ²
                // (b adding k_b parameters). To first order it removes b's score gain at a's
                // fit (unweighted, as the evidence counts χ²); where that is below a quarter
                // of the need both ways round, the pair is not fitted. (Seeds 11-18 of the
                // 1000-row benchmark: `preload_stiffening + hertz_softening`, 10 % of the run,
                // ended 68 000 below `radial_friction` in evidence.) Without a best single,
                // or a fit of either effect, there is nothing to screen on.
                let evidence = |e: Effect| ranking.iter().find(|r| r.effect == e.name()).map(|r| r.evidence);
                let reaches = |a: Effect, b: Effect| -> Option<bool> {
                    let best = best_single.as_ref()?.evidence;
                    pair_may_beat(fits.get(a.name())?, evidence(a)?, best, rows, b, &sc)
                };
                let mut hopeless = Vec::new();
                for i in 0..names.len().min(3) {
                    for j in i + 1..names.len().min(3) {
                        let (a, b) = (names[i], names[j]);
                        let led = leads.contains(&a) || leads.contains(&b);
                        if led || reaches(a, b).unwrap_or(true) || reaches(b, a).unwrap_or(true) {
                            push(a, b);
                        } else {
                            hopeless.push(format!("{a}+{b}"));
                        }
                    }
                }
                if !hopeless.is_empty() {
                    skipped_notes.push(format!(
                        "not fitted as a pair (first-order gain of either effect at the other's fit below a quarter of what beating the best single effect's evidence needs): {}",
                        hopeless.join(", ")
                    ));
                }
            }
            if !skipped_notes.is_empty() {
                screened_note = Some(skipped_notes.join("; "));
            }
            // a pair led by a lead starts from that lead's own fit
            let from = |p: &[Effect; 2]| lead_starts.iter().find(|(l, _)| *l == p[0]).map(|x| &x.1).unwrap_or(&start);
            // the model a pair nests: its lead's own fit, when the pair starts there
            let nested: Vec<Nested> = pairs
                .iter()
                .map(|p| {
                    let lead = p[0].name();
                    let led = lead_starts.iter().any(|(l, _)| *l == p[0]);
                    fits.get(lead)
                        .filter(|_| led)
                        .zip(cv_preds.get(lead))
                        .map(|(c, preds)| (c.chi2, preds.clone(), c.params.clone()))
                })
                .collect();
            let scored: Vec<Scored> = pairs.par_iter().zip(&nested).map(|(p, n)| score(p, from(p), n)).collect();
            let mut pr: Vec<RankEntry> = collect(&mut cv_preds, &mut fits, scored);
            sort_ranking(&mut pr);
            best_pair = pr.first().cloned();
            ranking.extend(pr);
            sort_ranking(&mut ranking);
        }
        // A pair is two effects only when it beats the best single effect clearly, in
        // evidence (½ΔBIC > 5 over the single) and on held-out data: no worse in either
        // held-out measure, at least a third of what the single leaves beyond noise gone
        // in one of them, and that gain above zero at the bootstrap 5 % bound. (Parsimony:
        // a second effect that only polishes the first one's form error is not an effect.)
        let pair_beats_single = |bp: &RankEntry| -> bool {
            if !supported(bp) {
                return false;
            }
            let Some(single) = best_single.as_ref() else { return closes(bp) };
            if bp.evidence <= single.evidence + 5.0
                || bp.heldout_nrmse_after > single.heldout_nrmse_after
                || bp.heldout_chi2_after > single.heldout_chi2_after
            {
                return false;
            }
            let (gain_nrmse, gain_chi2) = pair_gains(single, bp, n_read, noise_weights);
            let held = |name: &str| cv_preds.iter().find(|(n, _)| same_set(n, name)).map(|(_, p)| errors(rows, p, &sc));
            let (Some(hs), Some(hp)) = (held(&single.effect), held(&bp.effect)) else { return false };
            let real =
                |before: &[f64], after: &[f64]| bootstrap_shrink(before, after, opts.bootstrap, opts.seed).0 > 0.0;
            (gain_nrmse >= PAIR_GAIN && real(&hs.2, &hp.2)) || (gain_chi2 >= PAIR_GAIN && real(&hs.3, &hp.3))
        };
        match best_pair.filter(|bp| pair_beats_single(bp) && closes(bp)) {
            Some(bp) => {
                // name the stronger single effect first
                let ev =
                    |n: &str| ranking.iter().find(|r| r.effect == n).map(|r| r.evidence).unwrap_or(f64::NEG_INFINITY);
                let mut ns: Vec<&str> = bp.effect.split('+').collect();
                ns.sort_by(|a, b| ev(b).total_cmp(&ev(a)));
                let joined = ns.join("+");
                for r in ranking.iter_mut() {
                    if r.effect == bp.effect {
                        r.effect = joined.clone();
                    }
                }
                verdict = joined;
            }
            None if single_closes => verdict = best_single.as_ref().map(|b| b.effect.clone()).unwrap_or_default(),
            // The best supported single that closes a material part of the gap is the
            // verdict even when a gap remains (`complete: false`): the data's form of the
            // effect may lie outside every form its candidate family can take.
            None => match best_single.as_ref().filter(|b| material(b)) {
                Some(b) => {
                    verdict = b.effect.clone();
                    complete = false;
                    notes.push(format!(
                        "{} closes {} % of the held-out gap ({} % of its part beyond the noise) but not all of it: \
                         the data's form of the effect may differ from every form its candidate takes, or \
                         something else remains",
                        b.effect,
                        rounded(100.0 * b.shrink),
                        rounded(100.0 * excess_shrink(b))
                    ));
                }
                None => verdict = "unexplained".into(),
            },
        }
        if verdict == "unexplained" {
            complete = false;
            partial = best_single.as_ref().map(|b| b.effect.clone());
            if let Some(b) = best_single.as_ref() {
                notes.push(format!(
                    "{} is supported (evidence {:.1}) but closes only {} % of the held-out gap; something else remains",
                    b.effect,
                    b.evidence,
                    rounded(100.0 * b.shrink)
                ));
            }
        } else if !verdict.contains('+') {
            // Confounded: another supported single effect that explains the data about as
            // well (held-out error within 15 %, evidence within 5), or one that also closes
            // the gap while the data see its signature and the verdict's as one shape
            // (|cos| ≥ 0.95 at the calibrated baseline): then the held-out ranking between
            // them rests on the candidates' form, not on what the data can separate.
            let vsig = Effect::from_name(&verdict).ok().and_then(|e| base_sigs.get(&e));
            for r in ranking.iter_mut() {
                if let (Some(v), Some(e)) = (vsig, Effect::from_name(&r.effect).ok()) {
                    r.signature_overlap = base_sigs.get(&e).map(|s| signature::overlap(v, s));
                }
            }
            if let Some(best) = ranking.iter().find(|r| r.effect == verdict).cloned() {
                for r in &ranking {
                    let alike =
                        r.heldout_nrmse_after <= 1.15 * best.heldout_nrmse_after && best.evidence - r.evidence < 5.0;
                    // (for an incomplete verdict: any supported candidate the evidence does
                    // not separate from it)
                    let close_call = !complete && best.evidence - r.evidence < 5.0;
                    let one_shape = r.signature_overlap.is_some_and(|o| o >= 0.95) && (closes(r) || !complete);
                    if r.effect != best.effect
                        && !r.effect.contains('+')
                        && supported(r)
                        && (alike || one_shape || close_call)
                    {
                        confounded.push(r.effect.clone());
                    }
                }
            }
        }
    } else {
        notes.push(format!(
            "the calibrated baseline predicts the held-out regions at the noise level (mean squared normalised residual {base_z2:.2}) and no candidate effect is supported; no effect is needed"
        ));
    }
    notes.extend(screened_note);
    notes.extend(start_notes.into_inner().unwrap_or_default());
    // held-out figures that rest partly on in-sample predictions
    let stuck: Vec<String> = std::iter::once(("the calibrated baseline".to_string(), base_cv.in_sample))
        .chain(ranking.iter().map(|r| (r.effect.clone(), r.heldout_in_sample_folds)))
        .filter(|(_, n)| *n > 0)
        .map(|(name, n)| format!("{name} in {n} of {k}"))
        .collect();
    if !stuck.is_empty() {
        notes.push(format!(
            "held-out blocks predicted in-sample, so these held-out figures are optimistic: {} folds (the fold's fit could not be moved off the full-data fit: even a quarter of the first-order step raised the training χ², as where a row changes between moving and clamped)",
            stuck.join(", ")
        ));
    }
    if reduced && verdict != "none" {
        notes.push(format!("with so few readings the verdict '{verdict}' is tentative; measure more operating points"));
    }

    // Where the gap lies: the calibrated baseline's residuals by quantity and region. A fit
    // that passes through every point (few readings, as many parameters) leaves no
    // residual there, while it misses the same points held out; then the held-out
    // residuals tell where.
    let in_sample = predict(&base_cal.motor, &rows.iter().collect::<Vec<_>>());
    let (_, in_z2, _, _) = errors(rows, &in_sample, &sc);
    let through_every_point = in_z2 < 2.0 && base_z2 > 4.0 * in_z2.max(0.5);
    let gap_where = locate_gap(rows, if through_every_point { &base_cv.preds } else { &in_sample });
    if through_every_point && !gap_where.is_empty() {
        notes.push(format!(
            "the calibrated baseline passes through the points (mean squared normalised residual {in_z2:.2}) but \
             misses them held out ({base_z2:.1}): `where` is located on the held-out residuals"
        ));
    }
    // held-out predictions with the verdict's effects (pairs were scored under the
    // unsorted name, so look up by the set of names)
    let after_preds = cv_preds
        .iter()
        .find(|(name, _)| same_set(name, &verdict))
        .map(|(_, p)| p.clone())
        .unwrap_or_else(|| base_cv.preds.clone());
    let mut heldout = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        for (j, &(o, v, _)) in r.readings.iter().enumerate() {
            heldout.push(HeldOut {
                row: i,
                observable: o,
                measured: v,
                baseline: base_cv.preds[i][j],
                after: after_preds[i][j],
            });
        }
    }
    // (no verdict from figures that overflowed: json::guard_non_finite)
    Ok(json::guard_non_finite(Diagnosis {
        verdict,
        complete,
        confounded_with: confounded,
        partial,
        baseline_heldout_nrmse: base_nrmse,
        noise_nrmse: noise_best,
        noise_nrmse_weights: noise_weights,
        baseline_heldout_chi2_per_reading: base_z2,
        noise_scale,
        gap_where,
        ranking,
        notes,
        n_rows: rows.len(),
        n_readings: n_read,
        folds: k,
        baseline_params: base_cal.params.iter().map(|p| (p.name.clone(), p.value)).collect(),
        heldout,
    }))
}

/// Two effect lists (`a+b`) name the same set.
pub fn same_set(a: &str, b: &str) -> bool {
    let mut x: Vec<&str> = a.split('+').collect();
    let mut y: Vec<&str> = b.split('+').collect();
    x.sort_unstable();
    y.sort_unstable();
    x == y
}

/// Part of what the best single effect leaves beyond noise on held-out data (in NRMSE or
/// in σ) that a pair must remove to count as two effects.
const PAIR_GAIN: f64 = 1.0 / 3.0;

fn sort_ranking(r: &mut [RankEntry]) {
    r.sort_by(|a, b| b.evidence.total_cmp(&a.evidence).then(a.heldout_nrmse_after.total_cmp(&b.heldout_nrmse_after)));
}

/// Percentile bootstrap (5 %, 95 %) of 1 − sqrt(mean e2_after)/sqrt(mean e2_before) over
/// readings resampled in pairs.
fn bootstrap_shrink(before: &[f64], after: &[f64], n: usize, seed: u64) -> (f64, f64) {
    use rand::{RngExt, SeedableRng};
    let m = before.len().min(after.len());
    if m == 0 || n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut v: Vec<f64> = (0..n)
        .map(|_| {
            let (mut b, mut a) = (0.0f64, 0.0f64);
            for _ in 0..m {
                let i = rng.random_range(0..m);
                b += before[i];
                a += after[i];
            }
            1.0 - (a / b.max(1e-300)).sqrt()
        })
        .collect();
    v.sort_by(f64::total_cmp);
    (v[(0.05 * (n - 1) as f64) as usize], v[(0.95 * (n - 1) as f64) as usize])
}

fn locate_gap(rows: &[ObservedRow], preds: &[Vec<f64>]) -> Vec<GapRegion> {
    // (coordinate name, accessor)
    type Coord = (&'static str, fn(&ObservedRow) -> f64);
    let coords: [Coord; 5] = [
        ("preload_n", |r| r.op.preload_n),
        ("torque_nm", |r| r.op.torque_nm),
        ("voltage_v", |r| r.op.voltage_v),
        ("frequency_hz", |r| r.op.frequency_hz),
        ("elapsed_s", |r| r.op.elapsed_s),
    ];
    let mut out = Vec::new();
    for o in Observable::ALL {
        let idx: Vec<(usize, usize)> = rows
            .iter()
            .enumerate()
            .flat_map(|(i, r)| r.readings.iter().enumerate().filter(|(_, x)| x.0 == o).map(move |(j, _)| (i, j)))
            .collect();
        if idx.len() < 3 {
            continue;
        }
        for (name, get) in coords {
            let mut vals: Vec<f64> = idx.iter().map(|&(i, _)| get(&rows[i])).collect();
            vals.sort_by(f64::total_cmp);
            vals.dedup();
            if vals.len() < 2 {
                continue;
            }
            // Terciles of the distinct values; with few readings (a handful of published
            // points), each distinct value is its own region.
            type Bin = (String, Box<dyn Fn(f64) -> bool>);
            let few = idx.len() < 9;
            let bins: Vec<Bin> = if few {
                vals.iter()
                    .map(|&v| -> Bin { (format!("{name} = {}", fmt_num(v)), Box::new(move |x| x == v)) })
                    .collect()
            } else {
                let cut1 = vals[vals.len() / 3];
                let cut2 = vals[(2 * vals.len()) / 3];
                vec![
                    (format!("{name} < {}", fmt_num(cut1)), Box::new(move |x| x < cut1)),
                    (
                        format!("{} <= {name} < {}", fmt_num(cut1), fmt_num(cut2)),
                        Box::new(move |x| x >= cut1 && x < cut2),
                    ),
                    (format!("{name} >= {}", fmt_num(cut2)), Box::new(move |x| x >= cut2)),
                ]
            };
            for (label, inside) in bins.iter() {
                let sel: Vec<&(usize, usize)> = idx.iter().filter(|&&(i, _)| inside(get(&rows[i]))).collect();
                if sel.is_empty() || (sel.len() < 3 && !few) {
                    continue;
                }
                let n = sel.len() as f64;
                let (mut mean_raw, mut mean_z) = (0.0, 0.0);
                for &&(i, j) in &sel {
                    let (_, v, s) = rows[i].readings[j];
                    let y = preds[i][j];
                    let d = v - if y.is_finite() { y } else { 0.0 };
                    mean_raw += d;
                    mean_z += d / s;
                }
                mean_raw /= n;
                mean_z /= n;
                let z = mean_z * n.sqrt();
                if z.abs() > 3.5 {
                    out.push(GapRegion {
                        quantity: o.column().into(),
                        region: label.clone(),
                        mean_residual: mean_raw,
                        n: sel.len(),
                        z,
                    });
                }
            }
        }
    }
    out.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    out.truncate(10);
    out
}

fn fmt_num(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// True for rows where the model must run (used by callers to pre-check data).
pub fn status_ok(s: Status) -> bool {
    s.is_valid()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::tests::classic_tolerances;
    use crate::synth::{synthesize, Campaign, SynthConfig};

    fn data(m: &Motor, noise: f64, seed: u64) -> (Vec<ObservedRow>, Vec<String>) {
        let cfg = SynthConfig { campaign: Campaign::PreloadTorque, noise, seed, ..SynthConfig::default() };
        let rows = synthesize(m, &cfg).expect("synth");
        (rows.iter().map(|r| r.observed()).collect(), rows.iter().map(|r| r.run_id.clone()).collect())
    }

    fn quick(exact_cv: bool) -> DiagnoseOptions {
        DiagnoseOptions {
            candidates: vec![Effect::VoltageSag, Effect::PreloadStiffening],
            try_pairs: false,
            bootstrap: 50,
            exact_cv,
            ..DiagnoseOptions::default()
        }
    }

    /// The nominal trum60a and seeded preload-torque data of it with voltage sag (300 Ω).
    fn sag_data() -> (Motor, Vec<ObservedRow>, Vec<String>) {
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
        let (s0, params) = fit_params(&nominal, &nominal, &rows, &[], false, &BTreeMap::new());
        let cal = calibrate(&s0, &rows, &params, &fit).expect("baseline");
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
        // 64 times too long: even a quarter of it overshoots, the folds keep the full-data
        // fit and say so
        short.lin.jacobian *= 1.0 / 16.0;
        let stuck = approx_cv(&short, &rows, &folds, 4, &fit);
        assert_eq!(stuck.in_sample, 4);
        assert!(gap(&stuck.preds, &in_sample) < 1e-9, "{}", gap(&stuck.preds, &in_sample));
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
                let synth = synthesize(&m, &cfg).expect("synth");
                let rows: Vec<ObservedRow> = synth.iter().map(|r| r.observed()).collect();
                let groups: Vec<String> = synth.iter().map(|r| r.run_id.clone()).collect();
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
        let base = calibrate(&s0, &rows, &params, &fit).expect("baseline");
        let sig = signature::signature(&base, &rows, Effect::RadialFriction).expect("signature");
        let sc = scales(&rows);
        let (d_chi2, d_e2) = first_order_gains(&base, &rows, &sig, &sc);
        let (s1, params) =
            fit_params(&nominal, &base.motor, &rows, &[Effect::RadialFriction], false, &classic_tolerances());
        let with = calibrate_adding(&s1, &rows, &params, &fit, &[Effect::RadialFriction]).expect("refit");
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
        let penalty = 0.5 * Effect::ThermalDrift.info().params.len() as f64 * (d.n_readings as f64).ln();
        assert!(thermal.params.is_empty() && thermal.shrink == 0.0, "{thermal:?}");
        assert!((thermal.evidence + penalty).abs() < 1e-9 * penalty, "{} vs −{penalty}", thermal.evidence);
        assert!(thermal.signature_match.is_none());
        let sag = entry("voltage_sag");
        assert!(!sag.params.is_empty() && sag.evidence > 5.0 && sag.signature_match.is_some(), "{sag:?}");
        assert!(d.notes.iter().any(|n| n.contains("thermal_drift cannot act")));
        // the same when the nominal motor already carries it (no probe then: switched off)
        let mut carrying = nominal.clone();
        let typical: Vec<f64> = Effect::ThermalDrift.info().params.iter().map(|p| p.typical).collect();
        carrying.effects.set(Effect::ThermalDrift, &typical);
        let d = diagnose(&carrying, &rows, &groups, &opts).expect("diagnosis");
        let thermal = d.ranking.iter().find(|r| r.effect == "thermal_drift").expect("ranked");
        assert!(thermal.params.is_empty() && thermal.shrink == 0.0, "{thermal:?}");
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
        let synth = synthesize(&truth, &cfg).expect("synth");
        let rows: Vec<ObservedRow> = synth.iter().map(|r| r.observed()).collect();
        let groups: Vec<String> = synth.iter().map(|r| r.run_id.clone()).collect();
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

    /// On a `combined` campaign the weights' noise levels put the whole held-out NRMSE of
    /// the baseline inside the noise, where noise alone gives a small fraction of it. The
    /// test "half of the NRMSE beyond the noise is gone" measured against the weights'
    /// level would then hold for every supported effect, and a `radial_friction` closing a
    /// fifth of a preload-stiffening gap would pass for the whole answer. Against the best
    /// noise estimate it closes only part: named, as the best partial explanation among the
    /// candidates (the truth is left out of them), with `complete: false`.
    #[test]
    fn a_gap_inside_the_weights_noise_is_not_closed_by_every_effect() {
        let d =
            diagnosed_single(Effect::PreloadStiffening, 0.05, Campaign::Combined, 0.5, 136, &[Effect::RadialFriction]);
        // the premise: the weights' noise is above the baseline's gap, the best estimate far below
        assert!(
            d.noise_nrmse_weights > d.baseline_heldout_nrmse,
            "{} vs {}",
            d.noise_nrmse_weights,
            d.baseline_heldout_nrmse
        );
        assert!(d.noise_nrmse < 0.5 * d.baseline_heldout_nrmse, "{} vs {}", d.noise_nrmse, d.baseline_heldout_nrmse);
        let rf = d.ranking.iter().find(|r| r.effect == "radial_friction").expect("ranked");
        assert!(rf.evidence > 5.0 && rf.shrink_interval.0 > 0.0, "radial friction no longer supported: {rf:?}");
        assert!(rf.shrink < 0.5 && rf.heldout_chi2_after > 2.0, "{rf:?}");
        assert_eq!(d.verdict, "radial_friction");
        assert!(!d.complete, "a remaining gap is reported");
        assert!(
            d.notes.iter().any(|n| n.starts_with("radial_friction closes") && n.contains("not all")),
            "{:?}",
            d.notes
        );
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
        assert!((rho / 3.0 - 1.0).abs() < 0.05 && rf.shrink > 0.9, "{rf:?}");
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
            assert!(best.shrink < 0.2 && best.heldout_chi2_after > 3.0, "{truth_effect:?}: {best:?}");
            assert_eq!(d.verdict, "unexplained", "{truth_effect:?}: {:?}", d.ranking);
        }
    }

    /// One motor measured at four drive voltages (preload-torque runs, radial friction in its
    /// truth form): calibrated from the nominal motor, the baseline presses the modal damping
    /// onto its upper bound, where the logistic transform holds it (a radial-friction fit
    /// started there stays in that valley, held-out χ² 108 per reading, without the second
    /// start from the nominal motor). Refitted from its own end, the baseline leaves
    /// the bound at a fraction of the χ²; `calibrate_refitting_bounds` and so the diagnosis
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
        let first = calibrate(&s0, &scaled, &bp, &opts.fit).expect("baseline");
        assert!(on_damping_bound(&first), "the baseline no longer ends on the damping bound: the test needs new data");
        let again = calibrate(&first.motor, &scaled, &bp, &opts.fit).expect("refit");
        assert!(!on_damping_bound(&again));
        // (χ² 1.74e5 → 6.3e4 when written)
        assert!(again.chi2 < 0.5 * first.chi2, "χ² {} → {}", first.chi2, again.chi2);
        // what `trum calibrate` and the diagnosis call does both
        let refitted = calibrate_refitting_bounds(&s0, &scaled, &bp, &opts.fit).expect("refitting");
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
    fn ranked(effect: &str, chi2: f64, nrmse: f64) -> RankEntry {
        RankEntry {
            effect: effect.into(),
            evidence: 100.0,
            heldout_nrmse_after: nrmse,
            heldout_chi2_after: chi2,
            shrink: 0.5,
            shrink_interval: (0.4, 0.6),
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
            assert!(
                names.iter().any(|n| n.starts_with(&format!("effects.{}.", e.name()))),
                "{e:?} not fitted: {names:?}"
            );
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
        let without = calibrate_adding(&start, &rows, &params, &opts, &[tc]).expect("fit");
        // (not abandoned when written: 0.3 % of the range, on its bound by the 0.5 % rule)
        assert!(without.abandoned || added_near_zero(&params, &without.params, &[tc]), "{:?}", without.params);
        let mut truth = nominal.clone();
        truth.effects.set(tc, &[tc.info().params[0].typical]);
        let with = calibrate_adding(&start, &grid(&truth), &params, &opts, &[tc]).expect("fit");
        assert!(!with.abandoned && !added_near_zero(&params, &with.params, &[tc]), "{:?}", with.params);
    }
}
