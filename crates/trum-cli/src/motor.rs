//! `--motor` and `--effect`: a motor file or a preset, with effects switched on.

use crate::args::MotorArgs;
use anyhow::{anyhow, bail, Context, Result};
use std::path::Path;
use trum_core::dynamics::bar_type::BarMotor;
use trum_core::params::SweepTable;
use trum_core::presets;
use trum_core::Motor;

impl MotorArgs {
    /// The motor with the command-line effects applied, and its `[sweep]` table. An
    /// effect given twice is an error (which of the two was meant?).
    pub fn load(&self) -> Result<(Motor, SweepTable)> {
        let (mut motor, sweep) = load_motor(&self.motor)?;
        let mut seen: Vec<&str> = Vec::new();
        for spec in &self.effects {
            let name = spec.split(['=', ':']).next().unwrap_or("").trim();
            if seen.contains(&name) {
                bail!("--effect '{spec}': {name} is given twice; give each effect once (NAME:param=value,... sets several parameters)");
            }
            seen.push(name);
            motor.effects.parse_assignment(spec).map_err(|m| anyhow!("--effect '{spec}': {m}{}", effect_hint(spec)))?;
        }
        Ok((motor, sweep))
    }
}

/// Reads `--motor`: an existing file is read as a motor file, anything else must be a
/// preset name. The error says which of the two was tried.
pub fn load_motor(spec: &str) -> Result<(Motor, SweepTable)> {
    let path = Path::new(spec);
    // any existing path but a directory is read: a regular file, and also /dev/null, a
    // FIFO or a process substitution (`--motor <(...)`)
    if path.exists() && !path.is_dir() {
        crate::output::note_input(path, &format!("--motor '{spec}'"));
        let text = read_text(path, spec)?;
        if BarMotor::is_bar_file(&text) {
            bail!("'{spec}' is a bar-type motor file: {BAR_ONLY}");
        }
        // ParamError's message names the file, line and key; show it unchanged.
        return Motor::from_toml_str_with_sweep(&text, spec).map_err(|e| anyhow!("{e}"));
    }
    if path.is_dir() {
        bail!("--motor '{spec}' is a directory, not a motor file");
    }
    if presets::find_bar(spec).is_some() {
        let names = presets::PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", ");
        bail!("'{spec}' is a bar-type motor preset: {BAR_ONLY}; the ring-motor presets are: {names}");
    }
    match presets::find(spec) {
        Ok(p) => Ok((p.motor(), SweepTable::default())),
        Err(_) => {
            let names = presets::PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", ");
            let looks_like_file = spec.ends_with(".toml") || spec.contains('/') || spec.contains('\\');
            if looks_like_file {
                bail!("motor file '{spec}' does not exist (nor is it a preset name; valid presets are: {names})")
            }
            let hint = crate::suggest::preset_hint(spec);
            bail!("unknown preset '{spec}' (and no file of that name exists); valid presets are: {names}{hint}")
        }
    }
}

/// What a ring-motor command says when it is given a bar-type motor.
const BAR_ONLY: &str =
    "the bar-type motor model is a step-response model, so only `trum step` runs it; this command needs a ring motor";

/// `--motor` as a bar-type motor (a bar-type preset name, or a file with `kind = "bar"`
/// or a bar-type `preset`); `None` when it names a ring motor or nothing readable (the
/// ring-motor reader then gives the error).
pub fn load_bar_motor(spec: &str) -> Result<Option<BarMotor>> {
    let path = Path::new(spec);
    if path.is_file() {
        let text = std::fs::read_to_string(path).with_context(|| format!("cannot read motor file '{spec}'"))?;
        if !BarMotor::is_bar_file(&text) {
            return Ok(None);
        }
        return BarMotor::from_toml_str(&text, spec).map(Some).map_err(|e| anyhow!("{e}"));
    }
    Ok(presets::find_bar(spec).map(|p| p.motor()))
}

/// The `[tolerances]` table of `--motor` when it is a motor file (empty for a preset): the
/// priors of the baseline calibration (`trum_core::params::tolerances_from_toml_str`).
pub fn load_tolerances(spec: &str) -> Result<std::collections::BTreeMap<String, f64>> {
    let path = Path::new(spec);
    if !path.is_file() {
        // (a preset; or a device or FIFO already read once by load_motor)
        return Ok(Default::default());
    }
    let text = read_text(path, spec)?;
    trum_core::params::tolerances_from_toml_str(&text, spec).map_err(|e| anyhow!("{e}"))
}

/// The plausible ranges of the measured columns for `--motor` (docs/MEASUREMENTS.md,
/// "Plausible ranges"): the defaults with the motor file's `[plausible]` table applied
/// (the defaults alone for a preset).
pub fn load_plausible(spec: &str) -> Result<trum_core::measurements::PlausibleRanges> {
    let path = Path::new(spec);
    if !path.is_file() {
        return Ok(Default::default());
    }
    let text = read_text(path, spec)?;
    trum_core::params::plausible_from_toml_str(&text, spec).map_err(|e| anyhow!("{e}"))
}

/// `"; did you mean 'radial_friction'?"` when the effect named in `spec` is not known.
pub fn effect_hint(spec: &str) -> String {
    let name = spec.split([':', '=']).next().unwrap_or("").trim();
    let known = trum_core::effects::EFFECTS.iter().map(|e| e.name);
    if name.is_empty() || name == "none" || known.clone().any(|n| n == name) {
        return String::new();
    }
    crate::suggest::hint(name, crate::suggest::names(known))
}

/// A motor file's text; invalid UTF-8 is an error with its line and byte offset.
fn read_text(path: &Path, spec: &str) -> Result<String> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read motor file '{spec}'"))?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
        anyhow!(
            "{spec}: line {line}: byte 0x{:02X} at offset {at} is not valid UTF-8; save the file as UTF-8",
            bytes.get(at).copied().unwrap_or(0)
        )
    })
}
