//! Whether the calibrated baseline's misses repeat from run to run: the test that tells a
//! gap in the motor's model from scatter that belongs to each run.
//!
//! The noise levels come from residuals about lines through neighbouring readings within
//! each run (`crate::noise`), which see the noise that changes from one reading to the next.
//! Noise that is correlated along a run (a run's mounting, its friction layer's state or
//! its drive's warm-up differing from the next run's: at the extreme a random offset per
//! run) is smooth on that scale, so those levels leave it out, and a baseline that is right
//! misses held-out data by more than they allow. A gap in the model is a function of the
//! operating point: where two runs pass near the same operating point, their misses agree.
//! Scatter of the runs is not: it is independent from run to run.
//!
//! The statistic: every normalised residual z of the baseline's full-data fit (the
//! reading's miss over its noise level, clipped at √[`OUTLIER_Z2`]) times the mean of the
//! residuals of the same quantity at the [`NEIGHBOURS`] nearest operating points of
//! *other* runs (each operating coordinate over its range in the data), summed. Misses
//! that repeat across runs make it large; under independent runs whose residuals are as
//! likely to have either sign, every assignment of a sign to each run's residuals as a
//! whole is as likely as the data's, so the p-value is the share of sign assignments with
//! a statistic at least the data's (a sign-flip randomisation test; Fisher 1935, The
//! Design of Experiments §21; exact over all assignments up to [`EXACT_RUNS`] runs, else
//! [`FLIPS`] random ones). Flipping whole runs keeps each run's own correlation, however
//! strong, which is what makes the test valid for such noise. With fewer than
//! [`MIN_RUNS`] runs no p-value reaches 5 % and there is no test.
//!
//! The full-data residuals rather than the held-out ones: a baseline refitted without a
//! block of runs bends towards the runs beside it, so held-out misses of neighbouring runs
//! can disagree even where the model lacks something (a strong `voltage_sag` on a
//! `trum60-qut` preload-torque campaign: agreement −0.39 held out, 1.00 on the full-data
//! fit). A fit through runs that scatter independently leaves residuals that alternate
//! between neighbouring runs (agreement near −1, p near 1), not ones that agree.

use super::folds::OUTLIER_Z2;
use crate::observable::ObservedRow;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;

/// Residuals of other runs averaged into the prediction of each one.
pub(super) const NEIGHBOURS: usize = 3;
/// Fewest runs with held-out readings for a test (2^(n−1) sign patterns: 32 at six runs,
/// so a p-value can fall below 5 %).
pub(super) const MIN_RUNS: usize = 6;
/// Up to this many runs every sign pattern is counted (2^15 of them at 16 runs).
const EXACT_RUNS: usize = 16;
/// Random sign patterns beyond [`EXACT_RUNS`] runs.
const FLIPS: usize = 19_999;
/// The misses repeat across runs when the p-value is at most this.
pub(super) const REPEAT_P: f64 = 0.05;

/// The outcome of the test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Repeat {
    /// Share of sign patterns of the runs with a statistic at least the data's.
    pub(super) p_value: f64,
    /// Runs with held-out readings.
    pub(super) runs: usize,
    /// The statistic over its largest value under any sign pattern: 1 where every run's
    /// misses agree with its neighbours', about 0 for independent runs.
    pub(super) agreement: f64,
}

impl Repeat {
    /// The misses repeat from run to run (at [`REPEAT_P`]).
    pub(super) fn repeats(&self) -> bool {
        self.p_value <= REPEAT_P
    }
}

