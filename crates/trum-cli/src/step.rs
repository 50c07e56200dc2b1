//! `trum step`: the start-up (step response) of the rotor speed with the stick-slip
//! contact of [BarTransient] (docs/REFERENCES.md; `trum_core::dynamics::transient`), compared with the steady-state
//! solver at the same operating point; time series, contact snapshots and plots. A
//! bar-type motor (`trum_core::dynamics::bar_type`, e.g. the `bar36` preset) runs on the
//! same integrator, driven by a moment; it has no steady solver.

use crate::args::MotorArgs;
use crate::data::write_atomic;
use crate::format::{csv_number, fmt_sig};
use crate::grid::parse_axis;
use crate::plot::{series_color, write_figure, Line, LinePlot, Stroke};
use crate::table::{write_table, Align};
use anyhow::{anyhow, bail, Result};
use clap::Args;
use plotters::style::RGBColor;
use rayon::prelude::*;

/// Time steps per drive period when `--steps-per-period` is not given.
const DEFAULT_STEPS_PER_PERIOD: usize = 64;
use std::io::Write;
use std::path::PathBuf;
use trum_core::dynamics::bar_type::{bar_step_response, BarMotor, BarStepConfig};
use trum_core::dynamics::transient::{
    steady_comparison, step_response, SteadyComparison, SteadyGap, StepResponse, TransientConfig, TransientError,
};
use trum_core::sweep::Axis;
use trum_core::Motor;

#[derive(Args, Debug)]
pub struct StepArgs {
    #[command(flatten)]
    motor: MotorArgs,
    /// Ring motor: drive voltage amplitude per phase, zero-to-peak [V] (default: the motor's [drive], else 200): VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true)]
    voltage_v: Option<Axis>,
    /// Bar-type motor: drive moment amplitude per axis [N·m] (default: the motor's [drive]): VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true)]
    moment_nm: Option<Axis>,
    /// Drive frequency [Hz] (default: the motor's [drive]; a ring motor without one 43000): VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true)]
    frequency_hz: Option<Axis>,
    /// Phase of phase B behind phase A [deg] (default 90: travelling wave; 0: standing wave; -90: reversed): VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true)]
    phase_difference_deg: Option<Axis>,
    /// Axial preload [N] (ring default 260; bar-type: the motor's [drive]).
    #[arg(long)]
    preload_n: Option<f64>,
    /// Load torque [N·m]: a brake that opposes the rotation in either direction and holds a rotor at rest against a smaller contact torque.
    #[arg(long, default_value_t = 0.0)]
    torque_nm: f64,
    /// Simulated time [s] (ring default 0.01, bar-type 0.015).
    #[arg(long)]
    duration_s: Option<f64>,
    /// Time steps per drive period (default 64 on a ring motor, raised in steps of 16 where
    /// the explicit scheme would be unstable; given, it is used as is).
    #[arg(long)]
    steps_per_period: Option<usize>,
    /// Contact nodes per wavelength (256 in [BarTransient]; on a bar-type motor, nodes on the contact circle).
    #[arg(long, default_value_t = 256)]
    nodes_per_wavelength: usize,
    /// Ring motor: tangential stiffness of the contact layer as a multiple of the normal (Winkler) stiffness (default 300).
    #[arg(long)]
    tangential_stiffness_ratio: Option<f64>,
    /// Record the time series every this many steps.
    #[arg(long, default_value_t = 16)]
    record_every: usize,
    /// Time series CSV (single operating point; `-` for stdout, the table then goes to stderr).
    #[arg(short = 'o', long = "output", value_name = "CSV")]
    output: Option<PathBuf>,
    /// Metrics CSV: one row per operating point of the sweep.
    #[arg(long, value_name = "CSV")]
    table: Option<PathBuf>,
    /// Instants [s] for the friction-force distribution, comma separated (e.g. 2e-5,1e-4,9e-3).
    #[arg(long, value_name = "T1,T2,...", value_delimiter = ',', allow_hyphen_values = true)]
    snapshot_at_s: Vec<f64>,
    /// Friction-force distribution CSV at the --snapshot-at-s instants (state per node).
    #[arg(long, value_name = "CSV", requires = "snapshot_at_s")]
    snapshots: Option<PathBuf>,
    /// Plot of the speed against time (.png or .svg).
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Plot of the friction-force distribution with the Coulomb limits ±μp (.png or .svg).
    #[arg(long, value_name = "FILE", requires = "snapshot_at_s")]
    snapshot_plot: Option<PathBuf>,
    /// Print the result as JSON (one object per operating point: status and every quantity) instead of the table.
    #[arg(long)]
    json: bool,
    /// No progress spinner.
    #[arg(short, long)]
    quiet: bool,
}

