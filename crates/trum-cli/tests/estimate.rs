//! End-to-end tests of `trum estimate`: the estimate of exact bench data is the bench's own
//! state, its columns, and the errors for data it cannot estimate from.

use std::process::{Command, Output};

fn trum(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trum")).args(args).output().expect("run trum")
}

fn ok(args: &[&str]) -> (String, String) {
    let o = trum(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(0), "{args:?}: {err}");
    (String::from_utf8_lossy(&o.stdout).into_owned(), err)
}

fn fails(args: &[&str]) -> String {
    let o = trum(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
fn estimate_of_exact_bench_data_is_the_benchs_state() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bench = dir.path().join("bench.csv");
    let b = bench.to_str().unwrap_or_default();
    // the bench is the nominal motor read without noise: the measured feedback voltage is
    // the model's own, so the estimate must give the measured efficiency back
    ok(&[
        "synth",
        "--motor",
        "generic60",
        "--campaign",
        "preload-torque",
        "--noise",
        "0",
        "--perturbation",
        "0",
        "--seed",
        "1",
        "-o",
        b,
    ]);
    let (csv, summary) = ok(&["estimate", "--motor", "generic60", "--data", b]);
    let mut r = csv::Reader::from_reader(csv.as_bytes());
    let h: Vec<String> = r.headers().expect("header").iter().map(String::from).collect();
    for c in [
        "line",
        "preload_n",
        "feedback_v",
        "status",
        "warnings",
        "amplitude_m",
        "contact_length_m",
        "driving_length_m",
        "friction_loss_w",
        "output_power_w",
        "efficiency",
        "measured_efficiency",
    ] {
        assert!(h.iter().any(|x| x == c), "no column {c}: {h:?}");
    }
    let col = |name: &str| h.iter().position(|x| x == name).expect("column");
    let rows: Vec<Vec<String>> = r.records().map(|x| x.expect("row").iter().map(String::from).collect()).collect();
    assert_eq!(rows.len(), 56);
    let mut compared = 0;
    for row in &rows {
        assert!(row[col("status")] == "ok" || row[col("status")] == "stall", "{row:?}");
        let (e, m) = (&row[col("efficiency")], &row[col("measured_efficiency")]);
        if m.is_empty() {
            continue;
        }
        let (e, m): (f64, f64) = (e.parse().expect("number"), m.parse().expect("number"));
        assert!((e - m).abs() < 1e-6, "estimated {e} vs measured {m}");
        compared += 1;
    }
    assert!(compared >= 40, "{compared}");
    assert!(summary.contains("56 rows") && summary.contains("correlation r = 1"), "{summary}");
    // -o writes the file and the summary to stdout
    let out = dir.path().join("est.csv");
    let (stdout, _) = ok(&["estimate", "--motor", "generic60", "--data", b, "-o", out.to_str().unwrap_or_default()]);
    assert!(stdout.contains("56 rows"), "{stdout}");
    assert_eq!(std::fs::read_to_string(&out).expect("written"), csv);
}

#[test]
fn estimate_says_what_it_cannot_estimate_from() {
    let dir = tempfile::tempdir().expect("tempdir");
    let no_fb = dir.path().join("no_fb.csv");
    std::fs::write(&no_fb, "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n250,200,43000,0.1,80\n")
        .expect("write");
    let e = fails(&["estimate", "--motor", "generic60", "--data", no_fb.to_str().unwrap_or_default()]);
    assert!(e.contains("no 'feedback_v' column"), "{e}");
    // an empty feedback cell and a zero feedback voltage: rows with a status, no numbers
    let gaps = dir.path().join("gaps.csv");
    std::fs::write(
        &gaps,
        "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm,feedback_v\n250,200,43000,0.1,80,\n250,200,43000,0.1,0,0\n250,200,43000,0.1,80,60\n",
    )
    .expect("write");
    let (csv, summary) = ok(&["estimate", "--motor", "generic60", "--data", gaps.to_str().unwrap_or_default()]);
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[1].starts_with("2,") && lines[1].contains(",no_feedback,"), "{csv}");
    assert!(lines[2].contains(",no_contact_state,"), "{csv}");
    assert!(lines[3].contains(",ok,"), "{csv}");
    assert!(summary.contains("1 ok, 1 no_contact_state, 1 no_feedback"), "{summary}");
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm,feedback_v\n250,200,43000,0.1,80,-3\n")
        .expect("write");
    let e = fails(&["estimate", "--motor", "generic60", "--data", bad.to_str().unwrap_or_default()]);
    assert!(e.contains("line 2") && e.contains("feedback_v"), "{e}");
}
