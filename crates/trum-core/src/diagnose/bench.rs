//! The bench model of the diagnosis: what a test bench does to its records besides the
//! readings' random noise, undone or accounted for before any fit (docs/DIAGNOSIS.md,
//! "The bench model").
//!
//! - **Set points read back.** A drive voltage, frequency, preload or load held constant
//!   through a run is recorded as the bench reads it back, with the read-back's noise;
//!   the motor ran at the set point. Within a run, a column that scatters by less than
//!   [`SET_POINT_CV`] around its mean without a trend in row order is such a read-back,
//!   and each row gets the run's mean (the set point's best estimate: a nuisance
//!   parameter per run and column). Left as recorded: a column swept within the run
//!   (monotone in row order), one whose values repeat exactly (set points written as set,
//!   at several levels), and one the readings follow (a real variation of the operating
//!   point, whatever the rows' order: files without runs, or with rows in random order,
//!   show no trend).
//! - **Quantised readings.** A column whose every reading is a whole multiple of a step
//!   carries the rounding's uniform error, of variance step²/12, beside its noise.
//! - **Stale readings.** A reading that repeats the previous reading of its quantity in its
//!   run to every one of more than five significant digits is an instrument that had not
//!   updated when the row was logged, and is left out.
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

/// True when the values `v` are written as set rather than read back: fewer than three
/// quarters of them are distinct (a read-back's noise makes every value its own; exact
/// repeats are levels).
fn repeats_levels(v: &[f64]) -> bool {
    let mut sorted = v.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    (sorted.len() as f64) < 0.75 * v.len() as f64
}

/// Family-wise false-alarm rate of [`readings_follow`] for one run and column: the
/// chance that the readings of a run held at one set point seem to follow its read-back
/// noise. A sweep that moves the motor's state gives correlations far beyond it.
const FOLLOW_P: f64 = 1e-3;

/// Two-sided tail probability P(|T| ≥ t) of Student's t with `nu` ≥ 1 degrees of freedom,
/// by the finite series in θ = atan(t/√ν) of Abramowitz & Stegun (1964), eqs. 26.7.3 (odd
/// ν) and 26.7.4 (even ν); exact to rounding for every ν, O(ν) terms.
fn student_t_two_sided(t: f64, nu: usize) -> f64 {
    let t = t.abs();
    if nu == 0 || t.is_nan() {
        return 1.0;
    }
    if t.is_infinite() {
        return 0.0;
    }
    let theta = (t / (nu as f64).sqrt()).atan();
    let (s, c) = theta.sin_cos();
    let c2 = c * c;
    // the series' terms: products of (k/(k+1))·cos²θ over k = 2, 4, … (odd ν) or 1, 3, …
    // (even ν), up to k = ν − 3
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = if nu % 2 == 1 { 2 } else { 1 };
    while k + 1 < nu {
        term *= k as f64 / (k + 1) as f64 * c2;
        sum += term;
        k += 2;
    }
    let within = if nu == 1 {
        2.0 / std::f64::consts::PI * theta
    } else if nu % 2 == 1 {
        2.0 / std::f64::consts::PI * (theta + s * c * sum)
    } else {
        s * sum
    };
    (1.0 - within).clamp(0.0, 1.0)
}