/// The test on the normalised residuals `z` of `rows` (one per reading, in order), the run
/// of each row `groups` (rows beyond it are in run ""), with `seed` for the random sign
/// patterns. `None` with fewer than [`MIN_RUNS`] runs or no reading that has a neighbour
/// in another run.
pub(super) fn across_runs(rows: &[ObservedRow], z: &[f64], groups: &[String], seed: u64) -> Option<Repeat> {
    let coords = coordinates(rows);
    let mut run_of: BTreeMap<&str, usize> = BTreeMap::new();
    let run_index: Vec<usize> = (0..rows.len())
        .map(|i| {
            let g = groups.get(i).map(String::as_str).unwrap_or("");
            let n = run_of.len();
            *run_of.entry(g).or_insert(n)
        })
        .collect();
    // held-out normalised residuals by quantity: (row, z)
    let mut by_quantity: BTreeMap<_, Vec<(usize, f64)>> = BTreeMap::new();
    let clip = OUTLIER_Z2.sqrt();
    let mut zs = z.iter();
    for (i, r) in rows.iter().enumerate() {
        for &(o, _, _) in &r.readings {
            let Some(&z) = zs.next() else { break };
            if z.is_finite() {
                by_quantity.entry(o).or_default().push((i, z.clamp(-clip, clip)));
            }
        }
    }
    let n_runs = run_of.len();
    // pair sums C[a][b] = Σ z_i · z_j / NEIGHBOURS over readings i of run a and their
    // neighbours j in run b ≠ a
    let mut pair = vec![0.0; n_runs * n_runs];
    let mut used = vec![false; n_runs];
    for readings in by_quantity.values() {
        for &(i, zi) in readings {
            let near = nearest_in_other_runs(i, readings, &coords, &run_index);
            if near.is_empty() {
                continue;
            }
            let (a, w) = (run_index[i], 1.0 / near.len() as f64);
            used[a] = true;
            for &(j, zj) in &near {
                pair[a * n_runs + run_index[j]] += w * zi * zj;
            }
        }
    }
    let runs: Vec<usize> = (0..n_runs).filter(|&a| used[a]).collect();
    if runs.len() < MIN_RUNS {
        return None;
    }
    // the symmetric form: S(s) = Σ_{a<b} s_a·s_b·(C_ab + C_ba)
    let m = runs.len();
    let mut sym = vec![0.0; m * m];
    for (x, &a) in runs.iter().enumerate() {
        for (y, &b) in runs.iter().enumerate() {
            if x != y {
                sym[x * m + y] = pair[a * n_runs + b] + pair[b * n_runs + a];
            }
        }
    }
    let statistic = |signs: &[f64]| -> f64 {
        let mut s = 0.0;
        for x in 0..m {
            let row = &sym[x * m..(x + 1) * m];
            let inner: f64 = (x + 1..m).map(|y| signs[y] * row[y]).sum();
            s += signs[x] * inner;
        }
        s
    };
    let observed = statistic(&vec![1.0; m]);
    let largest: f64 = (0..m).map(|x| (x + 1..m).map(|y| sym[x * m + y].abs()).sum::<f64>()).sum();
    let tolerance = 1e-12 * largest;
    let (mut at_least, mut total) = (0usize, 0usize);
    let mut signs = vec![1.0; m];
    if m <= EXACT_RUNS {
        // the first run's sign fixed: S is even in a global flip
        for pattern in 0u32..(1u32 << (m - 1)) {
            for (x, s) in signs.iter_mut().enumerate().skip(1) {
                *s = if pattern >> (x - 1) & 1 == 1 { -1.0 } else { 1.0 };
            }
            total += 1;
            at_least += usize::from(statistic(&signs) >= observed - tolerance);
        }
    } else {
        // the data's own pattern counts once (Phipson and Smyth 2010)
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        total = 1;
        at_least = 1;
        for _ in 0..FLIPS {
            for s in signs.iter_mut().skip(1) {
                *s = if rng.random::<bool>() { -1.0 } else { 1.0 };
            }
            total += 1;
            at_least += usize::from(statistic(&signs) >= observed - tolerance);
        }
    }
    Some(Repeat {
        p_value: at_least as f64 / total as f64,
        runs: m,
        agreement: if largest > 0.0 { observed / largest } else { 0.0 },
    })
}

/// The operating coordinates of each row (preload, torque, voltage, frequency, elapsed
/// time), each over its range in the data; a coordinate that does not vary is left out.
fn coordinates(rows: &[ObservedRow]) -> Vec<[f64; 5]> {
    let raw: Vec<[f64; 5]> = rows
        .iter()
        .map(|r| [r.op.preload_n, r.op.torque_nm, r.op.voltage_v, r.op.frequency_hz, r.op.elapsed_s])
        .collect();
    let mut out = vec![[0.0; 5]; rows.len()];
    for k in 0..5 {
        let (lo, hi) =
            raw.iter().map(|c| c[k]).fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x), h.max(x)));
        let span = hi - lo;
        if span.is_finite() && span > 1e-9 * hi.abs().max(lo.abs()) {
            for (o, c) in out.iter_mut().zip(&raw) {
                o[k] = (c[k] - lo) / span;
            }
        }
    }
    out
}

