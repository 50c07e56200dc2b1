//! `trum diagnose`: the sim-to-real gap diagnosis — where the calibrated baseline misses,
//! which unmodelled effect causes it, and how far the held-out gap shrinks once that
//! effect is added. Summary to stdout, the JSON document (docs/DIAGNOSIS_JSON.md) and an
//! HTML report (crate::report) on request.

use crate::data::{read_data, write_atomic};
use crate::format::fmt_sig;
use crate::motor::load_motor;
use crate::table::{write_table, Align};
use crate::verdict::{after_nrmse, verdict_words};
use anyhow::{anyhow, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::Duration;
use trum_core::diagnose::json::{to_json, Provenance};
use trum_core::diagnose::{diagnose, stated_noise_from_texts, DiagnoseOptions, Diagnosis};
use trum_core::Motor;

use trum_core::diagnose::json::{unit, EVIDENCE_SCALE};

#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    /// Nominal motor: a TOML motor file or a preset name.
    #[arg(long, value_name = "MOTOR.toml|PRESET")]
    motor: String,
    /// Measurement CSV (layout: docs/MEASUREMENTS.md); several files, or a pattern such
    /// as 'runs/*.csv', with --summary (a fleet: docs/CLI.md, "Fleets").
    #[arg(long, value_name = "DATA.csv", num_args = 1.., required = true)]
    data: Vec<String>,
    /// Diagnose every --data file (in parallel) and write one summary row per file to
    /// this CSV (`-`: stdout) instead of one file's summary.
    #[arg(long, value_name = "FLEET.csv")]
    summary: Option<PathBuf>,
    /// Worker threads of a fleet run (default: RAYON_NUM_THREADS or every core; never
    /// more than the cores).
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    #[command(flatten)]
    plausible: crate::data::PlausibleArgs,
    /// Most measurement rows to diagnose (docs/CLI.md, "Limits"): more are refused before
    /// the run with the estimated time and memory; raise this to run anyway.
    #[arg(long, value_name = "N", default_value_t = 1_000_000)]
    max_rows: usize,
    /// Most rows the fits see: larger data are diagnosed on a systematic subsample of this
    /// many (one row in every n/N, in file order; a note says so, and the evidence and the
    /// held-out figures are the subsample's). 0: every row, at a cost that grows with them.
    #[arg(long, value_name = "N", default_value_t = trum_core::diagnose::MAX_FIT_ROWS)]
    fit_rows: usize,
    /// Write the diagnosis as JSON here (`-`: JSON to stdout instead of the summary).
    #[arg(long, value_name = "OUT.json")]
    json: Option<PathBuf>,
    /// Write a self-contained HTML report (plots, tables, method) here.
    #[arg(long, value_name = "OUT.html")]
    report: Option<PathBuf>,
    /// Noise level of a sensor as the bench states it, in place of the default and of the
    /// estimate from the data: COLUMN=SD (standard deviation in the column's unit) or
    /// COLUMN=SD,REL (plus REL × the reading), e.g. speed_rpm=0.3,0.005 (repeatable;
    /// docs/DIAGNOSIS.md, "Noise levels from the data").
    #[arg(long = "sensor-noise", value_name = "COLUMN=SD[,REL]")]
    sensor_noise: Vec<String>,
    /// Refit every model on every cross-validation fold instead of the approximate
    /// leave-block-out refit (slower; docs/DIAGNOSIS.md).
    #[arg(long)]
    exact_cv: bool,
    /// No progress spinner.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(a: &DiagnoseArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    let files = crate::fleet::expand_data(&a.data)?;
    if a.summary.is_some() || files.len() > 1 {
        return run_fleet(a, &files, out, err);
    }
    let data = &files[0];
    let (motor, _) = load_motor(&a.motor)?;
    let (_, bench) = read_data(data, &motor, &a.plausible.ranges(&a.motor)?, err)?;
    crate::data::check_rows(data, bench.rows.len(), a.max_rows, &crate::data::DIAGNOSE_ROW)?;
    // Check the output paths before the long run, so a typo fails at once.
    for p in [&a.json, &a.report].into_iter().flatten() {
        drop(crate::output::OutputTarget::create(p, ".tmp")?);
    }
    let spinner =
        spinner("diagnosing: calibrating the baseline and every candidate effect on held-out regions", a.quiet);
    let opts = DiagnoseOptions {
        exact_cv: a.exact_cv,
        max_fit_rows: a.fit_rows,
        tolerances: crate::motor::load_tolerances(&a.motor)?,
        stated_noise: stated_noise_from_texts(&a.sensor_noise, "--sensor-noise")?,
        ..DiagnoseOptions::default()
    };
    let d = diagnose(&motor, &bench.rows, &bench.groups, &opts);
    spinner.finish_and_clear();
    let d = d.map_err(|e| anyhow!("cannot diagnose '{data}': {e}"))?;
    let json_stdout = a.json.as_ref().is_some_and(|p| p.as_os_str() == "-");
    if let Some(p) = &a.json {
        let src = Provenance { motor_name: &motor.name, motor_source: &a.motor, data, lines: &bench.lines };
        let doc = to_json(&d, &src);
        write_atomic(p, ".json", &(serde_json::to_string_pretty(&doc)? + "\n"), out)?;
    }
    if let Some(p) = &a.report {
        let html = crate::report::html(&d, &motor, data, &bench);
        write_atomic(p, ".html", &html, out)?;
    }
    if !json_stdout {
        write_summary(&d, &motor, data, out)?;
    }
    Ok(0)
}

