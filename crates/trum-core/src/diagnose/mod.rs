//! The sim-to-real gap diagnosis (docs/DIAGNOSIS.md): where the calibrated
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
//!    A verdict that leaves a gap (`unexplained`, or an effect that closes only part of
//!    it) stands only where the calibrated baseline's misses repeat from run to run
//!    (`repeatability`); else the gap is scatter of the runs and the verdict `none`.
//! 4. Where: baseline residuals grouped by quantity and region; a group is reported when
//!    its mean normalised residual is more than 3.5 standard errors from zero (z-test;
//!    3.5 keeps the family-wise false-alarm rate near 1 % over ~50 groups).
//!
//! The stages, each in a module of its own over one context (`context::Context`): the prepared
//! rows and their `folds`, the calibrated `baseline`, the `candidates` scored (and their
//! `pairs`), the `verdict` (with the runs' `repeatability`), and where the gap lies
//! (`where_`).

mod baseline;
mod bench;
mod candidates;
mod context;
mod folds;
// (built for the fuzz targets, and for its own test so it cannot drift from `diagnose`)
#[cfg(any(fuzzing, test))]
pub mod fuzzing;
pub mod json;
mod pairs;
mod repeatability;
mod scan;
pub mod separation;
mod signature;
#[cfg(test)]
mod tests;
mod verdict;
mod where_;

use crate::calibrate::{residuals, FitOptions};
use crate::effects::{Effect, ALL};
use crate::error::TrumError;
use crate::observable::{Observable, ObservedRow};
use crate::params::Motor;
use crate::solve::Status;
use candidates::{Fits, Scorer};
use context::Context;
pub use folds::OUTLIER_Z2;
use rayon::prelude::*;
use std::collections::BTreeMap;
use verdict::{GapTests, Verdict};

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
    /// Most rows the fits see: larger data are diagnosed on a systematic subsample of this
    /// many rows (one in every n/m in file order), said in a note, with the evidence and
    /// the held-out figures of the subsample; set points and noise levels still come from
    /// every row. 0: every row, however many (the cost then grows with the rows).
    pub max_fit_rows: usize,
    /// Noise levels of the bench's sensors as the user states them, by quantity: (absolute
    /// standard deviation in the quantity's unit, relative part), a reading's σ being
    /// `absolute + relative · |reading|`, the absolute part > 0 and the relative one ≥ 0
    /// (an error names the quantity otherwise). A stated level replaces the default one
    /// ([`Observable::default_sigma`]) and is not rescaled by the estimate from the data
    /// (docs/DIAGNOSIS.md, "Noise levels from the data"). Empty by default.
    pub stated_noise: BTreeMap<Observable, (f64, f64)>,
}

/// The default [`DiagnoseOptions::max_fit_rows`]: the size at which a diagnosis with all
/// seven candidates stays near a second on two cores (docs/PERFORMANCE.md), and where a
/// candidate that matters reaches an evidence of hundreds on nominal bench noise.
pub const MAX_FIT_ROWS: usize = 160;