/// One operating point of the sweep and its outcome.
struct Run {
    /// Drive amplitude: voltage [V] (ring motor) or moment [N·m] (bar-type motor).
    drive: f64,
    frequency_hz: f64,
    phase_deg: f64,
    result: Result<StepResponse, TransientError>,
    /// The steady solver at the same point, signed as the wave turns the rotor, or why it
    /// does not describe the point (ring motors only: `None` for a bar-type motor).
    steady: Option<Result<SteadyComparison, SteadyGap>>,
}

/// The motor of a run: a ring motor (driven by a voltage, with a steady solver) or a
/// bar-type motor (driven by a moment).
// one value per command run: the size of the larger variant costs nothing
#[allow(clippy::large_enum_variant)]
enum StepMotor {
    Ring(Motor),
    Bar(BarMotor),
}

impl StepMotor {
    /// Name of the drive column and its unit.
    fn drive_column(&self) -> (&'static str, &'static str) {
        match self {
            StepMotor::Ring(_) => ("voltage_v", "V"),
            StepMotor::Bar(_) => ("moment_nm", "N·m"),
        }
    }
}

fn values(ax: &Axis, flag: &str) -> Result<Vec<f64>> {
    if ax.n == 0 || ax.n > 10_000 {
        bail!("{flag}: between 1 and 10000 points, got {}", ax.n);
    }
    Ok((0..ax.n).map(|i| ax.at(i)).collect())
}

/// Status of a run: `ok` (moving, a negative speed is rotation the other way),
/// `not_moving` (at rest at the end, no metrics), `not_settled` (outside the ±2 % band at
/// the end), or the failure.
fn status(r: &Result<StepResponse, TransientError>) -> &'static str {
    match r {
        Ok(s) => s.metrics.status(),
        Err(TransientError::Diverged { .. }) => "diverged",
        Err(_) => "invalid_input",
    }
}

