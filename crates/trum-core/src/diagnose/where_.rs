//! Where the gap lies: the calibrated baseline's residuals grouped by quantity and
//! operating region; a group is reported when its mean normalised residual is more than
//! 3.5 standard errors from zero (z-test; 3.5 keeps the family-wise false-alarm rate near
//! 1 % over ~50 groups).

use super::baseline::Baseline;
use super::context::Context;
use super::folds::{errors, predict};
use super::GapRegion;
use crate::observable::{Observable, ObservedRow};

/// The regions where the baseline misses, strongest first, and a note when they are
/// located on the held-out residuals. A fit that passes through every point (few readings,
/// as many parameters) leaves no residual there, while it misses the same points held out;
/// then the held-out residuals tell where.
pub(super) fn locate(ctx: &Context, base: &Baseline) -> (Vec<GapRegion>, Option<String>) {
    let (rows, sc) = (&ctx.rows[..], &ctx.sc);
    let (base_cal, base_cv, base_z2) = (&base.cal, &base.cv, base.z2);
    let in_sample = predict(&base_cal.motor, &rows.iter().collect::<Vec<_>>());
    let (_, in_z2, _, _) = errors(rows, &in_sample, sc);
    let through_every_point = in_z2 < 2.0 && base_z2 > 4.0 * in_z2.max(0.5);
    let gap_where = locate_gap(rows, if through_every_point { &base_cv.preds } else { &in_sample });
    let note = (through_every_point && !gap_where.is_empty()).then(|| {
        format!(
            "the calibrated baseline passes through the points (mean squared normalised residual {in_z2:.2}) but \
             misses them held out ({base_z2:.1}): `where` is located on the held-out residuals"
        )
    });
    (gap_where, note)
}

