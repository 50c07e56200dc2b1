//! `trum calibrate`: fits the uncertain baseline parameters of a motor to a measurement
//! file and writes the calibrated motor file.

use crate::args::{fmt_sig, MotorArgs};
use crate::data::{num, read_data, write_atomic};
use crate::table::{write_table, Align};
use anyhow::{anyhow, Result};
use clap::Args;
use serde_json::json;
use std::io::Write;
use std::path::PathBuf;
use trum_core::calibrate::{rescale_uncertainties, Calibration, FitOptions};

#[derive(Args, Debug)]
pub struct CalibrateArgs {
    #[command(flatten)]
    motor: MotorArgs,
    /// Measurement CSV (docs/MEASUREMENTS.md; `trum synth` writes one); several files, or a
    /// pattern such as 'runs/*.csv', with --summary (a fleet: docs/CLI.md, "Fleets").
    #[arg(long, value_name = "FILE", num_args = 1.., required = true)]
    data: Vec<String>,
    /// Calibrate to every --data file on its own (in parallel) and write one summary row
    /// per file to this CSV (`-`: stdout).
    #[arg(long, value_name = "FLEET.csv")]
    summary: Option<PathBuf>,
    /// Worker threads of a fleet run (default: RAYON_NUM_THREADS or every core; never
    /// more than the cores).
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    #[command(flatten)]
    plausible: crate::data::PlausibleArgs,
    /// Most measurement rows to calibrate to (docs/CLI.md, "Limits"): more are refused
    /// before the fit with the estimated time and memory; raise this to run anyway.
    #[arg(long, value_name = "N", default_value_t = 2_000_000)]
    max_rows: usize,
    /// Most rows the fit sees: larger data are fitted on a systematic subsample of this many
    /// (one row in every n/N, in file order; a warning says so, and the χ² and the standard
    /// errors are the subsample's). 0: every row, at a cost that grows with them.
    #[arg(long, value_name = "N", default_value_t = trum_core::calibrate::MAX_FIT_ROWS)]
    fit_rows: usize,
    /// Write the calibrated motor file here (TOML; `-` for stdout instead of the table).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
    /// Write the fit result as JSON here (`-` for stdout instead of the table).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// No progress spinner.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(a: &CalibrateArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    let to_stdout = |p: &Option<PathBuf>| p.as_ref().is_some_and(|p| p.as_os_str() == "-");
    if to_stdout(&a.output) && to_stdout(&a.json) {
        anyhow::bail!("-o - and --json - cannot both go to stdout");
    }
    let files = crate::fleet::expand_data(&a.data)?;
    if a.summary.is_some() || files.len() > 1 {
        return run_fleet(a, &files, out, err);
    }
    let data = &files[0];
    let (motor, _) = a.motor.load()?;
    let (_, bench) = read_data(data, &motor, &a.plausible.ranges(&a.motor.motor)?, err)?;
    let tolerances = crate::motor::load_tolerances(&a.motor.motor)?;
    // Check the output paths before the fit, so a typo or an input named as output fails at once.
    for p in [&a.output, &a.json].into_iter().flatten() {
        drop(crate::output::OutputTarget::create(p, ".tmp")?);
    }
    crate::data::check_rows(data, bench.rows.len(), a.max_rows, &crate::data::CALIBRATE_ROW)?;
    refuse_unsolvable(&motor, &bench, data)?;
    let spinner = crate::diagnose::spinner(
        &format!(
            "calibrating the baseline parameters to {} rows (about {})",
            bench.rows.len(),
            crate::output::human_seconds(bench.rows.len() as f64 * crate::data::CALIBRATE_ROW.seconds)
        ),
        a.quiet,
    );
    let cal = Calibration::builder(&motor, &bench.rows)
        .tolerances(&tolerances)
        .options(&FitOptions::default())
        .refit_bounds(true)
        .search_starts(true)
        .max_rows(a.fit_rows)
        .run();
    let mut cal = cal.map_err(|e| anyhow!("{data}: {e}"));
    if let Ok(cal) = &mut cal {
        rescale_uncertainties(cal, &bench.rows);
    }
    spinner.finish_and_clear();
    let cal = cal?;
    let chi2_per = cal.chi2 / cal.n_readings.max(1) as f64;
    if let Some(path) = &a.json {
        let doc = json!({
            "motor": { "name": motor.name, "source": a.motor.motor, "effects": motor.effects.to_string() },
            "data": data,
            "n_rows": bench.rows.len(),
            "n_rows_fitted": cal.sample.map_or(bench.rows.len(), |(m, _)| m),
            "n_readings": cal.n_readings,
            "chi2": num(cal.chi2),
            "chi2_per_reading": num(chi2_per),
            "evaluations": cal.evaluations,
            "params": cal.params.iter().map(|p| json!({
                "name": p.name,
                "nominal": num(motor.param(&p.name).unwrap_or(f64::NAN)),
                "value": num(p.value),
                "std_error": num(p.std_error),
                "at_bound": p.at_bound,
                "identifiable": p.identifiable,
            })).collect::<Vec<_>>(),
            "warnings": cal.warnings,
        });
        write_atomic(path, ".json", &(serde_json::to_string_pretty(&doc)? + "\n"), out)?;
    }
    if let Some(path) = &a.output {
        write_atomic(path, ".toml", &calibrated_toml(&cal, &motor, data, chi2_per), out)?;
    }
    if !to_stdout(&a.output) && !to_stdout(&a.json) {
        print_table(&cal, &motor, data, chi2_per, out)?;
    }
    for w in &cal.warnings {
        writeln!(err, "warning: {w}")?;
    }
    Ok(0)
}