/// The reported quantities of a run: name (unit-suffixed), value, unit, meaning.
fn quantities(r: &Run) -> Vec<(&'static str, f64, &'static str, &'static str)> {
    let nan = f64::NAN;
    let (m, a) = match &r.result {
        Ok(s) => (Some(s.metrics), Some(s.averages)),
        Err(_) => (None, None),
    };
    let opt = |v: Option<f64>| v.unwrap_or(nan);
    let rel = |x: f64, y: f64| (x - y) / y;
    // empty where the steady model does not describe the point (no solver, or a SteadyGap)
    let st = |f: fn(&SteadyComparison) -> f64| r.steady.and_then(Result::ok).as_ref().map_or(nan, f);
    let speed = a.map_or(nan, |a| a.speed_rpm);
    let torque = a.map_or(nan, |a| a.contact_torque_nm);
    let amp = a.map_or(nan, |a| a.amplitude_m);
    vec![
        ("delay_s", opt(m.and_then(|m| m.delay_s)), "s", "time to 50 % of the final speed"),
        ("rise_time_s", opt(m.and_then(|m| m.rise_time_s)), "s", "10 % to 90 % of the final speed"),
        ("rise_to_final_s", opt(m.and_then(|m| m.rise_to_final_s)), "s", "0 to 100 %: first time at the final speed"),
        ("peak_time_s", opt(m.and_then(|m| m.peak_time_s)), "s", "time of the peak speed"),
        ("overshoot", opt(m.and_then(|m| m.overshoot)), "-", "(peak - final) / final"),
        ("settling_time_s", opt(m.and_then(|m| m.settling_time_s)), "s", "last entry into the ±2 % band"),
        ("peak_speed_rpm", m.map_or(nan, |m| m.peak_speed_rpm), "rpm", "peak period-averaged speed (signed)"),
        ("final_speed_rpm", speed, "rpm", "mean speed over the last 20 % of the run"),
        ("steady_speed_rpm", st(|s| s.speed_rpm), "rpm", "steady-state solver at this point"),
        ("speed_difference", rel(speed, st(|s| s.speed_rpm)), "-", "(final - steady) / steady"),
        ("contact_torque_nm", torque, "N·m", "mean contact torque over the last 20 %"),
        ("steady_contact_torque_nm", st(|s| s.contact_torque_nm), "N·m", "load + rotor viscous torque at steady speed"),
        ("torque_difference", rel(torque, st(|s| s.contact_torque_nm)), "-", "(transient - steady) / steady"),
        ("amplitude_m", amp, "m", "mean wave amplitude over the last 20 %"),
        ("steady_amplitude_m", st(|s| s.amplitude_m), "m", "steady-state wave amplitude"),
        ("contact_fraction", a.map_or(nan, |a| a.contact_fraction), "-", "mean fraction of the wavelength in contact"),
        ("stick_fraction", a.map_or(nan, |a| a.stick_fraction), "-", "mean fraction of the wavelength sticking"),
    ]
}

/// The motor of `--motor`: a bar-type motor, or a ring motor with the effects handling
/// of the transient model.
fn load(a: &StepArgs, err: &mut dyn Write) -> Result<StepMotor> {
    if let Some(bar) = crate::motor::load_bar_motor(&a.motor.motor)? {
        if !a.motor.effects.is_empty() {
            bail!("--effect: the bar-type motor model has no unmodelled effects");
        }
        if a.voltage_v.is_some() {
            bail!("--voltage-v: a bar-type motor is driven by a moment; use --moment-nm");
        }
        if a.tangential_stiffness_ratio.is_some() {
            bail!("--tangential-stiffness-ratio: a bar-type motor file sets contact.tangential_stiffness_n_per_m2");
        }
        return Ok(StepMotor::Bar(bar));
    }
    if a.moment_nm.is_some() {
        bail!("--moment-nm drives a bar-type motor; a ring motor is driven by --voltage-v");
    }
    let (mut motor, _) = a.motor.load()?;
    // A paper preset may carry effects its paper's model includes (docs/PRESETS.md); the
    // transient model has none of them, so it runs on the preset's baseline and says so.
    // Effects asked for by --effect or a file's own [effects] are still refused.
    if let Some(preset) = motor.preset.as_deref().and_then(|n| trum_core::presets::find(n).ok()) {
        let own = preset.motor().effects;
        if a.motor.effects.is_empty() && !own.is_none() && motor.effects == own {
            let names: Vec<&str> = own.active().iter().map(|e| e.name()).collect();
            writeln!(err, "note: the transient model leaves out the preset's {}", names.join(", "))?;
            motor.effects = trum_core::Effects::none();
        }
    }
    if !motor.effects.is_none() {
        bail!(
            "the transient model does not include unmodelled effects; remove --effect and the motor file's [effects]"
        );
    }
    Ok(StepMotor::Ring(motor))
}

/// Settings of one run, for either kind of motor.
enum Settings {
    Ring(TransientConfig),
    Bar(BarStepConfig),
}

impl Settings {
    fn validate(&self) -> Result<(), TransientError> {
        match self {
            Settings::Ring(c) => c.validate(),
            Settings::Bar(c) => c.validate(),
        }
    }
}

