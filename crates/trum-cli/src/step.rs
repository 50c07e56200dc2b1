//! `trum step`: the start-up (step response) of the rotor speed with the stick-slip
//! contact of [BarTransient] (docs/REFERENCES.md; `trum_core::dynamics::transient`), compared with the steady-state
//! solver at the same operating point; time series, contact snapshots and plots.

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
use std::io::Write;
use std::path::PathBuf;
use trum_core::dynamics::transient::{
    steady_comparison, step_response, SteadyComparison, StepResponse, TransientConfig, TransientError,
};
use trum_core::sweep::Axis;
use trum_core::Motor;

#[derive(Args, Debug)]
pub struct StepArgs {
    #[command(flatten)]
    motor: MotorArgs,
    /// Drive voltage amplitude per phase, zero-to-peak [V]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true, default_value = "200")]
    voltage_v: Axis,
    /// Drive frequency [Hz]: VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true, default_value = "43000")]
    frequency_hz: Axis,
    /// Phase of phase B behind phase A [deg] (90: travelling wave, 0: standing wave): VALUE or START:STOP:N.
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true, default_value = "90")]
    phase_difference_deg: Axis,
    /// Axial preload [N].
    #[arg(long, default_value_t = 260.0)]
    preload_n: f64,
    /// Load torque [N·m].
    #[arg(long, default_value_t = 0.0)]
    torque_nm: f64,
    /// Simulated time [s].
    #[arg(long, default_value_t = 10e-3)]
    duration_s: f64,
    /// Time steps per drive period.
    #[arg(long, default_value_t = 64)]
    steps_per_period: usize,
    /// Contact nodes per wavelength (256 in [BarTransient]).
    #[arg(long, default_value_t = 256)]
    nodes_per_wavelength: usize,
    /// Tangential stiffness of the contact layer as a multiple of the normal (Winkler) stiffness.
    #[arg(long, default_value_t = trum_core::dynamics::transient::DEFAULT_TANGENTIAL_STIFFNESS_RATIO)]
    tangential_stiffness_ratio: f64,
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
    voltage_v: f64,
    frequency_hz: f64,
    phase_deg: f64,
    result: Result<StepResponse, TransientError>,
    steady: SteadyComparison,
}

fn values(ax: &Axis, flag: &str) -> Result<Vec<f64>> {
    if ax.n == 0 || ax.n > 10_000 {
        bail!("{flag}: between 1 and 10000 points, got {}", ax.n);
    }
    Ok((0..ax.n).map(|i| ax.at(i)).collect())
}

/// Status of a run: `ok`, `not_moving` (no positive final speed, no metrics),
/// `not_settled` (outside the ±2 % band at the end), or the failure.
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
    let speed = a.map_or(nan, |a| a.speed_rpm);
    let torque = a.map_or(nan, |a| a.contact_torque_nm);
    let amp = a.map_or(nan, |a| a.amplitude_m);
    vec![
        ("delay_s", opt(m.and_then(|m| m.delay_s)), "s", "time to 50 % of the final speed"),
        ("rise_time_s", opt(m.and_then(|m| m.rise_time_s)), "s", "10 % to 90 % of the final speed"),
        ("overshoot", opt(m.and_then(|m| m.overshoot)), "-", "(peak - final) / final"),
        ("settling_time_s", opt(m.and_then(|m| m.settling_time_s)), "s", "last entry into the ±2 % band"),
        ("peak_speed_rpm", m.map_or(nan, |m| m.peak_speed_rpm), "rpm", "largest period-averaged speed"),
        ("final_speed_rpm", speed, "rpm", "mean speed over the last 20 % of the run"),
        ("steady_speed_rpm", r.steady.speed_rpm, "rpm", "steady-state solver at this point"),
        ("speed_difference", rel(speed, r.steady.speed_rpm), "-", "(final - steady) / steady"),
        ("contact_torque_nm", torque, "N·m", "mean contact torque over the last 20 %"),
        ("steady_contact_torque_nm", r.steady.contact_torque_nm, "N·m", "load + rotor viscous torque at steady speed"),
        ("torque_difference", rel(torque, r.steady.contact_torque_nm), "-", "(transient - steady) / steady"),
        ("amplitude_m", amp, "m", "mean wave amplitude over the last 20 %"),
        ("steady_amplitude_m", r.steady.amplitude_m, "m", "steady-state wave amplitude"),
        ("contact_fraction", a.map_or(nan, |a| a.contact_fraction), "-", "mean fraction of the wavelength in contact"),
        ("stick_fraction", a.map_or(nan, |a| a.stick_fraction), "-", "mean fraction of the wavelength sticking"),
    ]
}

