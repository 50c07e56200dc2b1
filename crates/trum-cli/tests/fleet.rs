//! A fleet through the binary: `trum diagnose` and `trum calibrate` over many measurement
//! files (`--data 'runs/*.csv' --summary fleet.csv`). Each row agrees with the
//! single-file command on the same file, the table does not depend on the thread count,
//! a file that fails is a row with its error and exit status 3, and the summary is
//! written atomically (nothing is left behind, an input is never overwritten).

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output};

fn trum(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trum")).current_dir(dir).args(args).output().expect("run trum")
}

/// `json` and `cell` are the same double: the CLI writes both with shortest round-trip
/// digits, but serde_json's default parser may land one unit in the last place off.
fn same(json: &serde_json::Value, cell: &str) -> bool {
    match (json.as_f64(), cell.parse::<f64>()) {
        (Some(a), Ok(b)) => (a - b).abs() <= 4.0 * f64::EPSILON * a.abs().max(b.abs()),
        _ => false,
    }
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The summary as one map per row, column name to cell.
fn table(text: &str) -> Vec<BTreeMap<String, String>> {
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let header: Vec<String> = r.headers().expect("header").iter().map(String::from).collect();
    r.records().map(|rec| header.iter().cloned().zip(rec.expect("record").iter().map(String::from)).collect()).collect()
}

/// Three small campaigns of one design (eight rows each, the nominal bench noise), one
/// with a strong voltage sag, and a file without most required columns.
fn fleet_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::create_dir(d.join("runs")).expect("mkdir");
    for (name, seed, extra) in [("m01", "1", None), ("m02", "2", None), ("m03", "3", Some("voltage_sag=150"))] {
        let out = format!("runs/{name}.csv");
        let campaign = if extra.is_some() { "preload-torque" } else { "stability" };
        let mut args = vec!["synth", "--motor", "generic60", "--campaign", campaign, "--noise", "1", "--seed", seed];
        if let Some(e) = extra {
            args.extend(["--effect", e]);
        }
        args.extend(["-o", &out]);
        let o = trum(d, &args);
        assert_eq!(o.status.code(), Some(0), "synth {name}: {}", stderr(&o));
    }
    std::fs::write(d.join("runs/m04.csv"), "preload_n,voltage_v\n250,200\n").expect("write");
    dir
}

