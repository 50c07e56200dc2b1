//! The bench model of the diagnosis: what a test bench does to its records besides the
//! readings' random noise, undone or accounted for before any fit (docs/DIAGNOSIS.md,
//! "The bench model").
//!
//! - **Set points read back.** A drive voltage, frequency, preload or load held constant
//!   through a run is recorded as the bench reads it back, with the read-back's noise;
//!   the motor ran at the set point. Within a run, a column that scatters by less than
//!   [`SET_POINT_CV`] around its mean without a trend in row order is such a read-back,
//!   and each row gets the run's mean (the set point's best estimate: a nuisance
//!   parameter per run and column). A column swept within the run (monotone in row order)
//!   is left as recorded.
//! - **Quantised readings.** A column whose every reading is a whole multiple of a step
//!   carries the rounding's uniform error, of variance step²/12, beside its noise.
//! - **Instrument floors** are nuisance parameters of the fit itself
//!   ([`crate::effects::Instrument`]).

use crate::observable::{Observable, ObservedRow};
use std::collections::BTreeMap;

/// Largest coefficient of variation of a run's column that is taken as a constant set
/// point read back with noise (2 %: a bench's read-back scatters by well under it, and a
/// deliberate step of an operating variable within a run is larger, or monotone).
pub const SET_POINT_CV: f64 = 0.02;

/// Fewest rows of a run for its set points to be estimated from the run's mean.
const MIN_RUN_ROWS: usize = 4;

/// Operating-point columns that a run may hold at a set point.
const SET_POINT_COLUMNS: [&str; 4] = ["voltage_v", "frequency_hz", "preload_n", "torque_nm"];

fn column_mut<'a>(r: &'a mut ObservedRow, name: &str) -> &'a mut f64 {
    match name {
        "voltage_v" => &mut r.op.voltage_v,
        "frequency_hz" => &mut r.op.frequency_hz,
        "preload_n" => &mut r.op.preload_n,
        _ => &mut r.op.torque_nm,
    }
}

/// True when `v` (in row order) is a read-back scatter around one set point: at most
/// [`SET_POINT_CV`] relative spread, more than one distinct value, and no trend (a sweep
/// moves the same way from row to row; a scatter changes direction about every other
/// row).
fn is_read_back(v: &[f64]) -> bool {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    if mean.abs() <= 0.0 || !mean.is_finite() {
        return false;
    }
    let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    if sd == 0.0 || sd > SET_POINT_CV * mean.abs() {
        return false;
    }
    let steps: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).filter(|d| *d != 0.0).collect();
    if steps.len() < 2 {
        return false;
    }
    let turns = steps.windows(2).filter(|w| w[0].signum() != w[1].signum()).count();
    // a random scatter turns at about two thirds of its steps; a monotone sweep never
    turns as f64 >= 0.25 * (steps.len() - 1) as f64
}

/// Rows with each run's read-back set points replaced by the run's mean, and a note
/// naming what was replaced (`None` when nothing was).
pub fn snap_set_points(rows: &[ObservedRow], groups: &[String]) -> (Vec<ObservedRow>, Option<String>) {
    let mut out = rows.to_vec();
    let mut runs: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for i in 0..rows.len() {
        runs.entry(groups.get(i).map_or("", String::as_str)).or_default().push(i);
    }
    let mut snapped: BTreeMap<&str, usize> = BTreeMap::new();
    for idx in runs.values().filter(|idx| idx.len() >= MIN_RUN_ROWS) {
        for col in SET_POINT_COLUMNS {
            let v: Vec<f64> = idx.iter().map(|&i| *column_mut(&mut out[i], col)).collect();
            if is_read_back(&v) {
                let mean = v.iter().sum::<f64>() / v.len() as f64;
                for &i in idx {
                    *column_mut(&mut out[i], col) = mean;
                }
                *snapped.entry(col).or_default() += 1;
            }
        }
    }
    let note = (!snapped.is_empty()).then(|| {
        let list: Vec<String> = snapped.iter().map(|(c, n)| format!("{c} in {n} run(s)")).collect();
        format!(
            "set points read back with noise (within a run, under {:.0} % scatter and no trend) are taken at the run's mean: {}",
            100.0 * SET_POINT_CV,
            list.join(", ")
        )
    });
    (out, note)
}

/// The rounding step of readings `v` if every one is a whole multiple of one (tried from
/// coarse to fine among 1, 2 and 5 × powers of ten), with enough distinct values to tell;
/// `None` otherwise.
fn quantum(v: &[f64]) -> Option<f64> {
    if v.len() < 10 {
        return None;
    }
    let big = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if big == 0.0 {
        return None;
    }
    let top = 10f64.powf(big.log10().floor());
    for k in 0..12 {
        let decade = top * 10f64.powi(-k);
        for q in [5.0 * decade, 2.0 * decade, decade] {
            let whole = v.iter().all(|x| ((x / q) - (x / q).round()).abs() < 1e-6);
            let mut levels: Vec<i64> = v.iter().map(|x| (x / q).round() as i64).collect();
            levels.sort_unstable();
            levels.dedup();
            if whole && levels.len() >= 3 {
                return Some(q);
            }
        }
    }
    None
}