pub fn run(a: &StepArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    for p in [&a.plot, &a.snapshot_plot].into_iter().flatten() {
        crate::plot::check_plot_path(p)?;
    }
    let motor = load(a, err)?;
    let axis = |ax: &Option<Axis>, default: f64| ax.unwrap_or(Axis { start: default, stop: default, n: 1 });
    let (drive_axis, drive_flag, freq_default, phase_default) = match &motor {
        StepMotor::Ring(_) => {
            // the drive of the motor's figures ([drive]), as `trum point` and `trum optimize` use it
            let drive = crate::optimize::motor_drive(&a.motor.motor)?;
            let v = drive.map_or(crate::point::DEFAULT_VOLTAGE_V, |d| d.voltage_v);
            let f = drive.map_or(crate::point::DEFAULT_FREQUENCY_HZ, |d| d.frequency_hz);
            (axis(&a.voltage_v, v), "--voltage-v", f, 90.0)
        }
        StepMotor::Bar(b) => {
            (axis(&a.moment_nm, b.moment_amplitude_nm), "--moment-nm", b.frequency_hz, b.phase_difference_deg)
        }
    };
    let drives = values(&drive_axis, drive_flag)?;
    let freqs = values(&axis(&a.frequency_hz, freq_default), "--frequency-hz")?;
    let phases = values(&axis(&a.phase_difference_deg, phase_default), "--phase-difference-deg")?;
    let mut points = Vec::new();
    for &v in &drives {
        for &f in &freqs {
            points.extend(phases.iter().map(|&p| (v, f, p)));
        }
    }
    let single = points.len() == 1;
    if !single && (a.output.is_some() || a.plot.is_some() || !a.snapshot_at_s.is_empty()) {
        bail!("-o, --plot and --snapshot-at-s need a single operating point; a sweep writes --table");
    }
    let (preload, duration) = match &motor {
        StepMotor::Ring(_) => (a.preload_n.unwrap_or(260.0), a.duration_s.unwrap_or(10e-3)),
        StepMotor::Bar(b) => (a.preload_n.unwrap_or(b.preload_n), a.duration_s.unwrap_or(b.step_config().duration_s)),
    };
    let config = |v: f64, f: f64, p: f64| match &motor {
        StepMotor::Ring(_) => Settings::Ring(TransientConfig {
            duration_s: duration,
            steps_per_period: a.steps_per_period.unwrap_or(DEFAULT_STEPS_PER_PERIOD),
            nodes_per_wavelength: a.nodes_per_wavelength,
            phase_difference_rad: p.to_radians(),
            load_torque_nm: a.torque_nm,
            voltage_v: v,
            frequency_hz: f,
            preload_n: preload,
            record_every: a.record_every,
            snapshot_times_s: a.snapshot_at_s.clone(),
            tangential_stiffness_ratio: a
                .tangential_stiffness_ratio
                .unwrap_or(trum_core::dynamics::transient::DEFAULT_TANGENTIAL_STIFFNESS_RATIO),
            ..TransientConfig::default()
        }),
        StepMotor::Bar(_) => Settings::Bar(BarStepConfig {
            duration_s: duration,
            steps_per_period: a.steps_per_period.unwrap_or(DEFAULT_STEPS_PER_PERIOD),
            nodes: a.nodes_per_wavelength,
            phase_difference_rad: p.to_radians(),
            load_torque_nm: a.torque_nm,
            moment_amplitude_nm: v,
            frequency_hz: f,
            preload_n: preload,
            record_every: a.record_every,
            snapshot_times_s: a.snapshot_at_s.clone(),
        }),
    };
    // Bad settings are the user's error, not a status: check every point before running.
    for &(v, f, p) in &points {
        config(v, f, p).validate().map_err(|e| anyhow!("{}", flag_message(&e)))?;
    }
    let spinner = crate::diagnose::spinner(
        &format!("simulating {} operating point{}", points.len(), if single { "" } else { "s" }),
        a.quiet,
    );
    let runs: Vec<Run> = points
        .par_iter()
        .map(|&(v, f, p)| {
            let (result, steady) = match (&motor, config(v, f, p)) {
                (StepMotor::Ring(m), Settings::Ring(c)) => {
                    let r = if a.steps_per_period.is_some() {
                        step_response(m, &c)
                    } else {
                        trum_core::dynamics::transient::step_response_stable(m, &c).map(|(r, _)| r)
                    };
                    (r, Some(steady_comparison(m, &c)))
                }
                (StepMotor::Bar(m), Settings::Bar(c)) => (bar_step_response(m, &c), None),
                _ => unreachable!("the settings follow the motor"),
            };
            Run { drive: v, frequency_hz: f, phase_deg: p, result, steady }
        })
        .collect();
    spinner.finish_and_clear();
    let (drive_name, drive_unit) = motor.drive_column();
    if single {
        if let Err(e) = &runs[0].result {
            bail!("{}", flag_message(e));
        }
    } else {
        for r in &runs {
            if let Err(e) = &r.result {
                writeln!(err, "note: {} {drive_unit}, {} Hz, {} deg: {e}", r.drive, r.frequency_hz, r.phase_deg)?;
            }
        }
    }
    if !single {
        gap_notes(&runs, err)?;
    }
    if let Some(path) = &a.table {
        write_atomic(path, ".csv", &table_csv(&runs, drive_name), out)?;
    }
    // the Coulomb limit drawn and written beside the friction force: μ (ring), μ_s (bar-type)
    let mu = match &motor {
        StepMotor::Ring(m) => m.friction_layer.friction_coefficient,
        StepMotor::Bar(b) => b.static_friction_coefficient,
    };
    let to_stderr =
        [&a.output, &a.table, &a.snapshots].iter().any(|p| p.as_deref().is_some_and(|p| p.as_os_str() == "-"));
    if let (true, Ok(resp)) = (single, &runs[0].result) {
        if let Some(path) = &a.output {
            write_atomic(path, ".csv", &series_csv(resp), out)?;
        }
        if let Some(path) = &a.snapshots {
            write_atomic(path, ".csv", &snapshots_csv(resp, mu), out)?;
        }
        if let Some(path) = &a.plot {
            let name = match &motor {
                StepMotor::Ring(m) => m.name.as_str(),
                StepMotor::Bar(b) => b.name.as_str(),
            };
            write_figure(path, &speed_plot(resp, &runs[0], name, drive_unit, preload, a.torque_nm), err)?;
        }
        if let Some(path) = &a.snapshot_plot {
            write_figure(path, &snapshot_plot(resp, mu), err)?;
        }
    }
    if a.json {
        if to_stderr {
            bail!("--json and an output to stdout (`-`) cannot both go to stdout");
        }
        let list: Vec<_> = runs
            .iter()
            .map(|r| {
                let mut q = serde_json::Map::new();
                for (n, v, _, _) in quantities(r) {
                    q.insert(n.into(), crate::data::num(v));
                }
                let mut run = serde_json::Map::new();
                run.insert(drive_name.into(), crate::data::num(r.drive));
                run.insert("frequency_hz".into(), crate::data::num(r.frequency_hz));
                run.insert("phase_difference_deg".into(), crate::data::num(r.phase_deg));
                run.insert("preload_n".into(), crate::data::num(preload));
                run.insert("torque_nm".into(), crate::data::num(a.torque_nm));
                run.insert("status".into(), status(&r.result).into());
                // (no steady solver for a bar-type motor; a point outside the steady model
                // is `not_comparable`, with the reason)
                let (steady_status, steady_note) = match &r.steady {
                    None => (serde_json::Value::Null, serde_json::Value::Null),
                    Some(Ok(s)) => (s.status.to_string().into(), serde_json::Value::Null),
                    Some(Err(g)) => (NOT_COMPARABLE.into(), g.to_string().into()),
                };
                run.insert("steady_status".into(), steady_status);
                run.insert("steady_note".into(), steady_note);
                run.insert("quantities".into(), q.into());
                serde_json::Value::Object(run)
            })
            .collect();
        let name = match &motor {
            StepMotor::Ring(m) => m.name.as_str(),
            StepMotor::Bar(b) => b.name.as_str(),
        };
        let doc = serde_json::json!({ "motor": name, "runs": list });
        writeln!(out, "{}", serde_json::to_string_pretty(&doc)?)?;
        return Ok(0);
    }
    let summary: &mut dyn Write = if to_stderr { err } else { out };
    let settings = Shown { preload_n: preload, duration_s: duration };
    if single {
        print_single(&runs[0], &motor, a, &settings, summary)?;
    } else {
        print_sweep(&runs, drive_name, summary)?;
    }
    Ok(0)
}