/// The [`NEIGHBOURS`] readings of `readings` (one quantity's) nearest to reading row `i`
/// in the operating coordinates, among the rows of other runs.
fn nearest_in_other_runs(i: usize, readings: &[(usize, f64)], coords: &[[f64; 5]], run: &[usize]) -> Vec<(usize, f64)> {
    let mut best: Vec<(f64, usize, f64)> = Vec::with_capacity(NEIGHBOURS + 1);
    for &(j, zj) in readings {
        if run[j] == run[i] {
            continue;
        }
        let d: f64 = coords[i].iter().zip(&coords[j]).map(|(a, b)| (a - b) * (a - b)).sum();
        if best.len() < NEIGHBOURS || d < best[best.len() - 1].0 {
            // (ties keep the earlier row: the result does not depend on the sort)
            let at = best.partition_point(|b| b.0 <= d);
            best.insert(at, (d, j, zj));
            best.truncate(NEIGHBOURS);
        }
    }
    best.into_iter().map(|(_, j, z)| (j, z)).collect()
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::observable::Observable;
    use crate::solve::OperatingPoint;

    /// A preload-torque design: `runs` runs at preloads 100 N apart, each a torque sweep of
    /// 10 rows; every speed reading is missed by `miss(run, k)` noise levels (its
    /// normalised residual).
    fn design(runs: usize, miss: impl Fn(usize, usize) -> f64) -> (Vec<ObservedRow>, Vec<f64>, Vec<String>) {
        let mut rows = Vec::new();
        let mut preds = Vec::new();
        let mut groups = Vec::new();
        for a in 0..runs {
            for k in 0..10 {
                let op = OperatingPoint::new(100.0 + 100.0 * a as f64, 0.05 * k as f64, 200.0, 43e3);
                rows.push(ObservedRow {
                    op,
                    readings: vec![(Observable::SpeedRpm, 100.0, 1.0)],
                    ambient_c: 25.0,
                    speed_std_clipped: false,
                });
                preds.push(miss(a, k));
                groups.push(format!("run{a}"));
            }
        }
        (rows, preds, groups)
    }

    /// A standard normal draw from a seeded generator.
    pub(in crate::diagnose) fn normal(rng: &mut ChaCha8Rng) -> f64 {
        rng.sample(rand_distr::StandardNormal)
    }

    /// A miss that is a smooth function of the operating point (here of the torque and the
    /// preload, three noise levels at most) repeats across runs: p at its smallest, 1/2^8
    /// at nine runs (every run's sign agrees with its neighbours').
    #[test]
    fn a_miss_shared_by_the_runs_repeats() {
        let (rows, preds, groups) = design(9, |a, k| 3.0 * (0.3 * k as f64 - 1.0) * (1.0 + 0.05 * a as f64));
        let r = across_runs(&rows, &preds, &groups, 1).expect("nine runs");
        assert_eq!(r.runs, 9);
        assert!((r.p_value - 1.0 / 256.0).abs() < 1e-15, "{r:?}");
        assert!(r.repeats());
        assert!(r.agreement > 0.99, "{r:?}");
    }

    /// A random offset per run, however large against the noise level, does not repeat:
    /// over 200 draws of nine runs the p-value is about uniform (the share at or below 5 %
    /// is 5 % within its binomial spread: at most 20 of 200, where 10 are expected), and
    /// the same offsets with a shared miss added repeat in nearly every draw (the test's
    /// power there, at least 195 of 200).
    #[test]
    fn offsets_of_independent_runs_do_not_repeat() {
        let mut state = ChaCha8Rng::seed_from_u64(42);
        let (mut repeated, mut shared_repeated) = (0, 0);
        for _ in 0..200 {
            let offsets: Vec<f64> = (0..9).map(|_| 5.0 * normal(&mut state)).collect();
            let noise: Vec<f64> = (0..90).map(|_| normal(&mut state)).collect();
            let (rows, preds, groups) = design(9, |a, k| offsets[a] + noise[10 * a + k]);
            let r = across_runs(&rows, &preds, &groups, 1).expect("nine runs");
            repeated += usize::from(r.repeats());
            let (rows, preds, groups) =
                design(9, |a, k| 0.3 * offsets[a] + noise[10 * a + k] + 4.0 * (0.25 * k as f64 - 1.1));
            shared_repeated += usize::from(across_runs(&rows, &preds, &groups, 1).expect("nine runs").repeats());
        }
        assert!(repeated <= 20, "{repeated} of 200 independent designs repeat");
        assert!(repeated >= 1, "the test never rejects: {repeated}");
        assert!(shared_repeated >= 195, "a shared miss repeats in only {shared_repeated} of 200 designs");
    }

    /// Below MIN_RUNS runs there is no test; at twenty runs the random sign patterns give
    /// the same answer as the exact count would (a shared miss: p at its floor).
    #[test]
    fn few_runs_have_no_test_and_many_take_random_patterns() {
        let (rows, preds, groups) = design(MIN_RUNS - 1, |_, k| k as f64 - 4.5);
        assert!(across_runs(&rows, &preds, &groups, 1).is_none());
        let (rows, preds, groups) = design(20, |_, k| k as f64 - 4.5);
        let r = across_runs(&rows, &preds, &groups, 1).expect("twenty runs");
        assert_eq!(r.runs, 20);
        assert!((r.p_value - 1.0 / (FLIPS + 1) as f64).abs() < 1e-15, "{r:?}");
    }
}
