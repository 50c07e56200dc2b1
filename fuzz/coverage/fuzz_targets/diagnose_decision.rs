//! The diagnosis' decision stage alone (`trum_core::diagnose::fuzzing`, built with
//! `--cfg fuzzing`): the rows of `common/rows.rs` from the input's first 50 bytes, and
//! from the rest the figures fits would give — the baseline's held-out gap, up to seven
//! single effects and three pairs with their evidence, held-out NRMSE and mean z² (each
//! shrink consistent with them) and bootstrap intervals, their held-out predictions, the
//! singles' full-data residuals and signatures. A whole diagnosis reaches this stage a
//! few times a second; here it runs at thousands of inputs a second, and on figures that
//! fits seldom give (ties at the thresholds, intervals straddling zero, pairs worse than
//! their singles).
//! Properties: no panic; the same input decides the same; `none` only without a gap, with
//! nothing confounded or partial; `unexplained` incomplete, with the best supported single
//! as `partial`; a single verdict a supported single; a pair verdict one of the pairs
//! given, supported, ahead of the best supported single by more than 5 in evidence and no
//! worse on held-out data, its stronger effect first; the confounded effects supported
//! singles other than the verdict, none for a pair; the ranking the singles plus the pairs
//! where pairs were tried.
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::diagnose::fuzzing::{decide, FittedFigures};
use trum_core::diagnose::{DiagnoseOptions, RankEntry};
use trum_core::effects::ALL;
use trum_core::presets;

#[path = "../common/rows.rs"]
mod rows;

/// The input's bytes after the rows, read one at a time (zeros once they run out).
struct Bytes<'a>(std::slice::Iter<'a, u8>);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        self.0.next().copied().unwrap_or(0)
    }
    fn unit(&mut self) -> f64 {
        f64::from(self.byte()) / 255.0
    }
    /// 10^(lo + (hi − lo)·u): a positive figure over decades.
    fn decades(&mut self, lo: f64, hi: f64) -> f64 {
        10f64.powf(lo + (hi - lo) * self.unit())
    }
    /// A signed figure near the thresholds at 0 and 5 as often as far from them.
    fn evidence(&mut self) -> f64 {
        let b = self.byte();
        let magnitude = if b & 1 == 0 { 10.0 * self.unit() } else { self.decades(0.0, 4.0) };
        if b & 2 == 0 {
            magnitude
        } else {
            -magnitude
        }
    }
    /// A bootstrap interval around `x`.
    fn interval(&mut self, x: f64) -> (f64, f64) {
        let (lo, hi) = (0.5 * self.unit(), 0.5 * self.unit());
        (x - lo, x + hi)
    }
}

/// An entry named `effect` whose held-out figures follow from the baseline's (`base_nrmse`,
/// `base_z2`) as a fit's do.
fn entry(b: &mut Bytes, effect: String, base_nrmse: f64, base_z2: f64) -> RankEntry {
    let heldout_nrmse_after = base_nrmse * b.decades(-2.0, 0.3);
    let heldout_chi2_after = base_z2 * b.decades(-2.0, 0.3);
    let shrink = 1.0 - heldout_nrmse_after / base_nrmse;
    let z2_shrink = 1.0 - (heldout_chi2_after / base_z2).sqrt();
    RankEntry {
        effect,
        evidence: b.evidence(),
        heldout_nrmse_after,
        heldout_chi2_after,
        shrink,
        shrink_interval: b.interval(shrink),
        z2_shrink_interval: b.interval(z2_shrink),
        params: Vec::new(),
        signature_match: None,
        linear_chi2_drop: None,
        signature_overlap: None,
        heldout_in_sample_folds: 0,
    }
}

fn supported(r: &RankEntry) -> bool {
    r.evidence > 5.0 && r.shrink > 0.0 && (r.shrink_interval.0 > 0.0 || r.z2_shrink_interval.0 > 0.0)
}

fn same_set(a: &str, b: &str) -> bool {
    let mut x: Vec<&str> = a.split('+').collect();
    let mut y: Vec<&str> = b.split('+').collect();
    x.sort_unstable();
    y.sort_unstable();
    x == y
}

