//! The calibrated baseline: the full-data fit of the nominal motor's uncertain
//! parameters, its held-out predictions, errors and evidence, and the held-out NRMSE
//! that noise alone would give.

use super::candidates::fit_params;
use super::context::{applied_factor, Context};
use super::folds::{approx_cv, cross_validate, errors, predict, CvResult};
use crate::calibrate::Calibration;
use crate::error::TrumError;
use crate::observable::{Observable, ObservedRow};
use crate::params::Motor;
use std::collections::BTreeMap;

/// The calibrated baseline and its held-out figures.
pub(super) struct Baseline {
    /// The full-data fit (the start of every other fit; "where", BIC, reported parameters).
    pub(super) cal: Calibration,
    /// Its motor, the start of every candidate's fit.
    pub(super) start: Motor,
    /// Held-out predictions, each block by the baseline refitted without it.
    pub(super) cv: CvResult,
    /// Held-out NRMSE.
    pub(super) nrmse: f64,
    /// Held-out mean squared normalised residual (each reading's clipped at `OUTLIER_Z2`).
    pub(super) z2: f64,
    /// Per held-out reading: squared residual over the quantity's scale.
    pub(super) e2: Vec<f64>,
    /// Per held-out reading: squared normalised residual, clipped at `OUTLIER_Z2`.
    pub(super) z2s: Vec<f64>,
    /// The held-out mean z² with each quantity's noise level at the upper end of its
    /// estimate's 90 % interval ([`z2_at_upper_noise`]).
    pub(super) z2_upper_noise: f64,
    /// Held-out NRMSE that noise alone gives, with the best noise levels
    /// ([`noise_nrmse_best`]; the reported `noise_nrmse`).
    pub(super) noise_best: f64,
    /// BIC of the full-data fit.
    pub(super) bic: f64,
}

/// The Bayesian information criterion of a fit with χ² `chi2` and `kpar` parameters on
/// `n_read` readings: χ² + k·ln n.
pub(super) fn bic(chi2: f64, kpar: usize, n_read: usize) -> f64 {
    chi2 + kpar as f64 * (n_read as f64).ln()
}

/// Calibrates the baseline on all rows of `ctx` and predicts each fold's block held out.
pub(super) fn fit(ctx: &Context) -> Result<Baseline, TrumError> {
    let base_cal = calibrate(ctx, ctx.motor)?;
    with_held_out(ctx, base_cal)
}

/// The baseline calibrated on all rows of `ctx` from the baseline parameters of `from` (the
/// nominal motor, or a better start found by the candidates' fits, `better_start`).
pub(super) fn calibrate(ctx: &Context, from: &Motor) -> Result<Calibration, TrumError> {
    let (motor, rows, opts, reduced) = (ctx.motor, &ctx.rows[..], &ctx.opts, ctx.reduced);
    let (start0, bparams) = fit_params(motor, from, rows, &[], reduced, &opts.tolerances);
    // A baseline that ends with a parameter on a bound is refitted from its own end
    // (`Calibrate::refit_bounds`). (1000-row benchmark, seeds 31-38: every single fit,
    // started from the baseline left on the damping bound, first refitted the baseline
    // whatever its effect.)
    Calibration::builder(&start0, rows).params(&bparams).options(&opts.fit).refit_bounds(true).search_starts(true).run()
}

/// A start for the baseline that the candidates' fits found: the fit of the candidate with
/// the most evidence, its effect taken out, when its data χ² is below the calibrated
/// baseline's by more than 2 — the baseline is the model of every candidate at zero
/// strength, so a lower χ² there means the baseline's own fit stopped in a valley of its
/// parameters and every candidate's evidence measures that valley, not its effect (seen
/// where half the readings are of a stalled rotor: every candidate gained ½ΔBIC ≈ 100
/// with no held-out shrink). `None` when there is none.
pub(super) fn better_start(ctx: &Context, base: &Baseline, fits: &BTreeMap<String, Calibration>) -> Option<Motor> {
    let chi2 = |m: &Motor| crate::calibrate::residuals(m, &ctx.rows).iter().map(|z| z * z).sum::<f64>();
    let base_chi2 = chi2(&base.cal.motor);
    fits.iter()
        .filter_map(|(name, c)| {
            let e = crate::effects::Effect::from_name(name).ok()?;
            let mut m = c.motor.clone();
            m.effects.clear(e);
            let x = chi2(&m);
            (x.is_finite() && x < base_chi2 - 2.0).then_some((x, m))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, m)| m)
}

