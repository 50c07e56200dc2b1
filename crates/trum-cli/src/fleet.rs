//! A fleet: `trum diagnose` and `trum calibrate` over many measurement files at once
//! (`--data 'runs/*.csv' --summary fleet.csv`), the files spread over worker threads, one
//! summary row per file. A file that fails gives its row with the error; the others go
//! on. The table does not depend on the number of threads: rows come in the order of the
//! file list, and each file's work is the single-file command's.

use crate::format::csv_number;
use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use std::io::Write;
use std::path::{Component, Path, PathBuf};
use std::sync::Mutex;

/// Exit status of a fleet run in which at least one file failed (its row holds the
/// error; the summary was written). docs/CLI.md, "Fleets".
pub const SOME_FILES_FAILED: i32 = 3;

/// What a fleet run needs besides the per-file work.
pub struct FleetRun<'a> {
    /// The expanded measurement files, in the table's order.
    pub files: &'a [String],
    /// `--summary`: the CSV (`-`: stdout).
    pub summary: &'a Path,
    /// `--threads`.
    pub threads: Option<usize>,
    /// `--quiet`.
    pub quiet: bool,
}

/// One file's result: `(column, cell)` pairs in the command's column order, and the
/// reader's and the fit's warnings.
pub struct Outcome {
    /// Rows read from the file.
    pub rows: usize,
    /// The command's columns.
    pub cells: Vec<(String, String)>,
    /// Warnings (ignored columns, a parameter at a bound, ...).
    pub warnings: Vec<String>,
}

/// A row of the summary: the file, and its outcome or its error.
struct Row {
    file: String,
    result: std::result::Result<Outcome, String>,
    panicked: bool,
}

/// Runs `work` on every file (in parallel, at most `--threads` at a time), writes the
/// summary atomically, prints a short account to `out` (unless the table goes there) and
/// each failed file's error to `err`. Exit code: 0 when every file succeeded,
/// [`SOME_FILES_FAILED`] when one failed, 101 when one hit a bug.
pub fn run<F>(run: &FleetRun<'_>, fixed: &[&str], out: &mut dyn Write, err: &mut dyn Write, work: F) -> Result<i32>
where
    F: Fn(&str) -> Result<Outcome> + Sync,
{
    for f in run.files {
        crate::output::note_input(Path::new(f), &format!("--data '{f}'"));
    }
    // the summary path is checked (and refused when it is an input) before any work
    drop(crate::output::OutputTarget::create(run.summary, ".tmp")?);
    // not capped at the number of files: a file's own diagnosis or fit spreads its work
    // over the pool's idle threads (rayon steals across the nested parallel loops)
    let threads = crate::output::worker_threads(run.threads, "--threads", err)?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().context("cannot start worker threads")?;
    let progress = Mutex::new((crate::output::Progress::new(run.files.len() as u64, "files", run.quiet), 0u64));
    let rows: Vec<Row> = pool.install(|| {
        run.files
            .par_iter()
            .map(|file| {
                let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(file)));
                let row = match caught {
                    Ok(Ok(o)) => Row { file: file.clone(), result: Ok(o), panicked: false },
                    Ok(Err(e)) => Row { file: file.clone(), result: Err(format!("{e:#}")), panicked: false },
                    Err(_) => Row {
                        file: file.clone(),
                        result: Err("internal error (a bug in trum; please report it with the command line)".into()),
                        panicked: true,
                    },
                };
                let mut p = progress.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                p.1 += 1;
                let done = p.1;
                p.0.set(done);
                row
            })
            .collect()
    });
    progress.lock().unwrap_or_else(std::sync::PoisonError::into_inner).0.finish();
    let csv = summary_csv(&rows, fixed)?;
    crate::data::write_atomic(run.summary, ".csv", &csv, out)?;
    let failed: Vec<&Row> = rows.iter().filter(|r| r.result.is_err()).collect();
    for r in &failed {
        if let Err(e) = &r.result {
            // most messages name the file already
            if e.contains(r.file.as_str()) {
                writeln!(err, "error: {e}")?;
            } else {
                writeln!(err, "error: {}: {e}", r.file)?;
            }
        }
    }
    if run.summary.as_os_str() != "-" {
        writeln!(
            out,
            "{} files: {} done, {} failed; summary written to {}",
            rows.len(),
            rows.len() - failed.len(),
            failed.len(),
            run.summary.display()
        )?;
    }
    Ok(if rows.iter().any(|r| r.panicked) {
        101
    } else if failed.is_empty() {
        0
    } else {
        SOME_FILES_FAILED
    })
}

