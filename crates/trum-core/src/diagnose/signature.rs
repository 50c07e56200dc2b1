//! Sensitivity signatures: what switching an effect on does to a fit's residuals, beyond
//! what the fit's own parameters can absorb. Compared with the residual pattern they say
//! whether the calibrated model misses in the way an effect would move it (a score test:
//! the χ² the effect could remove to first order, without fitting it), and compared with
//! each other they say which effects the data cannot tell apart.
//!
//! With r the fit's weighted residuals, J their Jacobian in the fitted parameters and S
//! the effect's columns (one per parameter: the residual change when the effect is
//! switched on at a tenth of its typical strength, then each further parameter doubled), the
//! signature is S̃ = (I − J J⁺) S, the part of S orthogonal to what refitting the other
//! parameters already does. Linearised, adding the effect lowers χ² by ‖P_S̃ r‖², the
//! projection of r onto the span of S̃ (Rao's score statistic for a least-squares model),
//! one-sided for an effect whose strength is bounded below by off: a residual that only a
//! negative strength would remove is no evidence for the effect.

use super::folds::pseudo_inverse;
use crate::calibrate::{residuals, Calibration};
use crate::effects::Effect;
use crate::lsq::LeastSquares;
use crate::observable::ObservedRow;
use nalgebra::{DMatrix, DVector};

/// Probe strength of the primary parameter, as a fraction of its typical value.
const PROBE: f64 = 0.1;

/// An effect's signature at one fit.
#[derive(Clone, Debug)]
pub(crate) struct Signature {
    /// S̃: one column per effect parameter, rows in reading order (weighted σ units).
    pub(crate) columns: DMatrix<f64>,
    /// ‖P_S̃ r‖²: the χ² the effect removes to first order, at a strength no lower than
    /// off (one-sided: zero for a one-parameter effect the residual would need negative).
    pub(crate) linear_chi2_drop: f64,
    /// S̃a at that minimum: the first-order change of the fit's weighted residuals when the
    /// effect is added and everything refitted (r + S̃a is the refit's residual).
    pub(crate) linear_change: DVector<f64>,
    /// cos(r, −S̃₀): +1 when the residual is exactly what the effect's primary parameter
    /// (raised from the fit's value) removes, −1 when it would need the opposite sign.
    pub(crate) matched: f64,
}

/// The fit's weighted residuals for `motor` (the fit's final Huber weights).
fn weighted(cal: &Calibration, motor: &crate::Motor, rows: &[ObservedRow]) -> DVector<f64> {
    let r = residuals(motor, rows);
    DVector::from_iterator(r.len(), r.iter().zip(&cal.lin.weights).map(|(x, w)| x * w))
}

/// The signature of `e` at the fit `cal` (an effect the fit already carries is not probed:
/// None). Costs one model pass over the rows per effect parameter.
pub(crate) fn signature(cal: &Calibration, rows: &[ObservedRow], e: Effect) -> Option<Signature> {
    if cal.motor.effects.is_on(e) {
        return None;
    }
    let info = e.info();
    let r = &cal.lin.residuals;
    let mut probe = cal.motor.clone();
    // A small probe (a tenth of the typical strength): the shape of the effect's leading
    // term. It changes with strength (radial friction's at its typical strength matches
    // its own weak residual with cos 0.2 instead of 0.99), and the test is one of first order.
    let typical = info.with_primary(PROBE * info.params[0].typical);
    probe.effects.set(e, &typical);
    let on = weighted(cal, &probe, rows);
    let mut cols = vec![&on - r];
    // (a column for each parameter the fits free; a held shape parameter is not fitted)
    for (i, &v) in typical.iter().enumerate().skip(1).filter(|(i, _)| !info.params[*i].held) {
        let mut m = probe.clone();
        *m.effects.value_mut(e, i) = 2.0 * v;
        cols.push(weighted(cal, &m, rows) - &on);
    }
    let s = DMatrix::from_columns(&cols);
    if !s.iter().all(|x| x.is_finite()) {
        return None;
    }
    // (I − U Uᵀ) S from the SVD of J, directions with a singular value at or below 1e-5 of
    // the largest not refitted (the eigenvalues of JᵀJ below 1e-10 of its largest); a
    // non-finite Jacobian refits nothing
    let st = LeastSquares::new(&cal.lin.jacobian, 1e-5).map_or_else(|| s.clone(), |l| l.orthogonal_part(&s));
    let shape: Vec<bool> = info.params.iter().filter(|p| !p.held).map(|p| p.shape).collect();
    let (linear_chi2_drop, linear_change) = one_sided_drop(&st, r, info.params[0].min >= 0.0, &shape);
    let s0 = st.column(0);
    let denom = s0.norm() * r.norm();
    let matched = if denom > 0.0 { -s0.dot(r) / denom } else { 0.0 };
    Some(Signature { columns: st, linear_chi2_drop, linear_change, matched })
}