#[test]
fn a_diagnosis_fleet_agrees_with_single_runs_and_reports_the_bad_file() {
    let dir = fleet_dir();
    let d = dir.path();
    let o = trum(d, &["diagnose", "--motor", "generic60", "--data", "runs/*.csv", "--summary", "fleet.csv", "-q"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("4 files: 3 done, 1 failed; summary written to fleet.csv"));
    assert!(stderr(&o).contains("error: runs/m04.csv: line 1: missing required columns"), "{}", stderr(&o));
    let text = std::fs::read_to_string(d.join("fleet.csv")).expect("summary");
    let rows = table(&text);
    let files: Vec<&str> = rows.iter().map(|r| r["file"].as_str()).collect();
    assert_eq!(files, ["runs/m01.csv", "runs/m02.csv", "runs/m03.csv", "runs/m04.csv"]);
    assert_eq!(rows[2]["motor_id"], "m03");
    // the bad file: its error, no figures
    assert_eq!(rows[3]["status"], "error");
    assert!(rows[3]["error"].contains("missing required columns 'frequency_hz'"), "{}", rows[3]["error"]);
    assert_eq!(rows[3]["verdict"], "");
    // the strong voltage sag is found, and closes part of the held-out gap
    assert_eq!(rows[2]["verdict"], "voltage_sag", "{text}");
    let shrink: f64 = rows[2]["shrink"].parse().expect("shrink");
    let (lo, hi): (f64, f64) =
        (rows[2]["shrink_low"].parse().expect("low"), rows[2]["shrink_high"].parse().expect("high"));
    assert!(0.0 < shrink && shrink < 1.0 && lo <= shrink && shrink <= hi, "shrink {shrink} in [{lo}, {hi}]");
    for r in &rows[..3] {
        assert_eq!(r["status"], "ok");
        assert_eq!(r["error"], "");
        // every calibrated baseline parameter is a column, near the design's value
        // (the synthetic motors are drawn within a few per cent of it)
        let mass: f64 = r["stator.modal_mass_kg"].parse().expect("modal mass");
        assert!((mass / 0.01 - 1.0).abs() < 0.2, "{}: modal mass {mass}", r["file"]);
        let nrmse: f64 = r["baseline_heldout_nrmse"].parse().expect("nrmse");
        assert!(nrmse.is_finite() && nrmse > 0.0);
    }
    // a row is what the single-file command finds in the same file
    for (i, f) in ["runs/m01.csv", "runs/m03.csv"].iter().enumerate() {
        let o = trum(d, &["diagnose", "--motor", "generic60", "--data", f, "--json", "-", "-q"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
        let row = &rows[2 * i];
        assert_eq!(doc["verdict"].as_str(), Some(row["verdict"].as_str()), "{f}");
        assert_eq!(doc["complete"].to_string(), row["complete"], "{f}");
        assert_eq!(doc["n_rows"].to_string(), row["rows"], "{f}");
        assert!(same(&doc["gap"]["baseline_heldout_nrmse"], &row["baseline_heldout_nrmse"]), "{f}");
        for p in doc["baseline_params"].as_array().expect("params") {
            let name = p["name"].as_str().expect("name");
            assert!(same(&p["value"], &row[name]), "{f}: {name}: {} vs {}", p["value"], row[name]);
        }
    }
    // one worker thread gives the same table, byte for byte
    let o = trum(d, &["diagnose", "--motor", "generic60", "--data", "runs/*.csv", "--summary", "-", "--threads", "1"]);
    assert_eq!(o.status.code(), Some(3));
    assert_eq!(String::from_utf8_lossy(&o.stdout), text);
}

#[test]
fn a_calibration_fleet_agrees_with_single_runs_and_exits_0_when_all_succeed() {
    let dir = fleet_dir();
    let d = dir.path();
    std::fs::remove_file(d.join("runs/m04.csv")).expect("rm");
    // files listed one by one (as an unquoted shell pattern arrives) work as a pattern does
    let o = trum(
        d,
        &["calibrate", "--motor", "generic60", "--data", "runs/m01.csv", "runs/m02.csv", "--summary", "cal.csv"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rows = table(&std::fs::read_to_string(d.join("cal.csv")).expect("summary"));
    assert_eq!(rows.len(), 2);
    for r in &rows {
        let o = trum(d, &["calibrate", "--motor", "generic60", "--data", &r["file"], "--json", "-"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
        assert!(same(&doc["chi2_per_reading"], &r["chi2_per_reading"]));
        for p in doc["params"].as_array().expect("params") {
            let name = p["name"].as_str().expect("name");
            assert!(same(&p["value"], &r[name]), "{name}: {} vs {}", p["value"], r[name]);
            assert!(same(&p["std_error"], &r[&format!("std_error.{name}")]), "{name}");
        }
    }
    // the summary went through a temporary file: nothing else is left in the directory
    let names: Vec<String> = std::fs::read_dir(d)
        .expect("ls")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

#[test]
fn fleet_usage_errors_are_refused_before_any_work() {
    let dir = fleet_dir();
    let d = dir.path();
    let cases: [(&[&str], &str); 5] = [
        (
            &["diagnose", "--motor", "generic60", "--data", "runs/*.csv"],
            "--data names 4 measurement files: give --summary",
        ),
        (
            &["calibrate", "--motor", "generic60", "--data", "runs/*.tsv", "--summary", "s.csv"],
            "--data 'runs/*.tsv': no file matches this pattern",
        ),
        (
            &["diagnose", "--motor", "generic60", "--data", "runs/*.csv", "--summary", "s.csv", "--json", "d.json"],
            "--json and --report describe one measurement file",
        ),
        (
            &["calibrate", "--motor", "generic60", "--data", "runs/*.csv", "--summary", "runs/m01.csv"],
            "output 'runs/m01.csv' is the input file --data 'runs/m01.csv'",
        ),
        (
            &["calibrate", "--motor", "generic61", "--data", "runs/*.csv", "--summary", "s.csv"],
            "unknown preset 'generic61'",
        ),
    ];
    let before = std::fs::read(d.join("runs/m01.csv")).expect("read");
    for (args, words) in cases {
        let o = trum(d, args);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(words), "{args:?}: {}", stderr(&o));
        assert!(!d.join("s.csv").exists());
    }
    assert_eq!(std::fs::read(d.join("runs/m01.csv")).expect("read"), before, "an input was overwritten");
}
