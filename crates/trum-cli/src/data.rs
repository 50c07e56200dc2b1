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
    /// The ranges in force: the defaults with every `--plausible` applied; a column given
    /// twice is an error (which one was meant?).
    pub fn ranges(&self) -> Result<PlausibleRanges> {
        let mut r = PlausibleRanges::default();
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

/// Reads and checks a measurement file (layout: docs/MEASUREMENTS.md), values within
/// `plausible`; warnings (ignored columns, ...) are printed to `err`.
pub fn read_data(
    path: &str,
    motor: &Motor,
    plausible: &PlausibleRanges,
    err: &mut dyn Write,
) -> Result<(Measurements, BenchData)> {
    let p = Path::new(path);
    if p.is_dir() {
        bail!("--data '{path}' is a directory, not a measurement file");
    }
    if !p.exists() {
        bail!("measurement file '{path}' does not exist");
    }
    crate::output::note_input(p, &format!("--data '{path}'"));
    let bytes = std::fs::read(p).with_context(|| format!("cannot read measurement file '{path}'"))?;
    // MeasurementError's message names the file, line and column; show it unchanged.
    let m = parse_measurements_with(&bytes, path, plausible).map_err(|e| anyhow!("{e}"))?;
    for w in &m.warnings {
        writeln!(err, "warning: {w}")?;
    }
    let bench = observations(&m, motor);
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