fuzz_target!(|data: &[u8]| {
    let motor = presets::find("generic60").expect("preset").motor();
    let split = data.len().min(50);
    let Some(m) = rows::small_rows(&motor, &data[..split]) else { return };
    let bench = trum_core::bench::observations(&m, &motor);
    let readings: Vec<Vec<f64>> = bench.rows.iter().map(|r| r.readings.iter().map(|x| x.1).collect()).collect();
    let n_read: usize = readings.iter().map(Vec::len).sum();
    let mut b = Bytes(data[split..].iter());
    let config = b.byte();
    let base_nrmse = b.decades(-4.0, 1.0);
    let gap_noise = base_nrmse * 2.0 * b.unit();
    let base_z2 = b.decades(-1.0, 3.0);
    let z2_upper_noise = base_z2 * (1.0 + 3.0 * b.unit());
    let mut singles = Vec::new();
    for _ in 0..config % 8 {
        let e = ALL[usize::from(b.byte()) % ALL.len()];
        if !singles.iter().any(|r: &RankEntry| r.effect == e.name()) {
            singles.push(entry(&mut b, e.name().to_string(), base_nrmse, base_z2));
        }
    }
    let mut pairs: Vec<RankEntry> = Vec::new();
    for _ in 0..(config >> 3) % 4 {
        let (i, j) = (usize::from(b.byte()) % ALL.len(), usize::from(b.byte()) % ALL.len());
        let name = format!("{}+{}", ALL[i].name(), ALL[j].name());
        if i != j && !pairs.iter().any(|p| same_set(&p.effect, &name)) {
            pairs.push(entry(&mut b, name, base_nrmse, base_z2));
        }
    }
    let mut figures = FittedFigures { base_nrmse, gap_noise, base_z2, z2_upper_noise, ..FittedFigures::default() };
    for r in singles.iter().chain(&pairs) {
        let preds = readings.iter().map(|row| row.iter().map(|v| v * (1.0 + 0.4 * (b.unit() - 0.5))).collect()).collect();
        figures.cv_preds.insert(r.effect.clone(), preds);
    }
    for r in &singles {
        figures.z2.insert(r.effect.clone(), (0..n_read).map(|_| (4.0 * b.unit()).powi(2)).collect());
        let e = trum_core::Effect::from_name(&r.effect).expect("an effect's name");
        figures.signatures.insert(e, (0..n_read).map(|_| 2.0 * b.unit() - 1.0).collect());
    }
    figures.singles = singles.clone();
    figures.pairs = pairs.clone();
    let opts = DiagnoseOptions { bootstrap: usize::from(config >> 5) * 4, try_pairs: config & 128 != 0, ..DiagnoseOptions::default() };
    let Ok(d) = decide(&motor, &bench.rows, &bench.groups, &opts, figures.clone()) else { return };
    assert_eq!(decide(&motor, &bench.rows, &bench.groups, &opts, figures).ok().as_ref(), Some(&d), "not deterministic");

    let best_single = {
        let mut s = singles.clone();
        s.sort_by(|a, b| b.evidence.total_cmp(&a.evidence).then(a.heldout_nrmse_after.total_cmp(&b.heldout_nrmse_after)));
        s.into_iter().find(supported)
    };
    let v = d.verdict.as_str();
    match v {
        "none" => {
            assert!(z2_upper_noise <= 2.0, "none with a gap: {d:?}");
            assert!(d.complete && d.confounded_with.is_empty() && d.partial.is_none(), "{d:?}");
            assert!(!d.pairs_tried, "pairs tried without a gap: {d:?}");
        }
        "unexplained" => {
            assert!(!d.complete, "{d:?}");
            assert_eq!(d.partial, best_single.as_ref().map(|b| b.effect.clone()), "{d:?}");
        }
        _ if !v.contains('+') => {
            let r = singles.iter().find(|r| r.effect == v).unwrap_or_else(|| panic!("{v} not a single given: {d:?}"));
            assert!(supported(r), "{v} not supported: {d:?}");
            assert!(d.partial.is_none(), "{d:?}");
        }
        _ => {
            assert!(d.pairs_tried, "{d:?}");
            let p = pairs.iter().find(|p| same_set(&p.effect, v)).unwrap_or_else(|| panic!("{v} not a pair given: {d:?}"));
            assert!(supported(p), "{v} not supported: {d:?}");
            if let Some(s) = &best_single {
                assert!(p.evidence > s.evidence + 5.0, "{v} not ahead of {}: {d:?}", s.effect);
                assert!(p.heldout_nrmse_after <= s.heldout_nrmse_after && p.heldout_chi2_after <= s.heldout_chi2_after);
            }
            let ev = |n: &str| singles.iter().find(|r| r.effect == n).map_or(f64::NEG_INFINITY, |r| r.evidence);
            let names: Vec<&str> = v.split('+').collect();
            assert!(ev(names[0]) >= ev(names[1]), "{v}: the weaker effect first: {d:?}");
            assert!(d.confounded_with.is_empty() && d.partial.is_none(), "{d:?}");
        }
    }
    for c in &d.confounded_with {
        assert!(c != v && !c.contains('+'), "{c} confounded with {v}");
        let r = singles.iter().find(|r| &r.effect == c).unwrap_or_else(|| panic!("{c} not a single given"));
        assert!(r.evidence > 5.0, "{c} confounded with {v} without support: {d:?}");
    }
    let mut seen = d.confounded_with.clone();
    seen.sort();
    seen.dedup();
    assert_eq!(seen.len(), d.confounded_with.len(), "a confounded effect twice: {d:?}");
    let expected = singles.len() + if d.pairs_tried { pairs.len() } else { 0 };
    assert_eq!(d.ranking.len(), expected, "{d:?}");
});