/// The baseline `base_cal` with its held-out predictions, errors, evidence and noise level.
pub(super) fn with_held_out(ctx: &Context, base_cal: Calibration) -> Result<Baseline, TrumError> {
    let (motor, rows, opts, reduced, sc) = (ctx.motor, &ctx.rows[..], &ctx.opts, ctx.reduced, &ctx.sc);
    let (folds, k, est) = (&ctx.folds[..], ctx.k, &ctx.est);
    let n_params = fit_params(motor, motor, rows, &[], reduced, &opts.tolerances).1.len();
    let start = base_cal.motor.clone();
    let base_cv = if opts.exact_cv {
        cross_validate(motor, &start, rows, folds, k, &[], opts, reduced)
    } else {
        approx_cv(&base_cal, rows, folds, k, &opts.fit)
    };
    let (base_nrmse, base_z2, base_e2, base_z2s) = errors(rows, &base_cv.preds, sc);
    // The noise NRMSE reported (the document's `noise_nrmse`) is the best estimate of what noise
    // alone gives; the tests beyond the noise below keep the weights' levels, upper bounds
    // consistent with the χ² the fits minimise (with the best levels in those tests the
    // blind benchmark lost 3 of its 45 correct verdicts: docs/DIAGNOSIS.md).
    let noise_best = {
        // the model's own values, not expected clipped readings
        let plain: Vec<ObservedRow> =
            rows.iter().map(|r| ObservedRow { speed_std_clipped: false, ..r.clone() }).collect();
        let refs: Vec<&ObservedRow> = plain.iter().collect();
        let best = match &ctx.best_noise {
            Some(b) => b.clone(),
            None => noise_estimate(motor, &ctx.unscaled, &ctx.groups, est),
        };
        noise_nrmse_best(rows, est, &best, &predict(&base_cal.motor, &refs), sc)
    };
    Ok(Baseline {
        bic: bic(base_cal.chi2, n_params, ctx.n_read),
        start,
        cv: base_cv,
        nrmse: base_nrmse,
        z2: base_z2,
        e2: base_e2,
        z2_upper_noise: z2_at_upper_noise(rows, &clipped(&base_z2s), est),
        z2s: clipped(&base_z2s),
        noise_best,
        cal: base_cal,
    })
}

/// Standard deviation of ln(factor) of a noise factor estimated from n line residuals,
/// × √n: the estimate is the square root of their median squared residual over 0.4549
/// (`noise::estimate`), and the sample median m of n χ²₁ values has a variance of
/// 1/(4n·f(m)²), f the χ²₁ density (0.4711 at m = 0.4549), so ln(factor) has
/// ½·√(1/(4·0.4711²))/0.4549 = 1.167 over √n.
const LN_FACTOR_SD_ROOT_N: f64 = 1.167;

/// The one-sided 90 % point of the standard normal.
const Z90: f64 = 1.2816;

/// The held-out mean of the per-reading squared normalised residuals `z2s` (in the order of
/// `rows`' readings) with each quantity's noise level at the upper end of its estimate's
/// 90 % interval: σ × e^(1.28·1.167/√n) for a factor estimated from n residuals (a quantity
/// without an estimate keeps its stated level). A noise level estimated from some forty
/// residuals is uncertain by about a fifth; where it comes out low by chance, every
/// held-out z² comes out high with it (a null preload-torque campaign with speed readings
/// only gave 2.29 on a factor of 0.62 where the same bench's full campaign gave 0.83).
pub(super) fn z2_at_upper_noise(
    rows: &[ObservedRow],
    z2s: &[f64],
    est: &BTreeMap<Observable, crate::noise::NoiseScale>,
) -> f64 {
    let quantities = rows.iter().flat_map(|r| r.readings.iter().map(|x| x.0));
    let (mut sum, mut n) = (0.0, 0usize);
    for (o, z2) in quantities.zip(z2s) {
        let widen = est
            .get(&o)
            .filter(|e| e.residuals > 0)
            .map_or(1.0, |e| (Z90 * LN_FACTOR_SD_ROOT_N / (e.residuals as f64).sqrt()).exp());
        sum += z2 / (widen * widen);
        n += 1;
    }
    sum / n.max(1) as f64
}

/// Each reading's squared normalised residual clipped at [`super::folds::OUTLIER_Z2`], as the
/// held-out mean z² counts it.
pub(super) fn clipped(z2: &[f64]) -> Vec<f64> {
    z2.iter().map(|x| x.min(super::folds::OUTLIER_Z2)).collect()
}

