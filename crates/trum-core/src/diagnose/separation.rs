//! Which measurement would separate effects that the data do not. Two candidates' fitted
//! models (each the calibrated motor with its effect) are run through every single
//! campaign of `trum synth` (docs/SYNTH.md) at the data's drive, and the difference of
//! their readings, in the nominal bench noise of that page, is the χ² a test between the
//! two would gain from that campaign: the classical criterion for discriminating between
//! rival models by design (Atkinson and Fedorov 1975, T-optimality), evaluated here at the
//! two fits rather than optimised over a continuous design.
//!
//! It changes no verdict; it tells the experimenter what to measure next.

use crate::observable::ObservedRow;
use crate::params::Motor;
use crate::solve::{solve_prepared, Prepared};
use crate::synth::{reading_noise, synthesize, Campaign, SynthConfig};

/// The single campaign kinds of `trum synth` (a combined campaign is their union).
pub const CAMPAIGNS: [Campaign; 4] =
    [Campaign::PreloadTorque, Campaign::FrequencySweep, Campaign::WarmUp, Campaign::Stability];

/// A log Bayes factor (evidence, ½·ΔBIC) below which the lead's preference over a rival
/// is not strong: 2·ln B < 6 is at most "positive" evidence on the scale of Kass and
/// Raftery 1995 ("Bayes factors", J. Am. Stat. Assoc. 90, 773-795), the scale the
/// diagnosis JSON's `evidence_scale` states.
pub const CLOSE_EVIDENCE: f64 = 3.0;

/// Why the separation of a rival effect from the lead is reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rival {
    /// In `confounded_with`: the data do not tell the two apart.
    Confounded,
    /// Not confounded, but the best other single effect, supported and behind the lead by
    /// less than [`CLOSE_EVIDENCE`]: the data prefer the lead, though not strongly.
    CloseInEvidence,
}

impl Rival {
    /// The name in the diagnosis JSON.
    pub fn name(self) -> &'static str {
        match self {
            Rival::Confounded => "confounded",
            Rival::CloseInEvidence => "close_in_evidence",
        }
    }
}

/// The rivals of the single effect `lead` whose separation from it is reported: every
/// effect in `confounded`, then the other single effect of `ranking` with the most
/// evidence where it is supported (evidence > 0) and within [`CLOSE_EVIDENCE`]
/// of the lead's evidence. Pairs are never rivals: a separation compares two fits of
/// one effect each. Empty where `lead` is a pair or not in `ranking`.
pub fn rivals(ranking: &[super::RankEntry], lead: &str, confounded: &[String]) -> Vec<(String, Rival)> {
    let Some(lead_evidence) = ranking.iter().find(|r| r.effect == lead).map(|r| r.evidence) else {
        return Vec::new();
    };
    if lead.contains('+') {
        return Vec::new();
    }
    let mut out: Vec<(String, Rival)> = confounded.iter().map(|e| (e.clone(), Rival::Confounded)).collect();
    let runner_up = ranking
        .iter()
        .filter(|r| r.effect != lead && !r.effect.contains('+') && !confounded.contains(&r.effect))
        .filter(|r| r.evidence.is_finite())
        .max_by(|a, b| a.evidence.total_cmp(&b.evidence));
    if let Some(r) = runner_up.filter(|r| r.evidence > 0.0 && lead_evidence - r.evidence < CLOSE_EVIDENCE) {
        out.push((r.effect.clone(), Rival::CloseInEvidence));
    }
    out
}