/// min over a of ‖r + S̃a‖² subtracted from ‖r‖²: the χ² the columns remove to first order,
/// with the change S̃a at the minimum. With `bounded` the primary coefficient a₀ must be ≥ 0
/// (an effect whose strength cannot go below off): when the unconstrained a₀ is negative
/// the constrained minimum lies on a₀ = 0 (one inequality on a convex quadratic), and only
/// the other columns remove anything (nothing for a one-parameter effect). Without the
/// bound a fit would be screened in on a residual only a negative strength removes, and
/// collapse onto the model it nests.
/// A shape column (`shape[i]`) changes nothing at zero strength, so on a₀ = 0 it goes too.
fn one_sided_drop(st: &DMatrix<f64>, r: &DVector<f64>, bounded: bool, shape: &[bool]) -> (f64, DVector<f64>) {
    // (drop, change, a₀) of the least-squares a over the columns `s`
    let drop = |s: &DMatrix<f64>| -> (f64, DVector<f64>, f64) {
        if s.ncols() == 0 {
            return (0.0, DVector::zeros(r.len()), 0.0);
        }
        let a = -(pseudo_inverse(s) * r);
        let change = s * &a;
        // ‖r‖² − ‖r + S̃a‖² = −rᵀS̃a at the least-squares a
        ((-r.dot(&change)).max(0.0), change, a[0])
    };
    let (full, change, a0) = drop(st);
    if bounded && a0 < 0.0 {
        let kept: Vec<_> =
            (1..st.ncols()).filter(|&i| !shape.get(i).copied().unwrap_or(false)).map(|i| st.column(i)).collect();
        let (d, c, _) =
            if kept.is_empty() { drop(&DMatrix::zeros(r.len(), 0)) } else { drop(&DMatrix::from_columns(&kept)) };
        (d, c)
    } else {
        (full, change)
    }
}