/// Noise factors per quantity (`noise::estimate`), each the smaller of two estimates:
/// from the readings themselves (`raw`, as estimated), and from their residuals from the nominal motor's
/// predictions. Both are biased upwards only by what the lines through neighbouring
/// readings cannot follow; the model follows most of the curvature (stall knee, efficiency
/// peak, resonance) that dominates that bias on coarse grids, the raw readings follow what
/// the nominal model gets wrong in shape (a temperature time series).
pub(super) fn noise_estimate(
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
pub(super) fn clipped_second_moment(x: f64, centred: bool) -> f64 {
    let (cdf, upper, pdf) = (crate::normal::normal_cdf(x), crate::normal::normal_cdf(-x), crate::normal::normal_pdf(x));
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
pub(super) fn noise_nrmse_best(
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

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::super::tests::{data, quick, sag_data};
    use super::*;

    /// Data of the nominal motor itself: the calibrated baseline predicts held-out regions
    /// at the noise level, its NRMSE near what noise alone gives. Data with a voltage sag
    /// the baseline cannot follow: a held-out gap well beyond the noise. The BIC is
    /// χ² + k·ln n of the full-data fit.
    #[test]
    fn the_baseline_misses_held_out_data_only_where_an_effect_is_missing() {
        let nominal = crate::calibrate::tests::reference_motor();
        let (rows, groups) = data(&nominal, 1.0, 5);
        let ctx = Context::new(&nominal, &rows, &groups, &quick(false)).unwrap();
        let base = fit(&ctx).unwrap();
        assert!(base.z2 < 2.0, "held-out χ² per reading {}", base.z2);
        assert!(base.nrmse < 1.5 * base.noise_best, "NRMSE {} against noise {}", base.nrmse, base.noise_best);
        assert!(base.cv.preds.iter().flatten().all(|p| p.is_finite()));
        assert_eq!(base.e2.len(), ctx.n_read);
        let k = base.cal.params.len();
        assert!((base.bic - (base.cal.chi2 + k as f64 * (ctx.n_read as f64).ln())).abs() < 1e-9 * base.bic);
        assert_eq!(base.start, base.cal.motor);

        let (nominal, rows, groups) = sag_data();
        let ctx = Context::new(&nominal, &rows, &groups, &quick(false)).unwrap();
        let sag = fit(&ctx).unwrap();
        // (well beyond the noise's 2, though the current reading's gain, a bench nuisance,
        // takes a part of the sag's current)
        assert!(sag.z2 > 3.0, "held-out χ² per reading {}", sag.z2);
        assert!(sag.nrmse > 2.0 * sag.noise_best, "NRMSE {} against noise {}", sag.nrmse, sag.noise_best);
    }

    /// Each quantity's z² is divided by the square of its noise level's widening to the
    /// upper end of the estimate's 90 % interval, e^(1.2816·1.167/√n): 1.587 for n = 42
    /// residuals, 1.32 for 116; a quantity without an estimate keeps its z²; a factor from
    /// more residuals widens less.
    #[test]
    fn the_upper_noise_z2_widens_each_quantity_by_its_estimates_uncertainty() {
        use crate::noise::NoiseScale;
        let op = crate::solve::OperatingPoint::new(200.0, 0.1, 200.0, 43_000.0);
        let row = ObservedRow {
            op,
            readings: vec![(Observable::SpeedRpm, 100.0, 1.0), (Observable::FeedbackV, 40.0, 0.5)],
            ambient_c: 20.0,
            speed_std_clipped: false,
        };
        let rows = vec![row.clone(), row];
        let z2s = [4.0, 2.0, 4.0, 2.0];
        let est = BTreeMap::from([(Observable::SpeedRpm, NoiseScale { factor: 0.62, residuals: 42 })]);
        let widen2 = (2.0 * Z90 * LN_FACTOR_SD_ROOT_N / 42f64.sqrt()).exp();
        assert!((widen2 - 1.587).abs() < 1e-3, "{widen2}");
        let got = z2_at_upper_noise(&rows, &z2s, &est);
        assert!((got - (4.0 / widen2 + 2.0) / 2.0).abs() < 1e-12, "{got}");
        let more = BTreeMap::from([(Observable::SpeedRpm, NoiseScale { factor: 0.62, residuals: 116 })]);
        let wider = z2_at_upper_noise(&rows, &z2s, &more);
        assert!(wider > got && wider < 3.0, "{wider} vs {got}");
        assert_eq!(z2_at_upper_noise(&rows, &z2s, &BTreeMap::new()), 3.0);
    }
}
