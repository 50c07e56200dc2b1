//! Bench data ↔ model observations: measurement files (crate::measurements) become the
//! observed rows that calibration and diagnosis fit, and synthetic campaigns become
//! measurement files.

use crate::error::TrumError;
use crate::measurements::{Column, Measurements, Row};
use crate::observable::{Observable, ObservedRow};
use crate::params::Motor;
use crate::solve::OperatingPoint;
use crate::synth::SynthRow;

/// The column of an observable.
pub fn column_of(o: Observable) -> Column {
    match o {
        Observable::SpeedRpm => Column::SpeedRpm,
        Observable::InputPowerW => Column::InputPowerW,
        Observable::CurrentA => Column::CurrentA,
        Observable::Efficiency => Column::Efficiency,
        Observable::FeedbackV => Column::FeedbackV,
        Observable::TemperatureC => Column::TemperatureC,
        Observable::SpeedStdRpm => Column::SpeedStdRpm,
    }
}

/// Observed rows of a measurement file, ready for calibration and diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchData {
    /// One per measurement row.
    pub rows: Vec<ObservedRow>,
    /// Run id of each row (empty when the file has none).
    pub groups: Vec<String>,
    /// File line of each row.
    pub lines: Vec<usize>,
    /// Observables present in the file.
    pub observables: Vec<Observable>,
    /// What the conversion did to the rows (rows that repeat an earlier one, dropped), for
    /// the user: one line each, without the file's name.
    pub warnings: Vec<String>,
}

/// Converts measurements into observations. Every present reading becomes one
/// observation with the default noise level of its quantity; temperatures use the
/// row's `ambient_c`, else the motor's ambient temperature.
///
/// A row equal to an earlier row in every column of the layout (`run_id` included; columns
/// outside the layout are not compared) is dropped, with one warning naming the lines: it
/// is one reading logged twice (a logger that wrote a line twice, a file joined with
/// itself, an instrument polled faster than it updates), not a second measurement. Kept,
/// it would count one reading's noise twice in every fit, and the model-free noise levels
/// (crate::noise), which take a repeated reading's difference from the first for noise,
/// would see zero differences and read the bench as quieter than it is. Independent
/// readings at one set point differ by their noise and are all kept.
pub fn observations(m: &Measurements, motor: &Motor) -> BenchData {
    let present: Vec<Observable> = Observable::ALL.into_iter().filter(|o| m.has(column_of(*o))).collect();
    let repeats = repeated_rows(m);
    let mut dropped = vec![false; m.len()];
    for &(i, _) in &repeats {
        dropped[i] = true;
    }
    let mut rows = Vec::with_capacity(m.len());
    let (mut groups, mut lines) = (Vec::with_capacity(m.len()), Vec::with_capacity(m.len()));
    for i in (0..m.len()).filter(|&i| !dropped[i]) {
        let mut op = OperatingPoint::new(m.preload_n[i], m.torque_nm[i], m.voltage_v[i], m.frequency_hz[i]);
        op.elapsed_s = m.value(Column::ElapsedS, i).unwrap_or(0.0);
        let readings =
            present.iter().filter_map(|&o| m.value(column_of(o), i).map(|v| (o, v, o.default_sigma(v)))).collect();
        let ambient_c = m.value(Column::AmbientC, i).unwrap_or(motor.thermal.ambient_c);
        rows.push(ObservedRow { op, readings, ambient_c, speed_std_clipped: false });
        groups.push(m.run_id_at(i).unwrap_or("").to_string());
        lines.push(m.lines.get(i).copied().unwrap_or(i + 2));
    }
    let warnings = repeats_warning(m, &repeats).into_iter().collect();
    BenchData { rows, groups, lines, observables: present, warnings }
}

