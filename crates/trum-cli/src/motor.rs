//! `--motor` and `--effect`: a motor file or a preset, with effects switched on.

use crate::args::MotorArgs;
use anyhow::{anyhow, bail, Context, Result};
use std::path::Path;
use trum_core::params::SweepTable;
use trum_core::presets;
use trum_core::Motor;

impl MotorArgs {
    /// The motor with the command-line effects applied, and its `[sweep]` table.
    pub fn load(&self) -> Result<(Motor, SweepTable)> {
        let (mut motor, sweep) = load_motor(&self.motor)?;
        for spec in &self.effects {
            motor.effects.parse_assignment(spec).map_err(|m| anyhow!("--effect '{spec}': {m}"))?;
        }
        Ok((motor, sweep))
    }
}

/// Reads `--motor`: an existing file is read as a motor file, anything else must be a
/// preset name. The error says which of the two was tried.
pub fn load_motor(spec: &str) -> Result<(Motor, SweepTable)> {
    let path = Path::new(spec);
    if path.is_file() {
        crate::output::note_input(path, &format!("--motor '{spec}'"));
        let text = std::fs::read_to_string(path).with_context(|| format!("cannot read motor file '{spec}'"))?;
        // ParamError's message names the file, line and key; show it unchanged.
        return Motor::from_toml_str_with_sweep(&text, spec).map_err(|e| anyhow!("{e}"));
    }
    if path.is_dir() {
        bail!("--motor '{spec}' is a directory, not a motor file");
    }
    match presets::find(spec) {
        Ok(p) => Ok((p.motor(), SweepTable::default())),
        Err(_) => {
            let names = presets::PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", ");
            let looks_like_file = spec.ends_with(".toml") || spec.contains('/') || spec.contains('\\');
            if looks_like_file {
                bail!("motor file '{spec}' does not exist (nor is it a preset name; valid presets are: {names})")
            }
            bail!("unknown preset '{spec}' (and no file of that name exists); valid presets are: {names}")
        }
    }
}

/// The `[tolerances]` table of `--motor` when it is a motor file (empty for a preset): the
/// priors of the baseline calibration (`trum_core::params::tolerances_from_toml_str`).
pub fn load_tolerances(spec: &str) -> Result<std::collections::BTreeMap<String, f64>> {
    let path = Path::new(spec);
    if !path.is_file() {
        return Ok(Default::default());
    }
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read motor file '{spec}'"))?;
    trum_core::params::tolerances_from_toml_str(&text, spec).map_err(|e| anyhow!("{e}"))
}
