//! Candidate scoring: which candidate effects the data can test (score tests at the
//! calibrated baseline), and each candidate refitted with the baseline parameters from
//! several starts, scored by its full-data evidence and its held-out error.

use super::baseline::{self, Baseline};
use super::context::Context;
use super::folds::{approx_cv, cross_validate, errors};
use super::{scan, signature, RankEntry};
use crate::calibrate::{
    baseline_params_with, effect_params, residuals, Calibration, FitParam, FittedParam, InstrumentParam, ObservedRow,
    ParamRef, Start, IRLS_START_RTOL,
};
use crate::effects::Effect;
use crate::observable::Observable;
use crate::params::Motor;
use crate::solve::{solve_prepared, Prepared, Status};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// What the score tests at the calibrated baseline say about the candidates.
pub(super) struct Probes {
    /// Effects that move no prediction of these rows (`thermal_drift` without a time
    /// series): ranked with the baseline's fit and its parameter penalty, not fitted, and
    /// joining no pair.
    pub(super) untestable: Vec<Effect>,
    /// The signature of each testable candidate at the calibrated baseline (only nonzero
    /// ones: a zero probe, of an effect testable only at the nominal motor, is no
    /// signature, and its match, score and overlap are not reported as zeros).
    pub(super) base_sigs: BTreeMap<Effect, signature::Signature>,
    /// The note when the baseline has the rotor at rest wherever it was measured turning.
    pub(super) at_rest_note: Option<String>,
}

