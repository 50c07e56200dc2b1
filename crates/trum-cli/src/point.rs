//! `trum point`: one operating point, every quantity with its unit.

use crate::args::MotorArgs;
use crate::format::fmt_sig;
use crate::table::{write_table, Align};
use anyhow::{bail, Result};
use clap::Args;
use serde_json::{json, Map, Value};
use std::io::Write;
use trum_core::layout::status_meaning;
use trum_core::limits::LimitedQuantities;
use trum_core::quantities::QUANTITIES;
use trum_core::{solve, OperatingPoint, Status};

#[derive(Args, Debug)]
pub struct PointArgs {
    #[command(flatten)]
    motor: MotorArgs,
    /// Axial preload [N].
    #[arg(long)]
    preload_n: f64,
    /// Load torque [N·m].
    #[arg(long, default_value_t = 0.0)]
    torque_nm: f64,
    /// Drive voltage amplitude per phase, zero-to-peak [V] (default: the motor's `[drive]`, else 200 V).
    #[arg(long)]
    voltage_v: Option<f64>,
    /// Drive frequency [Hz] (default: the motor's `[drive]`, else 43 kHz).
    #[arg(long)]
    frequency_hz: Option<f64>,
    /// Time since the drive was switched on [s] (only thermal quantities and `thermal_drift` use it).
    #[arg(long, default_value_t = 0.0)]
    elapsed_s: f64,
    /// Print JSON (full precision, null for invalid numbers) instead of the table.
    #[arg(long)]
    json: bool,
}

pub fn run(a: &PointArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    let (motor, _) = a.motor.load()?;
    let drive = crate::optimize::motor_drive(&a.motor.motor)?;
    let op = OperatingPoint {
        preload_n: a.preload_n,
        torque_nm: a.torque_nm,
        voltage_v: a.voltage_v.or(drive.map(|d| d.voltage_v)).unwrap_or(DEFAULT_VOLTAGE_V),
        frequency_hz: a.frequency_hz.or(drive.map(|d| d.frequency_hz)).unwrap_or(DEFAULT_FREQUENCY_HZ),
        elapsed_s: a.elapsed_s,
    };
    if let Some(reason) = op.invalid_reason() {
        bail!("invalid operating point: {reason}");
    }
    let s = solve(&motor, &op);
    let valid = s.status.is_valid();
    let limit_notes = motor.limits.describe(&LimitedQuantities::of_point(motor.thermal.ambient_c, &op, &s), s.warnings);
    let loaded_stall = loaded_stall(&motor, &op, &s);
    let mut notes: Vec<String> = clamps_before_stall(loaded_stall, s.stall_torque_nm).into_iter().collect();
    if s.work_bound_reached {
        notes.push(format!(
            "the solve spent its work bound ({} units) before it found a steady state (docs/RELIABILITY.md)",
            trum_core::solve::WORK_BOUND
        ));
    }
    let inputs: [(&str, f64, &str); 5] = [
        ("preload_n", op.preload_n, "N"),
        ("torque_nm", op.torque_nm, "N·m"),
        ("voltage_v", op.voltage_v, "V"),
        ("frequency_hz", op.frequency_hz, "Hz"),
        ("elapsed_s", op.elapsed_s, "s"),
    ];
    if a.json {
        let mut q = Map::new();
        let mut units = Map::new();
        for qu in QUANTITIES {
            let v = (qu.get)(&s);
            // JSON has no NaN: invalid numbers are null, like the empty CSV cells.
            let v = if valid && v.is_finite() { json!(v) } else { Value::Null };
            q.insert(qu.name.into(), v);
            units.insert(qu.name.into(), json!(qu.unit));
        }
        let mut inp = Map::new();
        for (n, v, _) in inputs {
            inp.insert(n.into(), json!(v));
        }
        let doc = json!({
            "motor": { "name": motor.name, "preset": motor.preset, "source": a.motor.motor, "effects": motor.effects.to_string() },
            "inputs": inp,
            "status": s.status.as_str(),
            "valid": valid,
            "full_contact": s.full_contact,
            "iterations": s.iterations,
            "work_bound_reached": s.work_bound_reached,
            "warnings": s.warnings.keys().collect::<Vec<_>>(),
            "warning_details": limit_notes,
            "quantities": q,
            "notes": notes,
            "loaded_stall_torque_nm": if loaded_stall.is_finite() { json!(loaded_stall) } else { Value::Null },
            "units": units,
        });
        writeln!(out, "{}", serde_json::to_string_pretty(&doc)?)?;
    } else {
        let preset = motor.preset.as_deref().map(|p| format!(" (preset {p})")).unwrap_or_default();
        writeln!(out, "motor    {}{}", motor.name, preset)?;
        if drive.is_some() && (a.voltage_v.is_none() || a.frequency_hz.is_none()) {
            writeln!(
                out,
                "drive    {} V, {} Hz (the motor's [drive] where not given)",
                fmt_sig(op.voltage_v, 6),
                fmt_sig(op.frequency_hz, 6)
            )?;
        }
        writeln!(out, "effects  {}", motor.effects)?;
        writeln!(out, "status   {}{}", s.status, status_note(s.status, s.full_contact))?;
        if limit_notes.is_empty() {
            writeln!(out, "limits   inside the motor's [limits]")?;
        }
        for (i, note) in limit_notes.iter().enumerate() {
            writeln!(out, "{}{note}", if i == 0 { "warning  " } else { "         " })?;
        }
        for note in &notes {
            writeln!(out, "note     {note}")?;
        }
        writeln!(out)?;
        let mut rows = Vec::new();
        for (n, v, u) in inputs {
            rows.push(vec![n.to_string(), fmt_sig(v, 6), u.to_string(), "input".to_string()]);
        }
        for qu in QUANTITIES {
            let v = if valid { (qu.get)(&s) } else { f64::NAN };
            rows.push(vec![qu.name.to_string(), fmt_sig(v, 6), qu.unit.to_string(), qu.doc.to_string()]);
        }
        rows.push(vec![
            "loaded_stall_torque_nm".to_string(),
            fmt_sig(loaded_stall, 6),
            "N·m".to_string(),
            "load torque at which the loaded motor stops (stall or clamp) at this preload and drive".to_string(),
        ]);
        write_table(out, &["quantity", "value", "unit", "meaning"], &[Align::Left, Align::Right, Align::Left], &rows)?;
    }
    if !valid {
        // The numbers are not a steady state; say so and fail, but after printing the status.
        writeln!(err, "error: no valid steady state at this point (status {})", s.status)?;
        return Ok(1);
    }
    Ok(0)
}

