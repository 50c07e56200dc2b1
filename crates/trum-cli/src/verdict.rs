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
        v if !d.complete => format!(
            "{v} (incomplete: it closes part of the held-out gap, {} % of it, and a gap beyond the noise remains)",
            fmt_sig(100.0 * d.ranking.iter().find(|r| r.effect == v).map_or(0.0, |r| r.shrink), 2)
        ),
        v if v.contains('+') => format!("{v} (both effects together are needed to close the gap)"),
        v => v.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An incomplete verdict says so in words, with what it closes; a complete one does not.
    #[test]
    fn an_incomplete_verdict_is_worded_as_such() {
        let entry = trum_core::diagnose::RankEntry {
            effect: "voltage_sag".into(),
            evidence: 40.0,
            heldout_nrmse_after: 0.1,
            heldout_chi2_after: 4.0,
            shrink: 0.35,
            shrink_interval: (0.2, 0.5),
            z2_shrink_interval: (0.2, 0.5),
            lone_row_shares: (1.0, 1.0),
            params: vec![],
            signature_match: None,
            linear_chi2_drop: None,
            signature_overlap: None,
            heldout_in_sample_folds: 0,
        };
        let mut d = Diagnosis {
            verdict: "voltage_sag".into(),
            complete: false,
            confounded_with: vec![],
            partial: None,
            baseline_heldout_nrmse: 0.15,
            noise_nrmse: 0.02,
            noise_nrmse_weights: 0.03,
            baseline_heldout_chi2_per_reading: 9.0,
            noise_scale: vec![],
            gap_where: vec![],
            ranking: vec![entry],
            notes: vec![],
            n_rows: 10,
            n_readings: 30,
            folds: 4,
            baseline_params: vec![],
            baseline_held_near_prior: vec![],
            heldout: vec![],
            separating_campaigns: vec![],
        };
        let w = verdict_words(&d);
        assert!(w.starts_with("voltage_sag (incomplete") && w.contains("35 %"), "{w}");
        d.complete = true;
        assert_eq!(verdict_words(&d), "voltage_sag");
    }
}
