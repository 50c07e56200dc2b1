//! End-to-end tests of `trum synth`, `trum calibrate` and `trum diagnose`.

use std::path::Path;
use std::process::{Command, Output};

fn trum(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trum")).args(args).output().expect("run trum")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn ok(args: &[&str]) -> String {
    let o = trum(args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", text(&o.stderr));
    text(&o.stdout)
}

/// Runs and expects failure with `code`; returns stderr.
fn fails(args: &[&str], code: i32) -> String {
    let o = trum(args);
    assert_eq!(o.status.code(), Some(code), "{args:?}: stdout {} stderr {}", text(&o.stdout), text(&o.stderr));
    let e = text(&o.stderr);
    assert!(!e.contains("panicked"), "{e}");
    e
}

fn path(dir: &Path, name: &str) -> String {
    dir.join(name).to_string_lossy().into_owned()
}

/// The motor these tests synthesise and diagnose: a frozen copy of the TRUM60A values
/// without effects, so that the null campaigns stay null whatever the built-in preset
/// carries.
const MOTOR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/motors/ring60.toml");

fn synth(dir: &Path, name: &str, extra: &[&str]) -> String {
    let p = path(dir, name);
    let mut args = vec!["synth", "--motor", MOTOR, "-o", &p];
    args.extend_from_slice(extra);
    ok(&args);
    p
}

/// `trum synth` drives its fixed-drive runs at the motor's `[drive]` unless told, as every
/// other command does (trum60-qut: 150 V, 42 kHz); `--voltage-v` and `--frequency-hz`
/// override it; a motor without a `[drive]` (the frozen reference motor of the blind
/// benchmark) runs at the core's `SynthConfig` default, 200 V and 43 kHz, and the file is
/// byte for byte the core's own synthesis of it.
#[test]
fn synth_drives_at_the_motors_drive_unless_told() {
    let base = ["--campaign", "stability", "--noise", "0", "--seed", "1", "-o", "-"];
    // every row's (voltage_v, frequency_hz)
    let drives = |csv: &str| -> Vec<(f64, f64)> {
        let mut lines = csv.lines();
        let h: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
        let (iv, ifr) = (
            h.iter().position(|c| *c == "voltage_v").expect("voltage_v column"),
            h.iter().position(|c| *c == "frequency_hz").expect("frequency_hz column"),
        );
        let num = |s: &str| s.parse::<f64>().unwrap_or_else(|_| panic!("'{s}' is not a number"));
        lines
            .map(|l| {
                let c: Vec<&str> = l.split(',').collect();
                (num(c[iv]), num(c[ifr]))
            })
            .collect()
    };
    let close = |got: &[(f64, f64)], want: (f64, f64)| {
        assert_eq!(got.len(), 8, "{got:?}");
        for &(v, f) in got {
            assert!((v - want.0).abs() < 1e-9 * want.0 && (f - want.1).abs() < 1e-9 * want.1, "{got:?} vs {want:?}");
        }
    };
    close(&drives(&ok(&[&["synth", "--motor", "trum60-qut"][..], &base[..]].concat())), (150.0, 42_000.0));
    let told = ["--voltage-v", "180", "--frequency-hz", "43500"];
    close(&drives(&ok(&[&["synth", "--motor", "trum60-qut"][..], &told[..], &base[..]].concat())), (180.0, 43_500.0));
    let only_v = ["--voltage-v", "120"];
    close(&drives(&ok(&[&["synth", "--motor", "trum60-qut"][..], &only_v[..], &base[..]].concat())), (120.0, 42_000.0));
    let file = ok(&[&["synth", "--motor", MOTOR][..], &base[..]].concat());
    close(&drives(&file), (200.0, 43_000.0));
    let motor = trum_core::Motor::from_toml_str(&std::fs::read_to_string(MOTOR).expect("motor file"), MOTOR)
        .expect("reference motor");
    let cfg = trum_core::synth::SynthConfig {
        campaign: trum_core::synth::Campaign::Stability,
        noise: 0.0,
        seed: 1,
        nominal_effects: motor.effects.clone(),
        ..trum_core::synth::SynthConfig::default()
    };
    let rows = trum_core::synth::synthesize(&motor, &cfg).expect("synth");
    let core = trum_core::bench::to_measurements(&rows).expect("measurements").to_csv_string();
    assert_eq!(file, core, "the CLI's file of a motor without [drive] is the core's default synthesis");
    let e = fails(&[&["synth", "--motor", "trum60-qut", "--voltage-v", "-5"][..], &base[..]].concat(), 1);
    assert!(e.contains("--voltage-v -5 must be a finite number > 0"), "{e}");
}

#[test]
fn synth_writes_a_valid_reproducible_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let base = ["--campaign", "stability", "--noise", "1", "--seed", "1"];
    let a = synth(d, "a.csv", &base);
    let b = synth(d, "b.csv", &base);
    let c = synth(d, "c.csv", &["--campaign", "stability", "--noise", "1", "--seed", "2"]);
    let (a, b, c) = (std::fs::read(a).expect("a"), std::fs::read(b).expect("b"), std::fs::read(c).expect("c"));
    assert_eq!(a, b, "same seed, same bytes");
    assert_ne!(a, c, "different seed, different data");
    let m = trum_core::measurements::parse_measurements(&a, "a.csv").expect("the reader accepts synth output");
    assert_eq!(m.len(), 8);
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    assert!(m.has(trum_core::measurements::Column::SpeedStdRpm));
    // stdout gives the same bytes
    let o = trum(&["synth", "--motor", MOTOR, "-o", "-", base[0], base[1], base[2], base[3], base[4], base[5]]);
    assert_eq!(o.stdout, a);
    // --omit drops columns; effects change the data; truth and candidate forms differ
    let om = synth(d, "om.csv", &[&base[..], &["--omit", "feedback_v,current_a"]].concat());
    let header = std::fs::read_to_string(om).expect("om").lines().next().unwrap_or_default().to_string();
    assert!(!header.contains("feedback_v") && !header.contains("current_a") && header.contains("input_power_w"));
    let eff = ["--campaign", "preload-torque", "--noise", "0", "--seed", "1", "--effect", "radial_friction=0.5"];
    let truth = std::fs::read(synth(d, "t.csv", &eff)).expect("t");
    let cand = std::fs::read(synth(d, "cf.csv", &[&eff[..], &["--candidate-forms"]].concat())).expect("cf");
    let none = std::fs::read(synth(d, "n.csv", &eff[..6])).expect("n");
    assert_ne!(truth, none);
    assert_ne!(truth, cand);
}

