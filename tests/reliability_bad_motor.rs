//! The bad-input corpus of motor files (`tests/data/bad/motor/`): every file is rejected
//! with exactly the message in its sibling `.expected` file (`{source}` stands for the
//! source name). UTF-8 files go through `Motor::from_toml_str_with_sweep` (what the CLI
//! calls); files that are not UTF-8 cannot reach the core as `&str`, so they go through
//! the CLI's own reader, in process. The spawned-binary version of this test is
//! `crates/trum-cli/tests/reliability_bad_motor.rs`; the Python one
//! `crates/trum-py/tests/test_bad_inputs.py`.

use std::path::{Path, PathBuf};
use trum_core::Motor;

/// Corpus files listed in `known_bugs.txt` (their `.expected` holds the message trum
/// should print but does not yet; tests/reliability_known_bugs.rs checks them).
pub fn known_bugs() -> Vec<String> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad/motor/known_bugs.txt");
    std::fs::read_to_string(p)
        .unwrap_or_default()
        .lines()
        .map(|l| l.split('#').next().unwrap_or("").trim().to_string())
        .filter(|l| !l.is_empty())
        .collect()
}

fn corpus() -> Vec<(PathBuf, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad/motor");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/data/bad/motor")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let exp = std::fs::read_to_string(p.with_extension("expected")).unwrap_or_default();
            let exp = exp.strip_suffix('\n').unwrap_or(&exp).to_string();
            (p, exp)
        })
        .collect()
}

fn source_of(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

#[test]
fn corpus_is_complete_and_large_enough() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad");
    let mut total = 0;
    for sub in ["motor", "measurements"] {
        for e in std::fs::read_dir(root.join(sub)).expect("corpus dir") {
            let p = e.expect("entry").path();
            let ext = p.extension().and_then(|x| x.to_str()).unwrap_or("");
            if p.file_name().is_some_and(|n| n == "known_bugs.txt") {
                continue;
            }
            assert!(["toml", "csv", "expected"].contains(&ext), "stray file {}", p.display());
            if ext == "expected" {
                let input = if sub == "motor" { "toml" } else { "csv" };
                assert!(p.with_extension(input).exists(), "{} has no input file", p.display());
            } else {
                total += 1;
            }
        }
    }
    let motor = corpus().len();
    assert!(motor >= 20, "only {motor} bad motor files");
    assert!(total >= 30, "only {total} bad input files");
    for name in known_bugs() {
        assert!(root.join("motor").join(&name).exists(), "known_bugs.txt lists {name}, which does not exist");
    }
}

#[test]
fn every_bad_motor_file_fails_with_its_expected_message() {
    let mut problems = Vec::new();
    // UPDATE_EXPECTED=1 writes the current messages to the .expected files (review them!).
    let update = std::env::var_os("UPDATE_EXPECTED").is_some();
    let known = known_bugs();
    for (path, expected) in corpus() {
        let source = source_of(&path);
        if known.iter().any(|k| path.ends_with(k)) {
            continue;
        }
        if update {
            let msg = match std::fs::read(&path).map(String::from_utf8) {
                Ok(Ok(text)) => Motor::from_toml_str_with_sweep(&text, &source).err().map(|e| e.to_string()),
                _ => {
                    let (mut out, mut err) = (Vec::new(), Vec::new());
                    trum_cli::run_with_io(
                        ["trum", "point", "--motor", &source, "--preload-n", "100"],
                        &mut out,
                        &mut err,
                    );
                    String::from_utf8_lossy(&err).trim_end().strip_prefix("error: ").map(str::to_string)
                }
            };
            let msg = msg.unwrap_or_else(|| "ACCEPTED (not an error)".into()).replace(&source, "{source}");
            std::fs::write(path.with_extension("expected"), msg + "\n").expect("write .expected");
            continue;
        }
        assert!(!expected.is_empty(), "{}: empty or missing .expected file", path.display());
        let expected = expected.replace("{source}", &source);
        let bytes = std::fs::read(&path).expect("read");
        let Ok(text) = std::str::from_utf8(&bytes) else {
            // Not UTF-8: the CLI's reader is the only way in; it must fail cleanly.
            let mut out = Vec::new();
            let mut err = Vec::new();
            let code = trum_cli::run_with_io(
                ["trum", "point", "--motor", source.as_str(), "--preload-n", "100"],
                &mut out,
                &mut err,
            );
            let err = String::from_utf8_lossy(&err).into_owned();
            if code != 1 || err.trim_end() != format!("error: {expected}") {
                problems.push(format!("{}: exit {code}, stderr {err:?}, expected {expected:?}", path.display()));
            }
            continue;
        };
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        match Motor::from_toml_str_with_sweep(text, &source) {
            Ok(_) => problems.push(format!("{}: accepted", path.display())),
            Err(e) if e.to_string() != expected => {
                problems.push(format!("{}:\n   got      {e}\n   expected {expected}", path.display()))
            }
            Err(e) => {
                // every message names the source, and the line when it has one
                assert!(e.to_string().starts_with(&source), "{e}");
            }
        }
        // `from_toml_str` (what Python calls) checks the `[sweep]` table's shape but not its
        // values, so it may accept a `sweep_*` file; otherwise it fails the same way.
        let plain = Motor::from_toml_str(text, &source);
        let accepted_sweep = name.starts_with("sweep_") && plain.is_ok();
        if !accepted_sweep && plain.as_ref().err().map(ToString::to_string).as_deref() != Some(expected.as_str()) {
            problems.push(format!("{}: from_toml_str gives {plain:?}", path.display()));
        }
    }
    assert!(problems.is_empty(), "{} problem(s):\n{}", problems.len(), problems.join("\n"));
}
