//! `trum estimate`: the measured-input estimator (Sun et al. 2021) over the rows of a
//! measurement file: amplitude from the feedback voltage, contact and driving zones, every
//! loss, output power and efficiency per row (`trum_core::estimate`).

use crate::args::{csv_number, fmt_sig, MotorArgs};
use crate::data::{read_data, write_atomic};
use anyhow::{anyhow, bail, Result};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;
use trum_core::estimate::{EstimateStatus, Estimator, MeasuredPoint, ESTIMATE_COLUMNS};
use trum_core::measurements::Column;

#[derive(Args, Debug)]
pub struct EstimateArgs {
    #[command(flatten)]
    motor: MotorArgs,
    /// Measurement CSV (docs/MEASUREMENTS.md) with a `feedback_v` column.
    #[arg(long, value_name = "CSV")]
    data: String,
    /// Output CSV (default `-`: stdout; the summary then goes to stderr).
    #[arg(short = 'o', long = "output", value_name = "FILE", default_value = "-")]
    output: PathBuf,
    #[command(flatten)]
    plausible: crate::data::PlausibleArgs,
}

/// The input columns echoed in front of every estimate, as the measurement file names them.
pub const INPUT_COLUMNS: [&str; 6] = ["line", "preload_n", "voltage_v", "frequency_hz", "torque_nm", "feedback_v"];

pub fn run(a: &EstimateArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    let (motor, _) = a.motor.load()?;
    let est = Estimator::new(&motor).map_err(|e| anyhow!("--motor {}: {e}", a.motor.motor))?;
    let (m, _) = read_data(&a.data, &motor, &a.plausible.ranges(&a.motor.motor)?, err)?;
    if !m.has(Column::FeedbackV) {
        bail!(
            "{}: no 'feedback_v' column; the estimator reads the wave amplitude from the feedback-electrode voltage (docs/MEASUREMENTS.md)",
            a.data
        );
    }
    let measured_eff = m.has(Column::Efficiency);
    let mut header: Vec<&str> = INPUT_COLUMNS.to_vec();
    header.extend(["measured_speed_rpm", "status", "warnings"]);
    header.extend(ESTIMATE_COLUMNS.iter().map(|c| c.name));
    if measured_eff {
        header.push("measured_efficiency");
    }
    let mut csv = header.join(",") + "\n";
    let mut counts = [0usize; EstimateStatus::ALL.len()];
    let (mut est_eff, mut meas_eff) = (Vec::new(), Vec::new());
    for i in 0..m.len() {
        let v = |c: Column| m.value(c, i);
        let point = MeasuredPoint {
            preload_n: v(Column::PreloadN).unwrap_or(f64::NAN),
            voltage_v: v(Column::VoltageV).unwrap_or(f64::NAN),
            frequency_hz: v(Column::FrequencyHz).unwrap_or(f64::NAN),
            torque_nm: v(Column::TorqueNm).unwrap_or(f64::NAN),
            feedback_v: v(Column::FeedbackV),
            speed_rpm: v(Column::SpeedRpm),
        };
        let e = est.estimate(&point);
        counts[usize::from(e.status.code())] += 1;
        let mut cells = vec![m.line_of(i).map_or(String::new(), |l| l.to_string())];
        cells.extend(
            [
                point.preload_n,
                point.voltage_v,
                point.frequency_hz,
                point.torque_nm,
                point.feedback_v.unwrap_or(f64::NAN),
            ]
            .map(csv_number),
        );
        cells.push(csv_number(point.speed_rpm.unwrap_or(f64::NAN)));
        cells.push(e.status.as_str().into());
        cells.push(e.warnings.to_string());
        cells.extend(ESTIMATE_COLUMNS.iter().map(|c| csv_number((c.get)(&e))));
        if measured_eff {
            let me = v(Column::Efficiency);
            cells.push(csv_number(me.unwrap_or(f64::NAN)));
            if let (Some(me), true) = (me, e.status.is_valid()) {
                est_eff.push(e.efficiency);
                meas_eff.push(me);
            }
        }
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    write_atomic(&a.output, ".csv", &csv, out)?;
    let summary: &mut dyn Write = if a.output.as_os_str() == "-" { err } else { out };
    let words: Vec<String> = EstimateStatus::ALL
        .iter()
        .zip(counts)
        .filter(|(_, n)| *n > 0)
        .map(|(s, n)| format!("{n} {}", s.as_str()))
        .collect();
    writeln!(summary, "{} rows: {}", m.len(), words.join(", "))?;
    if meas_eff.len() >= 3 {
        let (r, rmse) = agreement(&est_eff, &meas_eff);
        writeln!(
            summary,
            "estimated vs measured efficiency over {} rows: correlation r = {}, RMS error {}",
            meas_eff.len(),
            fmt_sig(r, 4),
            fmt_sig(rmse, 3)
        )?;
    }
    Ok(0)
}

/// Pearson correlation and RMS difference of paired samples.
fn agreement(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy, mut sq) = (0.0, 0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
        sq += (a - b) * (a - b);
    }
    let r = if sxx > 0.0 && syy > 0.0 { sxy / (sxx * syy).sqrt() } else { f64::NAN };
    (r, (sq / n).sqrt())
}
