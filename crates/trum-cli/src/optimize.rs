//! `trum optimize`: the preload criterion table and the optimum region.

use crate::args::{csv_number, fmt_sig, parse_axis, MotorArgs, OutputTarget, Progress};
use crate::table::{write_table, Align};
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use std::io::{BufWriter, Write};
use std::path::PathBuf;
use trum_core::criterion::{evaluate, region_overlap, CriterionConfig, CriterionRow, Edge};
use trum_core::params::Drive;
use trum_core::sweep::Axis;

/// Published optimum preload regions [N], by preset: Chen, Zheng and Fan 2020 section 5
/// (TRUM60A, 260-320 N; tests/data/papers/chen2020_figures.csv).
const PAPER_REGIONS_N: &[(&str, (f64, f64), &str)] = &[("trum60a", (260.0, 320.0), "Chen et al. 2020 section 5")];

#[derive(Args, Debug)]
pub struct OptimizeArgs {
    #[command(flatten)]
    motor: MotorArgs,
    /// Drive voltage amplitude per phase [V] (default: the motor's [drive], else 200 V).
    #[arg(long)]
    voltage_v: Option<f64>,
    /// Drive frequency [Hz] (default: the motor's [drive], else 43 kHz).
    #[arg(long)]
    frequency_hz: Option<f64>,
    /// Candidate preloads [N] as START:STOP:N (default 150:500:36, as in Chen et al. 2020).
    #[arg(long, value_name = "START:STOP:N", value_parser = parse_axis)]
    preload_n: Option<Axis>,
    /// Weights of stall torque, max efficiency, temperature rise, speed fluctuation.
    #[arg(long, value_name = "a,b,c,d", default_value = "1,1,2,2")]
    weights: String,
    /// Run time for the temperature rise [s].
    #[arg(long, default_value_t = 10.0)]
    run_time_s: f64,
    /// Axial runout of the rotor for the speed fluctuation [m].
    #[arg(long, default_value_t = 5e-6)]
    runout_m: f64,
    /// Score tolerance of the optimum region, as a fraction of the best score.
    #[arg(long, default_value_t = 0.1)]
    region_tolerance: f64,
    /// Also write the table as CSV (`-` for stdout instead of the text table).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
    /// Print the result as JSON (settings, optimum, region, notes, every row) instead of the table.
    #[arg(long)]
    json: bool,
}

/// Columns of the criterion table.
pub const COLUMNS: [&str; 11] = [
    "preload_n",
    "status",
    "stall_torque_nm",
    "max_efficiency",
    "torque_at_max_efficiency_nm",
    "temperature_rise_after_run_k",
    "speed_std_rpm",
    "no_load_speed_rpm",
    "score",
    "in_region",
    "warnings",
];

fn parse_weights(s: &str) -> Result<[f64; 4]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().map_err(|_| anyhow!("--weights: '{}' is not a number", t.trim())))
        .collect::<Result<_>>()?;
    let w: [f64; 4] = v.try_into().map_err(|v: Vec<f64>| {
        anyhow!(
            "--weights: expected 4 numbers (stall torque, max efficiency, temperature rise, speed fluctuation), got {}",
            v.len()
        )
    })?;
    if w.iter().any(|x| !(x.is_finite() && *x >= 0.0)) || w.iter().sum::<f64>() <= 0.0 {
        bail!("--weights: weights must be finite, >= 0 and not all zero");
    }
    Ok(w)
}

fn row_cells(r: &CriterionRow, fmt: &dyn Fn(f64) -> String) -> Vec<String> {
    let valid = r.status.as_str() == "ok";
    // Disqualified candidates (not running at no load) have no indicators: leave them empty.
    let ind = |v: f64| if valid { fmt(v) } else { fmt(f64::NAN) };
    vec![
        fmt(r.preload_n),
        r.status.as_str().to_string(),
        fmt(r.stall_torque_nm),
        ind(r.max_efficiency),
        ind(r.torque_at_max_efficiency_nm),
        ind(r.temperature_rise_after_run_k),
        ind(r.speed_std_rpm),
        fmt(r.no_load_speed_rpm),
        ind(r.score),
        r.in_region.to_string(),
        r.warnings.to_string(),
    ]
}

/// The drive a motor's source figures were taken at: a file's `[drive]` (or its preset's),
/// or a preset's.
pub fn motor_drive(spec: &str) -> Result<Option<Drive>> {
    let path = std::path::Path::new(spec);
    if path.is_file() {
        let text = std::fs::read_to_string(path).with_context(|| format!("cannot read motor file '{spec}'"))?;
        return Drive::from_toml_str(&text, spec).map_err(|e| anyhow!("{e}"));
    }
    Ok(trum_core::presets::find(spec).ok().and_then(|p| p.drive()))
}