pub fn run(a: &StepArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    for p in [&a.plot, &a.snapshot_plot].into_iter().flatten() {
        crate::plot::check_plot_path(p)?;
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
    let volts = values(&a.voltage_v, "--voltage-v")?;
    let freqs = values(&a.frequency_hz, "--frequency-hz")?;
    let phases = values(&a.phase_difference_deg, "--phase-difference-deg")?;
    let mut points = Vec::new();
    for &v in &volts {
        for &f in &freqs {
            points.extend(phases.iter().map(|&p| (v, f, p)));
        }
    }
    let single = points.len() == 1;
    if !single && (a.output.is_some() || a.plot.is_some() || !a.snapshot_at_s.is_empty()) {
        bail!("-o, --plot and --snapshot-at-s need a single operating point; a sweep writes --table");
    }
    let config = |v: f64, f: f64, p: f64| TransientConfig {
        duration_s: a.duration_s,
        steps_per_period: a.steps_per_period,
        nodes_per_wavelength: a.nodes_per_wavelength,
        phase_difference_rad: p.to_radians(),
        load_torque_nm: a.torque_nm,
        voltage_v: v,
        frequency_hz: f,
        preload_n: a.preload_n,
        record_every: a.record_every,
        snapshot_times_s: a.snapshot_at_s.clone(),
        tangential_stiffness_ratio: a.tangential_stiffness_ratio,
        ..TransientConfig::default()
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
        .map(|&(v, f, p)| Run {
            voltage_v: v,
            frequency_hz: f,
            phase_deg: p,
            result: step_response(&motor, &config(v, f, p)),
            steady: steady_comparison(&motor, &config(v, f, p)),
        })
        .collect();
    spinner.finish_and_clear();
    if single {
        if let Err(e) = &runs[0].result {
            bail!("{}", flag_message(e));
        }
    } else {
        for r in &runs {
            if let Err(e) = &r.result {
                writeln!(err, "note: {} V, {} Hz, {} deg: {e}", r.voltage_v, r.frequency_hz, r.phase_deg)?;
            }
        }
    }
    if let Some(path) = &a.table {
        write_atomic(path, ".csv", &table_csv(&runs), out)?;
    }
    let to_stderr =
        [&a.output, &a.table, &a.snapshots].iter().any(|p| p.as_deref().is_some_and(|p| p.as_os_str() == "-"));
    if let (true, Ok(resp)) = (single, &runs[0].result) {
        if let Some(path) = &a.output {
            write_atomic(path, ".csv", &series_csv(resp), out)?;
        }
        if let Some(path) = &a.snapshots {
            write_atomic(path, ".csv", &snapshots_csv(resp, motor.friction_layer.friction_coefficient), out)?;
        }
        if let Some(path) = &a.plot {
            write_figure(path, &speed_plot(resp, &runs[0], &motor, a), err)?;
        }
        if let Some(path) = &a.snapshot_plot {
            write_figure(path, &snapshot_plot(resp, motor.friction_layer.friction_coefficient), err)?;
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
                serde_json::json!({
                    "voltage_v": r.voltage_v,
                    "frequency_hz": r.frequency_hz,
                    "phase_difference_deg": r.phase_deg,
                    "preload_n": a.preload_n,
                    "torque_nm": a.torque_nm,
                    "status": status(&r.result),
                    "steady_status": r.steady.status.to_string(),
                    "quantities": q,
                })
            })
            .collect();
        let doc = serde_json::json!({ "motor": motor.name, "runs": list });
        writeln!(out, "{}", serde_json::to_string_pretty(&doc)?)?;
        return Ok(0);
    }
    let summary: &mut dyn Write = if to_stderr { err } else { out };
    if single {
        print_single(&runs[0], &motor, a, summary)?;
    } else {
        print_sweep(&runs, summary)?;
    }
    Ok(0)
}

/// The core names config fields; say which command-line flag they come from.
fn flag_message(e: &TransientError) -> String {
    match e {
        TransientError::InvalidConfig { name, value, reason } => {
            let flag = match *name {
                "phase_difference_rad" => "--phase-difference-deg".to_string(),
                "snapshot_times_s" => "--snapshot-at-s".to_string(),
                "load_torque_nm" => "--torque-nm".to_string(),
                n => format!("--{}", n.replace('_', "-")),
            };
            format!("{flag} = {value}: {reason}")
        }
        TransientError::StepTooLarge { .. } => format!("{e} (--steps-per-period)"),
        TransientError::TooManySteps { .. } => format!("{e} (shorten --duration-s or lower --steps-per-period)"),
        _ => e.to_string(),
    }
}

fn print_single(r: &Run, motor: &Motor, a: &StepArgs, out: &mut dyn Write) -> Result<()> {
    let Ok(resp) = &r.result else { return Ok(()) };
    let source = motor.preset.as_deref().map(|p| format!(" (preset {p})")).unwrap_or_default();
    writeln!(out, "motor    {}{source}", motor.name)?;
    writeln!(
        out,
        "drive    {} V, {} Hz, phase {} deg, preload {} N, load {} N·m",
        fmt_sig(r.voltage_v, 6),
        fmt_sig(r.frequency_hz, 6),
        fmt_sig(r.phase_deg, 6),
        fmt_sig(a.preload_n, 6),
        fmt_sig(a.torque_nm, 6)
    )?;
    writeln!(
        out,
        "model    {} s, {} steps ({} per period), {} nodes per wavelength, k_t/k_f = {}",
        fmt_sig(a.duration_s, 6),
        resp.steps,
        a.steps_per_period,
        a.nodes_per_wavelength,
        fmt_sig(a.tangential_stiffness_ratio, 6)
    )?;
    writeln!(out, "status   {} (steady solver: {})", status(&r.result), r.steady.status)?;
    writeln!(out)?;
    let rows: Vec<Vec<String>> =
        quantities(r).into_iter().map(|(n, v, u, m)| vec![n.into(), fmt_sig(v, 6), u.into(), m.into()]).collect();
    write_table(out, &["quantity", "value", "unit", "meaning"], &[Align::Left, Align::Right, Align::Left], &rows)?;
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

fn print_sweep(runs: &[Run], out: &mut dyn Write) -> Result<()> {
    let picked = ["final_speed_rpm", "delay_s", "rise_time_s", "overshoot", "settling_time_s", "steady_speed_rpm"];
    let mut header =
        vec!["voltage_v".to_string(), "frequency_hz".into(), "phase_difference_deg".into(), "status".into()];
    header.extend(picked.iter().map(|s| s.to_string()));
    let rows: Vec<Vec<String>> = runs
        .iter()
        .map(|r| {
            let q = quantities(r);
            let mut row = vec![fmt_sig(r.voltage_v, 6), fmt_sig(r.frequency_hz, 6), fmt_sig(r.phase_deg, 6)];
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

fn table_csv(runs: &[Run]) -> String {
    let mut s = String::from("voltage_v,frequency_hz,phase_difference_deg,status");
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
            csv_number(r.voltage_v),
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

fn speed_plot(resp: &StepResponse, r: &Run, motor: &Motor, a: &StepArgs) -> LinePlot {
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
    if r.steady.speed_rpm.is_finite() {
        let (t0, t1) = (t.time_s.first().copied().unwrap_or(0.0), t.time_s.last().copied().unwrap_or(0.0));
        let v = r.steady.speed_rpm;
        lines.push(Line {
            label: Some("steady-state solver".into()),
            color: series_color(2, 3),
            points: vec![(t0, v), (t1, v)],
            stroke: Stroke::Dashed,
        });
    }
    LinePlot {
        title: format!("{}: rotor speed after switch-on (stick-slip contact)", motor.name),
        subtitle: format!(
            "drive voltage {} V, drive frequency {} kHz, phase {}°, preload {} N, load torque {} N·m",
            fmt_sig(r.voltage_v, 6),
            fmt_sig(r.frequency_hz / 1e3, 6),
            fmt_sig(r.phase_deg, 6),
            fmt_sig(a.preload_n, 6),
            fmt_sig(a.torque_nm, 6)
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