/// The steady status of a point the steady model does not describe ([`SteadyGap`]).
const NOT_COMPARABLE: &str = "not_comparable";

/// One note on `err` per kind of [`SteadyGap`] in a sweep, with the phases it applies to:
/// the steady columns of those points are empty.
fn gap_notes(runs: &[Run], err: &mut dyn Write) -> Result<()> {
    let gaps: Vec<(f64, SteadyGap)> =
        runs.iter().filter_map(|r| r.steady.and_then(Result::err).map(|g| (r.phase_deg, g))).collect();
    let mut kinds: Vec<SteadyGap> = Vec::new();
    for (_, g) in &gaps {
        if !kinds.iter().any(|k| k.as_str() == g.as_str()) {
            kinds.push(*g);
        }
    }
    for first in kinds {
        let mut phases: Vec<f64> = gaps.iter().filter(|(_, g)| g.as_str() == first.as_str()).map(|(p, _)| *p).collect();
        phases.sort_by(f64::total_cmp);
        phases.dedup();
        let list: Vec<String> = phases.iter().map(|p| fmt_sig(*p, 6)).collect();
        writeln!(
            err,
            "note: no steady comparison (steady_* empty) at phase difference {} deg: {first}",
            list.join(", ")
        )?;
    }
    Ok(())
}

