//! Noise levels estimated from the data themselves, model-free, so that the diagnosis's
//! χ² tests mean what they say when a measurement file gives no noise levels.
//!
//! Within a run, readings along the coordinate that varies (torque, frequency, time, ...)
//! follow a smooth curve plus noise. The residual of each interior reading from the
//! straight line through its two neighbours, e_i = y_i − (a·y_{i−1} + b·y_{i+1}), has
//! variance σ_i² + a²σ_{i−1}² + b²σ_{i+1}² plus a curvature term (Gasser, Sroka and
//! Jennen-Steinmetz, Biometrika 73 (1986) 625-633). With σ the default noise model times
//! an unknown factor s per quantity, s² is estimated from the median of the normalised
//! squared residuals divided by the median of χ²₁ (0.4549), which keeps the few triples
//! where the curve bends sharply (resonance peak, stall) from inflating it.

use crate::normal::{normal_cdf, normal_pdf};
use crate::observable::{Observable, ObservedRow};
use std::collections::BTreeMap;

/// Median of the χ² distribution with one degree of freedom.
const CHI2_1_MEDIAN: f64 = 0.454_936_423_119_572_8;

/// Fewest line residuals per quantity for an estimate.
pub const MIN_TRIPLES: usize = 8;

/// Fewest readings for the censored estimate of a clipped speed std: a zero says less than
/// a reading, and the eight readings of one stability run gave a factor 30 % off (a
/// `combined` campaign, diagnose::tests::the_noise_nrmse_is_what_a_model_without_error_scores).
pub const MIN_CENSORED: usize = 2 * MIN_TRIPLES;

/// A reading the bench clipped: a speed standard deviation read as zero (it has no
/// negative values; a reading of 0 says only that spread plus noise was ≤ 0).
pub(crate) fn clipped_reading(o: Observable, y: f64) -> bool {
    o == Observable::SpeedStdRpm && y <= 0.0
}

/// Estimated noise factor of one quantity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseScale {
    /// s: the data's noise over the default noise model (1 = as assumed).
    pub factor: f64,
    /// Line residuals the estimate rests on; a clipped speed std's censored estimate adds
    /// the readings of its runs with zeros, one each.
    pub residuals: usize,
}

type Coord = fn(&ObservedRow) -> f64;

/// Operating coordinates with the resolution at which two setpoints count as equal.
const COORDS: [(Coord, f64); 5] = [
    (|r| r.op.torque_nm, 0.01),
    (|r| r.op.frequency_hz, 50.0),
    (|r| r.op.elapsed_s, 1.0),
    (|r| r.op.preload_n, 5.0),
    (|r| r.op.voltage_v, 2.0),
];

/// Sub-runs of one run along coordinate `c`: rows grouped by the other coordinates
/// (rounded to their resolution), each sorted along `c`.
fn lines(rows: &[&ObservedRow], c: usize) -> Vec<Vec<usize>> {
    let mut groups: BTreeMap<Vec<i64>, Vec<usize>> = BTreeMap::new();
    for (i, r) in rows.iter().enumerate() {
        let key: Vec<i64> = COORDS
            .iter()
            .enumerate()
            .filter(|(k, _)| *k != c)
            .map(|(_, (get, res))| (get(r) / res).round() as i64)
            .collect();
        groups.entry(key).or_default().push(i);
    }
    groups
        .into_values()
        .map(|mut g| {
            g.sort_by(|&a, &b| COORDS[c].0(rows[a]).total_cmp(&COORDS[c].0(rows[b])));
            g
        })
        .collect()
}

/// The rows of one run, with their indices in the input.
struct Run<'a> {
    rows: Vec<&'a ObservedRow>,
    index: Vec<usize>,
}