/// Score tests at the calibrated baseline: each candidate's signature against the
/// baseline's residual (one model pass per effect parameter). Its probe is also the test
/// of whether the effect moves any prediction at all: all columns exactly zero.
pub(super) fn probe(ctx: &Context, base: &Baseline) -> Probes {
    let (motor, rows, opts) = (ctx.motor, &ctx.rows[..], &ctx.opts);
    let (base_cal, start) = (&base.cal, &base.start);
    let probed: Vec<(Effect, Option<signature::Signature>)> =
        opts.candidates.par_iter().map(|&e| (e, signature::signature(base_cal, rows, e))).collect();
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
                &residuals(&off, rows) == base_res.get_or_init(|| residuals(start, rows))
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
    let mut at_rest_note = None;
    if !turning.is_empty() {
        let pb = Prepared::new(&base_cal.motor);
        let at_rest = turning
            .iter()
            .filter(|r| {
                let op = base_cal.motor.effects.instrument().operating_point(&r.op);
                matches!(solve_prepared(&pb, &base_cal.motor, &op, None).status, Status::Stall | Status::Clamped)
            })
            .count();
        if at_rest == turning.len() {
            at_rest_note = Some(format!(
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
    Probes { untestable, base_sigs, at_rest_note }
}

/// A scored candidate: its ranking entry, its held-out predictions and its full-data fit
/// (`None` when the nested model stands in for it).
pub(super) type Scored = (RankEntry, Vec<Vec<f64>>, Option<Calibration>);
/// The fitted model a fit nests, when not the baseline: its χ², held-out predictions and
/// fitted parameters.
pub(super) type Nested = Option<(f64, Vec<Vec<f64>>, Vec<FittedParam>)>;

/// Scores candidate models (single effects and pairs) against one baseline.
pub(super) struct Scorer<'a> {
    pub(super) ctx: &'a Context<'a>,
    pub(super) base: &'a Baseline,
    pub(super) probes: &'a Probes,
    /// χ² of the nominal motor itself, for the strong-effect probes (once, if needed).
    nominal_chi2: std::sync::OnceLock<f64>,
    /// Fits whose starts ended in different valleys (reported in the notes).
    start_notes: std::sync::Mutex<Vec<String>>,
    /// Full-data fits of the same models against an earlier baseline of the same data
    /// (before the baseline was refitted), by name: starts of their own.
    earlier: Option<&'a BTreeMap<String, Calibration>>,
}

impl<'a> Scorer<'a> {
    pub(super) fn new(ctx: &'a Context<'a>, base: &'a Baseline, probes: &'a Probes) -> Self {
        Scorer {
            ctx,
            base,
            probes,
            nominal_chi2: std::sync::OnceLock::new(),
            start_notes: Default::default(),
            earlier: None,
        }
    }

    /// The scorer with `fits`, full-data fits of the same models to the same data from an
    /// earlier baseline, as further starts: a single effect's fit keeps the better of its
    /// own and the earlier one.
    pub(super) fn with_earlier_fits(self, fits: &'a BTreeMap<String, Calibration>) -> Self {
        Scorer { earlier: Some(fits), ..self }
    }

    /// The notes on fits whose starts disagreed.
    pub(super) fn into_notes(self) -> Vec<String> {
        self.start_notes.into_inner().unwrap_or_default()
    }

    /// Fits and scores the model with `effects` added to the baseline. `from`: the start of
    /// the fit (the calibrated baseline; for a pair, the lead effect's own fit, so the pair
    /// starts where the single ended). `nested`: the χ² and held-out predictions of the
    /// fitted model this one nests (the lead effect's fit for a pair; the baseline when
    /// None), which stand in when the fit ends worse than it.
    pub(super) fn score(&self, effects: &[Effect], from: &Motor, nested: &Nested) -> Scored {
        let ctx = self.ctx;
        let (motor, rows, opts, reduced, sc) = (ctx.motor, &ctx.rows[..], &ctx.opts, ctx.reduced, &ctx.sc);
        let (folds, k, n_read) = (&ctx.folds[..], ctx.k, ctx.n_read);
        let base = self.base;
        let (base_cal, base_cv, start) = (&base.cal, &base.cv, &base.start);
        let (base_nrmse, base_z2, base_e2, base_bic) = (base.nrmse, base.z2, &base.e2, base.bic);
        let untestable = &self.probes.untestable;
        let (nominal_chi2, start_notes) = (&self.nominal_chi2, &self.start_notes);
        let bic = |chi2: f64, kpar: usize| baseline::bic(chi2, kpar, n_read);
        let single_sig = |effects: &[Effect]| match effects {
            [e] => self.probes.base_sigs.get(e),
            _ => None,
        };
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
                z2_shrink_interval: (0.0, 0.0),
                lone_row_shares: (0.0, 0.0),
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
                Calibration::builder(s, rows)
                    .params(&params)
                    .options(&opts.fit)
                    .adding(added)
                    .start(Start::Extending(IRLS_START_RTOL))
                    .run()
            } else {
                Calibration::builder(s, rows).params(&params).options(&opts.fit).adding(added).run()
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
            let alt =
                match Calibration::builder(&typical_shape, rows).params(&held).options(&opts.fit).adding(added).run() {
                    Ok(c) if !c.abandoned => Calibration::builder(&c.motor, rows)
                        .params(&params)
                        .options(&opts.fit)
                        .adding(added)
                        .start(Start::Extending(IRLS_START_RTOL))
                        .run(),
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
            let mut s1 = with_bench(motor, start);
            for &e in effects {
                s1.effects.set(e, &e.info().with_primary(e.info().params[0].typical));
            }
            if let Ok(c1) = Calibration::builder(&s1, rows)
                .params(&params)
                .options(&opts.fit)
                .adding(added)
                .start(Start::Restart)
                .run()
            {
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
                    let m = strong_start(&with_bench(motor, start), effects, &params, x);
                    let seen = starts.last().is_some_and(|l| l.effects.to_string() == m.effects.to_string());
                    if !(seen || (x == 1.0 && second_start)) {
                        starts.push(m);
                    }
                }
                let probe = starts.into_iter().map(|m| (chi2_of(&m), m)).min_by(|a, b| a.0.total_cmp(&b.0));
                if let Some((_, m)) = probe.filter(|p| p.0 < PROBE_LEFT * nominal) {
                    if let Ok(c2) = Calibration::builder(&m, rows)
                        .params(&params)
                        .options(&opts.fit)
                        .adding(added)
                        .start(Start::Restart)
                        .run()
                    {
                        if !c2.abandoned && c2.chi2 < fit_chi2 {
                            cal = Ok(c2);
                        }
                    }
                }
            }
        }
        // The fit of the same model from the baseline before it was refitted. Its priors,
        // rows and weights are this fit's, so it is a start like any other, and costs no
        // fit: from the refitted baseline, whose parameters may have moved to mimic part
        // of a strong effect, the effect's own valley can lie out of reach of every start
        // above, and the better of the two optima is the model's fit.
        if nested.is_none() && effects.len() == 1 {
            let earlier = self.earlier.and_then(|f| f.get(&name)).filter(|c| !c.abandoned);
            let current = match &cal {
                Ok(c) if !c.abandoned => c.chi2,
                _ => f64::INFINITY,
            };
            if let Some(c0) = earlier.filter(|c| c.chi2 < current) {
                cal = Ok(c0.clone());
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
            let valleys = scan::valleys(&[start, motor], &fit_motor, rows, effects[0]);
            // (the valleys' fits are independent: in parallel, then taken in the scan's order)
            let from_valleys: Vec<_> = valleys
                .par_iter()
                .map(|v| {
                    let mut wide = params.clone();
                    scan::widen(&mut wide, effects[0], &v.values);
                    let mut s2 = with_bench(&v.base, start);
                    s2.effects.set(effects[0], &v.values);
                    let c2 = Calibration::builder(&s2, rows)
                        .params(&wide)
                        .options(&opts.fit)
                        .adding(added)
                        .start(Start::Restart)
                        .run();
                    (v, c2)
                })
                .collect();
            let mut disagree = Vec::new();
            for (v, c2) in from_valleys {
                if let Ok(c2) = c2 {
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
        // A pair's second effect is searched as a single one is: over its whole documented
        // strength and at its held shapes' levels, from the lead's fit where the pair
        // starts. The pair fit itself holds that shape at its typical value, the plainest
        // form, which the data's form of the second effect need not be near.
        let pair_at_noise = cal.as_ref().is_ok_and(|c| !c.abandoned && c.chi2 <= 1.5 * n_read as f64);
        if nested.is_some() && effects.len() == 2 && !pair_at_noise {
            let second = effects[1];
            let fit_motor = match &cal {
                Ok(c) if !c.abandoned => c.motor.clone(),
                _ => from.clone(),
            };
            // (the best valley only, its fit resumed from the lead's calibrated parameters:
            // a pair's fits are many, and a restart with a slow effect such as
            // thermal_drift's passes cost a combined campaign a minute)
            for v in scan::valleys(&[from], &fit_motor, rows, second).into_iter().take(1) {
                let mut wide = params.clone();
                scan::widen(&mut wide, second, &v.values);
                let mut s2 = v.base.clone();
                s2.effects.set(second, &v.values);
                if let Ok(c2) = Calibration::builder(&s2, rows)
                    .params(&wide)
                    .options(&opts.fit)
                    .adding(added)
                    .start(Start::Extending(IRLS_START_RTOL))
                    .run()
                {
                    let current = match &cal {
                        Ok(c) if !c.abandoned => c.chi2,
                        _ => f64::INFINITY,
                    };
                    if !c2.abandoned && c2.chi2 < current {
                        cal = Ok(c2);
                    }
                }
            }
        }
        // A strength that ends on its fit's own bound (8 × typical, or the bound the scan
        // widened) inside the documented range is fenced in, not where the data put it:
        // the bound moves out (3 ×, within the range) and the fit resumes from its end,
        // while that lowers χ² (at most `FENCE_RELEASES` times).
        let mut params = params;
        for _ in 0..FENCE_RELEASES {
            let Ok(c) = cal.as_ref() else { break };
            if c.abandoned || c.chi2 >= base_cal.chi2 {
                break;
            }
            let mut wide = params.clone();
            if !release_fences(&mut wide, &c.params, added) {
                break;
            }
            match Calibration::builder(&c.motor, rows)
                .params(&wide)
                .options(&opts.fit)
                .adding(added)
                .start(Start::Extending(IRLS_START_RTOL))
                .run()
            {
                Ok(c2) if !c2.abandoned && c2.chi2 < c.chi2 - 1.0 => {
                    cal = Ok(c2);
                    params = wide;
                }
                _ => break,
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
                    cross_validate(motor, start, rows, folds, k, effects, opts, reduced)
                } else {
                    approx_cv(&c, rows, folds, k, &opts.fit)
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
        // the held shape parameters where the scan moved them: the form the fit is of
        let mut fitted = fitted;
        if let Some(m) = &fitted_motor {
            for &e in effects {
                for (i, p) in e.info().params.iter().enumerate().filter(|(_, p)| p.held) {
                    let v = m.motor.effects.value(e, i);
                    if v != p.typical {
                        fitted.push(FittedParam {
                            name: format!("effects.{}.{}", e.name(), p.name),
                            value: v,
                            std_error: f64::NAN,
                            at_bound: false,
                            identifiable: false,
                            prior_rel_sd: None,
                        });
                    }
                }
            }
        }
        let (after, chi2_after, e2, z2s) = errors(rows, &preds, sc);
        let shrink = 1.0 - after / base_nrmse.max(1e-300);
        let interval = bootstrap_shrink(base_e2, &e2, opts.bootstrap, opts.seed);
        let z2_after = super::baseline::clipped(&z2s);
        let z2_interval = bootstrap_shrink(&base.z2s, &z2_after, opts.bootstrap, opts.seed);
        let lone_row_share = |before: &[f64], after: &[f64]| {
            let (b, a) = without_top_row(rows, before, after);
            lone_share(shrink_of(before, after), shrink_of(&b, &a))
        };
        let lone_row_shares = (lone_row_share(base_e2, &e2), lone_row_share(&base.z2s, &z2_after));
        let entry = RankEntry {
            effect: name,
            evidence,
            heldout_nrmse_after: after,
            heldout_chi2_after: chi2_after,
            shrink,
            shrink_interval: interval,
            z2_shrink_interval: z2_interval,
            lone_row_shares,
            params: fitted.into_iter().filter(|p| p.name.starts_with("effects.")).map(|p| (p.name, p.value)).collect(),
            signature_match: single_sig(effects).map(|s| s.matched),
            linear_chi2_drop: single_sig(effects).map(|s| s.linear_chi2_drop),
            signature_overlap: None,
            heldout_in_sample_folds: in_sample,
        };
        (entry, preds, fitted_motor)
    }
}

/// `motor` with the bench's nuisance parameters of the calibrated baseline `calibrated`
/// (the speed-std instrument's floor, the torque and temperature offsets). They are the
/// bench's, not the motor's, and every fit estimates them anew; a fit started from the
/// nominal motor would start them at zero, the floor on its bound, where its transformed
/// gradient vanishes and a first step can throw it to the other bound: such a fit can end
/// with the floor 50 % above every reading, nearly free in χ² but most of its held-out
/// NRMSE (the speed std's readings spread little, so its scale is small).
fn with_bench(motor: &Motor, calibrated: &Motor) -> Motor {
    let mut m = motor.clone();
    *m.effects.instrument_mut() = *calibrated.effects.instrument();
    m
}

/// The scored models' held-out predictions and full-data fits, by name.
#[derive(Default)]
pub(super) struct Fits {
    /// Held-out predictions of every scored model.
    pub(super) cv_preds: BTreeMap<String, Vec<Vec<f64>>>,
    /// Full-data fits of the models that have their own.
    pub(super) fits: BTreeMap<String, Calibration>,
}

impl Fits {
    /// Keeps the predictions and fits of `scored`; returns their entries.
    pub(super) fn absorb(&mut self, scored: Vec<Scored>) -> Vec<RankEntry> {
        scored
            .into_iter()
            .map(|(e, p, m)| {
                self.cv_preds.insert(e.effect.clone(), p);
                if let Some(m) = m {
                    self.fits.insert(e.effect.clone(), m);
                }
                e
            })
            .collect()
    }
}

/// Every candidate of the options scored on its own (in parallel), strongest first.
pub(super) fn score_singles(scorer: &Scorer, fits: &mut Fits) -> Vec<RankEntry> {
    let start = &scorer.base.start;
    let mut ranking: Vec<RankEntry> =
        fits.absorb(scorer.ctx.opts.candidates.par_iter().map(|&e| scorer.score(&[e], start, &None)).collect());
    sort_ranking(&mut ranking);
    ranking
}

/// True when a fit ended with an added effect's primary strength within 1 % of its range
/// above zero: the data pulled it there from the nested model's fit, as in a fit abandoned
/// as collapsing (which is tested at 1e-3 of the range, where the logistic transform
/// freezes the strength; a fit that stops on the decrement just above that has the same
/// answer). Such a fit gets no second start: on the 1000-row benchmark with seeds 21-28,
/// `tangential_compliance` ended at 0.13 % of its range, and its second start spent 41
/// passes (a fifth of the run's CPU) refitting the baseline before collapsing too.
pub(super) fn added_near_zero(params: &[FitParam], fitted: &[FittedParam], added: &[Effect]) -> bool {
    params.iter().zip(fitted).any(|(fp, p)| {
        matches!(fp.param, ParamRef::Effect(e, 0) if added.contains(&e)) && fp.lo == 0.0 && p.value <= 0.01 * fp.hi
    })
}

/// Most times a fit's fenced strengths are released (each × 3: 8 × typical becomes at
/// most 216 ×, within the documented range).
const FENCE_RELEASES: usize = 3;

/// Moves out the fit bound of every strength of the `added` effects that the fit
/// `fitted` (aligned with `params`) ended on, where the bound lies inside the effect's
/// documented range: to 3 × the bound, at most the range's end. True when one moved.
fn release_fences(params: &mut [FitParam], fitted: &[FittedParam], added: &[Effect]) -> bool {
    let mut moved = false;
    for (fp, p) in params.iter_mut().zip(fitted) {
        let ParamRef::Effect(e, i) = fp.param else { continue };
        let info = &e.info().params[i];
        if !added.contains(&e) || info.shape || !p.at_bound {
            continue;
        }
        let span = fp.hi - fp.lo;
        if fp.hi > 0.0 && fp.hi < info.max && p.value >= fp.hi - 0.01 * span {
            fp.hi = (3.0 * fp.hi).min(info.max);
            moved = true;
        } else if fp.lo < 0.0 && fp.lo > info.min && p.value <= fp.lo + 0.01 * span {
            fp.lo = (3.0 * fp.lo).max(info.min);
            moved = true;
        }
    }
    moved
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
pub(super) fn strong_start(motor: &Motor, effects: &[Effect], params: &[FitParam], times: f64) -> Motor {
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
pub(super) fn fit_params(
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
    for fp in params.iter().filter(|fp| matches!(fp.param, ParamRef::Instrument(InstrumentParam::SpeedStdFloorRpm))) {
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
        // (a held shape parameter stays where the start puts it: `scan` moves it)
        params.extend(effect_params(e));
    }
    (m, params)
}

pub(super) fn sort_ranking(r: &mut [RankEntry]) {
    r.sort_by(|a, b| b.evidence.total_cmp(&a.evidence).then(a.heldout_nrmse_after.total_cmp(&b.heldout_nrmse_after)));
}

/// The shrink 1 − √(Σafter/Σbefore) of per-reading terms.
pub(super) fn shrink_of(before: &[f64], after: &[f64]) -> f64 {
    1.0 - (after.iter().sum::<f64>() / before.iter().sum::<f64>().max(1e-300)).sqrt()
}

/// The part of a held-out gain (`shrink`) that stays without the row that gains most
/// (where the shrink is `without`): 1 when that row carries none of it, 0 or less when it
/// carries all.
pub(super) fn lone_share(shrink: f64, without: f64) -> f64 {
    if shrink > 0.0 {
        without / shrink
    } else {
        0.0
    }
}

/// The per-reading terms `before` and `after` (aligned with the readings of `rows`) without
/// those of the row whose readings gain most (the largest Σbefore − Σafter).
pub(super) fn without_top_row(rows: &[ObservedRow], before: &[f64], after: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut spans = Vec::with_capacity(rows.len());
    let mut at = 0;
    for r in rows {
        spans.push(at..(at + r.readings.len()).min(before.len()).min(after.len()));
        at += r.readings.len();
    }
    let gain = |s: &std::ops::Range<usize>| s.clone().map(|i| before[i] - after[i]).sum::<f64>();
    let top = spans.iter().max_by(|a, b| gain(a).total_cmp(&gain(b))).cloned().unwrap_or(0..0);
    let keep = |v: &[f64]| v.iter().enumerate().filter(|(i, _)| !top.contains(i)).map(|(_, x)| *x).collect();
    (keep(before), keep(after))
}

/// Percentile bootstrap (5 %, 95 %) of 1 − sqrt(mean e2_after)/sqrt(mean e2_before) over
/// readings resampled in pairs.
pub(super) fn bootstrap_shrink(before: &[f64], after: &[f64], n: usize, seed: u64) -> (f64, f64) {
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

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::super::tests::{quick, sag_data};
    use super::super::DiagnoseOptions;
    use super::*;

    /// The row left out is the one whose readings gain most together, not the reading
    /// that gains most alone; its readings go from both sides, and the rest keep their
    /// order. Its share is what stays of the shrink: 1 when it gains nothing, below zero
    /// when the rest lose.
    #[test]
    fn the_row_that_gains_most_is_left_out_whole() {
        let row = |n: usize| ObservedRow {
            op: crate::solve::OperatingPoint::new(100.0, 0.1, 200.0, 43_000.0),
            readings: vec![(Observable::SpeedRpm, 1.0, 1.0); n],
            ambient_c: 20.0,
            speed_std_clipped: false,
        };
        let rows = vec![row(2), row(1), row(2)];
        // row 0 gains 3 + 3, row 1 gains 5 alone, row 2 gains 1 + 1
        let before = [4.0, 4.0, 6.0, 2.0, 2.0];
        let after = [1.0, 1.0, 1.0, 1.0, 1.0];
        let (b, a) = without_top_row(&rows, &before, &after);
        assert_eq!((b, a), (vec![6.0, 2.0, 2.0], vec![1.0, 1.0, 1.0]));
        assert!((shrink_of(&before, &after) - (1.0 - (5.0f64 / 18.0).sqrt())).abs() < 1e-12);
        assert_eq!(lone_share(0.5, 0.5), 1.0);
        assert_eq!(lone_share(0.5, -0.1), -0.2);
        assert_eq!(lone_share(-0.1, 0.2), 0.0);
    }

    /// A strength the fit ended on at its own bound is released threefold, within the
    /// documented range; a strength inside its bounds, a shape, an effect the fit does not
    /// add, and a bound at the range's end stay.
    #[test]
    fn fenced_strengths_are_released_within_their_documented_range() {
        let on_bound = |params: &[FitParam], which: usize| -> Vec<FittedParam> {
            params
                .iter()
                .enumerate()
                .map(|(k, fp)| FittedParam {
                    name: String::new(),
                    value: if k == which { fp.hi } else { 0.5 * (fp.lo + fp.hi) },
                    std_error: f64::NAN,
                    at_bound: k == which,
                    identifiable: true,
                    prior_rel_sd: None,
                })
                .collect()
        };
        let e = Effect::HertzSoftening;
        let mut params = effect_params(e);
        let hi = params[0].hi;
        assert!((hi - 8e18).abs() < 1e6, "{hi}");
        let fitted = on_bound(&params, 0);
        assert!(!release_fences(&mut params.clone(), &fitted, &[Effect::VoltageSag]));
        assert!(release_fences(&mut params, &fitted, &[e]));
        assert_eq!((params[0].hi, params[1].hi), (3.0 * hi, effect_params(e)[1].hi));
        // inside its bounds: stays
        let inside = on_bound(&params, usize::MAX);
        assert!(!release_fences(&mut params, &inside, &[e]));
        // radial_friction's fit bound is its documented end (3): nothing to release
        let mut radial = effect_params(Effect::RadialFriction);
        assert!(!release_fences(&mut radial.clone(), &on_bound(&radial, 0), &[Effect::RadialFriction]));
        // the range's end is never passed
        let mut vs = effect_params(Effect::VoltageSag);
        for _ in 0..10 {
            let f = on_bound(&vs, 0);
            release_fences(&mut vs, &f, &[Effect::VoltageSag]);
        }
        assert_eq!(vs[0].hi, Effect::VoltageSag.info().params[0].max);
        radial[0].hi = 1.0;
        let fenced = on_bound(&radial, 0);
        assert!(release_fences(&mut radial, &fenced, &[Effect::RadialFriction]));
        assert_eq!(radial[0].hi, 3.0);
    }

    /// Preload-torque data with a voltage sag: without a time series `thermal_drift` moves
    /// no prediction, so it is untestable and ranked with the baseline's fit and its
    /// parameter penalty (negative evidence, no shrink); `voltage_sag` has a signature
    /// that matches the baseline's residual, and its fit is supported and shrinks the gap.
    #[test]
    fn candidates_are_probed_then_scored_against_the_baseline() {
        let (nominal, rows, groups) = sag_data();
        let opts = DiagnoseOptions { candidates: vec![Effect::ThermalDrift, Effect::VoltageSag], ..quick(false) };
        let ctx = Context::new(&nominal, &rows, &groups, &opts).unwrap();
        let base = baseline::fit(&ctx).unwrap();
        let probes = probe(&ctx, &base);
        assert_eq!(probes.untestable, vec![Effect::ThermalDrift]);
        assert_eq!(probes.base_sigs.keys().copied().collect::<Vec<_>>(), vec![Effect::VoltageSag]);
        assert!(probes.base_sigs[&Effect::VoltageSag].matched > 0.3);

        let scorer = Scorer::new(&ctx, &base, &probes);
        let mut fits = Fits::default();
        let ranking = score_singles(&scorer, &mut fits);
        assert_eq!(ranking.iter().map(|r| r.effect.as_str()).collect::<Vec<_>>(), ["voltage_sag", "thermal_drift"]);
        let (sag, drift) = (&ranking[0], &ranking[1]);
        assert!(sag.evidence > 5.0 && sag.shrink > 0.3 && sag.shrink_interval.0 > 0.0, "{sag:?}");
        assert!(fits.fits.contains_key("voltage_sag") && !fits.fits.contains_key("thermal_drift"));
        assert!(drift.evidence < 0.0 && drift.shrink == 0.0 && drift.params.is_empty(), "{drift:?}");
        assert_eq!(fits.cv_preds["thermal_drift"], base.cv.preds);
    }
}