/// Rows whose reading noise levels include the rounding error of quantised columns
/// (σ² + q²/12), and a note naming them (`None` when no column is quantised more
/// coarsely than its noise).
pub fn account_for_quantisation(rows: &[ObservedRow]) -> (Vec<ObservedRow>, Option<String>) {
    let mut out = rows.to_vec();
    let mut seen = Vec::new();
    for o in Observable::ALL {
        let v: Vec<f64> = rows.iter().flat_map(|r| &r.readings).filter(|x| x.0 == o).map(|x| x.1).collect();
        let Some(q) = quantum(&v) else { continue };
        let mean_sigma =
            rows.iter().flat_map(|r| &r.readings).filter(|x| x.0 == o).map(|x| x.2).sum::<f64>() / v.len() as f64;
        // a step far below the noise changes nothing worth a note
        if q * q / 12.0 < 0.01 * mean_sigma * mean_sigma {
            continue;
        }
        for r in out.iter_mut() {
            for x in r.readings.iter_mut().filter(|x| x.0 == o) {
                x.2 = (x.2 * x.2 + q * q / 12.0).sqrt();
            }
        }
        seen.push(format!("{} (step {q})", o.column()));
    }
    let note = (!seen.is_empty()).then(|| {
        format!("quantised readings: their rounding error (step²/12) is added to the noise levels: {}", seen.join(", "))
    });
    (out, note)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::OperatingPoint;

    fn row(v: f64, f: f64) -> ObservedRow {
        ObservedRow {
            op: OperatingPoint::new(200.0, 0.1, v, f),
            readings: vec![(Observable::SpeedRpm, 100.0, 1.0)],
            ambient_c: 25.0,
            speed_std_clipped: false,
        }
    }

    #[test]
    fn a_scattered_set_point_is_snapped_and_a_sweep_is_kept() {
        // voltage read back ±0.5 % around 200 V; frequency swept 42.5-43.5 kHz (0.8 % CV)
        let volts = [200.9, 199.2, 200.4, 199.6, 201.1, 198.9, 200.2, 199.8];
        let rows: Vec<ObservedRow> =
            volts.iter().enumerate().map(|(i, &v)| row(v, 42_500.0 + 1000.0 * i as f64 / 7.0)).collect();
        let groups = vec!["run".to_string(); rows.len()];
        let (snapped, note) = snap_set_points(&rows, &groups);
        let mean = volts.iter().sum::<f64>() / volts.len() as f64;
        assert!(snapped.iter().all(|r| (r.op.voltage_v - mean).abs() < 1e-12));
        assert!(snapped.iter().zip(&rows).all(|(a, b)| a.op.frequency_hz == b.op.frequency_hz), "sweep moved");
        assert!(note.expect("note").contains("voltage_v in 1 run"));
        // rows of different runs are not averaged together; exact set points are left alone
        let exact: Vec<ObservedRow> = (0..8).map(|_| row(200.0, 43e3)).collect();
        assert!(snap_set_points(&exact, &groups).1.is_none());
    }

    #[test]
    fn a_deliberate_step_is_not_a_read_back() {
        // two voltage levels 5 % apart in one run: beyond the set-point scatter
        let v = [190.0, 190.0, 200.0, 200.0, 190.0, 200.0];
        assert!(!is_read_back(&v));
    }

    #[test]
    fn quantised_speeds_get_the_rounding_variance() {
        let rows: Vec<ObservedRow> = (0..20)
            .map(|i| {
                let mut r = row(200.0, 43e3);
                r.readings = vec![(Observable::SpeedRpm, (100 + 3 * i) as f64, 0.3)];
                r
            })
            .collect();
        let (out, note) = account_for_quantisation(&rows);
        assert!(note.expect("note").contains("speed_rpm (step 1)"));
        let s = out[0].readings[0].2;
        assert!((s - (0.09f64 + 1.0 / 12.0).sqrt()).abs() < 1e-12, "σ {s}");
        // readings with decimals are not quantised at a coarse step
        let fine: Vec<ObservedRow> = (0..20)
            .map(|i| {
                let mut r = row(200.0, 43e3);
                r.readings = vec![(Observable::SpeedRpm, 100.0 + 0.1234567 * i as f64 + 1e-3 * (i * i) as f64, 0.3)];
                r
            })
            .collect();
        assert!(account_for_quantisation(&fine).1.is_none());
    }
}