/// The resolved defaults shown in the summary.
struct Shown {
    preload_n: f64,
    duration_s: f64,
}

/// The core names config fields; say which command-line flag they come from.
fn flag_message(e: &TransientError) -> String {
    match e {
        TransientError::InvalidConfig { name, value, reason } => {
            let flag = match *name {
                "phase_difference_rad" => "--phase-difference-deg".to_string(),
                "snapshot_times_s" => "--snapshot-at-s".to_string(),
                "load_torque_nm" => "--torque-nm".to_string(),
                "moment_amplitude_nm" => "--moment-nm".to_string(),
                "nodes" => "--nodes-per-wavelength".to_string(),
                n => format!("--{}", n.replace('_', "-")),
            };
            format!("{flag} = {value}: {reason}")
        }
        TransientError::StepTooLarge { .. } => format!("{e} (--steps-per-period)"),
        TransientError::TooManySteps { .. } => format!("{e} (shorten --duration-s or lower --steps-per-period)"),
        _ => e.to_string(),
    }
}

fn print_single(r: &Run, motor: &StepMotor, a: &StepArgs, shown: &Shown, out: &mut dyn Write) -> Result<()> {
    let Ok(resp) = &r.result else { return Ok(()) };
    let (name, preset) = match motor {
        StepMotor::Ring(m) => (m.name.as_str(), m.preset.as_deref()),
        StepMotor::Bar(b) => (b.name.as_str(), b.preset.as_deref()),
    };
    let source = preset.map(|p| format!(" (preset {p})")).unwrap_or_default();
    writeln!(out, "motor    {name}{source}")?;
    let (_, unit) = motor.drive_column();
    writeln!(
        out,
        "drive    {} {unit}, {} Hz, phase {} deg, preload {} N, load {} N·m",
        fmt_sig(r.drive, 6),
        fmt_sig(r.frequency_hz, 6),
        fmt_sig(r.phase_deg, 6),
        fmt_sig(shown.preload_n, 6),
        fmt_sig(a.torque_nm, 6)
    )?;
    let contact = match motor {
        StepMotor::Ring(_) => format!(
            "{} nodes per wavelength, k_t/k_f = {}",
            a.nodes_per_wavelength,
            fmt_sig(
                a.tangential_stiffness_ratio
                    .unwrap_or(trum_core::dynamics::transient::DEFAULT_TANGENTIAL_STIFFNESS_RATIO),
                6
            )
        ),
        StepMotor::Bar(_) => format!("rigid-disc stator, {} contact nodes", a.nodes_per_wavelength),
    };
    writeln!(
        out,
        "model    {} s, {} steps ({} per period), {contact}",
        fmt_sig(shown.duration_s, 6),
        resp.steps,
        // (the steps the run used: a default is raised where it would be unstable)
        (1.0 / (r.frequency_hz * resp.time_step_s)).round(),
    )?;
    match &r.steady {
        Some(Ok(st)) => writeln!(out, "status   {} (steady solver: {})", status(&r.result), st.status)?,
        Some(Err(_)) => writeln!(out, "status   {} (steady solver: {NOT_COMPARABLE})", status(&r.result))?,
        None => writeln!(out, "status   {} (bar-type motor: no steady solver)", status(&r.result))?,
    }
    writeln!(out)?;
    let rows: Vec<Vec<String>> =
        quantities(r).into_iter().map(|(n, v, u, m)| vec![n.into(), fmt_sig(v, 6), u.into(), m.into()]).collect();
    write_table(out, &["quantity", "value", "unit", "meaning"], &[Align::Left, Align::Right, Align::Left], &rows)?;
    if let Some(Err(gap)) = &r.steady {
        writeln!(out, "note     no steady comparison (steady_* empty): {gap}")?;
    }
    for s in &resp.snapshots {
        let (nc, st, sl) = s.counts();
        writeln!(
            out,
            "snapshot t = {} s: {} rpm, {st} stick, {sl} slip, {nc} no-contact nodes",
            fmt_sig(s.time_s, 6),
            fmt_sig(s.speed_rpm, 6)
        )?;
    }
    Ok(())
}