pub fn run(a: &OptimizeArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    let (motor, _) = a.motor.load()?;
    let drive = motor_drive(&a.motor.motor)?;
    let mut cfg = CriterionConfig::seed000();
    if let Some(p) = a.preload_n {
        cfg.preload_n = p;
    }
    cfg.voltage_v = a.voltage_v.or(drive.map(|d| d.voltage_v)).unwrap_or(cfg.voltage_v);
    cfg.frequency_hz = a.frequency_hz.or(drive.map(|d| d.frequency_hz)).unwrap_or(cfg.frequency_hz);
    cfg.weights = parse_weights(&a.weights)?;
    cfg.run_time_s = a.run_time_s;
    cfg.runout_m = a.runout_m;
    cfg.region_tolerance = a.region_tolerance;
    let target = a.output.as_ref().map(|p| OutputTarget::create(p, ".csv")).transpose()?;
    let mut progress = Progress::new(cfg.preload_n.n as u64, "preloads", a.quiet);
    let res = evaluate(&motor, &cfg, &mut |done, _| progress.set(done as u64));
    progress.finish();
    let res = res.map_err(|e| anyhow!("{e}"))?;

    let to_stdout = matches!(target, Some(OutputTarget::Stdout));
    if to_stdout && a.json {
        bail!("-o - and --json cannot both go to stdout");
    }
    if let Some(t) = target {
        let rows: Vec<Vec<String>> = res.rows.iter().map(|r| row_cells(r, &csv_number)).collect();
        let write = |w: &mut dyn Write| -> std::io::Result<()> {
            writeln!(w, "{}", COLUMNS.join(","))?;
            for r in &rows {
                writeln!(w, "{}", r.join(","))?;
            }
            w.flush()
        };
        match t.open()? {
            None => write(out)?,
            Some(f) => {
                let name = a.output.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
                write(&mut BufWriter::new(f)).with_context(|| format!("writing '{name}'"))?
            }
        }
        t.finish()?;
    }
    if !to_stdout && !a.json {
        let rows: Vec<Vec<String>> = res.rows.iter().map(|r| row_cells(r, &|v| fmt_sig(v, 5))).collect();
        let header: Vec<String> = COLUMNS
            .iter()
            .map(|c| match crate::args::unit_of(c).or((*c == "temperature_rise_after_run_k").then_some("K")) {
                Some(u) if u != "-" => format!("{c} [{}]", u.replace(' ', "·")),
                _ => c.to_string(),
            })
            .collect();
        let header: Vec<&str> = header.iter().map(String::as_str).collect();
        let mut align = vec![Align::Right; COLUMNS.len()];
        align[1] = Align::Left;
        write_table(out, &header, &align, &rows)?;
        writeln!(out)?;
    }
    // The summary goes to stdout after the table, or to stderr when stdout carries the CSV.
    let mut summary = format!(
        "at {} V, {} Hz{}: optimum preload {} N; optimum region {}-{} N (score within {}% of the best; weights {})",
        fmt_sig(cfg.voltage_v, 5),
        fmt_sig(cfg.frequency_hz, 6),
        match (drive.is_some(), a.voltage_v.is_none(), a.frequency_hz.is_none()) {
            (true, true, true) => " (the motor's [drive])",
            (true, true, false) => " (voltage from the motor's [drive])",
            (true, false, true) => " (frequency from the motor's [drive])",
            _ => "",
        },
        fmt_sig(res.optimum_preload_n, 5),
        fmt_sig(res.region_n.0, 5),
        fmt_sig(res.region_n.1, 5),
        fmt_sig(100.0 * cfg.region_tolerance, 3),
        a.weights
    );
    // an end of the candidates within the limits next to candidates beyond them is an end
    // set by the limits, not by the searched range
    let limited_side = |above: bool| {
        res.within_limits
            && res.rows.iter().any(|r| {
                r.score.is_finite()
                    && !r.warnings.is_empty()
                    && if above { r.preload_n > res.optimum_preload_n } else { r.preload_n < res.optimum_preload_n }
            })
    };
    match res.optimum_edge() {
        Edge::Interior => {}
        Edge::Low if limited_side(false) => summary.push_str(
            "\nnote: the optimum is the lowest candidate within the motor's [limits]; the running candidates below it exceed them",
        ),
        Edge::High if limited_side(true) => summary.push_str(
            "\nnote: the optimum is the highest candidate within the motor's [limits]; the running candidates above it exceed them",
        ),
        Edge::Low => summary.push_str(&format!(
            "\nwarning: the optimum is the lowest running candidate ({} N): the best preload may lie below the searched range; widen it, e.g. --preload-n {}:{}:{}",
            fmt_sig(res.optimum_preload_n, 5),
            fmt_sig((res.optimum_preload_n - 0.5 * (cfg.preload_n.stop - cfg.preload_n.start)).max(0.5 * res.optimum_preload_n), 4),
            fmt_sig(cfg.preload_n.stop, 5),
            cfg.preload_n.n + cfg.preload_n.n / 2
        )),
        Edge::High => summary.push_str(&format!(
            "\nwarning: the optimum is the highest running candidate ({} N): the best preload may lie above the searched range; widen it, e.g. --preload-n {}:{}:{}",
            fmt_sig(res.optimum_preload_n, 5),
            fmt_sig(cfg.preload_n.start, 5),
            fmt_sig(res.optimum_preload_n + 0.5 * (cfg.preload_n.stop - cfg.preload_n.start), 4),
            cfg.preload_n.n + cfg.preload_n.n / 2
        )),
    }
    if res.optimum_edge() == Edge::Interior {
        let running: Vec<f64> = res
            .rows
            .iter()
            .filter(|r| r.score.is_finite() && (!res.within_limits || r.warnings.is_empty()))
            .map(|r| r.preload_n)
            .collect();
        let (lo, hi) = (running.first().copied(), running.last().copied());
        if lo == Some(res.region_n.0) {
            summary.push_str("\nnote: the optimum region reaches the lowest running candidate; it may extend below the searched range");
        }
        if hi == Some(res.region_n.1) {
            summary.push_str("\nnote: the optimum region reaches the highest running candidate; it may extend above the searched range");
        }
    }
    let beyond = res.rows.iter().filter(|r| r.score.is_finite() && !r.warnings.is_empty()).count();
    if beyond > 0 && res.within_limits {
        summary.push_str(&format!(
            "\nnote: {beyond} running candidate(s) exceed the motor's [limits] (warnings column) and are kept out of the optimum and its region"
        ));
    } else if beyond > 0 {
        summary.push_str(
            "\nwarning: every running candidate exceeds the motor's [limits] (warnings column); the optimum is chosen among them all",
        );
    }
    if let Some((_, paper, source)) = PAPER_REGIONS_N.iter().find(|(n, _, _)| motor.preset.as_deref() == Some(*n)) {
        let (overlap, frac) = region_overlap(res.region_n, *paper);
        let mid = |r: (f64, f64)| 0.5 * (r.0 + r.1);
        summary.push_str(&format!(
            "\npaper ({source}): optimum region {}-{} N; overlap {} N ({}% of the paper's region); optimum {} N {} the paper's region (centre difference {:+} N)",
            fmt_sig(paper.0, 5),
            fmt_sig(paper.1, 5),
            fmt_sig(overlap, 4),
            fmt_sig(100.0 * frac, 3),
            fmt_sig(res.optimum_preload_n, 5),
            if paper.0 <= res.optimum_preload_n && res.optimum_preload_n <= paper.1 { "inside" } else { "outside" },
            fmt_sig(mid(res.region_n) - mid(*paper), 4),
        ));
    }
    if a.json {
        let num = crate::data::num;
        let rows: Vec<_> = res
            .rows
            .iter()
            .map(|r| {
                let cells = row_cells(r, &|v| v.to_string());
                let mut m = serde_json::Map::new();
                for (c, v) in COLUMNS.iter().zip(cells) {
                    let value = match *c {
                        "status" => serde_json::json!(v),
                        "in_region" => serde_json::json!(r.in_region),
                        _ => num(v.parse::<f64>().unwrap_or(f64::NAN)),
                    };
                    m.insert((*c).to_string(), value);
                }
                serde_json::Value::Object(m)
            })
            .collect();
        let notes: Vec<&str> = summary.lines().skip(1).collect();
        let doc = serde_json::json!({
            "motor": { "name": motor.name, "source": a.motor.motor, "effects": motor.effects.to_string() },
            "voltage_v": cfg.voltage_v,
            "frequency_hz": cfg.frequency_hz,
            "drive_from_motor": drive.is_some() && (a.voltage_v.is_none() || a.frequency_hz.is_none()),
            "weights": { "stall_torque": cfg.weights[0], "efficiency": cfg.weights[1],
                         "temperature_rise": cfg.weights[2], "speed_fluctuation": cfg.weights[3] },
            "run_time_s": cfg.run_time_s,
            "runout_m": cfg.runout_m,
            "region_tolerance": cfg.region_tolerance,
            "optimum_preload_n": num(res.optimum_preload_n),
            "region_n": [num(res.region_n.0), num(res.region_n.1)],
            "notes": notes,
            "rows": rows,
        });
        writeln!(out, "{}", serde_json::to_string_pretty(&doc)?)?;
    } else if to_stdout {
        writeln!(err, "{summary}")?;
    } else {
        writeln!(out, "{summary}")?;
    }
    Ok(0)
}