/// The columns of a diagnosis fleet's summary (docs/CLI.md, "Fleets"), before the
/// calibrated baseline parameters.
const FLEET_COLUMNS: [&str; 12] = [
    "verdict",
    "complete",
    "confounded_with",
    "partial",
    "evidence",
    "shrink",
    "shrink_low",
    "shrink_high",
    "baseline_heldout_nrmse",
    "remaining_heldout_nrmse",
    "noise_nrmse",
    "readings",
];

/// `--data` with many files and `--summary`: one diagnosis per file, in parallel.
fn run_fleet(a: &DiagnoseArgs, files: &[String], out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    let Some(summary) = &a.summary else {
        anyhow::bail!(
            "--data names {} measurement files: give --summary FLEET.csv (or --summary - for stdout) for one \
             table over them (docs/CLI.md, \"Fleets\")",
            files.len()
        );
    };
    if a.json.is_some() || a.report.is_some() {
        anyhow::bail!(
            "--json and --report describe one measurement file; with --summary the fleet table has a row per file"
        );
    }
    let (motor, _) = load_motor(&a.motor)?;
    let plausible = a.plausible.ranges(&a.motor)?;
    let opts = DiagnoseOptions {
        exact_cv: a.exact_cv,
        tolerances: crate::motor::load_tolerances(&a.motor)?,
        stated_noise: stated_noise_from_texts(&a.sensor_noise, "--sensor-noise")?,
        ..DiagnoseOptions::default()
    };
    let run = crate::fleet::FleetRun { files, summary, threads: a.threads, quiet: a.quiet };
    crate::fleet::run(&run, &FLEET_COLUMNS, out, err, |file| {
        let (m, bench) = crate::data::read_data_quietly(file, &motor, &plausible)?;
        crate::data::check_rows(file, bench.rows.len(), a.max_rows, &crate::data::DIAGNOSE_ROW)?;
        let d = diagnose(&motor, &bench.rows, &bench.groups, &opts)
            .map_err(|e| anyhow!("cannot diagnose '{file}': {e}"))?;
        Ok(crate::fleet::Outcome { rows: bench.rows.len(), cells: fleet_cells(&d), warnings: m.warnings.clone() })
    })
}

/// One diagnosis as the fleet summary's cells: the verdict, how much of the held-out gap
/// it closes (the partial effect's share with `unexplained`; empty with `none`), the
/// held-out errors and the calibrated baseline parameters.
fn fleet_cells(d: &Diagnosis) -> Vec<(String, String)> {
    use crate::fleet::num;
    let of_verdict = d.ranking.iter().find(|r| trum_core::diagnose::same_set(&r.effect, &d.verdict));
    let entry = of_verdict.or_else(|| {
        d.partial
            .as_ref()
            .filter(|_| d.verdict == "unexplained")
            .and_then(|p| d.ranking.iter().find(|r| &r.effect == p))
    });
    let opt = |f: &dyn Fn(&trum_core::diagnose::RankEntry) -> f64| entry.map(|r| num(f(r))).unwrap_or_default();
    let mut cells: Vec<(String, String)> = vec![
        ("verdict".into(), d.verdict.clone()),
        ("complete".into(), d.complete.to_string()),
        ("confounded_with".into(), d.confounded_with.join(";")),
        ("partial".into(), d.partial.clone().unwrap_or_default()),
        ("evidence".into(), opt(&|r| r.evidence)),
        ("shrink".into(), opt(&|r| r.shrink)),
        ("shrink_low".into(), opt(&|r| r.shrink_interval.0)),
        ("shrink_high".into(), opt(&|r| r.shrink_interval.1)),
        ("baseline_heldout_nrmse".into(), num(d.baseline_heldout_nrmse)),
        // the held-out gap the verdict leaves (the baseline's with `none` and `unexplained`)
        ("remaining_heldout_nrmse".into(), num(of_verdict.map_or(d.baseline_heldout_nrmse, |r| r.heldout_nrmse_after))),
        ("noise_nrmse".into(), num(d.noise_nrmse)),
        ("readings".into(), d.n_readings.to_string()),
    ];
    cells.extend(d.baseline_params.iter().map(|(k, v)| (k.clone(), num(*v))));
    cells
}