fn print_sweep(runs: &[Run], drive_name: &str, out: &mut dyn Write) -> Result<()> {
    let picked = ["final_speed_rpm", "delay_s", "rise_time_s", "overshoot", "settling_time_s", "steady_speed_rpm"];
    let mut header =
        vec![drive_name.to_string(), "frequency_hz".into(), "phase_difference_deg".into(), "status".into()];
    header.extend(picked.iter().map(|s| s.to_string()));
    let rows: Vec<Vec<String>> = runs
        .iter()
        .map(|r| {
            let q = quantities(r);
            let mut row = vec![fmt_sig(r.drive, 6), fmt_sig(r.frequency_hz, 6), fmt_sig(r.phase_deg, 6)];
            row.push(status(&r.result).into());
            row.extend(picked.iter().map(|p| q.iter().find(|x| x.0 == *p).map_or("-".into(), |x| fmt_sig(x.1, 5))));
            row
        })
        .collect();
    let mut align = vec![Align::Right; header.len()];
    align[3] = Align::Left;
    let h: Vec<&str> = header.iter().map(String::as_str).collect();
    write_table(out, &h, &align, &rows)?;
    Ok(())
}

fn table_csv(runs: &[Run], drive_name: &str) -> String {
    let mut s = format!("{drive_name},frequency_hz,phase_difference_deg,status");
    if let Some(r) = runs.first() {
        for q in quantities(r) {
            s.push(',');
            s.push_str(q.0);
        }
    }
    s.push('\n');
    for r in runs {
        s.push_str(&format!(
            "{},{},{},{}",
            csv_number(r.drive),
            csv_number(r.frequency_hz),
            csv_number(r.phase_deg),
            status(&r.result)
        ));
        for q in quantities(r) {
            s.push(',');
            s.push_str(&csv_number(q.1));
        }
        s.push('\n');
    }
    s
}

fn series_csv(r: &StepResponse) -> String {
    let t = &r.series;
    let mut s = String::from(
        "time_s,speed_rpm,speed_period_mean_rpm,amplitude_m,axial_position_m,contact_torque_nm,axial_force_n\n",
    );
    for i in 0..t.time_s.len() {
        let row = [
            t.time_s[i],
            t.speed_rpm[i],
            t.speed_period_mean_rpm[i],
            t.amplitude_m[i],
            t.axial_position_m[i],
            t.torque_nm[i],
            t.axial_force_n[i],
        ];
        s.push_str(&row.map(csv_number).join(","));
        s.push('\n');
    }
    s
}

