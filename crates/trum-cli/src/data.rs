//! Shared by `synth`, `calibrate` and `diagnose`: reading a measurement file (its
//! warnings go to stderr), JSON numbers without NaN, and writing a small file atomically.

use crate::output::OutputTarget;
use anyhow::{anyhow, bail, Context, Result};
use std::io::Write;
use std::path::Path;
use trum_core::bench::{observations, BenchData};
use trum_core::measurements::{parse_measurements, Measurements};
use trum_core::Motor;

/// Reads and checks a measurement file (layout: docs/MEASUREMENTS.md); warnings (ignored
/// columns, ...) are printed to `err`.
pub fn read_data(path: &str, motor: &Motor, err: &mut dyn Write) -> Result<(Measurements, BenchData)> {
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
    let m = parse_measurements(&bytes, path).map_err(|e| anyhow!("{e}"))?;
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