/// The summary table: `file`, `motor_id`, `status` (`ok` or `error`), `rows`, the
/// command's `fixed` columns, the columns that only some files have (the calibrated
/// parameters, in order of first appearance), `warnings` and `error`.
fn summary_csv(rows: &[Row], fixed: &[&str]) -> Result<String> {
    let mut extra: Vec<String> = Vec::new();
    for r in rows {
        if let Ok(o) = &r.result {
            for (k, _) in &o.cells {
                if !fixed.contains(&k.as_str()) && !extra.contains(k) {
                    extra.push(k.clone());
                }
            }
        }
    }
    let mut header: Vec<&str> = vec!["file", "motor_id", "status", "rows"];
    header.extend(fixed);
    header.extend(extra.iter().map(String::as_str));
    header.extend(["warnings", "error"]);
    let mut w = csv::WriterBuilder::new().terminator(csv::Terminator::Any(b'\n')).from_writer(Vec::new());
    w.write_record(&header)?;
    for r in rows {
        let mut rec: Vec<String> = vec![r.file.clone(), motor_id(&r.file)];
        match &r.result {
            Ok(o) => {
                rec.push("ok".into());
                rec.push(o.rows.to_string());
                for col in &header[4..header.len() - 2] {
                    rec.push(o.cells.iter().find(|(k, _)| k == col).map(|(_, v)| v.clone()).unwrap_or_default());
                }
                rec.push(o.warnings.join("; "));
                rec.push(String::new());
            }
            Err(e) => {
                rec.push("error".into());
                // rows, the command's columns and warnings are empty
                rec.extend(vec![String::new(); header.len() - 4]);
                rec.push(e.clone());
            }
        }
        w.write_record(&rec)?;
    }
    let bytes = w.into_inner().map_err(|e| anyhow::anyhow!("{}", e.error()))?;
    Ok(String::from_utf8(bytes)?)
}

/// The motor a file belongs to: its name without directory and extension (a production
/// line names each motor's log after its serial number).
pub fn motor_id(file: &str) -> String {
    Path::new(file).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| file.to_string())
}

/// A number cell (empty when not finite).
pub fn num(x: f64) -> String {
    csv_number(x)
}

/// The `--data` values as files: a value with `*`, `?` or `[` that is not itself an
/// existing file is a pattern, expanded here (so it works quoted, and on shells that
/// do not expand it) to its matching files in sorted order; other values are kept as
/// given. A pattern that matches no file is an error, as is an empty list.
pub fn expand_data(specs: &[String]) -> Result<Vec<String>> {
    let mut files = Vec::new();
    for spec in specs {
        if !has_wildcard(spec) || Path::new(spec).exists() {
            files.push(spec.clone());
            continue;
        }
        let matches = expand_pattern(spec);
        if matches.is_empty() {
            bail!("--data '{spec}': no file matches this pattern");
        }
        files.extend(matches);
    }
    if files.is_empty() {
        bail!("--data: no measurement file given");
    }
    Ok(files)
}

fn has_wildcard(s: &str) -> bool {
    s.contains(['*', '?', '['])
}

/// Every regular file matching `pattern`, whose components may hold `*` (any run of
/// characters), `?` (one character) and `[...]` (one of a set, `[!...]` none of it); a
/// name starting with `.` is matched only by a component that starts with `.`, as in
/// the shell.
fn expand_pattern(pattern: &str) -> Vec<String> {
    let mut current: Vec<PathBuf> = vec![PathBuf::new()];
    for comp in Path::new(pattern).components() {
        let mut next = Vec::new();
        match comp {
            Component::Normal(os) if has_wildcard(&os.to_string_lossy()) => {
                let pat: Vec<char> = os.to_string_lossy().chars().collect();
                for dir in &current {
                    let listing = if dir.as_os_str().is_empty() { Path::new(".") } else { dir.as_path() };
                    let Ok(entries) = std::fs::read_dir(listing) else { continue };
                    let mut names: Vec<String> =
                        entries.filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).collect();
                    names.sort();
                    for n in names {
                        if (n.starts_with('.') && pat.first() != Some(&'.')) || !glob_match(&pat, &n) {
                            continue;
                        }
                        next.push(dir.join(n));
                    }
                }
            }
            other => next.extend(current.iter().map(|d| d.join(other.as_os_str()))),
        }
        current = next;
    }
    let mut files: Vec<String> =
        current.into_iter().filter(|p| p.is_file()).map(|p| p.to_string_lossy().into_owned()).collect();
    files.sort();
    files
}

