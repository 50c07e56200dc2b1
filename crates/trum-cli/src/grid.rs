//! Grid axes on the command line: the `VALUE` / `START:STOP:N` syntax, the order in which
//! the command line, the motor file's `[sweep]` and the defaults are taken, and the check
//! every grid passes before it is solved (the core's: [`trum_core::sweep::Grid::validate`]).

use crate::args::GridArgs;
use anyhow::{anyhow, Result};
use trum_core::params::SweepTable;
use trum_core::sweep::{Axis, Grid};

/// Parses an axis: `VALUE` or `START:STOP:N` (N ≥ 1 evenly spaced values, both ends included).
pub fn parse_axis(s: &str) -> Result<Axis, String> {
    let num = |t: &str| -> Result<f64, String> {
        let v: f64 = t.trim().parse().map_err(|_| format!("'{}' is not a number", t.trim()))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("'{}' is not a finite number", t.trim()))
        }
    };
    let parts: Vec<&str> = s.split(':').collect();
    match parts.as_slice() {
        [v] => Ok(Axis::fixed(num(v)?)),
        [a, b, n] => {
            let n: usize = n
                .trim()
                .parse()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| format!("the point count '{}' must be a whole number >= 1", n.trim()))?;
            Ok(Axis::linspace(num(a)?, num(b)?, n))
        }
        _ => Err(format!("expected VALUE or START:STOP:N (for example 150:400:11), got '{s}'")),
    }
}

/// Defaults for axes set neither on the command line nor in the motor file's `[sweep]`.
pub const DEFAULT_PRELOAD_N: f64 = 250.0;
/// Default load torque [N·m].
pub const DEFAULT_TORQUE_NM: f64 = 0.0;
/// Default voltage [V].
pub const DEFAULT_VOLTAGE_V: f64 = 200.0;
/// Default frequency [Hz].
pub const DEFAULT_FREQUENCY_HZ: f64 = 43_000.0;

impl GridArgs {
    /// Command line first, then the `[sweep]` table, then `fallback` (per axis).
    pub fn resolve(&self, sweep: &SweepTable, fallback: &Grid) -> Grid {
        Grid {
            preload_n: self.preload_n.or(sweep.preload_n).unwrap_or(fallback.preload_n),
            torque_nm: self.torque_nm.or(sweep.torque_nm).unwrap_or(fallback.torque_nm),
            voltage_v: self.voltage_v.or(sweep.voltage_v).unwrap_or(fallback.voltage_v),
            frequency_hz: self.frequency_hz.or(sweep.frequency_hz).unwrap_or(fallback.frequency_hz),
        }
    }
}

/// Margin of a default load-torque axis above the largest loaded stall torque: a few
/// points past the torque where the loaded motor stops show that it stops there.
pub const DEFAULT_TORQUE_MARGIN: f64 = 0.05;

/// The top [N·m] of a default load-torque axis: [`DEFAULT_TORQUE_MARGIN`] above the
/// largest loaded stall torque ([`trum_core::criterion::loaded_stall_torque_nm`], the load
/// at which the loaded rotor stops) over the preloads of `preload` [N], at `voltage_v` [V]
/// and `frequency_hz` [Hz]. The rotor-at-rest `stall_torque_nm` at no load can lie far
/// above it (the amplitude falls under load), and an axis up to it would be mostly
/// stalled or clamped rows. `None` when the rotor runs at none of the preloads.
pub fn running_torque_top(motor: &trum_core::Motor, preload: &Axis, voltage_v: f64, frequency_hz: f64) -> Option<f64> {
    use rayon::prelude::*;
    let prep = trum_core::solve::Prepared::new(motor);
    let largest = (0..preload.n)
        .into_par_iter()
        .map(|i| trum_core::criterion::loaded_stall_torque_nm(&prep, motor, preload.at(i), voltage_v, frequency_hz))
        .filter(|t| t.is_finite() && *t > 0.0)
        .reduce(|| 0.0, f64::max);
    (largest > 0.0).then_some((1.0 + DEFAULT_TORQUE_MARGIN) * largest)
}

/// The fixed default grid (one point: 250 N, 0 N·m, 200 V, 43 kHz).
pub fn default_grid() -> Grid {
    Grid {
        preload_n: Axis::fixed(DEFAULT_PRELOAD_N),
        torque_nm: Axis::fixed(DEFAULT_TORQUE_NM),
        voltage_v: Axis::fixed(DEFAULT_VOLTAGE_V),
        frequency_hz: Axis::fixed(DEFAULT_FREQUENCY_HZ),
    }
}

/// Checks a grid before it is solved: at least one point per axis, finite values, every
/// point a valid operating point (preload, voltage, frequency > 0, torque >= 0). The
/// message names the axis and the value (`preload_n: 0 must be > 0`).
pub fn check_grid(g: &Grid) -> Result<()> {
    g.validate().map_err(|e| anyhow!("{e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_syntax() {
        assert_eq!(parse_axis("250").expect("valid"), Axis::fixed(250.0));
        assert_eq!(parse_axis("100:300:5").expect("valid"), Axis::linspace(100.0, 300.0, 5));
        assert!(parse_axis("100:300").expect_err("invalid").contains("START:STOP:N"));
        assert!(parse_axis("100:300:0").expect_err("invalid").contains("whole number"));
        assert!(parse_axis("100:300:2.5").expect_err("invalid").contains("whole number"));
        assert!(parse_axis("nan").expect_err("invalid").contains("finite"));
        assert!(parse_axis("abc").expect_err("invalid").contains("not a number"));
    }

    #[test]
    fn grids_outside_the_model_domain_are_refused_with_the_axis_named() {
        let mut g = default_grid();
        assert!(check_grid(&g).is_ok());
        g.preload_n = parse_axis("0:200:3").expect("valid syntax");
        assert_eq!(check_grid(&g).expect_err("preload 0").to_string(), "preload_n: 0 must be > 0");
        let mut g = default_grid();
        g.torque_nm = parse_axis("-0.5").expect("valid syntax");
        assert_eq!(check_grid(&g).expect_err("negative torque").to_string(), "torque_nm: -0.5 must be >= 0");
    }
}