/// |cos| of the angle between two signatures' primary columns: 1 when the data see the two
/// effects' first-order changes as one shape (up to scale), 0 when they are orthogonal.
pub(crate) fn overlap(a: &Signature, b: &Signature) -> f64 {
    let (x, y) = (a.columns.column(0), b.columns.column(0));
    let d = x.norm() * y.norm();
    if d > 0.0 {
        (x.dot(&y) / d).abs()
    } else {
        0.0
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::*;
    use crate::calibrate::tests::classic_params;
    use crate::calibrate::FitOptions;

    fn rows_of(truth: &crate::Motor) -> Vec<ObservedRow> {
        crate::calibrate::tests::rows_on_grid(truth, &[100.0, 175.0, 250.0, 325.0, 400.0], &[0.0, 0.15, 0.3, 0.45])
    }

    /// The score test against a full refit: on data of the baseline plus weak radial
    /// friction, radial friction's signature matches the calibrated baseline's residual
    /// best of all candidates and its first-order χ² drop is close to what fitting it
    /// removes; on baseline data it finds nothing.
    #[test]
    fn the_true_effect_matches_the_residual_and_its_score_is_of_the_fits_order() {
        let nominal = crate::calibrate::tests::reference_motor();
        let mut truth = nominal.clone();
        truth.effects.set(Effect::RadialFriction, &[0.3]);
        let rows = rows_of(&truth);
        let fit = FitOptions::default();
        let params = crate::calibrate::tests::classic_params(&nominal, &rows);
        let base = Calibration::builder(&nominal, &rows).params(&params).options(&fit).run().unwrap();
        let sig = signature(&base, &rows, Effect::RadialFriction).unwrap();
        assert!(sig.matched > 0.95, "match {}", sig.matched);
        for e in crate::effects::ALL.into_iter().filter(|&e| e != Effect::RadialFriction) {
            let other = signature(&base, &rows, e).unwrap();
            assert!(other.matched < 0.8 && other.linear_chi2_drop < 0.6 * sig.linear_chi2_drop, "{e}: {other:?}");
        }
        // a full refit with the effect: χ² falls to ~0 (noise-free data)
        let mut params = classic_params(&nominal, &rows);
        params.extend(crate::calibrate::effect_params(Effect::RadialFriction));
        let mut start = base.motor.clone();
        start.effects.set(Effect::RadialFriction, &[0.1]);
        let with = Calibration::builder(&start, &rows).params(&params).options(&fit).run().unwrap();
        let removed = base.chi2 - with.chi2;
        assert!(removed > 0.0 && with.chi2 < 1e-3 * base.chi2, "{} -> {}", base.chi2, with.chi2);
        let ratio = sig.linear_chi2_drop / removed;
        assert!((0.8..=1.05).contains(&ratio), "linear drop {} vs refit {removed}", sig.linear_chi2_drop);
        // an effect already carried is not probed
        assert!(signature(&with, &rows, Effect::RadialFriction).is_none());

        // baseline data: the calibrated baseline fits exactly, nothing is left to explain
        let clean = rows_of(&nominal);
        let base0 = Calibration::builder(&nominal, &clean)
            .params(&classic_params(&nominal, &clean))
            .options(&fit)
            .run()
            .unwrap();
        let s0 = signature(&base0, &clean, Effect::RadialFriction).unwrap();
        assert!(s0.linear_chi2_drop < 1e-6 * sig.linear_chi2_drop.max(1.0), "{}", s0.linear_chi2_drop);
        // overlap is symmetric, 1 with itself, within [0, 1]
        let other = signature(&base, &rows, Effect::VoltageSag).unwrap();
        assert!((overlap(&sig, &sig) - 1.0).abs() < 1e-12);
        let (ab, ba) = (overlap(&sig, &other), overlap(&other, &sig));
        assert!((ab - ba).abs() < 1e-12 && (0.0..=1.0).contains(&ab), "{ab}");
    }

    /// The one-sided drop against a scan: min over a₀ ≥ 0 (a grid) of the residual with the
    /// other coefficient at its least-squares value for that a₀. Equal to the two-sided
    /// projection when the free optimum has a₀ ≥ 0, smaller otherwise, zero for one column.
    #[test]
    fn the_one_sided_drop_is_the_constrained_minimum() {
        let n = 30;
        let col = |f: &dyn Fn(f64) -> f64| DVector::from_iterator(n, (0..n).map(|i| f(i as f64 / n as f64)));
        let st = DMatrix::from_columns(&[col(&|x| x * x - 0.3), col(&|x| (3.0 * x).sin())]);
        let scan = |r: &DVector<f64>| -> f64 {
            let (s0, s1) = (st.column(0), st.column(1));
            let best = (0..=20000)
                .map(|i| {
                    let a0 = i as f64 * 1e-3;
                    let rr = r + s0 * a0;
                    let a1 = -s1.dot(&rr) / s1.dot(&s1);
                    (rr + s1 * a1).norm_squared()
                })
                .fold(f64::INFINITY, f64::min);
            r.norm_squared() - best
        };
        let noise = col(&|x| 0.05 * (17.0 * x).cos());
        for sign in [1.0, -1.0] {
            // a residual that a₀ = ∓4 (with some a₁) removes, plus a part neither column has
            let r = (st.column(0) * (-4.0 * sign) + st.column(1) * 0.7) + &noise;
            let (bounded, change) = one_sided_drop(&st, &r, true, &[]);
            let (free, free_change) = one_sided_drop(&st, &r, false, &[]);
            // the change is the one at the minimum: r + change is what is left
            for (d, c) in [(bounded, &change), (free, &free_change)] {
                assert!((d - (r.norm_squared() - (&r + c).norm_squared())).abs() < 1e-9 * free, "{sign}: {d}");
            }
            assert!((bounded - scan(&r)).abs() < 1e-6 * free, "{sign}: {bounded} vs scan {}", scan(&r));
            if sign > 0.0 {
                assert!((bounded - free).abs() < 1e-9 * free, "{bounded} vs {free}");
            } else {
                assert!(bounded < 0.5 * free, "{bounded} vs {free}");
            }
            let one = st.columns(0, 1).into_owned();
            let single = one_sided_drop(&one, &r, true, &[]).0;
            assert!(if sign > 0.0 { single > 0.5 * free } else { single == 0.0 }, "{sign}: {single}");
            // a shape column (nothing at zero strength) goes with the primary on its bound
            let shaped = one_sided_drop(&st, &r, true, &[false, true]).0;
            assert!(if sign > 0.0 { (shaped - free).abs() < 1e-9 * free } else { shaped == 0.0 }, "{sign}: {shaped}");
        }
    }

    /// Data the calibrated baseline misses the opposite way from voltage sag (readings
    /// mirrored about the baseline model: sag would have to be a negative resistance) carry
    /// no evidence for it, while sag's own data do.
    #[test]
    fn a_residual_only_a_negative_strength_removes_is_no_evidence() {
        let nominal = crate::calibrate::tests::reference_motor();
        let mut sag = nominal.clone();
        sag.effects.set(Effect::VoltageSag, &[300.0]);
        let with = rows_of(&sag);
        let base_rows = rows_of(&nominal);
        let mirrored: Vec<ObservedRow> = base_rows
            .iter()
            .zip(&with)
            .map(|(b, s)| {
                let mut r = b.clone();
                for (x, y) in r.readings.iter_mut().zip(&s.readings) {
                    x.1 = 2.0 * x.1 - y.1;
                }
                r
            })
            .collect();
        let fit = FitOptions::default();
        let score = |rows: &[ObservedRow]| {
            let base = Calibration::builder(&nominal, rows)
                .params(&classic_params(&nominal, rows))
                .options(&fit)
                .run()
                .unwrap();
            let s = signature(&base, rows, Effect::VoltageSag).unwrap();
            (s.linear_chi2_drop, s.matched, base.chi2)
        };
        let (drop, matched, chi2) = score(&with);
        assert!(matched > 0.5 && drop > 0.5 * chi2, "sag data: drop {drop} of χ² {chi2}, match {matched}");
        let (drop, matched, chi2) = score(&mirrored);
        assert!(chi2 > 100.0, "the mirrored data are missed: χ² {chi2}");
        assert!(matched < -0.5 && drop == 0.0, "mirrored: drop {drop}, match {matched}");
    }
}