/// `--motor-seed` draws the true motor apart from the noise: at noise 0 the file depends on
/// the motor only, so two noise seeds of one motor seed give the same bytes, and the motor
/// seed defaults to `--seed`.
#[test]
fn synth_motor_seed_fixes_the_motor_apart_from_the_noise() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let exact = ["--campaign", "preload-torque", "--noise", "0"];
    let read = |name: &str, extra: &[&str]| std::fs::read(synth(d, name, &[&exact[..], extra].concat())).expect(name);
    let a = read("a.csv", &["--seed", "1", "--motor-seed", "5"]);
    let b = read("b.csv", &["--seed", "2", "--motor-seed", "5"]);
    let c = read("c.csv", &["--seed", "5"]);
    let other = read("o.csv", &["--seed", "1"]);
    assert_eq!(a, b, "one motor, any noise seed: the same exact readings");
    assert_eq!(a, c, "the motor seed defaults to --seed");
    assert_ne!(a, other, "another motor seed, another motor");
    // with noise the noise seed still decides the readings
    let noisy = |name: &str, seed: &str| {
        std::fs::read(synth(
            d,
            name,
            &["--campaign", "preload-torque", "--noise", "1", "--seed", seed, "--motor-seed", "5"],
        ))
        .expect(name)
    };
    assert_ne!(noisy("n1.csv", "1"), noisy("n2.csv", "2"));
}

#[test]
fn synth_errors_list_the_valid_names() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = path(dir.path(), "x.csv");
    let e = fails(&["synth", "--motor", MOTOR, "--campaign", "sweep", "--noise", "1", "--seed", "1", "-o", &o], 2);
    for n in trum_core::synth::Campaign::NAMES {
        assert!(e.contains(n), "{e}");
    }
    let e = fails(
        &[
            "synth",
            "--motor",
            MOTOR,
            "--effect",
            "radial=1",
            "--campaign",
            "stability",
            "--noise",
            "1",
            "--seed",
            "1",
            "-o",
            &o,
        ],
        1,
    );
    assert!(e.contains("unknown effect 'radial'"), "{e}");
    for n in trum_core::effects::EFFECTS.iter().map(|e| e.name) {
        assert!(e.contains(n), "{e}");
    }
    let e = fails(
        &[
            "synth",
            "--motor",
            MOTOR,
            "--campaign",
            "stability",
            "--noise",
            "1",
            "--seed",
            "1",
            "--omit",
            "speed",
            "-o",
            &o,
        ],
        1,
    );
    assert!(e.contains("'speed'") && e.contains("input_power_w") && e.contains("speed_std_rpm"), "{e}");
    let e = fails(&["synth", "--motor", MOTOR, "--campaign", "stability", "--noise", "-1", "--seed", "1", "-o", &o], 1);
    assert!(e.contains("noise level -1"), "{e}");
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0, "a failed synth leaves no file");
}