/// How well each campaign would separate two fitted models.
#[derive(Clone, Debug, PartialEq)]
pub struct Separation {
    /// The two effects (the verdict's first).
    pub effects: (String, String),
    /// Why this pair is reported.
    pub rival: Rival,
    /// Per campaign kind (its `trum synth` name): Σ over its readings of the squared
    /// difference of the two models' predictions in units of the nominal bench noise
    /// (docs/SYNTH.md, noise level 1). 0 where the two models agree on every reading.
    pub chi2: Vec<(&'static str, f64)>,
    /// The same sum over the data's own operating points and quantities, for comparison:
    /// what the data already give a test between the two fits.
    pub chi2_on_the_data: f64,
}

impl Separation {
    /// The campaign with the largest χ², with its χ²; none when no campaign separates the
    /// two (every χ² is 0 or not a number).
    pub fn best(&self) -> Option<(&'static str, f64)> {
        self.chi2.iter().copied().filter(|(_, c)| c.is_finite() && *c > 0.0).max_by(|a, b| a.1.total_cmp(&b.1))
    }
}

/// The drive of a campaign for `rows`: the median voltage and frequency of the data [V,
/// Hz], the operating point at which an experimenter would extend them.
pub fn drive_of(rows: &[ObservedRow]) -> Option<(f64, f64)> {
    let median = |mut xs: Vec<f64>| {
        xs.retain(|x| x.is_finite());
        xs.sort_by(f64::total_cmp);
        xs.get(xs.len() / 2).copied()
    };
    Some((
        median(rows.iter().map(|r| r.op.voltage_v).collect())?,
        median(rows.iter().map(|r| r.op.frequency_hz).collect())?,
    ))
}

/// The χ² with which each campaign kind, run at `voltage_v` and `frequency_hz`, would tell
/// motor `a` from motor `b` (both with their effects and the bench's instruments as
/// fitted), and the χ² the data's own `rows` give. The campaigns' operating points are
/// those `trum synth` plans for `a` (its load torques follow `a`'s stall torque), each
/// reading weighed by the nominal bench noise; the data's readings are weighed by the
/// noise levels the diagnosis gave them. Units: χ² [-], the drive in V and Hz.
pub fn separation(
    names: (&str, &str),
    rival: Rival,
    a: &Motor,
    b: &Motor,
    rows: &[ObservedRow],
    voltage_v: f64,
    frequency_hz: f64,
) -> Separation {
    let (pa, pb) = (Prepared::new(a).without_stall_torque(), Prepared::new(b).without_stall_torque());
    let chi2 = CAMPAIGNS
        .iter()
        .filter_map(|&campaign| {
            let cfg = SynthConfig {
                campaign,
                noise: 0.0,
                perturbation: 0.0,
                voltage_v,
                frequency_hz,
                truth_forms: false,
                nominal_effects: a.effects.clone(),
                ..SynthConfig::default()
            };
            // (a campaign `trum synth` cannot plan for `a` is left out)
            let planned = synthesize(a, &cfg).ok()?;
            let sum: f64 = planned
                .iter()
                .map(|r| {
                    let mut row = r.observed();
                    for (o, v, sigma) in row.readings.iter_mut() {
                        *sigma = reading_noise(*o, *v);
                    }
                    difference(&row, &expected(a, &pa, &row), &expected(b, &pb, &row))
                })
                .sum();
            Some((campaign.name(), finite(sum)))
        })
        .collect();
    let chi2_on_the_data: f64 = rows.iter().map(|r| difference(r, &expected(a, &pa, r), &expected(b, &pb, r))).sum();
    Separation {
        effects: (names.0.to_string(), names.1.to_string()),
        rival,
        chi2,
        chi2_on_the_data: finite(chi2_on_the_data),
    }
}

/// The readings `motor` predicts for `row`, through its bench instruments (NaN where it has
/// no solution): the predictions calibration compares with the data.
fn expected(motor: &Motor, p: &Prepared, row: &ObservedRow) -> Vec<f64> {
    let inst = motor.effects.instrument();
    let s = solve_prepared(p, motor, &inst.operating_point(&row.op), None);
    row.readings
        .iter()
        .map(
            |&(o, _, sigma)| {
                if s.status.is_valid() {
                    crate::calibrate::expected(o, row, &s, inst, sigma)
                } else {
                    f64::NAN
                }
            },
        )
        .collect()
}

/// Σ ((x_a − x_b) / σ)² over the readings of `row` (σ each reading's noise level), `xa` and
/// `xb` the two models' predictions; a reading either model gives no number for counts 0.
fn difference(row: &ObservedRow, xa: &[f64], xb: &[f64]) -> f64 {
    row.readings
        .iter()
        .zip(xa.iter().zip(xb))
        .map(|(&(_, _, sigma), (&x, &y))| {
            let d = (x - y) / sigma;
            if d.is_finite() {
                d * d
            } else {
                0.0
            }
        })
        .sum()
}

/// A sum of squares that overflowed, as the largest double (the diagnosis JSON holds only
/// finite numbers).
fn finite(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        f64::MAX
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::observable::Observable;
    use crate::presets::preset;

    fn generic() -> Motor {
        preset("generic60").expect("preset")
    }

    fn with(effect: &str) -> Motor {
        let mut m = generic();
        m.effects.parse_assignment(effect).expect("effect");
        m
    }

    /// A model against itself: no campaign separates it.
    #[test]
    fn a_model_is_not_separated_from_itself() {
        let m = with("radial_friction=1");
        let s = separation(("a", "b"), Rival::Confounded, &m, &m, &[], 200.0, 43e3);
        assert!(s.chi2.iter().all(|&(_, c)| c == 0.0), "{s:?}");
        assert_eq!(s.best(), None);
        assert_eq!(s.chi2.len(), CAMPAIGNS.len());
        assert_eq!(s.chi2_on_the_data, 0.0);
        // every campaign by the name `trum synth` reads back
        for (name, _) in &s.chi2 {
            assert_eq!(Campaign::from_name(name).expect("name").name(), *name);
        }
    }

    /// A warm-up drift acts only through the time since switch-on: of the campaigns only
    /// the warm-up, the one time series, sees it.
    #[test]
    fn only_a_warm_up_separates_a_thermal_drift() {
        let (a, b) = (generic(), with("thermal_drift=-4e-4"));
        let s = separation(("none", "thermal_drift"), Rival::Confounded, &a, &b, &[], 200.0, 43e3);
        let get = |n: &str| s.chi2.iter().find(|(c, _)| *c == n).expect("campaign").1;
        assert!(get("warm-up") > 25.0, "{s:?}");
        for c in ["preload-torque", "frequency-sweep", "stability"] {
            assert_eq!(get(c), 0.0, "{c}: {s:?}");
        }
        assert_eq!(s.best().map(|b| b.0), Some("warm-up"));
    }

    /// A difference of one noise level on one reading counts one; a reading without a
    /// number counts nothing.
    #[test]
    fn the_difference_counts_noise_levels() {
        let row = ObservedRow {
            op: crate::solve::OperatingPoint::new(200.0, 0.1, 200.0, 43e3),
            readings: vec![(Observable::SpeedRpm, 100.0, 0.8), (Observable::CurrentA, 0.2, 0.01)],
            ambient_c: 25.0,
            speed_std_clipped: false,
        };
        assert!((difference(&row, &[100.0, 0.2], &[100.8, 0.2]) - 1.0).abs() < 1e-12);
        assert!((difference(&row, &[100.0, 0.2], &[100.0, 0.23]) - 9.0).abs() < 1e-9);
        assert_eq!(difference(&row, &[f64::NAN, 0.2], &[100.0, 0.2]), 0.0);
    }
}