/// A spinner with the elapsed time and `message` on stderr while a long step runs whose
/// length is not known beforehand (only on a terminal, and not with `--quiet`).
pub fn spinner(message: &str, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{spinner} {elapsed:>4} {msg}") {
        b.set_style(style.tick_chars("⠋⠙⠹⠸⠼⠴⠦⠧⠇⠏ "));
    }
    b.set_message(message.to_string());
    b.enable_steady_tick(Duration::from_millis(120));
    b
}

/// `0.1234` as `12.3 %`.
fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.1} %", 100.0 * x)
    } else {
        "-".into()
    }
}

pub fn write_summary(d: &Diagnosis, motor: &Motor, data: &str, out: &mut dyn Write) -> Result<()> {
    writeln!(out, "motor       {}", motor.name)?;
    writeln!(
        out,
        "data        {data} ({} rows, {} readings, {} cross-validation folds over operating regions)",
        d.n_rows, d.n_readings, d.folds
    )?;
    writeln!(out, "verdict     {}", verdict_words(d))?;
    let conf = if d.confounded_with.is_empty() { "none".to_string() } else { d.confounded_with.join(", ") };
    writeln!(out, "confounded  {conf}")?;
    let after = match after_nrmse(d) {
        Some(x) => format!(" -> {} with {}", fmt_sig(x, 3), d.verdict),
        None => String::new(),
    };
    writeln!(
        out,
        "gap         held-out NRMSE {} (baseline){after}; noise alone {}",
        fmt_sig(d.baseline_heldout_nrmse, 3),
        fmt_sig(d.noise_nrmse, 3)
    )?;
    writeln!(
        out,
        "            held-out chi2 per reading {} (1 = at the noise level)",
        fmt_sig(d.baseline_heldout_chi2_per_reading, 3)
    )?;
    writeln!(out)?;
    if d.gap_where.is_empty() {
        writeln!(out, "where: no quantity and region where the baseline misses by more than the noise explains")?;
    } else {
        writeln!(out, "where the baseline misses (mean residual = measured - model, full-data fit)")?;
        let rows: Vec<Vec<String>> = d
            .gap_where
            .iter()
            .map(|g| {
                vec![
                    g.quantity.clone(),
                    g.region.clone(),
                    fmt_sig(g.mean_residual, 3),
                    unit(&g.quantity).to_string(),
                    g.n.to_string(),
                    format!("{:.1}", g.z),
                ]
            })
            .collect();
        write_table(
            out,
            &["quantity", "region", "mean residual", "unit", "n", "z"],
            &[Align::Left, Align::Left, Align::Right, Align::Left, Align::Right, Align::Right],
            &rows,
        )?;
    }
    writeln!(out)?;
    writeln!(out, "ranking ({EVIDENCE_SCALE})")?;
    let rows: Vec<Vec<String>> = d
        .ranking
        .iter()
        .map(|r| {
            vec![
                r.effect.clone(),
                fmt_sig(r.evidence, 3),
                fmt_sig(r.heldout_nrmse_after, 3),
                pct(r.shrink),
                format!("[{}, {}]", pct(r.shrink_interval.0), pct(r.shrink_interval.1)),
                r.signature_match.map(|x| format!("{x:+.2}")).unwrap_or_default(),
                r.signature_overlap.map(|x| format!("{x:.2}")).unwrap_or_default(),
            ]
        })
        .collect();
    write_table(
        out,
        &["effect", "evidence", "NRMSE after", "shrink", "90 % interval", "signature match", "overlap"],
        &[Align::Left, Align::Right, Align::Right, Align::Right, Align::Left, Align::Right, Align::Right],
        &rows,
    )?;
    writeln!(
        out,
        "signature match: cos of the baseline's residual and the effect's first-order change (+1: exactly the \
         missing shape); overlap: |cos| with the verdict's signature (1: the data see one shape)"
    )?;
    if !d.notes.is_empty() {
        writeln!(out)?;
        writeln!(out, "notes")?;
        for n in &d.notes {
            writeln!(out, "- {n}")?;
        }
    }
    Ok(())
}