/// Shell-style match of one path component.
fn glob_match(pat: &[char], name: &str) -> bool {
    let name: Vec<char> = name.chars().collect();
    // iterative matcher with one backtrack point for the last `*`
    let (mut p, mut n) = (0usize, 0usize);
    let mut star: Option<(usize, usize)> = None;
    while n < name.len() {
        if p < pat.len() {
            match pat[p] {
                '*' => {
                    star = Some((p, n));
                    p += 1;
                    continue;
                }
                '?' => {
                    p += 1;
                    n += 1;
                    continue;
                }
                '[' => {
                    if let Some((hit, len)) = class_match(&pat[p..], name[n]) {
                        if hit {
                            p += len;
                            n += 1;
                            continue;
                        }
                    } else if name[n] == '[' {
                        p += 1;
                        n += 1;
                        continue;
                    }
                }
                c if c == name[n] => {
                    p += 1;
                    n += 1;
                    continue;
                }
                _ => {}
            }
        }
        match star {
            Some((sp, sn)) => {
                p = sp + 1;
                n = sn + 1;
                star = Some((sp, sn + 1));
            }
            None => return false,
        }
    }
    pat[p..].iter().all(|&c| c == '*')
}

/// `[...]` at the start of `pat` against `c`: whether it matches and the class's length;
/// `None` when the bracket is not closed (then it is a literal `[`).
fn class_match(pat: &[char], c: char) -> Option<(bool, usize)> {
    let mut i = 1;
    let negate = matches!(pat.get(1), Some('!') | Some('^'));
    if negate {
        i += 1;
    }
    let start = i;
    let mut hit = false;
    while i < pat.len() {
        if pat[i] == ']' && i > start {
            return Some((hit != negate, i + 1));
        }
        if i + 2 < pat.len() && pat[i + 1] == '-' && pat[i + 2] != ']' {
            hit |= pat[i] <= c && c <= pat[i + 2];
            i += 3;
        } else {
            hit |= pat[i] == c;
            i += 1;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(p: &str, n: &str) -> bool {
        glob_match(&p.chars().collect::<Vec<_>>(), n)
    }

    #[test]
    fn shell_patterns_match_as_the_shell_does() {
        assert!(m("*.csv", "a.csv") && m("*.csv", ".csv") && !m("*.csv", "a.csv.bak"));
        assert!(m("run_??.csv", "run_07.csv") && !m("run_?.csv", "run_07.csv"));
        assert!(m("m[0-9]*.csv", "m3x.csv") && !m("m[0-9]*.csv", "mx.csv"));
        assert!(m("m[!a]", "mb") && !m("m[!a]", "ma"));
        assert!(m("*a*b*", "xxaxxbxx") && !m("*a*b", "xxaxxbxx"));
        assert!(m("[x", "[x"), "an unclosed bracket is a literal");
        assert!(m("*", "") && !m("?", ""));
    }

    #[test]
    fn patterns_expand_to_sorted_files_in_any_component() {
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path();
        for sub in ["line1", "line2"] {
            std::fs::create_dir(d.join(sub)).expect("mkdir");
            for f in ["b.csv", "a.csv", ".hidden.csv", "notes.txt"] {
                std::fs::write(d.join(sub).join(f), "x").expect("write");
            }
        }
        let root = d.to_string_lossy();
        let got = expand_data(&[format!("{root}/line*/*.csv")]).expect("expand");
        let want: Vec<String> = ["line1/a.csv", "line1/b.csv", "line2/a.csv", "line2/b.csv"]
            .iter()
            .map(|f| format!("{root}/{f}"))
            .collect();
        assert_eq!(got, want);
        let e = expand_data(&[format!("{root}/*.tsv")]).expect_err("no match is an error");
        assert!(e.to_string().contains("no file matches this pattern"), "{e}");
        // a name that exists is a file even with a wildcard character in it
        std::fs::write(d.join("odd[1].csv"), "x").expect("write");
        assert_eq!(expand_data(&[format!("{root}/odd[1].csv")]).expect("expand"), [format!("{root}/odd[1].csv")]);
    }
}
