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

use crate::calibrate::{Observable, ObservedRow};
use std::collections::BTreeMap;

/// Median of the χ² distribution with one degree of freedom.
const CHI2_1_MEDIAN: f64 = 0.454_936_423_119_572_8;

/// Fewest line residuals per quantity for an estimate.
pub const MIN_TRIPLES: usize = 8;

/// Estimated noise factor of one quantity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseScale {
    /// s: the data's noise over the default noise model (1 = as assumed).
    pub factor: f64,
    /// Line residuals the estimate rests on.
    pub triples: usize,
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

/// Per quantity, the factor by which the readings' stated noise levels should be scaled,
/// estimated from runs (`groups[i]` is the run of row i). Quantities with fewer than
/// [`MIN_TRIPLES`] usable triples are absent: keep their stated levels.
pub fn estimate(rows: &[ObservedRow], groups: &[String]) -> BTreeMap<Observable, NoiseScale> {
    let mut by_run: BTreeMap<&str, Vec<&ObservedRow>> = BTreeMap::new();
    for (i, r) in rows.iter().enumerate() {
        by_run.entry(groups.get(i).map(String::as_str).unwrap_or("")).or_default().push(r);
    }
    let mut z2: BTreeMap<Observable, Vec<f64>> = BTreeMap::new();
    for run in by_run.values() {
        // the coordinate along which this run has the most triples
        let best = (0..COORDS.len())
            .map(|c| {
                let ls = lines(run, c);
                let n: usize = ls.iter().map(|l| l.len().saturating_sub(2)).sum();
                (n, ls, c)
            })
            .max_by_key(|(n, _, _)| *n);
        let Some((n, ls, c)) = best else { continue };
        if n == 0 {
            continue;
        }
        let x = |i: usize| COORDS[c].0(run[i]);
        for l in ls {
            for w in l.windows(3) {
                let (x0, x1, x2) = (x(w[0]), x(w[1]), x(w[2]));
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
                        z2.entry(o).or_default().push(e * e / var);
                    }
                }
            }
        }
    }
    z2.into_iter()
        .filter(|(_, v)| v.len() >= MIN_TRIPLES)
        .map(|(o, mut v)| {
            v.sort_by(f64::total_cmp);
            let m = v.len();
            let med = if m % 2 == 1 { v[m / 2] } else { 0.5 * (v[m / 2 - 1] + v[m / 2]) };
            (o, NoiseScale { factor: (med / CHI2_1_MEDIAN).sqrt(), triples: m })
        })
        .collect()
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

    #[test]
    fn recovers_the_noise_factor_on_a_curved_run() {
        for (true_sd, stated) in [(1.0, 1.0), (0.5, 1.0), (2.0, 1.0)] {
            let (r, g) = rows(true_sd, stated, 4);
            let s = estimate(&r, &g)[&Observable::SpeedRpm];
            assert_eq!(s.triples, 60);
            // 60 residuals: the median-based estimate is good to about ±20 %
            assert!((s.factor / (true_sd / stated) - 1.0).abs() < 0.25, "{true_sd}: {}", s.factor);
        }
    }

    #[test]
    fn too_few_triples_give_no_estimate() {
        let (r, g) = rows(1.0, 1.0, 1);
        let few: Vec<ObservedRow> = r.into_iter().take(5).collect();
        assert!(estimate(&few, &g[..5]).is_empty());
    }
}