#[test]
fn calibrate_writes_a_motor_file_that_point_reads() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let data = synth(d, "pt.csv", &["--campaign", "preload-torque", "--noise", "1", "--seed", "4"]);
    let (toml, json) = (path(d, "cal.toml"), path(d, "cal.json"));
    let out = ok(&["calibrate", "--motor", MOTOR, "--data", &data, "-o", &toml, "--json", &json]);
    assert!(out.contains("friction_layer.friction_coefficient") && out.contains("std error"), "{out}");
    assert!(out.contains("chi2"), "{out}");
    let p = ok(&["point", "--motor", &toml, "--preload-n", "250", "--torque-nm", "0.3", "--json"]);
    let p: serde_json::Value = serde_json::from_str(&p).expect("point JSON");
    assert_eq!(p["status"], "ok");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("JSON");
    let params = j["params"].as_array().expect("params");
    assert!(params.len() >= 5);
    for q in params {
        let (v, se) = (q["value"].as_f64().expect("value"), q["std_error"].as_f64().expect("std error"));
        if q["name"].as_str().is_some_and(|n| n.starts_with("bench.")) {
            // a bench nuisance centred on zero (an offset, a gain error): its uncertainty
            // is no fraction of its value, only positive
            assert!(se > 0.0 && se.is_finite(), "{q}");
            continue;
        }
        // a plausible uncertainty: positive, and well below the value for this rich campaign
        assert!(se > 1e-9 * v.abs() && se < 0.5 * v.abs(), "{q}");
    }
    assert!(j["chi2_per_reading"].as_f64().expect("chi2") > 0.0);
}

/// Sun et al. 2021 Table 2 (docs/DIAGNOSIS.md): `unexplained`. The JSON's `partial` is null
/// or a supported ranked effect, and the summary's and the report's verdict lines name it
/// with its shrink (a supported effect here is supported by a hair, so either is accepted).
#[test]
fn an_unexplained_verdict_names_what_explains_part_of_the_gap() {
    let dir = tempfile::tempdir().expect("tempdir");
    let json = path(dir.path(), "t2.json");
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/good/measurements/sun2021_table2.csv");
    let html = path(dir.path(), "t2.html");
    let out = ok(&["diagnose", "--motor", "trum60-qut", "--data", data]);
    ok(&["diagnose", "--motor", "trum60-qut", "--data", data, "--json", &json, "--report", &html]);
    let report = std::fs::read_to_string(&html).expect("report");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("JSON");
    assert_eq!(j["verdict"], "unexplained");
    let line = out.lines().find(|l| l.starts_with("verdict")).expect("verdict line");
    match j["partial"].as_str() {
        Some(p) => {
            let entry = j["ranking"].as_array().expect("ranking").iter().find(|r| r["effect"] == p).expect("ranked");
            assert!(entry["evidence"].as_f64().expect("evidence") > 5.0, "{entry}");
            assert!(entry["shrink_interval"][0].as_f64().expect("interval") > 0.0, "{entry}");
            assert!(line.contains(&format!("{p} explains part of it")), "{line}");
            assert!(report.contains(&format!("{p} explains part of it")), "the report's verdict");
        }
        None => {
            assert!(j["partial"].is_null(), "{}", j["partial"]);
            assert!(!line.contains("explains part") && !report.contains("explains part"), "{line}");
        }
    }
    // the paper's no-load points at 150 V are inside the preset's limits; under a 100 V cap
    // the report lists all four rows beyond it
    assert!(report.contains("No bench point is beyond the motor's <code>[limits]</code>"), "limits section");
    let capped = path(dir.path(), "capped.toml");
    std::fs::write(&capped, "preset = \"trum60-qut\"\n[limits]\nmax_voltage_v = 100\n").expect("write");
    ok(&["diagnose", "--motor", &capped, "--data", data, "--report", &html]);
    let report = std::fs::read_to_string(&html).expect("report");
    assert!(
        report.contains("<tr><td><code>max_voltage_v</code></td><td class=\"n\">100</td><td class=\"n\">4</td>"),
        "limits table"
    );
}