fn snapshots_csv(r: &StepResponse, mu: f64) -> String {
    let mut s = String::from(
        "requested_time_s,time_s,position_m,pressure_n_per_m,tangential_force_n_per_m,friction_limit_n_per_m,slip_speed_m_s,state\n",
    );
    for sn in &r.snapshots {
        for n in &sn.nodes {
            let nums = [
                sn.requested_time_s,
                sn.time_s,
                n.position_m,
                n.pressure_n_per_m,
                n.tangential_force_n_per_m,
                mu * n.pressure_n_per_m,
                n.slip_speed_m_s,
            ];
            s.push_str(&nums.map(csv_number).join(","));
            s.push(',');
            s.push_str(n.state.as_str());
            s.push('\n');
        }
    }
    s
}

fn speed_plot(resp: &StepResponse, r: &Run, name: &str, drive_unit: &str, preload_n: f64, torque_nm: f64) -> LinePlot {
    let t = &resp.series;
    let line = |y: &[f64], color, label: &str, stroke| Line {
        label: Some(label.into()),
        color,
        points: t.time_s.iter().copied().zip(y.iter().copied()).collect(),
        stroke,
    };
    let mut lines = vec![
        line(&t.speed_rpm, RGBColor(170, 170, 170), "rotor speed", Stroke::Solid),
        line(&t.speed_period_mean_rpm, series_color(0, 3), "mean over a drive period", Stroke::Solid),
    ];
    if let Some(v) = r.steady.and_then(Result::ok).map(|s| s.speed_rpm).filter(|v| v.is_finite()) {
        let (t0, t1) = (t.time_s.first().copied().unwrap_or(0.0), t.time_s.last().copied().unwrap_or(0.0));
        lines.push(Line {
            label: Some("steady-state solver".into()),
            color: series_color(2, 3),
            points: vec![(t0, v), (t1, v)],
            stroke: Stroke::Dashed,
        });
    }
    LinePlot {
        title: format!("{name}: rotor speed after switch-on (stick-slip contact)"),
        subtitle: format!(
            "drive {} {drive_unit}, drive frequency {} kHz, phase {}°, preload {} N, load torque {} N·m",
            fmt_sig(r.drive, 6),
            fmt_sig(r.frequency_hz / 1e3, 6),
            fmt_sig(r.phase_deg, 6),
            fmt_sig(preload_n, 6),
            fmt_sig(torque_nm, 6)
        ),
        x: "time_s".into(),
        y: "speed_rpm".into(),
        lines,
    }
}

fn snapshot_plot(resp: &StepResponse, mu: f64) -> LinePlot {
    let n = resp.snapshots.len();
    let mut lines = Vec::new();
    for (i, sn) in resp.snapshots.iter().enumerate() {
        let color = series_color(i, n);
        let (nc, st, sl) = sn.counts();
        let pts = |f: &dyn Fn(&trum_core::dynamics::transient::NodeSample) -> f64| {
            sn.nodes.iter().map(|x| (x.position_m, f(x))).collect::<Vec<_>>()
        };
        lines.push(Line {
            label: Some(format!("t = {} s: {st} stick, {sl} slip, {nc} no contact", fmt_sig(sn.time_s, 4))),
            color,
            points: pts(&|x| x.tangential_force_n_per_m),
            stroke: Stroke::Solid,
        });
        for sign in [1.0, -1.0] {
            lines.push(Line {
                label: None,
                color,
                points: pts(&|x| sign * mu * x.pressure_n_per_m),
                stroke: Stroke::Dashed,
            });
        }
    }
    LinePlot {
        title: "Friction force over one wavelength".into(),
        subtitle: format!("dashed: Coulomb limits ±μp (μ = {})", fmt_sig(mu, 3)),
        x: "position_m".into(),
        y: "tangential_force_n_per_m".into(),
        lines,
    }
}
