//! The real `trum` binary on the bad measurement-file corpus
//! (`tests/data/bad/measurements/` at the workspace root): `trum calibrate --motor
//! trum60a --data FILE` exits with code 1 and prints the message of the sibling
//! `.expected` file (`{source}` = the path given), writes nothing to stdout and no
//! output file.

use std::path::{Path, PathBuf};
use std::process::Command;

#[test]
fn every_bad_measurement_file_exits_1_with_its_message() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/bad/measurements");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/data/bad/measurements")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    assert!(files.len() >= 20, "only {} files in {}", files.len(), dir.display());
    let out_dir = std::env::temp_dir().join(format!("trum-bad-csv-{}", std::process::id()));
    std::fs::create_dir_all(&out_dir).expect("temp dir");
    let out = out_dir.join("calibrated.toml");
    let mut problems = Vec::new();
    for path in &files {
        let source = path.to_string_lossy().into_owned();
        let expected = std::fs::read_to_string(path.with_extension("expected")).expect("sibling .expected file");
        let expected = expected.trim_end_matches('\n').replace("{source}", &source);
        let o = Command::new(env!("CARGO_BIN_EXE_trum"))
            .args(["calibrate", "--motor", "trum60a", "--data", &source, "-o"])
            .arg(&out)
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
        if out.exists() {
            problems.push(format!("{}: wrote {}", path.display(), out.display()));
            let _ = std::fs::remove_file(&out);
        }
    }
    let _ = std::fs::remove_dir_all(&out_dir);
    assert!(problems.is_empty(), "{} of {} files:\n{}", problems.len(), files.len(), problems.join("\n"));
}
