//! The diagnosis as the JSON document of docs/DIAGNOSIS_JSON.md (its required fields
//! plus extras). Built here so that `trum diagnose --json` and Python's `trum.diagnose`
//! give the same document; writing it anywhere is the caller's business.

use super::Diagnosis;
use crate::measurements::Column;
use serde_json::{json, Value};

/// How to read `evidence` (in the JSON, the CLI summary and the report).
pub const EVIDENCE_SCALE: &str =
    "evidence = ½·ΔBIC vs the calibrated baseline (log Bayes factor): > 3 strong, > 5 very strong";

/// A JSON number, or `null` when not finite (JSON has no NaN).
pub fn num(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

/// Largest finite double: what a figure that overflowed (an infinity) is reported as.
pub const OVERFLOWED: f64 = f64::MAX;

/// The note of a diagnosis whose figures overflowed.
pub const NON_FINITE_NOTE: &str = "some of the diagnosis' figures are not finite numbers (readings of extreme \
     magnitude overflow the sums of squares): no effect can be named from these data; the figures that \
     overflowed are given as 1.7976931348623157e308, a not-a-number as 0 (evidence, shrink) or as that \
     value (a gap); check the data's plausible ranges (docs/MEASUREMENTS.md)";

/// A diagnosis with a non-finite required figure (the held-out and noise gaps, a
/// candidate's evidence, gap after or shrink) is no diagnosis: the figures
/// rest on sums that overflowed, and the ranking built on them means nothing. Such a
/// diagnosis gets the verdict `unexplained`, incomplete, nothing confounded, a note, and
/// finite figures in their place, so that every number the document requires is a number
/// (JSON has no NaN or infinity, and `null` is not a number): an infinity becomes
/// [`OVERFLOWED`] with its sign; a not-a-number becomes 0 for evidence and shrink (no
/// support, nothing closed) and [`OVERFLOWED`] for a gap (unbounded). A diagnosis with
/// finite figures is returned unchanged.
pub fn guard_non_finite(mut d: Diagnosis) -> Diagnosis {
    let gap = |v: &mut f64| -> bool {
        let bad = !v.is_finite();
        if bad {
            *v = if *v == f64::NEG_INFINITY { -OVERFLOWED } else { OVERFLOWED };
        }
        bad
    };
    let score = |v: &mut f64| -> bool {
        let bad = !v.is_finite();
        if bad {
            *v = if v.is_nan() { 0.0 } else { v.signum() * OVERFLOWED };
        }
        bad
    };
    // the required figures decide; the rest are made finite without deciding anything
    let mut bad = false;
    bad |= gap(&mut d.baseline_heldout_nrmse);
    bad |= gap(&mut d.noise_nrmse);
    gap(&mut d.noise_nrmse_weights);
    gap(&mut d.baseline_heldout_chi2_per_reading);
    for r in &mut d.ranking {
        bad |= score(&mut r.evidence);
        bad |= gap(&mut r.heldout_nrmse_after);
        bad |= score(&mut r.shrink);
        gap(&mut r.heldout_chi2_after);
        score(&mut r.shrink_interval.0);
        score(&mut r.shrink_interval.1);
        score(&mut r.z2_shrink_interval.0);
        score(&mut r.z2_shrink_interval.1);
    }
    for g in &mut d.gap_where {
        gap(&mut g.mean_residual);
        score(&mut g.z);
    }
    if bad {
        d.verdict = "unexplained".into();
        d.complete = false;
        d.confounded_with.clear();
        d.partial = None;
        d.notes.push(NON_FINITE_NOTE.into());
    }
    d
}

/// Unit of a measured column (empty when dimensionless or unknown).
pub fn unit(column: &str) -> &'static str {
    Column::from_name(column).map(|c| c.spec().unit).unwrap_or("")
}

/// Where the diagnosis came from, for the document's `motor` and `data` fields.
pub struct Provenance<'a> {
    /// Motor name.
    pub motor_name: &'a str,
    /// The motor as the user gave it (file path or preset name).
    pub motor_source: &'a str,
    /// The measurement file as the user gave it.
    pub data: &'a str,
    /// File line of each data row (for `heldout[].line`).
    pub lines: &'a [usize],
}