/// One diagnosis of a no-effect campaign: JSON fields and values, the report, the summary.
/// A null campaign whose every row the logger wrote twice: the repeats are counted once,
/// with a warning naming them, and the diagnosis is the file's once (it was `unexplained`
/// while the repeats' zero differences halved the noise levels estimated from the data).
#[test]
fn rows_logged_twice_are_one_reading_each() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let data = synth(d, "pt.csv", &["--campaign", "preload-torque", "--noise", "1", "--seed", "9111"]);
    let once_text = std::fs::read_to_string(&data).expect("data");
    let mut lines = once_text.lines();
    let header = lines.next().expect("header");
    let twice_text: String =
        std::iter::once(header).chain(lines.flat_map(|l| [l, l])).map(|l| format!("{l}\n")).collect();
    let twice = path(d, "twice.csv");
    std::fs::write(&twice, twice_text).expect("write");
    let (j1, j2) = (path(d, "once.json"), path(d, "twice.json"));
    ok(&["diagnose", "--motor", MOTOR, "--data", &data, "--json", &j1, "-q"]);
    let o = trum(&["diagnose", "--motor", MOTOR, "--data", &twice, "--json", &j2, "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("rows repeat an earlier row in every column (line 3 repeats line 2"), "{err}");
    let read = |p: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).expect("json")).expect("JSON")
    };
    let (a, b) = (read(&j1), read(&j2));
    assert_eq!(b["verdict"], "none", "{}", b["verdict"]);
    for k in ["verdict", "complete", "ranking", "gap", "n_rows"] {
        assert_eq!(a[k], b[k], "{k}");
    }
}

#[test]
fn diagnose_without_effect_says_none() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let data = synth(d, "st.csv", &["--campaign", "stability", "--noise", "1", "--seed", "3"]);
    let (json, html) = (path(d, "d.json"), path(d, "d.html"));
    let out = ok(&["diagnose", "--motor", MOTOR, "--data", &data, "--json", &json, "--report", &html]);
    assert!(out.contains("verdict     none"), "{out}");
    assert!(out.contains("ranking (evidence = ½·ΔBIC"), "{out}");
    let raw = std::fs::read_to_string(&json).expect("json");
    assert!(!raw.contains("NaN") && !raw.contains("Infinity"), "JSON has no NaN");
    let j: serde_json::Value = serde_json::from_str(&raw).expect("JSON");
    assert_eq!(j["verdict"], "none");
    assert!(j["confounded_with"].as_array().expect("confounded_with").is_empty());
    // present and null: only an `unexplained` verdict names a partial explanation
    assert!(j.get("partial").is_some_and(|p| p.is_null()), "{}", j["partial"]);
    let before = j["gap"]["baseline_heldout_nrmse"].as_f64().expect("before");
    assert!(before >= 0.0 && j["gap"]["noise_nrmse"].as_f64().expect("noise") >= 0.0);
    for w in j["gap"]["where"].as_array().expect("where") {
        assert!(w["quantity"].is_string() && w["region"].is_string() && w["mean_residual"].is_number(), "{w}");
    }
    let ranking = j["ranking"].as_array().expect("ranking");
    let names: Vec<&str> = ranking.iter().filter_map(|r| r["effect"].as_str()).collect();
    for e in trum_core::effects::EFFECTS.iter().map(|e| e.name) {
        assert!(names.contains(&e), "{e} missing from {names:?}");
    }
    let ev: Vec<f64> = ranking.iter().map(|r| r["evidence"].as_f64().unwrap_or(f64::NEG_INFINITY)).collect();
    assert!(ev.windows(2).all(|w| w[0] >= w[1]), "ranking sorted by evidence: {ev:?}");
    for r in ranking {
        let after = r["heldout_nrmse_after"].as_f64().expect("after");
        let shrink = r["shrink"].as_f64().expect("shrink");
        assert!(after >= 0.0);
        assert!((shrink - (1.0 - after / before)).abs() < 1e-9, "{r}");
        assert_eq!(r["shrink_interval"].as_array().map(Vec::len), Some(2));
        // what stays of each shrink without the row that gains most: 0 where the shrink
        // is not positive
        let shares: Vec<f64> =
            r["lone_row_shares"].as_array().expect("shares").iter().filter_map(|x| x.as_f64()).collect();
        assert_eq!(shares.len(), 2, "{r}");
        if shrink <= 0.0 {
            assert_eq!(shares[0], 0.0, "{r}");
        }
        // score test at the calibrated baseline: every single effect that moves a
        // prediction has one (thermal_drift does not without a time series), a cosine and a
        // non-negative χ² drop; a pair has none
        let name = r["effect"].as_str().unwrap_or_default();
        if name.contains('+') || name == "thermal_drift" {
            assert!(r["signature_match"].is_null() && r["linear_chi2_drop"].is_null(), "{r}");
        } else {
            let m = r["signature_match"].as_f64().expect("signature_match");
            assert!((-1.0..=1.0).contains(&m) && r["linear_chi2_drop"].as_f64().expect("drop") >= 0.0, "{r}");
        }
        // a `none` verdict has no signature to compare with
        assert!(r["signature_overlap"].is_null(), "{r}");
    }
    assert!(j["evidence_scale"].as_str().expect("scale").contains("> 3 strong, > 5 very strong"));
    assert_eq!(j["n_rows"], 8);
    assert!(j["folds"].as_u64().expect("folds") >= 2 && j["baseline_params"].is_array() && j["notes"].is_array());
    let page = std::fs::read_to_string(&html).expect("html");
    assert!(page.starts_with("<!DOCTYPE html>") && page.contains("<svg") && page.contains("Verdict"), "html");
    assert!(!page.contains("src=\"http") && !page.contains("href=\"http"), "self-contained");
    // --json - sends only the JSON to stdout
    let o = ok(&["diagnose", "--motor", MOTOR, "--data", &data, "--json", "-"]);
    let again: serde_json::Value = serde_json::from_str(&o).expect("stdout JSON");
    assert_eq!(again["ranking"], j["ranking"], "deterministic");
}

