//! Absurd data gets no confident answer: values outside a column's plausible range are
//! refused with the line and column; with the range lifted, a diagnosis whose figures
//! overflow says `unexplained` with every required figure a finite number; calibrate
//! refuses data the motor cannot solve at any row.

use std::path::Path;
use std::process::{Command, Output};

fn trum(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trum")).current_dir(dir).args(args).output().expect("run trum")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const ROWS: [&str; 8] = [
    "150,150,42000,0,120",
    "200,150,42000,0,140",
    "250,150,42000,0,142",
    "300,150,42000,0,131",
    "150,150,42000,0.1,90",
    "200,150,42000,0.1,112",
    "250,150,42000,0.1,118",
    "300,150,42000,0.1,110",
];

fn write(dir: &Path, name: &str, extra_col: Option<(&str, &[&str])>, extra_rows: &[&str]) {
    let mut t = String::from("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm");
    if let Some((c, _)) = extra_col {
        t += &format!(",{c}");
    }
    t.push('\n');
    for (i, r) in ROWS.iter().chain(extra_rows).enumerate() {
        t += r;
        if let Some((_, cells)) = extra_col {
            t += &format!(",{}", cells[i]);
        }
        t.push('\n');
    }
    std::fs::write(dir.join(name), t).expect("write data");
}

/// Every figure the diagnosis document requires is a finite JSON number.
fn assert_spec_figures_finite(doc: &serde_json::Value) {
    let finite = |v: &serde_json::Value, what: &str| {
        assert!(v.as_f64().is_some_and(f64::is_finite), "{what} is not a finite number: {v}");
    };
    finite(&doc["gap"]["baseline_heldout_nrmse"], "gap.baseline_heldout_nrmse");
    finite(&doc["gap"]["noise_nrmse"], "gap.noise_nrmse");
    let ranking = doc["ranking"].as_array().expect("ranking");
    assert!(!ranking.is_empty());
    for r in ranking {
        for k in ["evidence", "heldout_nrmse_after", "shrink"] {
            finite(&r[k], &format!("ranking[{}].{k}", r["effect"]));
        }
    }
    for w in doc["gap"]["where"].as_array().expect("where") {
        finite(&w["mean_residual"], "gap.where[].mean_residual");
    }
}

