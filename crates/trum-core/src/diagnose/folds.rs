//! Folds and cross-validation: rows grouped into operating regions, regions dealt
//! round-robin into K folds (block cross-validation, never random rows, so a held-out
//! block is an operating region the fit never saw), and each fold's block predicted by a
//! model refitted without it (approximately from the full-data optimum, or exactly).

use super::candidates::fit_params;
use super::{DiagnoseOptions, RankEntry};
use crate::calibrate::{prior_residuals, residuals, with_prior_rows, Calibration, FitOptions};
use crate::effects::Effect;
use crate::error::TrumError;
use crate::lsq::LeastSquares;
use crate::observable::{Observable, ObservedRow};
use crate::params::Motor;
use crate::solve::{solve_prepared, Prepared};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Region key of a row: run, preload level (25 N bins), frequency band (500 Hz), time
/// window (120 s).
fn region_key(r: &ObservedRow, group: &str) -> String {
    let t = if r.op.elapsed_s > 0.0 { (r.op.elapsed_s / 120.0).floor() as i64 } else { -1 };
    format!("{group}|{}|{}|{}", (r.op.preload_n / 25.0).round() as i64, (r.op.frequency_hz / 500.0).round() as i64, t)
}

/// The fold of each row and the number of folds: the rows' operating regions
/// ([`region_key`], with `groups[i]` the run of row i) in sorted order, dealt round-robin
/// into `folds` folds (clamped to between 2 and the number of regions). Errors when all
/// rows lie in one region.
pub(super) fn assign(rows: &[ObservedRow], groups: &[String], folds: usize) -> Result<(Vec<usize>, usize), TrumError> {
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
    let k = folds.clamp(2, uniq.len());
    let fold_of: BTreeMap<&String, usize> = uniq.iter().enumerate().map(|(i, key)| (*key, i % k)).collect();
    let of_row: Vec<usize> = keys.iter().map(|key| fold_of[key]).collect();
    Ok((of_row, k))
}