/// Drive of a motor without a `[drive]` table, when the command line gives none.
pub const DEFAULT_VOLTAGE_V: f64 = 200.0;
pub const DEFAULT_FREQUENCY_HZ: f64 = 43_000.0;

/// The load at which the loaded motor stops at the point's preload and drive
/// (`criterion::loaded_stall_torque_nm`, about 30 solves), or NaN where the rotor does not
/// run at no load. `stall_torque_nm` is the rotor-at-rest torque at the point's own
/// amplitude; under load the amplitude falls, and near clamping the motor stops far below it.
fn loaded_stall(motor: &trum_core::Motor, op: &OperatingPoint, s: &trum_core::Solution) -> f64 {
    if !s.status.is_valid() {
        return f64::NAN;
    }
    let p = trum_core::solve::Prepared::new(motor);
    trum_core::criterion::loaded_stall_torque_nm(&p, motor, op.preload_n, op.voltage_v, op.frequency_hz)
}

/// A warning when the loaded motor stops more than 5 % below the rotor-at-rest torque at
/// the point's amplitude: the stator clamps under load before the rotor stalls.
fn clamps_before_stall(loaded_nm: f64, at_rest_nm: f64) -> Option<String> {
    (loaded_nm.is_finite() && at_rest_nm.is_finite() && loaded_nm < 0.95 * at_rest_nm).then(|| {
        format!(
            "the loaded motor stops at {} N·m (loaded_stall_torque_nm): the amplitude falls under load, so the stator clamps before the load reaches the rotor-at-rest torque {} N·m (stall_torque_nm)",
            fmt_sig(loaded_nm, 4),
            fmt_sig(at_rest_nm, 4)
        )
    })
}

/// The status's meaning in brackets, as `trum_core::layout::status_meaning` words it.
fn status_note(s: Status, full: bool) -> String {
    match s {
        Status::Ok if full => format!(" ({}, full contact)", status_meaning(s)),
        Status::NoConvergence => format!(" ({}; numbers withheld)", status_meaning(s)),
        _ => format!(" ({})", status_meaning(s)),
    }
}