/// Reads stated sensor noise levels from `COLUMN=SD` or `COLUMN=SD,REL` texts (`SD` the
/// absolute standard deviation in the column's unit, `REL` the relative part, 0 when
/// left out) for [`DiagnoseOptions::stated_noise`]. `source` names where the texts come
/// from in errors (a flag, an argument). Errors name the text and why: an unknown column
/// (with the valid ones), a number that does not parse, a level out of range, a column
/// stated twice.
pub fn stated_noise_from_texts(texts: &[String], source: &str) -> Result<BTreeMap<Observable, (f64, f64)>, TrumError> {
    let columns = || Observable::ALL.iter().map(|o| o.column()).collect::<Vec<_>>().join(", ");
    let mut out = BTreeMap::new();
    for t in texts {
        let (col, levels) = t
            .split_once('=')
            .ok_or_else(|| TrumError::input(format!("{source} '{t}': expected COLUMN=SD or COLUMN=SD,REL")))?;
        let col = col.trim();
        let o = Observable::ALL.into_iter().find(|o| o.column() == col).ok_or_else(|| {
            TrumError::input(format!("{source} '{t}': unknown column '{col}'; measured columns are {}", columns()))
        })?;
        let mut parts = levels.split(',').map(str::trim);
        let number = |x: Option<&str>, what: &str| -> Result<Option<f64>, TrumError> {
            match x {
                None => Ok(None),
                Some(x) => x
                    .parse::<f64>()
                    .map(Some)
                    .map_err(|_| TrumError::input(format!("{source} '{t}': {what} '{x}' is not a number"))),
            }
        };
        let sd = number(parts.next(), "the standard deviation")?.unwrap_or(f64::NAN);
        let rel = number(parts.next(), "the relative part")?.unwrap_or(0.0);
        if parts.next().is_some() {
            return Err(TrumError::input(format!("{source} '{t}': expected COLUMN=SD or COLUMN=SD,REL")));
        }
        if !(sd.is_finite() && sd > 0.0 && rel.is_finite() && rel >= 0.0) {
            return Err(TrumError::input(format!(
                "{source} '{t}': the standard deviation must be a finite number > 0 (in the column's unit) and the relative part a finite number >= 0"
            )));
        }
        if out.insert(o, (sd, rel)).is_some() {
            return Err(TrumError::input(format!("{source}: column '{col}' is stated twice")));
        }
    }
    Ok(out)
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
            max_fit_rows: MAX_FIT_ROWS,
            stated_noise: BTreeMap::new(),
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
    /// Bootstrap 90 % interval of the same shrink in σ: 1 − √(Σz²_after/Σz²_before) over
    /// the held-out readings, each reading's z² clipped at [`OUTLIER_Z2`]. The NRMSE weighs
    /// each quantity by its spread, so a few readings of a quantity with a small spread can
    /// carry most of it and make its interval wide where the gain in σ is certain.
    pub z2_shrink_interval: (f64, f64),
    /// The part of each held-out shrink (NRMSE, σ) that stays with the one row that gains
    /// most left out: 1 when that row carries none of the gain, 0 or less when it carries
    /// all. A gain that a single operating point carries (a reading at the edge of a
    /// stall, an outlier) is no evidence of an effect.
    pub lone_row_shares: (f64, f64),
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
    /// Cross-validation folds whose training fit could not be moved off this fit's
    /// full-data optimum (neither by the approximate steps nor by a refit), so their held-out blocks were predicted in-sample (the held-out figures are
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
    /// The baseline parameters with a prior that the data did not identify (their
    /// posterior standard error not well inside the prior's width): held near their
    /// priors, so their values are the priors' more than the data's.
    pub baseline_held_near_prior: Vec<String>,
    /// Per held-out reading: (row index, observable, measured, baseline prediction,
    /// prediction with the verdict's effects) — for plots.
    pub heldout: Vec<HeldOut>,
    /// For each effect the verdict is confounded with, how well each `trum synth` campaign
    /// at the data's drive would separate the two fits ([`separation`]): what to measure
    /// next. Empty when nothing is confounded.
    pub separating_campaigns: Vec<separation::Separation>,
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

/// For a verdict that leaves a gap: whether the calibrated baseline's misses repeat from
/// run to run (`repeatability`), with the note that says so; `None` where there are too
/// few runs to tell. Scatter that changes from run to run and not along a run is the
/// bench's (or the motor's state at each mounting), not physics the model lacks: where
/// the misses do not repeat, the calibrated model explains the data within that scatter
/// and the verdict is `none` (an effect that closed part of such a gap fitted the runs'
/// scatter: its held-out gain is chance over a handful of runs).
fn run_scatter(ctx: &Context, base: &baseline::Baseline) -> Option<(bool, String)> {
    let z = residuals(&base.cal.motor, &ctx.rows);
    // the fit's Jacobian of the unweighted residuals (its rows carry the Huber weights;
    // a reading the fit gave no weight constrains nothing)
    let lin = &base.cal.lin;
    let mut jz = lin.jacobian.clone();
    for (mut row, &w) in jz.row_iter_mut().zip(&lin.weights) {
        if w > 0.0 {
            row /= w
        } else {
            row.fill(0.0)
        }
    }
    let r = repeatability::across_runs(&ctx.rows, &z, &ctx.groups, Some(&jz), ctx.opts.seed)?;
    let test = format!(
        "agreement of each miss with those of other runs at the nearest operating points {:.2}; sign-flip test over the {} runs, p = {}",
        r.agreement,
        r.runs,
        pairs::rounded(r.p_value)
    );
    let note = if r.repeats() {
        format!("the calibrated baseline's misses repeat from run to run ({test}): a gap in the model, not scatter of the runs")
    } else {
        format!(
            "the calibrated baseline misses the held-out data by more than the noise levels estimated along each run allow (mean squared normalised residual {:.2}), but its misses do not repeat from run to run ({test}): scatter that belongs to each run (noise correlated along a run, a run's own offset), which no effect of the motor explains; no effect is needed",
            base.z2
        )
    };
    Some((r.repeats(), note))
}

/// The quantity scales of the held-out NRMSEs a diagnosis of `rows` (runs `groups`)
/// reports ([`scales`] with the noise levels it estimates from the data): for outside
/// figures on the same scale, such as the blind benchmark's model without error.
pub fn nrmse_scales(rows: &[ObservedRow], groups: &[String]) -> BTreeMap<Observable, f64> {
    let groups = &bench::runs(rows, groups)[..];
    let rows = context::bench_model(rows, groups).0;
    context::scales(&context::noise_scaled(&rows, &crate::noise::estimate(&rows, groups)))
}

/// Diagnoses `rows` (with `groups[i]` the run of row i; empty strings are fine) against
/// `motor`. Errors on data that cannot support any held-out test.
pub fn diagnose(
    motor: &Motor,
    rows: &[ObservedRow],
    groups: &[String],
    opts: &DiagnoseOptions,
) -> Result<Diagnosis, TrumError> {
    // runs inferred from the set points where the data name none
    let named = groups.iter().any(|g| !g.is_empty());
    let groups = &bench::runs(rows, groups)[..];
    // The motor's own effects are part of its model: the baseline refits their strengths
    // (`calibrate::baseline_params_with`), so they are not candidates for what it lacks.
    let own: Vec<Effect> = motor.effects.active().into_iter().filter(|e| opts.candidates.contains(e)).collect();
    let without_own;
    let opts = if own.is_empty() {
        opts
    } else {
        without_own = DiagnoseOptions {
            candidates: opts.candidates.iter().copied().filter(|e| !own.contains(e)).collect(),
            ..opts.clone()
        };
        &without_own
    };
    let mut ctx = Context::new(motor, rows, groups, opts)?;
    let mut notes = std::mem::take(&mut ctx.notes);
    if !own.is_empty() {
        let names: Vec<&str> = own.iter().map(|e| e.name()).collect();
        notes.insert(
            0,
            format!(
                "the motor's own effects ({}) are part of the baseline: their strengths are calibrated with it (prior: the file's value, a factor of {:.2} at one σ) and they are not candidates",
                names.join(", "),
                crate::calibrate::OWN_EFFECT_REL_SD.exp()
            ),
        );
    }
    if !named && !rows.is_empty() {
        let n = groups.iter().collect::<std::collections::BTreeSet<_>>().len();
        notes.insert(
            0,
            format!("the data name no runs (run_id): {n} run(s) inferred from the preload and voltage levels"),
        );
    }
    let ctx = ctx;
    let base0 = baseline::fit(&ctx)?;
    // candidates in parallel; each returns its entry and its held-out predictions
    let probes0 = candidates::probe(&ctx, &base0);
    let scorer0 = Scorer::new(&ctx, &base0, &probes0);
    let mut fits0 = Fits::default();
    let ranking0 = candidates::score_singles(&scorer0, &mut fits0);
    // The baseline is every candidate at zero strength: where a candidate's fit, its effect
    // taken out, fits the data better than the calibrated baseline, the baseline's fit
    // stopped in a valley of its own and is refitted from there, and the candidates with it
    // (their evidence measured that valley, not their effects).
    let restart = match baseline::better_start(&ctx, &base0, &fits0.fits) {
        Some(from) => Some(baseline::calibrate(&ctx, &from)?).filter(|c| c.chi2 < base0.cal.chi2 - 1.0),
        None => None,
    };
    let (base1, probes1);
    let (base, probes, scorer, mut fits, mut ranking) = match restart {
        None => (&base0, &probes0, scorer0, fits0, ranking0),
        Some(cal) => {
            notes.push(format!(
                "the baseline was refitted from a candidate's fit with its effect taken out (χ² {} against {} from the nominal motor): the first calibration had stopped in a valley of its own parameters",
                pairs::rounded(cal.chi2),
                pairs::rounded(base0.cal.chi2)
            ));
            base1 = baseline::with_held_out(&ctx, cal)?;
            probes1 = candidates::probe(&ctx, &base1);
            let scorer = Scorer::new(&ctx, &base1, &probes1).with_earlier_fits(&fits0.fits);
            let mut fits = Fits::default();
            let ranking = candidates::score_singles(&scorer, &mut fits);
            (&base1, &probes1, scorer, fits, ranking)
        }
    };
    notes.extend(probes.at_rest_note.clone());

    let tests = GapTests { base_nrmse: base.nrmse, gap_noise: base.noise_best, base_z2: base.z2, n_read: ctx.n_read };
    let (mut decided, screened_note) = verdict::after_fits(
        &ctx,
        &tests,
        base.z2_upper_noise,
        &mut ranking,
        &mut fits,
        |fits, ranking, best_single, single_closes| {
            pairs::fit_pairs(&scorer, fits, ranking, best_single, single_closes, &tests)
        },
        &probes.base_sigs,
        |fits| {
            fits.fits
                .par_iter()
                .filter(|(name, _)| Effect::from_name(name).is_ok())
                .map(|(name, c)| (name.clone(), residuals(&c.motor, &ctx.rows).iter().map(|z| z * z).collect()))
                .collect()
        },
    );
    // (a gap that no candidate closes, or that the verdict closes only in part: is it the
    // model's, or scatter of the runs?)
    if !decided.complete {
        match run_scatter(&ctx, base) {
            Some((false, note)) => {
                decided = Verdict {
                    verdict: "none".into(),
                    complete: true,
                    confounded: Vec::new(),
                    partial: None,
                    notes: vec![note],
                }
            }
            Some((true, note)) => decided.notes.push(note),
            None => {}
        }
    }
    notes.append(&mut decided.notes);
    let Verdict { verdict, complete, confounded, partial, .. } = decided;
    notes.extend(screened_note);
    let lead = partial.as_deref().filter(|_| verdict == "unexplained").unwrap_or(&verdict);
    let separating_campaigns = separating_campaigns(&ctx.rows, &fits.fits, &ranking, lead, &confounded);
    notes.extend(separating_campaigns.iter().filter_map(separation_note));
    notes.extend(scorer.into_notes());
    notes.extend(folds::in_sample_note(base.cv.in_sample, &ranking, ctx.k));
    if ctx.reduced && verdict != "none" {
        notes.push(format!("with so few readings the verdict '{verdict}' is tentative; measure more operating points"));
    }
    let (gap_where, where_note) = where_::locate(&ctx, base);
    notes.extend(where_note);
    let mut heldout = held_out(&ctx.rows, &base.cv.preds, &fits.cv_preds, &verdict);
    if let Some(sample) = &ctx.sample {
        // (held-out readings name their row in the input)
        for h in heldout.iter_mut() {
            h.row = sample[h.row];
        }
    }
    // (no verdict from figures that overflowed: json::guard_non_finite)
    Ok(json::guard_non_finite(Diagnosis {
        verdict,
        complete,
        confounded_with: confounded,
        partial,
        baseline_heldout_nrmse: base.nrmse,
        noise_nrmse: base.noise_best,
        noise_nrmse_weights: ctx.noise_weights,
        baseline_heldout_chi2_per_reading: base.z2,
        noise_scale: ctx.noise_scale.clone(),
        gap_where,
        ranking,
        notes,
        n_rows: rows.len(),
        n_readings: ctx.n_read,
        folds: ctx.k,
        baseline_params: base.cal.params.iter().map(|p| (p.name.clone(), p.value)).collect(),
        baseline_held_near_prior: base
            .cal
            .params
            .iter()
            .filter(|p| p.prior_rel_sd.is_some() && !p.identifiable)
            .map(|p| p.name.clone())
            .collect(),
        heldout,
        separating_campaigns,
    }))
}

/// The separation of the lead effect from each of its rivals ([`separation::rivals`]),
/// between their full-data fits (`fits`), at the drive of `rows`. The lead is a
/// single-effect verdict, or with `unexplained` the effect that explains part of the gap
/// (`partial`): in both a user asks what would confirm it against the next explanation.
fn separating_campaigns(
    rows: &[ObservedRow],
    fits: &BTreeMap<String, crate::calibrate::Calibration>,
    ranking: &[RankEntry],
    lead: &str,
    confounded: &[String],
) -> Vec<separation::Separation> {
    let (Some(lead_fit), Some((voltage_v, frequency_hz))) = (fits.get(lead), separation::drive_of(rows)) else {
        return Vec::new();
    };
    separation::rivals(ranking, lead, confounded)
        .par_iter()
        .filter_map(|(e, why)| {
            let other = fits.get(e)?;
            Some(separation::separation((lead, e), *why, &lead_fit.motor, &other.motor, rows, voltage_v, frequency_hz))
        })
        .collect()
}

/// The note that says what would separate the lead from a rival, where a campaign does.
fn separation_note(s: &separation::Separation) -> Option<String> {
    let (campaign, chi2) = s.best()?;
    let relation = match s.rival {
        separation::Rival::Confounded => String::from("are not told apart by these data"),
        separation::Rival::CloseInEvidence => format!(
            "are both supported and the data prefer the first only weakly (evidence less than {} apart)",
            separation::CLOSE_EVIDENCE
        ),
    };
    Some(format!(
        "{} and {} {relation} (their fits differ by χ² {} over the data's readings at the nominal bench noise of docs/SYNTH.md); a {campaign} campaign at the data's drive would separate them by χ² {} (`trum synth --campaign {campaign}` shows its operating points)",
        s.effects.0,
        s.effects.1,
        pairs::rounded(s.chi2_on_the_data),
        pairs::rounded(chi2),
    ))
}

/// Every reading of `rows` with its baseline held-out prediction (`base_preds`) and the
/// held-out prediction with the verdict's effects (from `cv_preds`; the baseline's for
/// `none`). Pairs were scored under the unsorted name, so they are looked up by the set of
/// names.
fn held_out(
    rows: &[ObservedRow],
    base_preds: &[Vec<f64>],
    cv_preds: &BTreeMap<String, Vec<Vec<f64>>>,
    verdict: &str,
) -> Vec<HeldOut> {
    let after_preds =
        cv_preds.iter().find(|(name, _)| same_set(name, verdict)).map(|(_, p)| &p[..]).unwrap_or(base_preds);
    let mut heldout = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        for (j, &(o, v, _)) in r.readings.iter().enumerate() {
            heldout.push(HeldOut {
                row: i,
                observable: o,
                measured: v,
                baseline: base_preds[i][j],
                after: after_preds[i][j],
            });
        }
    }
    heldout
}

/// The span of `f` over `rows` relative to its largest magnitude, (max − min) / max|f|;
/// 0 for no rows or a quantity that is zero throughout.
fn span_of(rows: &[ObservedRow], f: impl Fn(&ObservedRow) -> f64) -> f64 {
    let (lo, hi, top) = rows
        .iter()
        .map(&f)
        .fold((f64::INFINITY, f64::NEG_INFINITY, 0.0_f64), |(lo, hi, top), x| (lo.min(x), hi.max(x), top.max(x.abs())));
    if top > 0.0 && hi >= lo {
        (hi - lo) / top
    } else {
        0.0
    }
}

/// Two effect lists (`a+b`) name the same set.
pub fn same_set(a: &str, b: &str) -> bool {
    let mut x: Vec<&str> = a.split('+').collect();
    let mut y: Vec<&str> = b.split('+').collect();
    x.sort_unstable();
    y.sort_unstable();
    x == y
}

/// True for rows where the model must run (used by callers to pre-check data).
pub fn status_ok(s: Status) -> bool {
    s.is_valid()
}
