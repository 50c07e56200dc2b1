//! `trum presets` and `trum effects`: the built-in registries.

use crate::table::{write_table, Align};
use anyhow::{anyhow, Result};
use clap::{Args, Subcommand};
use std::io::Write;
use trum_core::effects::EFFECTS;
use trum_core::presets::{self, PRESETS};

#[derive(Args, Debug)]
pub struct PresetsArgs {
    #[command(subcommand)]
    action: Option<PresetsAction>,
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
            let p = presets::find(name).map_err(|e| anyhow!("{}", e.reason))?;
            write!(out, "{}", p.to_toml())?;
        }
    }
    Ok(0)
}

pub fn effects(out: &mut dyn Write) -> Result<i32> {
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