/// `--data` with many files and `--summary`: one calibration per file, in parallel; the
/// summary's columns after `chi2_per_reading` are each fitted parameter and its standard
/// error (`std_error.NAME`).
fn run_fleet(a: &CalibrateArgs, files: &[String], out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    let Some(summary) = &a.summary else {
        anyhow::bail!(
            "--data names {} measurement files: give --summary FLEET.csv (or --summary - for stdout) for one \
             table over them (docs/CLI.md, \"Fleets\")",
            files.len()
        );
    };
    if a.output.is_some() || a.json.is_some() {
        anyhow::bail!("-o and --json describe one measurement file; with --summary the fleet table has a row per file");
    }
    let (motor, _) = a.motor.load()?;
    let plausible = a.plausible.ranges(&a.motor.motor)?;
    let tolerances = crate::motor::load_tolerances(&a.motor.motor)?;
    let run = crate::fleet::FleetRun { files, summary, threads: a.threads, quiet: a.quiet };
    crate::fleet::run(&run, &["readings", "chi2_per_reading", "evaluations"], out, err, |file| {
        use crate::fleet::num;
        let (m, bench) = crate::data::read_data_quietly(file, &motor, &plausible)?;
        crate::data::check_rows(file, bench.rows.len(), a.max_rows, &crate::data::CALIBRATE_ROW)?;
        refuse_unsolvable(&motor, &bench, file)?;
        let mut cal = Calibration::builder(&motor, &bench.rows)
            .tolerances(&tolerances)
            .options(&FitOptions::default())
            .refit_bounds(true)
            .search_starts(true)
            .run()
            .map_err(|e| anyhow!("{file}: {e}"))?;
        rescale_uncertainties(&mut cal, &bench.rows);
        let mut cells: Vec<(String, String)> = vec![
            ("readings".into(), cal.n_readings.to_string()),
            ("chi2_per_reading".into(), num(cal.chi2 / cal.n_readings.max(1) as f64)),
            ("evaluations".into(), cal.evaluations.to_string()),
        ];
        for p in &cal.params {
            cells.push((p.name.clone(), num(p.value)));
            cells.push((format!("std_error.{}", p.name), num(p.std_error)));
        }
        let mut warnings = m.warnings.clone();
        warnings.extend(cal.warnings.iter().cloned());
        Ok(crate::fleet::Outcome { rows: bench.rows.len(), cells, warnings })
    })
}

