//! Command-line arguments shared by several commands (clap definitions only; the logic
//! that uses them lives in [`crate::motor`], [`crate::grid`] and the commands).

use clap::Args;
use trum_core::sweep::Axis;

// `optimize` and `calib` import these helpers from here.
pub use crate::format::{csv_number, fmt_sig, unit_of};
pub use crate::grid::parse_axis;
pub use crate::output::{OutputTarget, Progress};

/// `--motor` and `--effect`, shared by every command that solves.
#[derive(Args, Debug, Clone)]
pub struct MotorArgs {
    /// Motor: a TOML motor file, or a preset name (see `trum presets`). A file wins if it exists.
    #[arg(long, value_name = "FILE|PRESET")]
    pub motor: String,
    /// Switch an unmodelled effect on: NAME=STRENGTH or NAME:param=value,... (repeatable; see `trum effects`).
    #[arg(long = "effect", value_name = "NAME=STRENGTH")]
    pub effects: Vec<String>,
}

/// The four grid axes on the command line.
#[derive(Args, Debug, Clone, Default)]
pub struct GridArgs {
    /// Axial preload [N]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = crate::grid::parse_axis, allow_hyphen_values = true)]
    pub preload_n: Option<Axis>,
    /// Load torque [N·m]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = crate::grid::parse_axis, allow_hyphen_values = true)]
    pub torque_nm: Option<Axis>,
    /// Drive voltage amplitude per phase, zero-to-peak [V]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = crate::grid::parse_axis, allow_hyphen_values = true)]
    pub voltage_v: Option<Axis>,
    /// Drive frequency [Hz]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = crate::grid::parse_axis, allow_hyphen_values = true)]
    pub frequency_hz: Option<Axis>,
}