impl<'a> std::ops::Deref for Run<'a> {
    type Target = [&'a ObservedRow];
    fn deref(&self) -> &Self::Target {
        &self.rows
    }
}

/// The rows of each run (`groups[i]` is the run of row i; a missing name is run "").
fn runs<'r, 'g>(rows: &'r [ObservedRow], groups: &'g [String]) -> BTreeMap<&'g str, Run<'r>> {
    let mut by_run: BTreeMap<&str, Run> = BTreeMap::new();
    for (i, r) in rows.iter().enumerate() {
        let name = groups.get(i).map(String::as_str).unwrap_or("");
        let run = by_run.entry(name).or_insert_with(|| Run { rows: Vec::new(), index: Vec::new() });
        run.rows.push(r);
        run.index.push(i);
    }
    by_run
}

/// The coordinate along which `run` has the most triples (interior readings of its lines),
/// and its lines along it; `None` when no line has three readings.
fn best_lines(run: &[&ObservedRow]) -> Option<(usize, Vec<Vec<usize>>)> {
    let (n, ls, c) = (0..COORDS.len())
        .map(|c| {
            let ls = lines(run, c);
            let n: usize = ls.iter().map(|l| l.len().saturating_sub(2)).sum();
            (n, ls, c)
        })
        .max_by_key(|(n, _, _)| *n)?;
    (n > 0).then_some((c, ls))
}

/// The line residuals of `run` along the coordinate that gives it the most triples: per
/// interior reading, its quantity and its residual from the straight line through its two
/// neighbours over the residual's standard deviation (the readings' stated noise levels).
fn line_residuals(run: &[&ObservedRow]) -> Vec<(Observable, f64)> {
    let mut out = Vec::new();
    let Some((c, ls)) = best_lines(run) else { return out };
    let x = |i: usize| COORDS[c].0(run[i]);
    for l in ls {
        for w in l.windows(3) {
            let (x0, x1, x2) = (x(w[0]), x(w[1]), x(w[2]));
            // a NaN coordinate must skip the triple
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            if !(x2 > x0) {
                continue;
            }
            let a = (x2 - x1) / (x2 - x0);
            let b = 1.0 - a;
            for &(o, y1, s1) in &run[w[1]].readings {
                let find = |j: usize| run[j].readings.iter().find(|q| q.0 == o).map(|q| (q.1, q.2));
                let (Some((y0, s0)), Some((y2, s2))) = (find(w[0]), find(w[2])) else { continue };
                let e = y1 - (a * y0 + b * y2);
                let var = s1 * s1 + a * a * s0 * s0 + b * b * s2 * s2;
                if var > 0.0 && e.is_finite() {
                    out.push((o, e / var.sqrt()));
                }
            }
        }
    }
    out
}

/// A reading off its leave-one-out local curve by more than this many standard deviations
/// is a spike candidate ([`isolated_spikes`]): under Gaussian noise |z| > 6 happens about
/// twice in 10⁹ readings.
pub const SPIKE_Z: f64 = 6.0;

/// The other quantities of a spike's row must stay within this many standard deviations
/// of their own leave-one-out curves ([`isolated_spikes`]).
const SPIKE_COHERENT_Z: f64 = 3.0;

/// At most this fraction of the readings (and at least one) is taken for isolated spikes:
/// more readings off their curves are not a few glitches but something systematic, which
/// the diagnosis must see.
const SPIKE_MAX_FRACTION: f64 = 0.05;

/// The reading of quantity `o` at place `j` of line `l` (rows of `run`) against the
/// quadratic through four other readings of the line, by weighted least squares:
/// (y − ŷ)/√(σ² + var ŷ), with the places of the four. They are two on each side where the
/// line has them, else three on one side and one on the other; only the ends of a line,
/// which have no reading on one side, are extrapolated from four on the other. `None` where
/// the reading or such neighbours are missing, or `removed` holds them.
fn leave_one_out_z(
    run: &[&ObservedRow],
    l: &[usize],
    j: usize,
    o: Observable,
    c: usize,
    removed: &std::collections::BTreeSet<(usize, Observable)>,
) -> Option<(f64, Vec<usize>)> {
    let read = |k: usize| -> Option<(usize, f64, f64, f64)> {
        if removed.contains(&(l[k], o)) {
            return None;
        }
        let &(_, y, s) = run[l[k]].readings.iter().find(|q| q.0 == o)?;
        (y.is_finite() && s > 0.0).then(|| (k, COORDS[c].0(run[l[k]]), y, s))
    };
    let (_, x0, y0, s0) = read(j)?;
    let before: Vec<_> = (0..j).rev().filter_map(read).take(4).collect();
    let after: Vec<_> = (j + 1..l.len()).filter_map(read).take(4).collect();
    let (nb, na) = match (before.len(), after.len()) {
        (0, 4) if j == 0 => (0, 4),
        (4, 0) if j + 1 == l.len() => (4, 0),
        (b, a) if b >= 2 && a >= 2 => (2, 2),
        (1, a) if a >= 3 => (1, 3),
        (b, 1) if b >= 3 => (3, 1),
        _ => return None,
    };
    let pts: Vec<_> = before[..nb].iter().chain(&after[..na]).copied().collect();
    let span = pts.iter().map(|p| (p.1 - x0).abs()).fold(0.0, f64::max);
    if span.is_nan() || span <= 0.0 {
        return None;
    }
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut aty = nalgebra::Vector3::<f64>::zeros();
    for &(_, x, y, s) in &pts {
        let t = (x - x0) / span;
        let g = nalgebra::Vector3::new(1.0, t, t * t);
        let w = 1.0 / (s * s);
        ata += w * g * g.transpose();
        aty += w * y * g;
    }
    let inv = ata.try_inverse()?;
    let beta = inv * aty;
    let z = (y0 - beta[0]) / (s0 * s0 + inv[(0, 0)]).sqrt();
    z.is_finite().then(|| (z, pts.iter().map(|p| p.0).collect()))
}

/// Readings that stand alone off their neighbours: gross outliers of the bench (a glitch of
/// one instrument on one reading), found without any model. Within each run, along the
/// coordinate that gives it the most triples (as [`estimate`]), a reading is one when
/// - it lies off the quadratic through four neighbouring readings of its quantity by more
///   than [`SPIKE_Z`] standard deviations (`rows`' noise levels): a smooth curve, bent as it
///   may be near a stall or a resonance, passes within the noise;
/// - the row's other quantities lie on their own such curves (within 3 standard
///   deviations; at least one of them read): what the motor does (a resonance peak, a
///   jump of the amplitude, a stall) shows in speed, power, current and feedback together,
///   an instrument's glitch in its own reading only.
///
/// - it is further off than each of the four readings its curve goes through are off
///   theirs: a glitch bends its neighbours' curves, and is the one to take.
///
/// The largest is taken first and left out of its neighbours' curves, and so on, up to 5 %
/// of the readings. The first and last readings of a line are never taken (a stall or the
/// end of a sweep cannot be told from a glitch there), and lines of fewer than five
/// readings are not searched. Returns (row index in `rows`, quantity), in row order.
pub fn isolated_spikes(rows: &[ObservedRow], groups: &[String]) -> Vec<(usize, Observable)> {
    let n_read: usize = rows.iter().map(|r| r.readings.len()).sum();
    let cap = ((SPIKE_MAX_FRACTION * n_read as f64) as usize).max(1);
    let mut out = Vec::new();
    for run in runs(rows, groups).values() {
        let Some((c, ls)) = best_lines(run) else { continue };
        let mut removed = std::collections::BTreeSet::new();
        while out.len() < cap {
            let mut best: Option<(f64, usize, Observable)> = None;
            for l in ls.iter().filter(|l| l.len() >= 5) {
                // every reading's z, the ends' extrapolated: a glitch at an end is never
                // taken, but it must not make its neighbour look like one
                let zs: Vec<Vec<(Observable, f64, Vec<usize>)>> = (0..l.len())
                    .map(|j| {
                        run[l[j]]
                            .readings
                            .iter()
                            .filter_map(|q| leave_one_out_z(run, l, j, q.0, c, &removed).map(|(z, w)| (q.0, z, w)))
                            .collect()
                    })
                    .collect();
                let z_at = |k: usize, o: Observable| zs[k].iter().find(|x| x.0 == o).map_or(0.0, |x| x.1);
                for j in 1..l.len() - 1 {
                    for (o, z, window) in zs[j].iter().filter(|x| x.1.abs() > SPIKE_Z) {
                        let others: Vec<f64> = zs[j].iter().filter(|x| x.0 != *o).map(|x| x.1).collect();
                        let coherent = !others.is_empty() && others.iter().all(|z| z.abs() < SPIKE_COHERENT_Z);
                        // the largest of its window: a glitch beside it bends the curve
                        // it is measured against, and is the one to take
                        let local_max = window.iter().all(|&k| z_at(k, *o).abs() < z.abs());
                        if coherent && local_max && best.as_ref().is_none_or(|b| z.abs() > b.0) {
                            best = Some((z.abs(), l[j], *o));
                        }
                    }
                }
            }
            let Some((_, k, o)) = best else { break };
            removed.insert((k, o));
            out.push((run.index[k], o));
        }
    }
    out.sort_by_key(|&(i, o)| (i, o));
    out
}

/// Per quantity, the factor by which the readings' stated noise levels should be scaled,
/// estimated from runs (`groups[i]` is the run of row i). Quantities with fewer than
/// [`MIN_TRIPLES`] usable triples are absent: keep their stated levels (a clipped speed
/// std then takes its censored estimate where it has one).
pub fn estimate(rows: &[ObservedRow], groups: &[String]) -> BTreeMap<Observable, NoiseScale> {
    let by_run = runs(rows, groups);
    let mut z2: BTreeMap<Observable, Vec<f64>> = BTreeMap::new();
    // A run with a clipped speed std gives that quantity no line residuals: zeros leave zero
    // residuals (a null 1000-row set's median fell to a factor 0.21 where the bench's is
    // about 0.4), and its readings above zero are a truncated sample, biased low (0.28 for
    // 0.5 where the spread is zero, tests below). Such runs are the censored estimate's.
    let clipped_run = |run: &[&ObservedRow]| run.iter().any(|r| r.readings.iter().any(|x| clipped_reading(x.0, x.1)));
    for run in by_run.values() {
        let skip_speed_std = clipped_run(run);
        for (o, z) in line_residuals(run) {
            if !(o == Observable::SpeedStdRpm && skip_speed_std) {
                z2.entry(o).or_default().push(z * z);
            }
        }
    }
    let mut out: BTreeMap<Observable, NoiseScale> = z2
        .into_iter()
        .filter(|(_, v)| v.len() >= MIN_TRIPLES)
        .map(|(o, mut v)| {
            v.sort_by(f64::total_cmp);
            let m = v.len();
            let med = if m % 2 == 1 { v[m / 2] } else { 0.5 * (v[m / 2 - 1] + v[m / 2]) };
            (o, NoiseScale { factor: (med / CHI2_1_MEDIAN).sqrt(), residuals: m })
        })
        .collect();
    // Too few line residuals from the runs without zeros: the censored estimate of the runs
    // with zeros. (Not pooled with enough line residuals: it takes one latent spread for all
    // those runs and comes out high where a weak eccentricity varies along them. Pooled, the
    // 1000-row set with eccentricity at 1/20 of typical had a factor 0.56 for the bench's
    // about 0.4, and its correct verdict went.)
    if let std::collections::btree_map::Entry::Vacant(slot) = out.entry(Observable::SpeedStdRpm) {
        if let Some(c) = censored_speed_std(by_run.values().map(|r| &r.rows[..]).filter(|r| clipped_run(r))) {
            slot.insert(c);
        }
    }
    out
}

/// The speed std's noise factor from the runs whose readings the bench clipped at zero
/// (some read exactly 0): a censored-normal moment estimate over all their readings. It
/// takes one latent value m for them: with the readings y = max(0, m + σZ) over the stated
/// levels (so σ is the factor), the fraction of zeros p0 = Φ(−m/σ) gives a = m/σ, and
/// E[y²] = σ²·((a² + 1)·Φ(a) + a·φ(a)) gives σ². A spread cannot be negative, so a ≥ 0
/// (p0 above ½ is noise: a = 0, σ² = 2·E[y²]). Runs with zeros spread by the order of the
/// noise; where that spread still varies (a weak eccentricity growing with the preload),
/// the variation adds to E[y²] and the factor comes out high: the conservative side.
/// (Per run, eight readings each, the estimate was unstable: a run with seven zeros
/// divides by g(a) ≈ 0.05, and sixteen such runs came out 25 % high.) `None` below
/// [`MIN_CENSORED`] readings or without a reading above zero. `runs`: those with a zero.
fn censored_speed_std<'a>(runs: impl Iterator<Item = &'a [&'a ObservedRow]>) -> Option<NoiseScale> {
    let z: Vec<f64> = runs
        .flatten()
        .filter_map(|r| r.readings.iter().find(|x| x.0 == Observable::SpeedStdRpm))
        .filter(|&&(_, y, s)| s > 0.0 && y.is_finite())
        .map(|&(_, y, s)| y.max(0.0) / s)
        .collect();
    let n = z.len();
    let zeros = z.iter().filter(|&&x| x == 0.0).count();
    // (no zero left: the runs' zeros had no stated noise level)
    if n < MIN_CENSORED || zeros == n || zeros == 0 {
        return None;
    }
    // a ≥ 0 with Φ(a) = 1 − p0 (Φ is monotonic); 0 where half or more are zeros
    let target = 1.0 - zeros as f64 / n as f64;
    let a = if target <= 0.5 { 0.0 } else { crate::dynamics::hertz::bisect(|a| normal_cdf(a) - target, 0.0, 8.0, 60) };
    let m2 = z.iter().map(|x| x * x).sum::<f64>() / n as f64;
    let g = (a * a + 1.0) * normal_cdf(a) + a * normal_pdf(a);
    Some(NoiseScale { factor: (m2 / g).sqrt(), residuals: n })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::OperatingPoint;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// Rows along torque with a curved speed and readings of known noise `true_sd` while
    /// the stated σ is `stated`.
    fn rows(true_sd: f64, stated: f64, seed: u64) -> (Vec<ObservedRow>, Vec<String>) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let n = Normal::new(0.0, true_sd).expect("normal");
        let mut out = Vec::new();
        let mut g = Vec::new();
        for p in 0..6 {
            for k in 0..12 {
                let t = 0.1 * k as f64;
                let y = 120.0 - 40.0 * t - 15.0 * t * t + p as f64 + n.sample(&mut rng);
                out.push(ObservedRow {
                    op: OperatingPoint::new(100.0 + 50.0 * p as f64, t, 200.0, 43e3),
                    readings: vec![(Observable::SpeedRpm, y, stated)],
                    ambient_c: 25.0,
                    speed_std_clipped: false,
                });
                g.push(format!("run{p}"));
            }
        }
        (out, g)
    }

