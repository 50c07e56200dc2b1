//! A diagnosis in words, as the summary (crate::diagnose) and the HTML report
//! (crate::report) both put it.

use crate::format::fmt_sig;
use trum_core::diagnose::Diagnosis;

/// The held-out NRMSE after adding the verdict's effect(s), when there is a verdict effect.
pub fn after_nrmse(d: &Diagnosis) -> Option<f64> {
    d.ranking.iter().find(|r| r.effect == d.verdict).map(|r| r.heldout_nrmse_after)
}

/// Verdict in words.
pub fn verdict_words(d: &Diagnosis) -> String {
    match d.verdict.as_str() {
        "none" => "none (the calibrated baseline is adequate within the noise)".into(),
        "unexplained" => match d.partial.as_ref().and_then(|p| d.ranking.iter().find(|r| &r.effect == p)) {
            Some(r) => format!(
                "unexplained (a real gap that no candidate effect closes; {} explains part of it, {} % of the held-out gap)",
                r.effect,
                fmt_sig(100.0 * r.shrink, 2)
            ),
            None => "unexplained (a real gap that no candidate effect closes)".into(),
        },
        v if v.contains('+') => format!("{v} (both effects together are needed to close the gap)"),
        v => v.to_string(),
    }
}