#[test]
fn a_row_at_1e300_rpm_is_refused_and_with_the_range_lifted_gets_no_verdict() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    write(d, "bad.csv", None, &["250,150,42000,0,1e300"]);
    let o = trum(d, &["diagnose", "--motor", "trum60a", "--data", "bad.csv"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("bad.csv: line 10, column 'speed_rpm'") && e.contains("plausible range"), "{e}");

    let o = trum(
        d,
        &["diagnose", "--motor", "trum60a", "--data", "bad.csv", "--plausible", "speed_rpm=any", "--json", "-"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    assert_eq!(doc["verdict"], "unexplained", "{}", doc["verdict"]);
    assert_eq!(doc["complete"], false);
    assert!(doc["notes"]
        .as_array()
        .expect("notes")
        .iter()
        .any(|n| n.as_str().is_some_and(|n| n.contains("not finite"))));
    assert_spec_figures_finite(&doc);
}

#[test]
fn a_temperature_of_1e300_leaves_every_figure_finite() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let cells = ["25", "1e300", "25", "25", "25", "25", "25", "25"];
    write(d, "t.csv", Some(("temperature_c", &cells)), &[]);
    let o = trum(d, &["diagnose", "--motor", "trum60a", "--data", "t.csv"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("line 3, column 'temperature_c'"), "{}", stderr(&o));
    let o = trum(
        d,
        &["diagnose", "--motor", "trum60a", "--data", "t.csv", "--plausible", "temperature_c=:", "--json", "-"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    assert_spec_figures_finite(&doc);
}

#[test]
fn calibrate_refuses_a_preload_of_1e308_n() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let rows: Vec<String> =
        ROWS.iter().map(|r| format!("1e308{}", &r[r.find(',').expect("comma")..])).collect::<Vec<_>>();
    let text = format!("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n{}\n", rows.join("\n"));
    std::fs::write(d.join("p.csv"), text).expect("write");
    let o = trum(d, &["calibrate", "--motor", "trum60a", "--data", "p.csv", "-o", "cal.toml"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("line 2, column 'preload_n'"), "{}", stderr(&o));
    let o = trum(
        d,
        &["calibrate", "--motor", "trum60a", "--data", "p.csv", "--plausible", "preload_n=any", "-o", "cal.toml"],
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no solution at any of the 8 measured operating points"), "{}", stderr(&o));
    assert!(!d.join("cal.toml").exists(), "a calibrated motor was written");
    // a bad --plausible names itself
    let o = trum(d, &["calibrate", "--motor", "trum60a", "--data", "p.csv", "--plausible", "preload=0:1"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--plausible 'preload=0:1': 'preload' is not a numeric measurement column"));
}

#[test]
fn control_characters_in_a_motor_name_are_refused_naming_the_key() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    for (escaped, code) in
        [("a\\u0000b", "U+0000"), ("a\\rb", "U+000D"), ("\\u001B[31mred", "U+001B"), ("x\\u007F", "U+007F")]
    {
        std::fs::write(d.join("m.toml"), format!("preset = \"trum60a\"\nname = \"{escaped}\"\n")).expect("write");
        let o = trum(d, &["point", "--motor", "m.toml", "--preload-n", "250"]);
        assert_eq!(o.status.code(), Some(1), "{escaped}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("line 2") && e.contains("key 'name'") && e.contains(code), "{escaped}: {e}");
        assert!(!o.stdout.contains(&0x1b) && !e.as_bytes().contains(&0x1b), "a raw ESC reached the terminal");
    }
}

#[test]
fn a_calibrated_motor_file_reads_back_whatever_the_names_in_it() {
    // A printable name with TOML's special characters, and a data file whose name holds an
    // ESC and a carriage return (written into the file's header comment).
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("m.toml"), "preset = \"trum60a\"\nname = \"Motör \\\"q\\\" \\\\ # [x]\"\n").expect("write");
    write(d, "d\u{1b}[2J\r.csv", None, &[]);
    let o = trum(d, &["calibrate", "--motor", "m.toml", "--data", "d\u{1b}[2J\r.csv", "-o", "cal.toml"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(d.join("cal.toml")).expect("read");
    assert!(!text.chars().any(|c| c.is_control() && c != '\n'), "a raw control character in the file");
    let o = trum(d, &["point", "--motor", "cal.toml", "--preload-n", "250"]);
    assert_eq!(o.status.code(), Some(0), "the calibrated file does not read back: {}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("Motör \"q\" \\ # [x]"));
}

/// A motor file's `[plausible]` table replaces the default ranges for calibrate, diagnose
/// and estimate; `--plausible` wins over it; a bad entry names the file, line and key.
#[test]
fn the_motor_files_plausible_table_sets_ranges_and_the_flag_wins() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    write(d, "fast.csv", None, &["250,150,42000,0,15000"]);
    std::fs::write(d.join("m.toml"), "preset = \"trum60a\"\n\n[plausible]\nspeed_rpm = [0, 20000]\n").expect("write");
    let o = trum(d, &["calibrate", "--motor", "trum60a", "--data", "fast.csv", "--json", "-"]);
    assert_eq!(o.status.code(), Some(1), "the default range let 15000 rev/min through");
    assert!(stderr(&o).contains("line 10, column 'speed_rpm'"), "{}", stderr(&o));
    let o = trum(d, &["calibrate", "--motor", "m.toml", "--data", "fast.csv", "--json", "-"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    assert_eq!(doc["n_rows"], 9);
    // the command line wins over the file
    let o = trum(d, &["calibrate", "--motor", "m.toml", "--data", "fast.csv", "--plausible", "speed_rpm=0:1e4"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("0 to 10000 rpm"), "{}", stderr(&o));
    // a misspelt column and an empty range name the key and its line
    for (entry, words) in [
        ("speedrpm = [0, 2e4]", "key 'plausible.speedrpm': unknown key `speedrpm`"),
        ("speed_rpm = [2e4, 0]", "key 'plausible.speed_rpm': the low end 20000 is above the high end 0"),
    ] {
        std::fs::write(d.join("bad.toml"), format!("preset = \"trum60a\"\n\n[plausible]\n{entry}\n")).expect("write");
        for cmd in ["calibrate", "diagnose"] {
            let o = trum(d, &[cmd, "--motor", "bad.toml", "--data", "fast.csv"]);
            assert_eq!(o.status.code(), Some(1), "{cmd} {entry}");
            let e = stderr(&o);
            assert!(e.contains("bad.toml: line 4,") && e.contains(words), "{cmd} {entry}: {e}");
        }
    }
}