/// True when some reading of the run's rows `idx` follows the column `col`: a correlation
/// of the two over the rows that have the reading (at least five) whose Student-t tail
/// probability, times the number of quantities tested, is below [`FOLLOW_P`] (a
/// Bonferroni bound over the quantities). A read-back's noise is not what the motor ran
/// at, so the readings cannot follow it; with seven quantities and runs of a few rows, a
/// fixed |t| threshold would be crossed by chance in several runs of a large file.
fn readings_follow(rows: &[ObservedRow], idx: &[usize], col: &str) -> bool {
    let mut rows_c: Vec<ObservedRow> = idx.iter().map(|&i| rows[i].clone()).collect();
    let x: Vec<f64> = rows_c.iter_mut().map(|r| *column_mut(r, col)).collect();
    let tails: Vec<f64> = Observable::ALL
        .iter()
        .filter_map(|&o| {
            let pairs: Vec<(f64, f64)> = x
                .iter()
                .zip(&rows_c)
                .filter_map(|(&xi, r)| r.readings.iter().find(|q| q.0 == o).map(|q| (xi, q.1)))
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .collect();
            let n = pairs.len() as f64;
            if n < 5.0 {
                return None;
            }
            let (mx, my) = (pairs.iter().map(|p| p.0).sum::<f64>() / n, pairs.iter().map(|p| p.1).sum::<f64>() / n);
            let sxy: f64 = pairs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
            let sxx: f64 = pairs.iter().map(|p| (p.0 - mx).powi(2)).sum();
            let syy: f64 = pairs.iter().map(|p| (p.1 - my).powi(2)).sum();
            if sxx <= 0.0 || syy <= 0.0 {
                return None;
            }
            let r = (sxy / (sxx * syy).sqrt()).clamp(-1.0, 1.0);
            let t = r.abs() * ((n - 2.0) / (1.0 - r * r).max(1e-300)).sqrt();
            Some(student_t_two_sided(t, pairs.len() - 2))
        })
        .collect();
    tails.iter().fold(1.0f64, |a, &p| a.min(p)) * tails.len() as f64 <= FOLLOW_P && !tails.is_empty()
}

/// The runs of `rows`: `groups` as given when any row names its run, else runs inferred
/// from the set points, whatever the rows' order (a file without `run_id`, perhaps with its
/// rows in random order, as a designed experiment runs them). An inferred run is the rows
/// that share a level of the preload and of the drive voltage (levels: values closer than
/// [`SET_POINT_CV`] of their size chain into one) and whether they are a time series
/// (`elapsed_s` > 0). Sweeps of the load or frequency then fall inside a run, where the
/// set-point test leaves them alone, and a read-back preload or voltage scatters around its
/// level inside one.
pub fn runs(rows: &[ObservedRow], groups: &[String]) -> Vec<String> {
    if groups.iter().any(|g| !g.is_empty()) {
        return groups.to_vec();
    }
    let preload = levels(&rows.iter().map(|r| r.op.preload_n).collect::<Vec<_>>());
    let voltage = levels(&rows.iter().map(|r| r.op.voltage_v).collect::<Vec<_>>());
    rows.iter()
        .enumerate()
        .map(|(i, r)| format!("inferred:{}:{}:{}", preload[i], voltage[i], u8::from(r.op.elapsed_s > 0.0)))
        .collect()
}

/// The level index of each value: sorted values chain into one level while neighbours are
/// within [`SET_POINT_CV`] of their size.
fn levels(v: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..v.len()).collect();
    order.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let mut out = vec![0; v.len()];
    let mut level = 0;
    for w in order.windows(2) {
        let (a, b) = (v[w[0]], v[w[1]]);
        // (a NaN starts a level of its own)
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(b - a <= SET_POINT_CV * a.abs().max(b.abs())) {
            level += 1;
        }
        out[w[1]] = level;
    }
    out
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
            if is_read_back(&v) && !repeats_levels(&v) && !readings_follow(rows, idx, col) {
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

/// `rows` with the noise level of every reading of a quantised column raised by the
/// rounding error (σ² + q²/12), in place (a large file's rows are held once), and a note
/// naming those columns (`None` when no column is quantised more coarsely than its noise).
pub fn account_for_quantisation(mut rows: Vec<ObservedRow>) -> (Vec<ObservedRow>, Option<String>) {
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
        for r in rows.iter_mut() {
            for x in r.readings.iter_mut().filter(|x| x.0 == o) {
                x.2 = (x.2 * x.2 + q * q / 12.0).sqrt();
            }
        }
        seen.push(format!("{} (step {q})", o.column()));
    }
    let note = (!seen.is_empty()).then(|| {
        format!("quantised readings: their rounding error (step²/12) is added to the noise levels: {}", seen.join(", "))
    });
    (rows, note)
}

/// True when `y` is written to more than five significant digits: no five-digit decimal is
/// the same number. Two independent readings of a noisy quantity agree to that many digits
/// about once in 10⁵ × (noise / value) pairs (a reading with 1 % noise: once in a thousand
/// pairs for five digits, once in 10⁸ for the full precision a logger writes by default).
/// Zero is a reading that repeats for real (a stalled rotor, a clipped speed spread).
fn written_finely(y: f64) -> bool {
    y != 0.0 && format!("{y:.4e}").parse::<f64>().is_ok_and(|short| short != y)
}

