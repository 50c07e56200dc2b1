//! The real `trum` binary on the bad motor-file corpus (`tests/data/bad/motor/` at the
//! workspace root): `trum point --motor FILE --preload-n 100` exits with code 1 and
//! prints the message of the sibling `.expected` file (`{source}` = the path given),
//! never a panic (exit 101) and never a number. Files listed in `known_bugs.txt` there
//! are skipped (their message is known to be wrong; see docs/RELIABILITY.md).

use std::path::{Path, PathBuf};
use std::process::Command;

#[test]
fn every_bad_motor_file_exits_1_with_its_message() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/bad/motor");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/data/bad/motor")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    // files whose message is known to be wrong (tests/reliability_known_bugs.rs at the root)
    let known: Vec<String> = std::fs::read_to_string(dir.join("known_bugs.txt"))
        .unwrap_or_default()
        .lines()
        .map(|l| l.split('#').next().unwrap_or("").trim().to_string())
        .filter(|l| !l.is_empty())
        .collect();
    assert!(files.len() >= 20, "only {} files in {}", files.len(), dir.display());
    let mut problems = Vec::new();
    for path in files.iter().filter(|p| !known.iter().any(|k| p.ends_with(k))) {
        let source = path.to_string_lossy().into_owned();
        let expected = std::fs::read_to_string(path.with_extension("expected")).expect("sibling .expected file");
        let expected = expected.trim_end_matches('\n').replace("{source}", &source);
        let o = Command::new(env!("CARGO_BIN_EXE_trum"))
            .args(["point", "--motor", &source, "--preload-n", "100"])
            .output()
            .expect("run trum");
        let err = String::from_utf8_lossy(&o.stderr);
        if o.status.code() != Some(1) || !err.contains(&expected) {
            problems.push(format!(
                "{}: exit {:?}\n   stderr   {}\n   expected {expected}",
                path.display(),
                o.status.code(),
                err.trim_end()
            ));
        }
        if !o.stdout.is_empty() {
            problems.push(format!("{}: printed to stdout: {}", path.display(), String::from_utf8_lossy(&o.stdout)));
        }
    }
    assert!(problems.is_empty(), "{} of {} files:\n{}", problems.len(), files.len(), problems.join("\n"));
}
