//! The diagnosis' decision stage on its own, for coverage-guided fuzzing (built only with
//! `--cfg fuzzing`, which cargo-fuzz sets; never part of the public interface).
//!
//! A whole diagnosis of a few rows costs 0.05-1 s, almost all of it in the fits, so a
//! fuzzer reaches the rules that turn fitted figures into a verdict only a few times a
//! second, and only through the figures that real fits happen to give. Here the fitted
//! figures are the input: a ranking of single effects and of pairs, their held-out
//! predictions, full-data residuals and signatures, and the baseline's gap, handed to the
//! same code `diagnose` runs after its fits ([`super::verdict::after_fits`]), with the
//! pairs given instead of fitted.

use super::candidates::{sort_ranking, Fits};
use super::context::Context;
use super::signature::Signature;
use super::verdict::{self, GapTests};
use super::{bench, DiagnoseOptions, RankEntry};
use crate::effects::Effect;
use crate::error::TrumError;
use crate::observable::ObservedRow;
use crate::params::Motor;
use nalgebra::{DMatrix, DVector};
use std::collections::BTreeMap;

/// The fitted figures the decision stage reads.
#[derive(Clone, Debug, Default)]
pub struct FittedFigures {
    /// The baseline's held-out NRMSE.
    pub base_nrmse: f64,
    /// What noise alone gives in that NRMSE (the gap tests' noise).
    pub gap_noise: f64,
    /// The baseline's held-out mean z².
    pub base_z2: f64,
    /// The same with the noise levels at the upper end of their estimates.
    pub z2_upper_noise: f64,
    /// Single effects' entries (sorted here as the scoring sorts them).
    pub singles: Vec<RankEntry>,
    /// Pairs' entries, given to the stage where it would fit pairs.
    pub pairs: Vec<RankEntry>,
    /// Held-out predictions by model name, one value a reading of each row.
    pub cv_preds: BTreeMap<String, Vec<Vec<f64>>>,
    /// Full-data squared normalised residuals of each single, one a reading.
    pub z2: BTreeMap<String, Vec<f64>>,
    /// Each effect's signature at the baseline (its primary column, one value a reading).
    pub signatures: BTreeMap<Effect, Vec<f64>>,
}

/// The decision: what `Diagnosis` reports of it.
#[derive(Clone, Debug, PartialEq)]
pub struct Decision {
    /// One effect, several joined with `+`, `none` or `unexplained`.
    pub verdict: String,
    /// No held-out gap beyond the noise is left.
    pub complete: bool,
    /// Effects that explain the data about as well as the verdict.
    pub confounded_with: Vec<String>,
    /// With `unexplained`, the supported effect that explains part of the gap.
    pub partial: Option<String>,
    /// The ranking after the stage (pairs added, names ordered, overlaps filled).
    pub ranking: Vec<RankEntry>,
    /// Whether pairs were asked for (and so given).
    pub pairs_tried: bool,
    /// The notes of the stage.
    pub notes: Vec<String>,
}

/// The decision stage of `diagnose` on `rows` (runs `groups`) with `opts`, from the fitted
/// figures `f` instead of fits. Errors as `diagnose` does on data no held-out test can use.
pub fn decide(
    motor: &Motor,
    rows: &[ObservedRow],
    groups: &[String],
    opts: &DiagnoseOptions,
    f: FittedFigures,
) -> Result<Decision, TrumError> {
    let groups = &bench::runs(rows, groups)[..];
    let ctx = Context::new(motor, rows, groups, opts)?;
    let tests = GapTests { base_nrmse: f.base_nrmse, gap_noise: f.gap_noise, base_z2: f.base_z2, n_read: ctx.n_read };
    let mut ranking = f.singles;
    sort_ranking(&mut ranking);
    let mut fits = Fits { cv_preds: f.cv_preds, fits: BTreeMap::new() };
    let n = ctx.n_read;
    let base_sigs: BTreeMap<Effect, Signature> = f
        .signatures
        .into_iter()
        .filter(|(_, c)| c.len() == n)
        .map(|(e, c)| {
            let columns = DMatrix::from_column_slice(n, 1, &c);
            (e, Signature { columns, linear_chi2_drop: 0.0, linear_change: DVector::zeros(n), matched: 0.0 })
        })
        .collect();
    let mut pairs_tried = false;
    let given = f.pairs;
    let (decided, screened) = verdict::after_fits(
        &ctx,
        &tests,
        f.z2_upper_noise,
        &mut ranking,
        &mut fits,
        |_, ranking, _, _| {
            pairs_tried = true;
            let mut pairs = given;
            sort_ranking(&mut pairs);
            ranking.extend(pairs.iter().cloned());
            sort_ranking(ranking);
            (pairs, None)
        },
        &base_sigs,
        |_| f.z2,
    );
    let mut notes = decided.notes;
    notes.extend(screened);
    Ok(Decision {
        verdict: decided.verdict,
        complete: decided.complete,
        confounded_with: decided.confounded,
        partial: decided.partial,
        ranking,
        pairs_tried,
        notes,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::super::tests::{data, quick, ranked};
    use super::*;

    /// The stage on given figures decides as `diagnose` would: a baseline at the noise is
    /// `none`; a supported single that closes the gap is the verdict, and a pair given while
    /// the single leaves the held-out z² above 2 is tried, though it does not beat it
    /// (no more evidence): the ranking holds it, the verdict stays the single.
    #[test]
    fn given_figures_are_decided_as_fits_would_be() {
        let motor = crate::calibrate::tests::reference_motor();
        let (rows, groups) = data(&motor, 1.0, 3);
        let opts = DiagnoseOptions { try_pairs: true, ..quick(false) };
        let base = FittedFigures { base_nrmse: 0.4, gap_noise: 0.05, base_z2: 20.0, ..FittedFigures::default() };
        let d = decide(&motor, &rows, &groups, &opts, FittedFigures { z2_upper_noise: 1.5, ..base.clone() }).unwrap();
        assert_eq!((d.verdict.as_str(), d.complete, d.pairs_tried), ("none", true, false));
        let single = RankEntry {
            shrink: 0.7,
            shrink_interval: (0.6, 0.8),
            z2_shrink_interval: (0.6, 0.8),
            ..ranked("voltage_sag", 3.0, 0.12)
        };
        let other = RankEntry { effect: "eccentricity".into(), evidence: 20.0, ..single.clone() };
        let pair = RankEntry { effect: "voltage_sag+eccentricity".into(), ..single.clone() };
        let figures = FittedFigures { z2_upper_noise: 25.0, singles: vec![other, single], pairs: vec![pair], ..base };
        let d = decide(&motor, &rows, &groups, &opts, figures).unwrap();
        assert_eq!((d.verdict.as_str(), d.complete, d.pairs_tried, d.ranking.len()), ("voltage_sag", true, true, 3));
        assert_eq!(d.ranking[0].effect, "voltage_sag", "sorted by evidence");
        assert!(d.confounded_with.is_empty(), "eccentricity is 80 behind in evidence: {:?}", d.confounded_with);
    }
}