/// Rows equal to an earlier row in every column of the layout: (row, the first row it
/// repeats), in file order. Cells compare by their values' bits (a file's text "1.50" and
/// "1.5" are one value); an empty cell equals only an empty cell. One hash a row is kept
/// (16 bytes a row, not the row's cells: a file of 10^6 rows adds tens of megabytes), and a
/// row whose hash was seen is compared with that row's cells, so a collision of two different
/// rows never drops one (it can only leave a later repeat of the second one undetected).
fn repeated_rows(m: &Measurements) -> Vec<(usize, usize)> {
    use std::hash::{Hash, Hasher};
    let columns: Vec<Column> = Column::ALL.into_iter().filter(|&c| c != Column::RunId && m.has(c)).collect();
    let cells = |i: usize| columns.iter().map(move |&c| m.value(c, i).map(f64::to_bits));
    let same = |i: usize, j: usize| m.run_id_at(i) == m.run_id_at(j) && cells(i).eq(cells(j));
    let hash = |i: usize| {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        cells(i).for_each(|x| x.hash(&mut h));
        m.run_id_at(i).hash(&mut h);
        h.finish()
    };
    let mut first: std::collections::HashMap<u64, usize> = std::collections::HashMap::with_capacity(m.len());
    let mut out = Vec::new();
    for i in 0..m.len() {
        match first.entry(hash(i)) {
            std::collections::hash_map::Entry::Occupied(e) => {
                if same(i, *e.get()) {
                    out.push((i, *e.get()));
                }
            }
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(i);
            }
        }
    }
    out
}

/// The one warning for the rows [`repeated_rows`] found, naming the first few by line.
fn repeats_warning(m: &Measurements, repeats: &[(usize, usize)]) -> Option<String> {
    let line = |i: usize| m.lines.get(i).copied().unwrap_or(i + 2);
    let mut named: Vec<String> =
        repeats.iter().take(5).map(|&(i, j)| format!("line {} repeats line {}", line(i), line(j))).collect();
    if repeats.len() > 5 {
        named.push(format!("and {} more", repeats.len() - 5));
    }
    let (n, total) = (repeats.len(), m.len());
    (n > 0).then(|| {
        format!(
            "{n} of {total} rows repeat an earlier row in every column ({}); each is counted once: \
             a reading logged twice is one measurement, not two",
            named.join(", ")
        )
    })
}