pub(super) fn locate_gap(rows: &[ObservedRow], preds: &[Vec<f64>]) -> Vec<GapRegion> {
    // (coordinate name, accessor)
    type Coord = (&'static str, fn(&ObservedRow) -> f64);
    let coords: [Coord; 5] = [
        ("preload_n", |r| r.op.preload_n),
        ("torque_nm", |r| r.op.torque_nm),
        ("voltage_v", |r| r.op.voltage_v),
        ("frequency_hz", |r| r.op.frequency_hz),
        ("elapsed_s", |r| r.op.elapsed_s),
    ];
    let mut out = Vec::new();
    for o in Observable::ALL {
        let idx: Vec<(usize, usize)> = rows
            .iter()
            .enumerate()
            .flat_map(|(i, r)| r.readings.iter().enumerate().filter(|(_, x)| x.0 == o).map(move |(j, _)| (i, j)))
            .collect();
        if idx.len() < 3 {
            continue;
        }
        for (name, get) in coords {
            let mut vals: Vec<f64> = idx.iter().map(|&(i, _)| get(&rows[i])).collect();
            vals.sort_by(f64::total_cmp);
            vals.dedup();
            if vals.len() < 2 {
                continue;
            }
            // Terciles of the distinct values; with few readings (a handful of published
            // points), each distinct value is its own region.
            type Bin = (String, Box<dyn Fn(f64) -> bool>);
            let few = idx.len() < 9;
            let bins: Vec<Bin> = if few {
                vals.iter()
                    .map(|&v| -> Bin { (format!("{name} = {}", fmt_num(v)), Box::new(move |x| x == v)) })
                    .collect()
            } else {
                let (i1, i2) = (vals.len() / 3, (2 * vals.len()) / 3);
                let (cut1, cut2) = (vals[i1], vals[i2]);
                // the label's bound: the roundest number between the value below the cut
                // and the cut, which splits the data the same way (no value lies between)
                let round1 = roundest_between(vals[i1.saturating_sub(1)], cut1);
                let round2 = roundest_between(vals[i2.saturating_sub(1)], cut2);
                vec![
                    (format!("{name} < {}", fmt_num(round1)), Box::new(move |x| x < cut1)),
                    (
                        format!("{} <= {name} < {}", fmt_num(round1), fmt_num(round2)),
                        Box::new(move |x| x >= cut1 && x < cut2),
                    ),
                    (format!("{name} >= {}", fmt_num(round2)), Box::new(move |x| x >= cut2)),
                ]
            };
            for (label, inside) in bins.iter() {
                let sel: Vec<&(usize, usize)> = idx.iter().filter(|&&(i, _)| inside(get(&rows[i]))).collect();
                if sel.is_empty() || (sel.len() < 3 && !few) {
                    continue;
                }
                let n = sel.len() as f64;
                let (mut mean_raw, mut mean_z) = (0.0, 0.0);
                for &&(i, j) in &sel {
                    let (_, v, s) = rows[i].readings[j];
                    let y = preds[i][j];
                    let d = v - if y.is_finite() { y } else { 0.0 };
                    mean_raw += d;
                    mean_z += d / s;
                }
                mean_raw /= n;
                mean_z /= n;
                let z = mean_z * n.sqrt();
                if z.abs() > 3.5 {
                    out.push(GapRegion {
                        quantity: o.column().into(),
                        region: label.clone(),
                        mean_residual: mean_raw,
                        n: sel.len(),
                        z,
                    });
                }
            }
        }
    }
    out.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    out.truncate(10);
    out
}

/// The number in (`lo`, `hi`] with the fewest significant digits (steps of 1, 2 or 5 times
/// a power of ten), `hi` itself when `lo >= hi`. Region bounds of measured operating
/// points (read back with noise: 249.8731 N) are labelled with it (245 N): any bound in
/// that interval splits the data the same way.
fn roundest_between(lo: f64, hi: f64) -> f64 {
    if !hi.is_finite() || !lo.is_finite() || lo >= hi {
        return hi;
    }
    let top = hi.abs().max(lo.abs()).log10().floor() as i32 + 1;
    for k in (top - 16..=top).rev() {
        for m in [5.0, 2.0, 1.0] {
            let step = m * 10f64.powi(k);
            let n = (lo / step).floor() + 1.0;
            // n·m / 10^-k rather than n·step: 3 · 0.1 is 0.30000000000000004, 3 / 10 is 0.3
            let c = if k < 0 { n * m / 10f64.powi(-k) } else { n * step };
            if c > lo && c <= hi {
                return c;
            }
        }
    }
    hi
}

#[cfg(test)]
mod region_bound_tests {
    use super::roundest_between;

    #[test]
    fn region_bounds_are_the_roundest_number_that_splits_the_data_the_same_way() {
        assert_eq!(roundest_between(240.1, 249.8731), 245.0);
        assert_eq!(roundest_between(0.2, 0.3000000004), 0.3);
        assert_eq!(roundest_between(199.0, 200.0), 200.0);
        assert_eq!(roundest_between(41_990.0, 42_010.0), 42_000.0);
        assert_eq!(roundest_between(3.0, 3.0), 3.0);
        // the bound stays inside (lo, hi]: every value <= lo is below it, hi is not
        for (lo, hi) in [(0.123, 0.1234), (1e-7, 1.1e-7), (-5.0, -4.9), (99.99, 100.01)] {
            let c = roundest_between(lo, hi);
            assert!(c > lo && c <= hi, "{lo} {hi} -> {c}");
        }
    }
}

fn fmt_num(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a panic is the failure report
mod tests {
    use super::*;
    use crate::solve::OperatingPoint;

    /// Thirty speed readings (σ = 1) along the preload; the model misses by `shift` at and
    /// above 300 N.
    fn rows_and_preds(shift: f64) -> (Vec<ObservedRow>, Vec<Vec<f64>>) {
        (0..30)
            .map(|i| {
                let p = 100.0 + 10.0 * i as f64;
                let row = ObservedRow {
                    op: OperatingPoint::new(p, 0.1, 200.0, 43_000.0),
                    readings: vec![(Observable::SpeedRpm, 100.0, 1.0)],
                    ambient_c: 20.0,
                    speed_std_clipped: false,
                };
                (row, vec![if p >= 300.0 { 100.0 - shift } else { 100.0 }])
            })
            .unzip()
    }

    /// A shift in the upper preload tercile is reported there, with its mean residual
    /// (measured − model) and z = mean/σ·√n; a model without misses has no region.
    #[test]
    fn a_miss_in_one_tercile_is_located_there() {
        let (rows, preds) = rows_and_preds(3.0);
        let found = locate_gap(&rows, &preds);
        assert_eq!(found.len(), 1, "{found:?}");
        let g = &found[0];
        assert_eq!((g.quantity.as_str(), g.region.as_str(), g.n), ("speed_rpm", "preload_n >= 300", 10));
        assert!((g.mean_residual - 3.0).abs() < 1e-12);
        assert!((g.z - 3.0 * 10f64.sqrt()).abs() < 1e-9);
        // below 3.5 standard errors: not reported
        let (rows, preds) = rows_and_preds(1.0);
        assert!(locate_gap(&rows, &preds).is_empty());
        let (rows, preds) = rows_and_preds(0.0);
        assert!(locate_gap(&rows, &preds).is_empty());
    }
}