/// `rows` without their stale readings, in place, and a note counting them by quantity
/// (`None` when there are none). A reading is stale when the previous reading of its
/// quantity in its run (`groups`, in row order) is the same number and is written to more
/// than five significant digits ([`written_finely`]): an instrument polled faster than it
/// updates repeats its last value while the motor has moved on (a power meter that updates
/// once a second on a bench that logs twice a second). Kept, such readings are wrong by
/// however far the motor moved, and their zero differences from the readings before them
/// read as a bench quieter than it is to the noise levels estimated from the data, which
/// then make the model's honest misses look like a gap in it (a null combined campaign with
/// seven power readings in ten carried over was `unexplained`). The first reading of each
/// value is kept.
pub fn drop_stale_readings(mut rows: Vec<ObservedRow>, groups: &[String]) -> (Vec<ObservedRow>, Option<String>) {
    let mut last: std::collections::HashMap<(&str, Observable), u64> = std::collections::HashMap::new();
    let mut dropped: BTreeMap<Observable, usize> = BTreeMap::new();
    for (i, r) in rows.iter_mut().enumerate() {
        let run = groups.get(i).map_or("", String::as_str);
        r.readings.retain(|&(o, y, _)| {
            let repeated = last.insert((run, o), y.to_bits()) == Some(y.to_bits());
            let stale = repeated && written_finely(y);
            if stale {
                *dropped.entry(o).or_default() += 1;
            }
            !stale
        });
    }
    let note = (!dropped.is_empty()).then(|| {
        let list: Vec<String> = dropped.iter().map(|(o, n)| format!("{} {n}", o.column())).collect();
        format!(
            "stale readings: a reading that repeats the previous one of its quantity in its run to every one of \
             more than five significant digits is an instrument that had not updated (no two noisy readings agree \
             so closely); left out of every fit and held-out figure: {}",
            list.join(", ")
        )
    });
    (rows, note)
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

    /// Rows in random order without runs: a frequency swept 41.5-45 kHz among rows held at
    /// 43 kHz scatters by under 2 % with no trend in row order, but its values repeat and
    /// the speed follows them; a voltage read back ±0.5 % around 200 V is still snapped.
    #[test]
    fn a_sweep_in_shuffled_rows_without_runs_is_kept() {
        let mut rows: Vec<ObservedRow> = Vec::new();
        for i in 0..15 {
            let f = 41_500.0 + 250.0 * i as f64;
            let mut r = row(200.0 + 0.8 * (1.7 * i as f64).sin(), f);
            r.readings = vec![(Observable::SpeedRpm, 200.0 - 0.05 * (f - 41_500.0), 1.0)];
            rows.push(r);
        }
        for i in 0..30 {
            let mut r = row(200.0 + 0.8 * (2.3 * i as f64 + 0.4).sin(), 43_000.0);
            r.readings = vec![(Observable::SpeedRpm, 120.0 + (i % 3) as f64, 1.0)];
            rows.push(r);
        }
        // a fixed shuffle: no trend in row order
        let order: Vec<usize> = (0..rows.len()).map(|i| (i * 17) % rows.len()).collect();
        let shuffled: Vec<ObservedRow> = order.iter().map(|&i| rows[i].clone()).collect();
        let f: Vec<f64> = shuffled.iter().map(|r| r.op.frequency_hz).collect();
        assert!(is_read_back(&f), "the order test alone would snap the sweep");
        let groups = vec![String::new(); shuffled.len()];
        let (snapped, note) = snap_set_points(&shuffled, &groups);
        assert!(snapped.iter().zip(&shuffled).all(|(a, b)| a.op.frequency_hz == b.op.frequency_hz), "sweep moved");
        assert!(note.expect("note").contains("voltage_v in 1 run"));
        // without the repeats, the speed following the frequency keeps it too
        let distinct: Vec<ObservedRow> = shuffled
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let mut r = r.clone();
                r.op.frequency_hz += 1e-3 * i as f64;
                r
            })
            .collect();
        assert!(!repeats_levels(&distinct.iter().map(|r| r.op.frequency_hz).collect::<Vec<_>>()));
        let (snapped, _) = snap_set_points(&distinct, &groups);
        assert!(snapped.iter().zip(&distinct).all(|(a, b)| a.op.frequency_hz == b.op.frequency_hz), "sweep moved");
    }

    /// Without run names, runs are the rows at one preload and voltage level, in any order.
    #[test]
    fn runs_are_inferred_from_set_point_levels_only_without_names() {
        let mut rows = Vec::new();
        for (k, preload) in [100.0, 150.0, 200.0].iter().enumerate() {
            for i in 0..5 {
                let mut r = row(200.0 * (1.0 + 0.004 * ((k * 5 + i) as f64).sin()), 43e3);
                r.op.preload_n = preload * (1.0 + 0.004 * ((3 * i + k) as f64).cos());
                r.op.torque_nm = 0.05 * i as f64;
                rows.push(r);
            }
        }
        rows.reverse();
        let inferred = runs(&rows, &vec![String::new(); rows.len()]);
        let distinct: std::collections::BTreeSet<&String> = inferred.iter().collect();
        assert_eq!(distinct.len(), 3, "{inferred:?}");
        // each run holds the five rows of one preload
        assert!(inferred.chunks(5).all(|c| c.iter().all(|g| g == &c[0])), "{inferred:?}");
        let named = vec!["a".to_string(); rows.len()];
        assert_eq!(runs(&rows, &named), named);
        // the read-back preload is then snapped within each run
        let (snapped, note) = snap_set_points(&rows, &inferred);
        assert!(note.expect("note").contains("preload_n in 3 run(s)"));
        assert!(snapped.iter().all(|r| [100.0, 150.0, 200.0].iter().any(|p| (r.op.preload_n - p).abs() < 0.5)));
    }

    /// Student's t tail against tabulated quantiles (two-sided 5 % and 0.1 %: 12.706 and
    /// 636.62 at 1 degree of freedom, 4.303 and 31.599 at 2, 2.571 and 6.869 at 5, 2.228
    /// and 4.587 at 10, 2.042 and 3.646 at 30) and the normal limit (1.960 at 10^4).
    #[test]
    fn student_t_tails_match_the_tables() {
        let cases = [
            (12.706, 1, 0.05),
            (636.62, 1, 0.001),
            (4.303, 2, 0.05),
            (31.599, 2, 0.001),
            (2.571, 5, 0.05),
            (6.869, 5, 0.001),
            (2.228, 10, 0.05),
            (4.587, 10, 0.001),
            (2.042, 30, 0.05),
            (3.646, 30, 0.001),
            (1.960, 10_000, 0.05),
        ];
        for (t, nu, p) in cases {
            let got = student_t_two_sided(t, nu);
            assert!((got - p).abs() < 2e-3 * p.max(0.01), "t {t}, ν {nu}: {got} against {p}");
        }
        assert_eq!(student_t_two_sided(0.0, 7), 1.0);
        assert_eq!(student_t_two_sided(f64::INFINITY, 7), 0.0);
    }

    /// A read-back voltage (±0.5 % normal noise) in 200 runs of seven rows along a load
    /// sweep that five readings follow, each with unit noise: the readings of at most one
    /// run seem to follow the voltage (the family-wise rate 10⁻³ expects 0.2 of 200; a
    /// fixed threshold |t| > 4 on the largest of the five correlations kept the read-back
    /// in 5 of these runs).
    #[test]
    fn chance_correlations_in_short_runs_do_not_keep_a_read_back() {
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut gauss = move || {
            let (u, v) = (1.0 - uniform(), uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        let quantities = [
            Observable::SpeedRpm,
            Observable::InputPowerW,
            Observable::CurrentA,
            Observable::FeedbackV,
            Observable::Efficiency,
        ];
        let mut kept = 0;
        for _ in 0..200 {
            let rows: Vec<ObservedRow> = (0..7)
                .map(|i| {
                    let mut r = row(200.0 * (1.0 + 0.005 * gauss()), 43e3);
                    r.op.torque_nm = 0.1 * i as f64;
                    r.readings = quantities
                        .iter()
                        .enumerate()
                        .map(|(k, &o)| {
                            let i = i as f64;
                            (o, 10.0 * i * (k + 1) as f64 - i * i + gauss(), 1.0)
                        })
                        .collect();
                    r
                })
                .collect();
            let idx: Vec<usize> = (0..rows.len()).collect();
            kept += usize::from(readings_follow(&rows, &idx, "voltage_v"));
        }
        assert!(kept <= 1, "{kept} of 200 runs kept their read-back voltage");
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
        let (out, note) = account_for_quantisation(rows);
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
        assert!(account_for_quantisation(fine).1.is_none());
    }

    /// A carried-over reading (the same number to every digit as the previous reading of
    /// its quantity in its run) is left out and counted; the first reading of the value,
    /// readings written to five digits or fewer (a quantised or coarse instrument), zeros,
    /// and the first reading of another run are kept.
    #[test]
    fn carried_over_readings_are_left_out_and_counted() {
        let power = [10.155413238443417, 10.155413238443417, 10.155413238443417, 12.0, 12.0, 0.0, 0.0, 13.5];
        let runs = ["a", "a", "a", "a", "a", "a", "a", "b"];
        let mut rows: Vec<ObservedRow> = power
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let mut r = row(200.0, 43e3);
                r.readings =
                    vec![(Observable::SpeedRpm, 100.0 + 0.37 * i as f64, 0.5), (Observable::InputPowerW, p, 0.1)];
                r
            })
            .collect();
        // run b starts with a value run a had: not a carry-over
        rows[7].readings[1].1 = 10.155413238443417;
        let groups: Vec<String> = runs.iter().map(|s| s.to_string()).collect();
        let (out, note) = drop_stale_readings(rows, &groups);
        let kept: Vec<usize> = out.iter().map(|r| r.readings.len()).collect();
        assert_eq!(kept, vec![2, 1, 1, 2, 2, 2, 2, 2]);
        assert!(out[1].readings.iter().all(|x| x.0 == Observable::SpeedRpm));
        let note = note.expect("note");
        assert!(note.ends_with("input_power_w 2"), "{note}");
        assert!(!written_finely(12.0) && !written_finely(0.0) && !written_finely(101.25));
        assert!(written_finely(10.155413238443417) && written_finely(101.2501));
    }

    /// Seven power readings in ten carried over from the row before, on a combined campaign:
    /// kept, their zero differences would read the power meter as about half as noisy as
    /// it is (the noise levels from the data); left out, the estimate is no lower than the
    /// one from the campaign as measured (the lines through the readings left then span
    /// wider gaps, whose curvature adds a little: the conservative side) and within 30 % of it.
    #[test]
    fn carried_over_readings_do_not_make_the_bench_look_quiet() {
        let m = crate::calibrate::tests::reference_motor();
        let cfg = crate::synth::SynthConfig {
            campaign: crate::synth::Campaign::Combined,
            noise: 1.0,
            seed: 9704,
            ..crate::synth::SynthConfig::default()
        };
        let synth = crate::synth::synthesize(&m, &cfg).expect("synth");
        let groups: Vec<String> = synth.iter().map(|r| r.run_id.clone()).collect();
        let clean: Vec<ObservedRow> = synth.iter().map(|r| r.observed()).collect();
        let mut stale = clean.clone();
        for i in 1..stale.len() {
            if i % 10 < 7 && groups[i] == groups[i - 1] {
                let prev = stale[i - 1].readings.iter().find(|x| x.0 == Observable::InputPowerW).map(|x| x.1);
                if let (Some(p), Some(x)) =
                    (prev, stale[i].readings.iter_mut().find(|x| x.0 == Observable::InputPowerW))
                {
                    x.1 = p;
                }
            }
        }
        let factor = |rows: &[ObservedRow]| crate::noise::estimate(rows, &groups)[&Observable::InputPowerW].factor;
        let (honest, kept) = (factor(&clean), factor(&stale));
        let (fresh, note) = drop_stale_readings(stale, &groups);
        assert!(note.is_some());
        let left_out = factor(&fresh);
        assert!(kept < 0.7 * honest, "factor {kept} with the carried-over readings against {honest}");
        assert!(left_out > 0.95 * honest && left_out < 1.3 * honest, "factor {left_out} without them against {honest}");
        // the clean campaign has none
        assert!(drop_stale_readings(clean, &groups).1.is_none());
    }
}