fn write(dir: &Path, name: &str, body: &str) -> String {
    let p = path(dir, name);
    std::fs::write(&p, body).expect("write");
    p
}

#[test]
fn diagnose_errors_are_clear() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let diag = |data: &str| fails(&["diagnose", "--motor", MOTOR, "--data", data], 1);
    let f = write(d, "nospeed.csv", "preload_n,voltage_v,frequency_hz,torque_nm\n250,200,43000,0\n");
    let e = diag(&f);
    assert!(e.contains("nospeed.csv") && e.contains("'speed_rpm'"), "{e}");
    let f = write(d, "header.csv", "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n");
    let e = diag(&f);
    assert!(e.contains("header.csv") && e.contains("no data rows"), "{e}");
    let mut one = String::from("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n");
    for k in 0..6 {
        one.push_str(&format!("250,200,43000,{},{}\n", 0.1 * k as f64, 120.0 - 10.0 * k as f64));
    }
    let f = write(d, "one.csv", &one);
    let e = diag(&f);
    assert!(e.contains("one.csv") && e.contains("one operating region"), "{e}");
    let f = write(
        d,
        "few.csv",
        "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n150,200,43000,0,120\n250,200,43000,0,110\n",
    );
    let e = diag(&f);
    assert!(e.contains("too few"), "{e}");
    let f = write(d, "bad.csv", "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n250,200,43000,0,fast\n");
    let e = diag(&f);
    assert!(e.contains("line 2") && e.contains("'speed_rpm'") && e.contains("\"fast\""), "{e}");
    let e = diag(&path(d, "missing.csv"));
    assert!(e.contains("missing.csv") && e.contains("does not exist"), "{e}");
    let e = fails(&["diagnose", "--motor", "trum61", "--data", &f], 1);
    assert!(e.contains("unknown preset 'trum61'"), "{e}");
    // an unwritable output fails at once, before the long run
    let good = synth(d, "st.csv", &["--campaign", "stability", "--noise", "1", "--seed", "1"]);
    let e = fails(&["diagnose", "--motor", MOTOR, "--data", &good, "--json", &path(d, "no/such/dir/x.json")], 1);
    assert!(e.contains("does not exist"), "{e}");
    fails(&["diagnose", "--motor", MOTOR], 2);
    let e = fails(
        &[
            "calibrate",
            "--motor",
            MOTOR,
            "--data",
            &write(d, "h2.csv", "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n"),
        ],
        1,
    );
    assert!(e.contains("no data rows"), "{e}");
}

