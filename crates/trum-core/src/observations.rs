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
}

/// Converts measurements into observations. Every present reading becomes one
/// observation with the default noise level of its quantity; temperatures use the
/// row's `ambient_c`, else the motor's ambient temperature.
pub fn observations(m: &Measurements, motor: &Motor) -> BenchData {
    let present: Vec<Observable> = Observable::ALL.into_iter().filter(|o| m.has(column_of(*o))).collect();
    let mut rows = Vec::with_capacity(m.len());
    for i in 0..m.len() {
        let mut op = OperatingPoint::new(m.preload_n[i], m.torque_nm[i], m.voltage_v[i], m.frequency_hz[i]);
        op.elapsed_s = m.value(Column::ElapsedS, i).unwrap_or(0.0);
        let readings =
            present.iter().filter_map(|&o| m.value(column_of(o), i).map(|v| (o, v, o.default_sigma(v)))).collect();
        let ambient_c = m.value(Column::AmbientC, i).unwrap_or(motor.thermal.ambient_c);
        rows.push(ObservedRow { op, readings, ambient_c, speed_std_clipped: false });
    }
    let groups = (0..m.len()).map(|i| m.run_id_at(i).unwrap_or("").to_string()).collect();
    BenchData { rows, groups, lines: m.lines.clone(), observables: present }
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
}