/// The spec's JSON document plus extras; non-finite numbers are `null`.
pub fn to_json(d: &Diagnosis, src: &Provenance<'_>) -> Value {
    let pairs =
        |v: &[(String, f64)]| -> Vec<Value> { v.iter().map(|(n, x)| json!({"name": n, "value": num(*x)})).collect() };
    // the held-out gap the verdict leaves (the baseline's for `none` and `unexplained`)
    let remaining = d
        .ranking
        .iter()
        .find(|r| super::same_set(&r.effect, &d.verdict))
        .map_or(d.baseline_heldout_nrmse, |r| r.heldout_nrmse_after);
    json!({
        "verdict": d.verdict,
        "complete": d.complete,
        "confounded_with": d.confounded_with,
        "partial": d.partial,
        "gap": {
            "baseline_heldout_nrmse": num(d.baseline_heldout_nrmse),
            "noise_nrmse": num(d.noise_nrmse),
            "remaining_heldout_nrmse": num(remaining),
            "noise_nrmse_weights": num(d.noise_nrmse_weights),
            "baseline_heldout_chi2_per_reading": num(d.baseline_heldout_chi2_per_reading),
            "noise_scale": d.noise_scale.iter().map(|(q, f, n)| json!({"quantity": q, "factor": num(*f), "residuals": n})).collect::<Vec<_>>(),
            "where": d.gap_where.iter().map(|g| json!({
                "quantity": g.quantity,
                "region": g.region,
                "mean_residual": num(g.mean_residual),
                "unit": unit(&g.quantity),
                "n": g.n,
                "z": num(g.z),
            })).collect::<Vec<_>>(),
        },
        "ranking": d.ranking.iter().map(|r| json!({
            "effect": r.effect,
            "evidence": num(r.evidence),
            "heldout_nrmse_after": num(r.heldout_nrmse_after),
            "heldout_chi2_after": num(r.heldout_chi2_after),
            "shrink": num(r.shrink),
            "shrink_interval": [num(r.shrink_interval.0), num(r.shrink_interval.1)],
            "z2_shrink_interval": [num(r.z2_shrink_interval.0), num(r.z2_shrink_interval.1)],
            "lone_row_shares": [num(r.lone_row_shares.0), num(r.lone_row_shares.1)],
            "params": pairs(&r.params),
            "signature_match": r.signature_match.map(num),
            "linear_chi2_drop": r.linear_chi2_drop.map(num),
            "signature_overlap": r.signature_overlap.map(num),
            "heldout_in_sample_folds": r.heldout_in_sample_folds,
        })).collect::<Vec<_>>(),
        "separating_campaigns": d.separating_campaigns.iter().map(|s| json!({
            "effects": [s.effects.0, s.effects.1],
            "rival": s.rival.name(),
            "chi2_on_the_data": num(s.chi2_on_the_data),
            "campaigns": s.chi2.iter().map(|(c, x)| json!({"campaign": c, "chi2": num(*x)})).collect::<Vec<_>>(),
            "best": s.best().map(|b| b.0),
        })).collect::<Vec<_>>(),
        "evidence_scale": EVIDENCE_SCALE,
        "notes": d.notes,
        "n_rows": d.n_rows,
        "n_readings": d.n_readings,
        "folds": d.folds,
        "baseline_params": pairs(&d.baseline_params),
        "baseline_held_near_prior": d.baseline_held_near_prior,
        "motor": { "name": src.motor_name, "source": src.motor_source },
        "data": src.data,
        "heldout": d.heldout.iter().map(|h| json!({
            "row": h.row,
            "line": src.lines.get(h.row),
            "quantity": h.observable.column(),
            "measured": num(h.measured),
            "baseline": num(h.baseline),
            "after": num(h.after),
        })).collect::<Vec<_>>(),
    })
}