/// A preset's own effects (`trum60a`: `preload_stiffening`, `radial_friction`) are part of
/// the model a diagnosis against that preset refits: `trum synth` simulates them in their
/// candidate forms, so data with nothing added are diagnosed `none`; an effect added with
/// `--effect` still takes its truth form.
#[test]
fn a_presets_own_effects_are_synthesised_in_candidate_form() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let data = path(d, "own.csv");
    let o = trum(&[
        "synth",
        "--motor",
        "trum60a",
        "--campaign",
        "preload-torque",
        "--noise",
        "1",
        "--seed",
        "3",
        "-o",
        &data,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("(candidate forms: radial_friction, preload_stiffening)"), "{err}");
    let out = ok(&["diagnose", "--motor", "trum60a", "--data", &data]);
    assert!(out.contains("verdict     none"), "{out}");
    let added = path(d, "added.csv");
    let o = trum(&[
        "synth",
        "--motor",
        "trum60a",
        "--campaign",
        "stability",
        "--noise",
        "0",
        "--seed",
        "3",
        "--effect",
        "voltage_sag=100",
        "-o",
        &added,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("(truth forms: voltage_sag; candidate forms: radial_friction, preload_stiffening)"), "{err}");
}

/// `--sensor-noise` states a sensor's noise level: the JSON's notes say so, and a bad
/// statement is refused before the run with the flag, the text and the reason.
#[test]
fn sensor_noise_is_stated_or_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = synth(dir.path(), "st.csv", &["--campaign", "stability", "--noise", "1", "--seed", "3"]);
    let json = ok(&[
        "diagnose",
        "--motor",
        MOTOR,
        "--data",
        &data,
        "--sensor-noise",
        "speed_std_rpm=0.08,0.1",
        "--json",
        "-",
        "-q",
    ]);
    let v: serde_json::Value = serde_json::from_str(&json).expect("JSON");
    let notes: Vec<&str> = v["notes"].as_array().expect("notes").iter().filter_map(|n| n.as_str()).collect();
    assert!(notes.iter().any(|n| n.contains("speed_std_rpm σ = 0.08 + 0.1 × reading")), "{notes:?}");
    let e = fails(&["diagnose", "--motor", MOTOR, "--data", &data, "--sensor-noise", "speed=1", "-q"], 1);
    assert!(e.contains("--sensor-noise 'speed=1': unknown column 'speed'") && e.contains("speed_std_rpm"), "{e}");
    let e = fails(&["diagnose", "--motor", MOTOR, "--data", &data, "--sensor-noise", "speed_rpm=0", "-q"], 1);
    assert!(e.contains("must be a finite number > 0"), "{e}");
}

/// A softening of the stator mode on a preload-torque campaign at one drive frequency: the
/// verdict `hertz_softening` is confounded with `preload_stiffening` (at one frequency both
/// are a detuning that follows the operating point), and the diagnosis says what would
/// part them: a frequency sweep, by orders of magnitude more than another campaign of the
/// kind the data are, which separates the two fits no better than the data do.
#[test]
fn a_confounded_verdict_names_the_campaign_that_separates_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let motor = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/motors/trum60a_baseline.toml");
    let data = path(dir.path(), "soft.csv");
    let json = path(dir.path(), "soft.json");
    let run = ["--campaign", "preload-torque", "--voltage-v", "200", "--frequency-hz", "43000", "--noise", "1"];
    let mut args = vec!["synth", "--motor", motor, "--effect", "hertz_softening=1e18", "--seed", "1", "-o", &data];
    args.extend_from_slice(&run);
    ok(&args);
    let out = ok(&["diagnose", "--motor", motor, "--data", &data, "--json", &json]);
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("JSON");
    assert_eq!(j["verdict"], "hertz_softening", "{out}");
    assert_eq!(j["confounded_with"], serde_json::json!(["preload_stiffening"]), "{out}");
    let s = &j["separating_campaigns"][0];
    assert_eq!(s["effects"], serde_json::json!(["hertz_softening", "preload_stiffening"]), "{s}");
    assert_eq!(s["rival"], "confounded", "{s}");
    assert_eq!(s["best"], "frequency-sweep", "{s}");
    let chi2 = |c: &str| {
        s["campaigns"].as_array().expect("campaigns").iter().find(|x| x["campaign"] == c).expect(c)["chi2"]
            .as_f64()
            .expect("chi2")
    };
    let on_data = s["chi2_on_the_data"].as_f64().expect("chi2 on the data");
    assert!(chi2("frequency-sweep") > 100.0 * chi2("preload-torque"), "{s}");
    assert!(chi2("preload-torque") < 10.0 * on_data.max(1.0), "{s}");
    assert!(out.contains("a frequency-sweep campaign at the data's drive would separate them"), "{out}");
}