/// Predictions of `motor` for `rows` (NaN where the model has no solution).
pub(super) fn predict(motor: &Motor, rows: &[&ObservedRow]) -> Vec<Vec<f64>> {
    let p = Prepared::new(motor).without_stall_torque();
    // in parallel: the baseline's held-out predictions are made while nothing else runs
    rows.par_iter()
        .map(|r| {
            let s = solve_prepared(&p, motor, &motor.effects.instrument().operating_point(&r.op), None);
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

pub(super) struct CvResult {
    /// held-out predictions aligned with rows/readings
    pub(super) preds: Vec<Vec<f64>>,
    /// folds whose fit could not be moved off the full-data fit (approximate CV: even the
    /// damped first step raised the training χ², and a refit on the training rows did not
    /// lower it), so their held-out blocks were predicted in-sample
    pub(super) in_sample: usize,
}

/// Approximate leave-block-out refits. From the full-data optimum û (where the gradient
/// of the full χ² vanishes), simplified Gauss–Newton steps on the training readings with
/// the full-data Jacobian, u ← u − J_T⁺ r_T(u) = u − (J_Tᵀ J_T)⁺ J_Tᵀ r_T(u), remove the
/// held-out block's influence on the parameters — to first order after one step (exact for
/// a model linear in u; the approximate leave-out estimators of Beirami et al. 2017 and
/// Rad & Maleki 2020 rest on the same step), closer after the second, which uses the training
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
pub(super) fn approx_cv(
    cal: &Calibration,
    rows: &[ObservedRow],
    folds: &[usize],
    k: usize,
    fit: &FitOptions,
) -> CvResult {
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
        // (one SVD of J_T for both steps, singular values at or below 1e-5 of the largest
        // dropped: the eigenvalues of J_TᵀJ_T below 1e-10 of its largest; a non-finite
        // Jacobian takes no step)
        let lsq = LeastSquares::new(&jt, 1e-5);
        let weighted = |u: &DVector<f64>| -> DVector<f64> {
            let r = residuals(&lin.motor_at(u), &train_rows);
            let prior = prior_residuals(&lin.params, u);
            DVector::from_iterator(r.len() + prior.len(), r.iter().zip(&w).map(|(x, w)| x * w).chain(prior))
        };
        let prior0 = prior_residuals(&lin.params, &lin.u);
        let mut r =
            DVector::from_iterator(idx.len() + prior0.len(), idx.iter().map(|&j| lin.residuals[j]).chain(prior0));
        let mut best = (lin.u.clone(), r.norm_squared());
        let mut stuck = false;
        for iteration in 0..2 {
            let step = lsq.as_ref().map_or_else(|| DVector::zeros(jt.ncols()), |l| l.solve(&r));
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
                stuck = iteration == 0 && promised >= crate::calibrate::FIT_DECREMENT_TOL;
                break;
            };
            best = (ut, rt.norm_squared());
            r = rt;
        }
        let moved = (&best.0 - &lin.u).amax();
        let fitted = if moved > 0.3 || stuck {
            // A stuck fold is refitted too: predicted with the full-data fit, its held-out
            // block would be scored in-sample, which flatters this model against one whose
            // folds moved. Where the refit cannot lower the training χ² either, the
            // full-data fit is the best training fit found, and the fold counts as
            // predicted in-sample.
            let stepped = lin.motor_at(&best.0);
            let refit = Calibration::builder(&stepped, &train_rows)
                .params(&lin.params)
                .options(fit)
                .weights(w.clone())
                .run()
                .ok()
                .filter(|c| !stuck || weighted(&c.lin.u).norm_squared() < best.1 - crate::calibrate::FIT_DECREMENT_TOL);
            if stuck && refit.is_none() {
                in_sample += 1;
            }
            refit.map_or(stepped, |c| c.motor)
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

/// The Moore–Penrose inverse J⁺ (n × m) of a weighted Jacobian or set of columns `j`
/// (m × n), so that J⁺r is the minimum-norm least-squares coefficient vector for residuals
/// r: directions the data do not determine (singular values of J at or below 1e-5 of the
/// largest, i.e. the eigenvalues of JᵀJ below 1e-10 of its largest) get none. From the
/// SVD of J itself ([`crate::lsq`]): forming JᵀJ would square its condition number. Zero
/// for a non-finite `j`; a `j` without columns gives a 0 × m matrix.
pub(super) fn pseudo_inverse(j: &DMatrix<f64>) -> DMatrix<f64> {
    LeastSquares::new(j, 1e-5).map_or_else(|| DMatrix::zeros(j.ncols(), j.nrows()), |l| l.pseudo_inverse())
}

#[allow(clippy::too_many_arguments)]
pub(super) fn cross_validate(
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
        let mut fitted = Calibration::builder(&s0, &train).params(&params).options(&opts.fit).run().ok();
        if !effects.is_empty() {
            // Nested models: the effect at zero strength is the baseline, so a fit that ends
            // worse than the baseline's is a local minimum; use the baseline fit instead.
            let (b0, bp) = fit_params(motor, start, &train, &[], reduced, &opts.tolerances);
            let base = Calibration::builder(&b0, &train).params(&bp).options(&opts.fit).run().ok();
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
/// per-reading squared residuals in σ). The NRMSE is not clipped: the reported shrink is
/// measured on it, and a baseline's large misses are the gap itself.
pub(super) fn errors(
    rows: &[ObservedRow],
    preds: &[Vec<f64>],
    sc: &BTreeMap<Observable, f64>,
) -> (f64, f64, Vec<f64>, Vec<f64>) {
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

/// The note on held-out figures that rest partly on in-sample predictions: the folds of
/// the baseline (`base_in_sample`) and of each ranked model whose refit could not be moved
/// off the full-data fit, out of `k`. `None` when there are none.
pub(super) fn in_sample_note(base_in_sample: usize, ranking: &[RankEntry], k: usize) -> Option<String> {
    let stuck: Vec<String> = std::iter::once(("the calibrated baseline".to_string(), base_in_sample))
        .chain(ranking.iter().map(|r| (r.effect.clone(), r.heldout_in_sample_folds)))
        .filter(|(_, n)| *n > 0)
        .map(|(name, n)| format!("{name} in {n} of {k}"))
        .collect();
    if stuck.is_empty() {
        return None;
    }
    Some(format!(
        "held-out blocks predicted in-sample, so these held-out figures are optimistic: {} folds (the fold's fit could not be moved off the full-data fit: even a quarter of the first-order step raised the training χ², as where a row changes between moving and clamped, and a refit on the fold's training rows did not lower it)",
        stuck.join(", ")
    ))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::*;
    use crate::solve::OperatingPoint;

    fn row(preload_n: f64) -> ObservedRow {
        ObservedRow {
            op: OperatingPoint::new(preload_n, 0.1, 200.0, 43_000.0),
            readings: vec![(Observable::SpeedRpm, 100.0, 1.0)],
            ambient_c: 20.0,
            speed_std_clipped: false,
        }
    }

    /// Regions (25 N preload bins here) are dealt round-robin in their sorted order: every
    /// row of a region in one fold, the fold count clamped to the number of regions.
    #[test]
    fn regions_are_dealt_round_robin_into_folds() {
        let rows: Vec<ObservedRow> =
            [100.0, 150.0, 200.0, 250.0, 300.0].iter().flat_map(|&p| [row(p), row(p + 5.0)]).collect();
        let (of_row, k) = assign(&rows, &[], 3).unwrap();
        assert_eq!(k, 3);
        // region keys sort as text: bins 10 (250 N), 12 (300 N), 4 (100 N), 6 (150 N), 8 (200 N)
        assert_eq!(of_row, vec![2, 2, 0, 0, 1, 1, 0, 0, 1, 1]);
        assert_eq!(assign(&rows, &[], 10).unwrap().1, 5);
        assert_eq!(assign(&rows, &[], 1).unwrap().1, 2);
        // two runs at one operating point are two regions; one region is no held-out test
        let runs = vec!["a".to_string(), "b".to_string()];
        assert_eq!(assign(&[row(100.0), row(100.0)], &runs, 4).unwrap(), (vec![0, 1], 2));
        assert!(assign(&[row(100.0), row(101.0)], &[], 4).is_err());
    }

    /// The errors' NRMSE is over the quantity scales, the mean z² over σ with each reading
    /// clipped at OUTLIER_Z2, and a missing prediction counts as zero.
    #[test]
    fn held_out_errors_scale_clip_and_count_missing_predictions() {
        let rows = vec![row(100.0), row(200.0)];
        let sc: BTreeMap<Observable, f64> = [(Observable::SpeedRpm, 10.0)].into();
        let (nrmse, z2, e2, raw) = errors(&rows, &[vec![103.0], vec![f64::NAN]], &sc);
        assert!((e2[0] - 0.09).abs() < 1e-12 && e2[1] == 100.0, "{e2:?}");
        assert_eq!(raw, vec![9.0, 10_000.0]);
        assert!((nrmse - (100.09f64 / 2.0).sqrt()).abs() < 1e-12);
        assert!((z2 - (9.0 + OUTLIER_Z2) / 2.0).abs() < 1e-12);
    }
}
