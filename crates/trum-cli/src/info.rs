//! `trum presets` and `trum effects`: the built-in registries.

use crate::table::{write_table, Align};
use anyhow::{anyhow, Result};
use clap::{Args, Subcommand};
use serde_json::json;
use std::io::Write;
use trum_core::effects::EFFECTS;
use trum_core::presets::{self, PRESETS};

#[derive(Args, Debug)]
pub struct PresetsArgs {
    #[command(subcommand)]
    action: Option<PresetsAction>,
    /// Print the list as JSON (name, display name, summary, sources, drive).
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
pub struct EffectsArgs {
    /// Print the registry as JSON (name, summary, source, parameters with range and typical value).
    #[arg(long)]
    json: bool,
}

#[derive(Subcommand, Debug)]
enum PresetsAction {
    /// Print a preset as a complete, commented motor file (reads back to the same motor).
    Show {
        /// Preset name.
        name: String,
    },
}

pub fn presets(a: &PresetsArgs, out: &mut dyn Write) -> Result<i32> {
    match &a.action {
        None if a.json => {
            let list: Vec<_> = PRESETS
                .iter()
                .map(|p| {
                    json!({
                        "name": p.name,
                        "display_name": p.motor().name,
                        "summary": p.summary,
                        "sources": p.sources,
                        "drive": p.drive().map(|d| json!({"voltage_v": d.voltage_v, "frequency_hz": d.frequency_hz})),
                    })
                })
                .collect();
            writeln!(out, "{}", serde_json::to_string_pretty(&list)?)?;
        }
        None => {
            let mut rows: Vec<Vec<String>> = PRESETS
                .iter()
                .map(|p| vec![p.name.to_string(), p.summary.to_string(), p.sources.to_string()])
                .collect();
            // bar-type motors run only in `trum step`; the summary says so
            rows.extend(presets::BAR_PRESETS.iter().map(|p| {
                vec![p.name.to_string(), format!("{} (bar-type: `trum step` only)", p.summary), p.sources.to_string()]
            }));
            write_table(out, &["name", "summary", "sources"], &[Align::Left; 3], &rows)?;
            writeln!(out, "\n`trum presets show NAME > motor.toml` writes one as a motor file to edit.")?;
        }
        Some(PresetsAction::Show { name }) => {
            if let Some(b) = presets::find_bar(name) {
                write!(out, "{}", b.to_toml())?;
                return Ok(0);
            }
            let p = presets::find(name).map_err(|e| anyhow!("{}{}", e.reason, crate::suggest::preset_hint(name)))?;
            write!(out, "{}", p.to_toml())?;
        }
    }
    Ok(0)
}

pub fn effects(a: &EffectsArgs, out: &mut dyn Write) -> Result<i32> {
    if a.json {
        let list: Vec<_> = EFFECTS
            .iter()
            .map(|e| {
                json!({
                    "name": e.name,
                    "summary": squash(e.summary),
                    "source": e.source,
                    "params": e.params.iter().enumerate().map(|(j, p)| json!({
                        "name": p.name,
                        "role": if j == 0 { "strength" } else if p.shape { "shape" } else { "parameter" },
                        "min": p.min,
                        "max": p.max,
                        "typical": p.typical,
                        "doc": squash(p.doc),
                    })).collect::<Vec<_>>(),
                })
            })
            .collect();
        writeln!(out, "{}", serde_json::to_string_pretty(&list)?)?;
        return Ok(0);
    }
    for (i, e) in EFFECTS.iter().enumerate() {
        if i > 0 {
            writeln!(out)?;
        }
        writeln!(out, "{}", e.name)?;
        writeln!(out, "  {}", squash(e.summary))?;
        writeln!(out, "  source: {}", e.source)?;
        let rows: Vec<Vec<String>> = e
            .params
            .iter()
            .enumerate()
            .map(|(j, p)| {
                vec![
                    format!(
                        "  {}{}",
                        p.name,
                        match (j, p.shape) {
                            (0, _) => " (strength)",
                            (_, true) => " (shape)",
                            _ => "",
                        }
                    ),
                    format!("[{}, {}]", p.min, p.max),
                    format!("{}", p.typical),
                    squash(p.doc),
                ]
            })
            .collect();
        write_table(out, &["  parameter", "range", "typical", "meaning"], &[Align::Left; 4], &rows)?;
    }
    writeln!(
        out,
        "\nSwitch on with `--effect NAME=STRENGTH` or `--effect NAME:param=value,param=value`,\n\
         or in a motor file's [effects] table (see docs/MOTOR_FILE.md)."
    )?;
    Ok(0)
}

/// Registry texts are wrapped in the source with `\` continuations; collapse the runs of spaces.
fn squash(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}