/// Refuses data at which the nominal motor has no solution at a single row (preloads of
/// 1e308 N, frequencies far from any resonance, ...): a fit to them would move nothing
/// and still write a "calibrated" motor. One solvable row is enough to go on; the fit
/// counts the others as misses and says so.
fn refuse_unsolvable(motor: &trum_core::Motor, bench: &trum_core::bench::BenchData, data: &str) -> Result<()> {
    let prep = trum_core::solve::Prepared::new(motor);
    let mut first_bad = None;
    for (i, r) in bench.rows.iter().enumerate() {
        let s = trum_core::solve::solve_prepared(&prep, motor, &r.op, None);
        if s.status.is_valid() {
            return Ok(());
        }
        first_bad.get_or_insert((i, s.status));
    }
    let Some((i, status)) = first_bad else { return Ok(()) };
    let line = bench.lines.get(i).copied().unwrap_or(0);
    let op = &bench.rows[i].op;
    anyhow::bail!(
        "{data}: the motor '{}' has no solution at any of the {} measured operating points (line {line}: preload {} N, \
         {} V, {} Hz, {} N·m: {}); nothing to calibrate to: check the data's units and the motor",
        motor.name,
        bench.rows.len(),
        fmt_sig(op.preload_n, 4),
        fmt_sig(op.voltage_v, 4),
        fmt_sig(op.frequency_hz, 6),
        fmt_sig(op.torque_nm, 4),
        status.as_str()
    )
}

/// The calibrated motor file, with the fit recorded in comments.
fn calibrated_toml(cal: &Calibration, nominal: &trum_core::Motor, data: &str, chi2_per: f64) -> String {
    let header = format!(
        "trum motor file: {}\ncalibrated by `trum calibrate` to {data} ({} readings, chi2/reading {})",
        cal.motor.name,
        cal.n_readings,
        fmt_sig(chi2_per, 4)
    );
    cal.motor.to_toml_annotated(&header, &|key| {
        cal.params.iter().find(|p| p.name == key).map(|p| {
            let nom = nominal.param(key).map(|v| fmt_sig(v, 6)).unwrap_or_else(|| "-".into());
            let flag = if !p.identifiable && p.prior_rel_sd.is_some() {
                ", held near its prior by this data"
            } else if !p.identifiable {
                ", not identifiable from this data"
            } else if p.at_bound {
                ", at a bound"
            } else {
                ""
            };
            format!("calibrated, std error {}, nominal {nom}{flag}", fmt_sig(p.std_error, 3))
        })
    })
}

fn print_table(
    cal: &Calibration,
    motor: &trum_core::Motor,
    data: &str,
    chi2_per: f64,
    out: &mut dyn Write,
) -> Result<()> {
    writeln!(out, "motor     {}", motor.name)?;
    writeln!(out, "data      {data} ({} readings, {} model passes)", cal.n_readings, cal.evaluations)?;
    writeln!(out, "chi2      {} per reading (1 = fits to within the assumed noise)", fmt_sig(chi2_per, 4))?;
    writeln!(out)?;
    let rows: Vec<Vec<String>> = cal
        .params
        .iter()
        .map(|p| {
            let nom = motor.param(&p.name).unwrap_or(f64::NAN);
            let change = if nom != 0.0 { 100.0 * (p.value / nom - 1.0) } else { f64::NAN };
            let mut flags = Vec::new();
            if p.at_bound {
                flags.push("at bound");
            }
            if !p.identifiable {
                flags.push(if p.prior_rel_sd.is_some() { "held by its prior" } else { "not identifiable" });
            }
            vec![
                p.name.clone(),
                fmt_sig(nom, 5),
                fmt_sig(p.value, 5),
                fmt_sig(p.std_error, 2),
                if change.is_finite() { format!("{change:+.1}%") } else { "-".into() },
                flags.join(", "),
            ]
        })
        .collect();
    write_table(
        out,
        &["parameter", "nominal", "fitted", "std error", "change", "note"],
        &[Align::Left, Align::Right, Align::Right, Align::Right, Align::Right, Align::Left],
        &rows,
    )?;
    Ok(())
}