/// Writes synthetic rows as measurements (the layout of docs/MEASUREMENTS.md).
pub fn to_measurements(rows: &[SynthRow]) -> Result<Measurements, TrumError> {
    let mut b = Measurements::builder();
    for r in rows {
        let speed = r.readings.iter().find(|x| x.0 == Observable::SpeedRpm).map(|x| x.1).unwrap_or(0.0);
        let mut row =
            Row::new(r.op.preload_n, r.op.voltage_v, r.op.frequency_hz, r.op.torque_nm, speed).with_run_id(&r.run_id);
        for &(o, v) in &r.readings {
            row = match o {
                Observable::SpeedRpm => row,
                Observable::InputPowerW => row.with_input_power_w(v),
                Observable::CurrentA => row.with_current_a(v),
                Observable::Efficiency => row.with_efficiency(v),
                Observable::FeedbackV => row.with_feedback_v(v),
                Observable::TemperatureC => row.with_temperature_c(v).with_ambient_c(r.ambient_c),
                Observable::SpeedStdRpm => row.with_speed_std_rpm(v),
            };
        }
        if r.time_series {
            row = row.with_elapsed_s(r.op.elapsed_s);
        }
        b.push(row);
    }
    b.build().map_err(|e| TrumError::input(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::frozen as preset;
    use crate::synth::{synthesize, Campaign, SynthConfig};

    #[test]
    fn synth_output_passes_the_reader_and_round_trips() {
        let m = preset("trum60a").expect("preset");
        let rows =
            synthesize(&m, &SynthConfig { campaign: Campaign::Combined, ..SynthConfig::default() }).expect("synthesis");
        let meas = to_measurements(&rows).expect("measurements");
        let text = meas.to_csv_string();
        let back =
            crate::measurements::parse_measurements(text.as_bytes(), "synth.csv").expect("the written file reads back");
        assert_eq!(back.len(), rows.len());
        assert!(back.warnings.is_empty(), "{:?}", back.warnings);
        let obs = observations(&back, &m);
        for (a, b) in obs.rows.iter().zip(&rows) {
            assert_eq!(a.op, b.op);
            let mut x: Vec<(Observable, f64)> = a.readings.iter().map(|r| (r.0, r.1)).collect();
            let mut y = b.readings.clone();
            x.sort_by_key(|p| p.0);
            y.sort_by_key(|p| p.0);
            assert_eq!(x, y);
        }
    }

    /// A measurement file with every row twice (a file joined with itself) gives the same
    /// observations as the file once, with one warning naming the repeats by line; without
    /// that, its model-free noise levels would come out at about half the truth's, as the
    /// zero differences of the repeats say (the reason for dropping them).
    #[test]
    fn a_file_joined_with_itself_gives_the_observations_of_the_file_once() {
        let m = preset("trum60a").expect("preset");
        let cfg = SynthConfig { campaign: Campaign::PreloadTorque, noise: 1.0, seed: 7, ..SynthConfig::default() };
        let once = to_measurements(&synthesize(&m, &cfg).expect("synthesis")).expect("measurements");
        let text = once.to_csv_string();
        let body = text.split_once('\n').expect("header").1;
        let twice_text = format!("{text}{body}");
        let twice = crate::measurements::parse_measurements(twice_text.as_bytes(), "twice.csv").expect("reads");
        assert_eq!(twice.len(), 2 * once.len());
        let (a, b) = (observations(&once, &m), observations(&twice, &m));
        assert!(a.warnings.is_empty(), "{:?}", a.warnings);
        assert_eq!((&b.rows, &b.groups), (&a.rows, &a.groups));
        // the lines kept are those of the first copy
        assert_eq!(b.lines, a.lines);
        assert_eq!(b.warnings.len(), 1, "{:?}", b.warnings);
        let n = once.len();
        let first_repeat = format!("line {} repeats line 2", n + 2);
        assert!(b.warnings[0].starts_with(&format!("{n} of {} rows repeat", 2 * n)), "{}", b.warnings[0]);
        assert!(b.warnings[0].contains(&first_repeat) && b.warnings[0].contains("more"), "{}", b.warnings[0]);
        // the repeats kept, every speed's noise level would be read from their zero
        // differences as well as from the lines through neighbours
        let mut kept = Vec::new();
        let mut kept_groups = Vec::new();
        for (r, g) in a.rows.iter().zip(&a.groups) {
            kept.extend([r.clone(), r.clone()]);
            kept_groups.extend([g.clone(), g.clone()]);
        }
        let honest = crate::noise::estimate(&a.rows, &a.groups)[&Observable::SpeedRpm].factor;
        let doubled = crate::noise::estimate(&kept, &kept_groups)[&Observable::SpeedRpm].factor;
        assert!(doubled < 0.7 * honest, "noise factor {doubled} with the repeats against {honest}");
    }

    /// Readings at one set point that differ (independent readings, however close) are all
    /// kept, as are rows that differ only in their run or in a reading left empty.
    #[test]
    fn readings_that_differ_in_any_column_are_all_kept() {
        let m = preset("trum60a").expect("preset");
        let text = "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm,current_a,run_id\n\
                    200,200,43000,0.1,100,0.1,a\n\
                    200,200,43000,0.1,100.000001,0.1,a\n\
                    200,200,43000,0.1,100,0.1,b\n\
                    200,200,43000,0.1,100,,a\n\
                    200,200,43000,0.1,100.0,0.10,a\n";
        let meas = crate::measurements::parse_measurements(text.as_bytes(), "d.csv").expect("reads");
        let b = observations(&meas, &m);
        assert_eq!(b.rows.len(), 4);
        assert_eq!(b.lines, vec![2, 3, 4, 5]);
        assert_eq!(b.warnings, vec!["1 of 5 rows repeat an earlier row in every column (line 6 repeats line 2); each is counted once: a reading logged twice is one measurement, not two".to_string()]);
    }
}