    /// Sweeps along torque of four quantities with unit noise: speed bends like a loaded
    /// rotor's near its stall (a steepening curve), power and current rise, feedback is
    /// flat; `bump` adds a resonance-like peak to all four at one torque of run 2.
    fn sweeps(seed: u64, bump: bool) -> (Vec<ObservedRow>, Vec<String>) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let n = Normal::new(0.0, 1.0).expect("normal");
        let (mut out, mut g) = (Vec::new(), Vec::new());
        for p in 0..5 {
            for k in 0..10 {
                let t = 0.04 * k as f64;
                let peak = if bump && p == 2 && k == 5 { 12.0 } else { 0.0 };
                let mut noisy = |y: f64| y + peak + n.sample(&mut rng);
                let readings = vec![
                    (Observable::SpeedRpm, noisy(110.0 - 60.0 * t - 900.0 * t.powi(3)), 1.0),
                    (Observable::InputPowerW, noisy(40.0 + 30.0 * t), 1.0),
                    (Observable::CurrentA, noisy(20.0 + 10.0 * t * t), 1.0),
                    (Observable::FeedbackV, noisy(50.0), 1.0),
                ];
                out.push(ObservedRow {
                    op: OperatingPoint::new(100.0 + 50.0 * p as f64, t, 200.0, 43e3),
                    readings,
                    ambient_c: 25.0,
                    speed_std_clipped: false,
                });
                g.push(format!("run{p}"));
            }
        }
        (out, g)
    }

    /// A glitch of one instrument on one reading (8σ on a speed reading inside a sweep, 14σ
    /// on a feedback reading next to the end of another) is found, and only it; a peak that
    /// all four quantities share (what the motor does) and the bend of the speed near the
    /// stall are not, over 200 seeds of noise alone; a glitch on the first reading of a line
    /// (15σ on a power reading) is never taken, nor its neighbour, whose curve it bends.
    #[test]
    fn isolated_spikes_are_lone_glitches_not_the_motors_features() {
        let mut false_alarms = 0;
        for seed in 0..200 {
            let (rows, g) = sweeps(seed, seed % 2 == 0);
            false_alarms += isolated_spikes(&rows, &g).len();
        }
        assert_eq!(false_alarms, 0);
        let (mut rows, g) = sweeps(7, true);
        rows[14].readings[0].1 += 8.0;
        rows[38].readings[3].1 -= 14.0;
        rows[20].readings[1].1 += 15.0;
        assert_eq!(isolated_spikes(&rows, &g), vec![(14, Observable::SpeedRpm), (38, Observable::FeedbackV)]);
        // the same glitch on every quantity of the row is a feature of the motor
        let (mut rows, g) = sweeps(7, false);
        for x in rows[14].readings.iter_mut() {
            x.1 += 9.0;
        }
        assert!(isolated_spikes(&rows, &g).is_empty());
    }

    /// Rows with repeated, unordered and non-finite coordinates, non-finite and zero
    /// readings and noise levels, in runs of every size: the search returns without a
    /// panic, names only readings that exist, and never more than 5 % of them.
    #[test]
    fn isolated_spikes_hold_on_degenerate_rows() {
        use rand::RngExt;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let odd = [0.0, -0.0, 1e-300, 1e308, f64::NAN, f64::INFINITY, -1.0, 5e-324];
        for _ in 0..300 {
            let n = rng.random_range(0..40);
            let mut pick = |typical: f64| {
                if rng.random::<f64>() < 0.1 {
                    odd[rng.random_range(0..odd.len())]
                } else {
                    typical * (1.0 + rng.random::<f64>())
                }
            };
            let rows: Vec<ObservedRow> = (0..n)
                .map(|_| ObservedRow {
                    op: OperatingPoint::new(pick(100.0), (pick(0.1) * 10.0).round() / 10.0, pick(200.0), 43e3),
                    readings: vec![
                        (Observable::SpeedRpm, pick(100.0), pick(1.0)),
                        (Observable::FeedbackV, pick(50.0), pick(0.5)),
                    ],
                    ambient_c: 25.0,
                    speed_std_clipped: false,
                })
                .collect();
            let groups: Vec<String> = (0..n).map(|i| format!("r{}", i % 3)).collect();
            let found = isolated_spikes(&rows, &groups);
            let readings = 2 * n;
            assert!(found.len() <= ((0.05 * readings as f64) as usize).max(1));
            assert!(found.iter().all(|&(i, o)| i < n && rows[i].readings.iter().any(|x| x.0 == o)));
        }
    }

    #[test]
    fn recovers_the_noise_factor_on_a_curved_run() {
        for (true_sd, stated) in [(1.0, 1.0), (0.5, 1.0), (2.0, 1.0)] {
            let (r, g) = rows(true_sd, stated, 4);
            let s = estimate(&r, &g)[&Observable::SpeedRpm];
            assert_eq!(s.residuals, 60);
            // 60 residuals: the median-based estimate is good to about ±20 %
            assert!((s.factor / (true_sd / stated) - 1.0).abs() < 0.25, "{true_sd}: {}", s.factor);
        }
    }

    /// Speed-std readings of runs where the spread is far below the noise read exactly
    /// zero (clipped) and give zero line residuals; counted, they dragged the median down
    /// (here to 0: half the triples are such runs). The factor comes from the other runs.
    #[test]
    fn clipped_zero_speed_std_readings_do_not_count() {
        let (mut rows, groups) = rows(0.5, 1.0, 7);
        for r in rows.iter_mut() {
            let y = r.readings[0].1;
            // runs 0-2: a spread well above the noise; runs 3-5: clipped at zero throughout
            let run = ((r.op.preload_n - 100.0) / 50.0).round() as usize;
            let v = if run < 3 { y - 30.0 } else { 0.0 };
            r.readings = vec![(Observable::SpeedStdRpm, v, 1.0)];
        }
        let s = estimate(&rows, &groups)[&Observable::SpeedStdRpm];
        assert_eq!(s.residuals, 30);
        assert!((s.factor / 0.5 - 1.0).abs() < 0.3, "{}", s.factor);
    }

    /// Clipped speed-std readings max(0, m + σZ), σ half the stated level, in runs of
    /// `per_run` rows along the preload, or all at one operating point (`repeated`).
    fn clipped_runs(m: f64, runs: usize, per_run: usize, repeated: bool, seed: u64) -> (Vec<ObservedRow>, Vec<String>) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let n = Normal::new(0.0, 0.5).expect("normal");
        let (mut rows, mut groups) = (Vec::new(), Vec::new());
        for run in 0..runs {
            for k in 0..per_run {
                let y: f64 = m + n.sample(&mut rng);
                rows.push(ObservedRow {
                    op: OperatingPoint::new(if repeated { 300.0 } else { 150.0 + 50.0 * k as f64 }, 0.0, 200.0, 43e3),
                    readings: vec![(Observable::SpeedStdRpm, y.max(0.0), 1.0)],
                    ambient_c: 25.0,
                    speed_std_clipped: false,
                });
                groups.push(format!("run{run}"));
            }
        }
        (rows, groups)
    }

    /// The censored moment estimate recovers the factor 0.5 at a latent spread of 0 and of
    /// half the noise (half and a third of the readings zero).
    #[test]
    fn the_censored_estimate_recovers_the_noise_of_clipped_readings() {
        for (m, seed) in [(0.0, 3), (0.25, 5)] {
            let (rows, groups) = clipped_runs(m, 50, 8, false, seed);
            let runs: Vec<Vec<&ObservedRow>> = (0..50)
                .map(|run| {
                    rows.iter().zip(&groups).filter(|(_, g)| **g == format!("run{run}")).map(|(r, _)| r).collect()
                })
                .collect();
            let s = censored_speed_std(runs.iter().map(|r| &r[..])).expect("estimate");
            // about 400 readings (the runs with a zero): ±10 %
            assert!(s.residuals >= 300 && (s.factor / 0.5 - 1.0).abs() < 0.1, "m = {m}: {s:?}");
        }
    }

    /// Runs of repeated readings at one operating point (no line residuals at all), about
    /// half of them clipped: the estimate is the censored one, over the runs with a zero.
    #[test]
    fn a_speed_std_clipped_in_most_readings_has_a_censored_estimate() {
        let (rows, groups) = clipped_runs(0.0, 16, 8, true, 11);
        let s = estimate(&rows, &groups)[&Observable::SpeedStdRpm];
        let zeros = |run: usize| (0..8).filter(|k| rows[8 * run + k].readings[0].1 == 0.0).count();
        assert_eq!(s.residuals, 8 * (0..16).filter(|&run| zeros(run) > 0).count());
        // about 128 readings: good to ±20 %
        assert!((s.factor / 0.5 - 1.0).abs() < 0.2, "{}", s.factor);
        // fewer than MIN_CENSORED readings: no estimate
        let (one, g1) = clipped_runs(0.0, 1, 8, true, 11);
        assert!(estimate(&one, &g1).is_empty());
    }

    /// Runs along the preload, the spread m from zero (half the readings clipped) to twice
    /// the noise (2 % clipped): a run with a zero goes whole to the censored estimate, the
    /// others give line residuals. Line residuals of the readings above zero alone were a
    /// truncated sample: 0.28 for 0.5 at m = 0. Known bias: at m = σ a run of eight is
    /// zero-free only by chance, so the runs without a zero are a selected sample and
    /// their residuals come out about 27 % low (0.35 and 0.37 with seeds 9 and 19); pooling
    /// them with the censored estimate instead cost a correct verdict (`estimate`).
    #[test]
    fn a_run_with_a_clipped_reading_gives_no_line_residuals() {
        for (m, seed, tol) in [(0.0, 7, 0.15), (0.25, 8, 0.15), (1.0, 10, 0.15), (0.5, 9, 0.35)] {
            let (rows, groups) = clipped_runs(m, 60, 8, false, seed);
            let s = estimate(&rows, &groups)[&Observable::SpeedStdRpm];
            // 480 readings or about 300 residuals: ±15 %
            assert!((s.factor / 0.5 - 1.0).abs() < tol, "m = {m}: {s:?}");
        }
    }

    #[test]
    fn too_few_triples_give_no_estimate() {
        let (r, g) = rows(1.0, 1.0, 1);
        let few: Vec<ObservedRow> = r.into_iter().take(5).collect();
        assert!(estimate(&few, &g[..5]).is_empty());
    }
}
