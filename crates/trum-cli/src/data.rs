//! Shared by `synth`, `calibrate` and `diagnose`: reading a measurement file (its
//! warnings go to stderr), JSON numbers without NaN, and writing a small file atomically.

use crate::output::OutputTarget;
use anyhow::{anyhow, bail, Context, Result};
use std::io::Write;
use std::path::Path;
use trum_core::bench::{observations, BenchData};
use trum_core::measurements::{parse_measurements_with, Measurements, PlausibleRanges};
use trum_core::Motor;

/// `--plausible COLUMN=LOW:HIGH`, shared by the commands that read a measurement file.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct PlausibleArgs {
    /// Plausible range of a measured column, replacing its default (docs/MEASUREMENTS.md,
    /// "Plausible ranges"): COLUMN=LOW:HIGH, an end left empty for no bound, or COLUMN=any (repeatable).
    #[arg(long = "plausible", value_name = "COLUMN=LOW:HIGH")]
    pub plausible: Vec<String>,
}

impl PlausibleArgs {
    /// The ranges in force: the defaults, then the `[plausible]` table of the motor file
    /// `motor` (when it is a file), then every `--plausible`; a column given twice on the
    /// command line is an error (which one was meant?).
    pub fn ranges(&self, motor: &str) -> Result<PlausibleRanges> {
        let mut r = crate::motor::load_plausible(motor)?;
        let mut seen: Vec<&str> = Vec::new();
        for spec in &self.plausible {
            let name = spec.split_once('=').map_or(spec.as_str(), |(n, _)| n.trim());
            if seen.contains(&name) {
                bail!("--plausible: '{name}' is given twice");
            }
            seen.push(name);
            r.parse_assignment(spec).map_err(|m| anyhow!("--plausible '{spec}': {m}"))?;
        }
        Ok(r)
    }
}

/// The size model of `calibrate` and `diagnose`: time and memory a measurement row costs
/// (docs/CLI.md, "Limits"). Both fit a systematic subsample of large data (20 000 and 160
/// rows by default), so beyond a constant a row costs its reading, the bench model and one
/// or two solves: 10^6 rows calibrated in 8.8 s (48 s at load average 11) and 0.70 GB,
/// 10^5 rows diagnosed in 1.4-2.5 s and 94 MB at load average 6 (docs/PERFORMANCE.md);
/// the figures here are the loaded machine's, upper bounds.
pub struct RowCost {
    /// Seconds a row, on the reference machine.
    pub seconds: f64,
    /// Bytes of memory a row.
    pub bytes: f64,
    /// What the work is called in the message (`calibrate`).
    pub what: &'static str,
}

/// Calibration's row cost.
pub const CALIBRATE_ROW: RowCost = RowCost { seconds: 5e-5, bytes: 7.2e2, what: "calibrate" };
/// The diagnosis's row cost (beyond the subsample's fits, a few seconds whatever the size).
pub const DIAGNOSE_ROW: RowCost = RowCost { seconds: 5e-5, bytes: 1e3, what: "diagnose" };

/// Refuses more than `max_rows` rows before any work, with the estimate and the flag.
pub fn check_rows(data: &str, rows: usize, max_rows: usize, cost: &RowCost) -> Result<()> {
    if rows > max_rows {
        bail!(
            "{data} has {rows} rows: an estimated {} and {} of memory to {} them; that is more than --max-rows \
             {max_rows} (docs/CLI.md, \"Limits\"); give --max-rows {rows} to run it anyway, or thin the data",
            crate::output::human_seconds(rows as f64 * cost.seconds),
            crate::output::human_bytes(rows as f64 * cost.bytes),
            cost.what
        );
    }
    Ok(())
}

/// Reads and checks a measurement file (layout: docs/MEASUREMENTS.md), values within
/// `plausible`; warnings (ignored columns, ...) are printed to `err`.
pub fn read_data(
    path: &str,
    motor: &Motor,
    plausible: &PlausibleRanges,
    err: &mut dyn Write,
) -> Result<(Measurements, BenchData)> {
    crate::output::note_input(Path::new(path), &format!("--data '{path}'"));
    let (m, bench) = read_data_quietly(path, motor, plausible)?;
    for w in &m.warnings {
        writeln!(err, "warning: {w}")?;
    }
    Ok((m, bench))
}

/// [`read_data`] with the warnings left in `Measurements::warnings` and the file not
/// recorded as an input (a fleet run records its files before its worker threads read them).
pub fn read_data_quietly(path: &str, motor: &Motor, plausible: &PlausibleRanges) -> Result<(Measurements, BenchData)> {
    let p = Path::new(path);
    if p.is_dir() {
        bail!("--data '{path}' is a directory, not a measurement file");
    }
    if !p.exists() {
        bail!("measurement file '{path}' does not exist");
    }
    let bytes = std::fs::read(p).with_context(|| format!("cannot read measurement file '{path}'"))?;
    // MeasurementError's message names the file, line and column; show it unchanged.
    let mut m = parse_measurements_with(&bytes, path, plausible).map_err(|e| anyhow!("{e}"))?;
    let bench = observations(&m, motor);
    // (the conversion's warnings, such as rows dropped as repeats, go with the reader's)
    m.warnings.extend(bench.warnings.iter().map(|w| format!("{path}: {w}")));
    Ok((m, bench))
}

/// A JSON number, or `null` when not finite (JSON has no NaN).
pub use trum_core::diagnose::json::num;

/// Writes `text` to `path` through a temporary file renamed at the end (`-`: stdout).
pub fn write_atomic(path: &Path, suffix: &str, text: &str, out: &mut dyn Write) -> Result<()> {
    let target = OutputTarget::create(path, suffix)?;
    match target.open()? {
        None => out.write_all(text.as_bytes())?,
        Some(mut f) => f.write_all(text.as_bytes()).with_context(|| format!("writing '{}'", path.display()))?,
    }
    target.finish()
}
