//! End-to-end tests of `trum resonance`, `trum identify-hertz` and `trum step`: the files
//! they write, agreement with trum-core, snapshots of the printed tables, bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use trum_core::dynamics::hertz::{HertzOscillator, OperatingPoint, RecordOptions, ResponseMethod, SimulationSettings};

mod common;
use common::snapshot;

/// The motor the transient tests were written for: a frozen TRUM60A baseline, independent
/// of the `trum60a` preset's calibration (the preset itself is run in the bad-input test).
const FROZEN_TRUM60A: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/motors/trum60a_baseline.toml");

fn trum(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trum")).args(args).output().expect("run trum")
}

fn ok(args: &[&str]) -> String {
    let o = trum(args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Runs, expects exit status 1 and returns stderr.
fn fails(args: &[&str]) -> String {
    let o = trum(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap_or_default()
}

/// Header and rows of a CSV as strings.
fn csv_rows(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let h = r.headers().expect("header").iter().map(String::from).collect();
    let rows = r.records().map(|x| x.expect("row").iter().map(String::from).collect()).collect();
    (h, rows)
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("'{s}' is not a number"))
}

#[test]
fn resonance_csv_has_every_branch_the_jumps_and_status_rows() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("r.csv");
    let summary = ok(&[
        "resonance",
        "--voltage-v",
        "100:300:3",
        "--preload-n",
        "400",
        "--frequency-hz",
        "40800:41050:251",
        "-o",
        p(&out),
    ]);
    snapshot("resonance_summary.txt", &summary);
    let text = std::fs::read_to_string(&out).expect("csv written");
    assert!(!text.to_lowercase().contains("nan"));
    let (h, rows) = csv_rows(&text);
    assert_eq!(
        h,
        ["voltage_v", "preload_n", "frequency_hz", "branch", "status", "amplitude_m", "phase_lag_rad", "stable"]
    );
    let o = HertzOscillator::default();
    let op = OperatingPoint { voltage_v: 200.0, preload_n: 400.0 };
    let jumps = o.jump_frequencies(&op, ResponseMethod::MultipleScales).expect("valid").expect("bistable at 200 V");
    let at200 = |branch: &str| -> Vec<(f64, f64)> {
        rows.iter().filter(|r| r[0] == "200" && r[3] == branch).map(|r| (num(&r[2]), num(&r[5]))).collect()
    };
    // the saddle nodes are the core's, bit for bit
    assert_eq!(at200("jump_up"), [(jumps.jump_up_hz, jumps.jump_up_amplitude_m)]);
    assert_eq!(at200("jump_down"), [(jumps.jump_down_hz, jumps.jump_down_amplitude_m)]);
    // inside the hysteresis band three roots, ordered, the middle one unstable
    let (lower, middle, upper) = (at200("lower"), at200("middle"), at200("upper"));
    assert!(lower.len() > 50 && lower.len() == middle.len() && middle.len() == upper.len());
    for i in 0..lower.len() {
        let f = lower[i].0;
        assert!(f > jumps.jump_down_hz && f < jumps.jump_up_hz, "{f} outside the band {jumps:?}");
        assert!(lower[i].1 < middle[i].1 && middle[i].1 < upper[i].1);
    }
    for r in rows.iter().filter(|r| r[3] == "middle") {
        assert_eq!(r[7], "false");
    }
    for r in rows.iter().filter(|r| ["lower", "upper"].contains(&r[3].as_str())) {
        assert_eq!(r[7], "true");
    }
    // softening backbone: starts at the linear resonance, frequency falls with amplitude
    let bb = at200("backbone");
    let eff = o.effective(&op).expect("valid");
    assert!((bb[0].0 - eff.linear_resonance_hz()).abs() < 1e-9 && bb[0].1 == 0.0);
    assert!(bb.windows(2).all(|w| w[1].0 < w[0].0 && w[1].1 > w[0].1));
    // hysteresis grows with voltage (the Hertzian driving-circuit paper (2022) Fig. 11a)
    let band = |v: &str| {
        let f = |b: &str| rows.iter().find(|r| r[0] == v && r[3] == b).map(|r| num(&r[2])).expect("jump row");
        f("jump_up") - f("jump_down")
    };
    assert!(band("100") < band("200") && band("200") < band("300"));

    // a preload the softening spring cannot carry: a status row, no numbers, no NaN
    let csv = ok(&["resonance", "--voltage-v", "200", "--preload-n", "1e6", "--frequency-hz", "41000", "-o", "-"]);
    let (_, rows) = csv_rows(&csv);
    assert_eq!(rows, [["200", "1000000", "", "", "no_static_equilibrium", "", "", ""]]);
}

#[test]
fn resonance_plots_and_preload_family() {
    let dir = tempfile::tempdir().expect("tempdir");
    let png = dir.path().join("r.png");
    let svg = dir.path().join("r.svg");
    ok(&["resonance", "--voltage-v", "200", "--preload-n", "200:400:3", "--plot", p(&png)]);
    assert_eq!(&std::fs::read(&png).expect("png")[..8], b"\x89PNG\r\n\x1a\n");
    let csv = ok(&[
        "resonance",
        "--voltage-v",
        "200",
        "--preload-n",
        "200:400:3",
        "--method",
        "harmonic-balance",
        "--plot",
        p(&svg),
        "-o",
        "-",
    ]);
    assert!(std::fs::read_to_string(&svg).expect("svg").starts_with("<svg"));
    // the peak amplitude grows with preload (the Hertzian driving-circuit paper (2022) Fig. 12)
    let (_, rows) = csv_rows(&csv);
    let peak =
        |n: &str| rows.iter().filter(|r| r[1] == n && r[3] != "backbone").map(|r| num(&r[5])).fold(0.0, f64::max);
    assert!(peak("200") < peak("300") && peak("300") < peak("400"));
    // bad plot name fails before anything is computed or written
    let e = fails(&["resonance", "--plot", p(&dir.path().join("r.jpg"))]);
    assert!(e.contains(".png or .svg"), "{e}");
    let e = fails(&["resonance"]);
    assert!(e.contains("-o CSV, --plot FILE and/or --json"), "{e}");
    // --json: the summary per curve, the jumps of the multiple-scales solution
    let j: serde_json::Value = serde_json::from_str(&ok(&["resonance", "--voltage-v", "200", "--json"])).expect("JSON");
    let c = &j["curves"][0];
    assert_eq!(c["status"], "ok");
    let (up, down) = (c["jump_up_hz"].as_f64().unwrap_or(0.0), c["jump_down_hz"].as_f64().unwrap_or(0.0));
    assert!((c["hysteresis_hz"].as_f64().unwrap_or(0.0) - (up - down).abs()).abs() < 1e-9 * up, "{c}");
}

/// A feedback-voltage record of the oscillator at 200 V, 400 N on its upper branch at
/// 40.93 kHz (the core's identification test case), started on the branch and settled.
fn waveform_csv(dir: &Path, displacement: bool) -> (PathBuf, f64) {
    let o = HertzOscillator::default();
    let op = OperatingPoint { voltage_v: 200.0, preload_n: 400.0 };
    let f = 40_930.0;
    let pts = o.frequency_response(&op, &[f], ResponseMethod::MultipleScales).expect("valid");
    let upper = pts.last().expect("a branch");
    let init = o.branch_state(&op, upper).expect("valid");
    let rec = RecordOptions { from_s: 0.6, stride: 2 };
    let ts = o
        .simulate_constant_frequency(&op, f, 0.6 + 40.0 / f, &init, &rec, &SimulationSettings::default())
        .expect("simulates");
    let (name, scale) = if displacement { ("displacement_m", 1.0) } else { ("feedback_voltage_v", 2.0e6) };
    let mut s = format!("# simulated at 200 V, 400 N, {f} Hz\ntime_s,{name}\n");
    for (t, w) in ts.time_s.iter().zip(&ts.displacement_m) {
        s.push_str(&format!("{t},{}\n", scale * w));
    }
    let path = dir.join(format!("{name}.csv"));
    std::fs::write(&path, s).expect("write waveform");
    (path, o.beta_at_n_per_m3(&op).expect("valid"))
}

#[test]
fn identify_hertz_recovers_beta_from_a_simulated_waveform() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (volts, beta) = waveform_csv(dir.path(), false);
    let args =
        ["identify-hertz", "--data", p(&volts), "--frequency-hz", "40930", "--voltage-v", "200", "--preload-n", "400"];
    let json = ok(&[&args[..], &["--feedback-gain-v-per-m", "2e6", "--json"]].concat());
    let v: serde_json::Value = serde_json::from_str(&json).expect("JSON");
    let got = v["beta_n_per_m3"].as_f64().expect("number");
    assert!((got / beta - 1.0).abs() < 0.01, "{got} vs {beta}");
    assert!(v["harmonic_fit_r_squared"].as_f64().expect("number") > 0.999_999);
    assert!(v["waveform_residual_rms_v"].is_number() && v["balance_relative_residual"].is_number());
    // the displacement form of the same record gives the same beta
    let (disp, _) = waveform_csv(dir.path(), true);
    let json = ok(&[
        "identify-hertz",
        "--data",
        p(&disp),
        "--frequency-hz",
        "40930",
        "--voltage-v",
        "200",
        "--preload-n",
        "400",
        "--json",
    ]);
    let v2: serde_json::Value = serde_json::from_str(&json).expect("JSON");
    let got2 = v2["beta_n_per_m3"].as_f64().expect("number");
    assert!((got2 / got - 1.0).abs() < 1e-6, "{got2} vs {got}");
    // the table names every figure with its unit
    let table = ok(&[&args[..], &["--feedback-gain-v-per-m", "2e6"]].concat());
    for want in ["beta_n_per_m3", "N/m³", "harmonic_fit_r_squared", "waveform_residual_rms_v", "balance_residual_rms_m"]
    {
        assert!(table.contains(want), "{table}");
    }
    // beta is sensitive to the assumed k (docs/DYNAMICS.md: ~300x the relative error of k);
    // a 10 Hz error in the linear resonance moves it by several per cent and worsens the fit
    let off =
        ok(&[&args[..], &["--feedback-gain-v-per-m", "2e6", "--linear-resonance-hz", "40990", "--json"]].concat());
    let v3: serde_json::Value = serde_json::from_str(&off).expect("JSON");
    let rel = |v: &serde_json::Value| v["balance_relative_residual"].as_f64().expect("number");
    assert!(rel(&v3) > 1.5 * rel(&v), "{} vs {}", rel(&v3), rel(&v));
    assert!((v3["beta_n_per_m3"].as_f64().expect("number") / got - 1.0).abs() > 0.05);
}

#[test]
fn identify_hertz_bad_input_names_file_line_and_column() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let file = |name: &str, text: &str| {
        let path = d.join(name);
        std::fs::write(&path, text).expect("write");
        path.to_string_lossy().into_owned()
    };
    let run = |f: &str, extra: &[&str]| {
        let base = ["identify-hertz", "--data", f, "--frequency-hz", "41000", "--voltage-v", "200"];
        fails(&[&base[..], extra].concat())
    };
    let f = file("cell.csv", "time_s,displacement_m\n0,1e-6\n1e-6,abc\n");
    let e = run(&f, &[]);
    assert!(e.contains(&format!("{f}, line 3, column 'displacement_m': 'abc' is not a finite number")), "{e}");
    let f = file("time.csv", "time_s,displacement_m\n0,1e-6\n2e-6,1e-6\n1e-6,1e-6\n");
    let e = run(&f, &[]);
    assert!(e.contains("line 4, column 'time_s'") && e.contains("times must increase"), "{e}");
    let f = file("cols.csv", "t,w\n0,1\n");
    let e = run(&f, &[]);
    assert!(e.contains(&f) && e.contains("line 1: no 'time_s' column; the columns are: t, w"), "{e}");
    let f = file("volts.csv", "time_s,feedback_voltage_v\n0,1\n1e-6,2\n");
    let e = run(&f, &[]);
    assert!(e.contains("--feedback-gain-v-per-m is needed"), "{e}");
    let f = file("short.csv", "time_s,displacement_m\n0,1e-6\n1e-6,2e-6\n2e-6,1e-6\n");
    let e = run(&f, &[]);
    assert!(e.contains(&f) && e.contains("input too short"), "{e}");
    let e = run(&d.join("missing.csv").to_string_lossy(), &[]);
    assert!(e.contains("cannot read waveform") && e.contains("missing.csv"), "{e}");
    // oscillator parameters: file, line and key; flags by name
    let osc = file("osc.toml", "modal_mass_kg = 0.05\ndamping_ns_per_mm = 1.0\n");
    let e = fails(&["resonance", "--oscillator", &osc, "-o", "-"]);
    assert!(e.contains(&format!("{osc}, line 2, key 'damping_ns_per_mm': unknown key; valid keys are:")), "{e}");
    let osc = file("neg.toml", "# comment\nmodal_mass_kg = -1\n");
    let e = fails(&["resonance", "--oscillator", &osc, "-o", "-"]);
    assert!(e.contains(&format!("{osc}, line 2, key 'modal_mass_kg': -1 must be finite and > 0")), "{e}");
    let osc = file("syntax.toml", "modal_mass_kg = 0.05\nfoo bar\n");
    let e = fails(&["resonance", "--oscillator", &osc, "-o", "-"]);
    assert!(e.contains(&format!("{osc}, line 2: ")), "{e}");
    let osc = file("str.toml", "beta_n_per_m3 = \"big\"\n");
    let e = fails(&["resonance", "--oscillator", &osc, "-o", "-"]);
    assert!(e.contains("line 1, key 'beta_n_per_m3': expected a number, got string"), "{e}");
    let e = fails(&["resonance", "--damping-ns-per-m", "0", "-o", "-"]);
    assert!(e.contains("--damping-ns-per-m 0: 0 must be finite and > 0"), "{e}");
    let e = fails(&["resonance", "--frequency-hz", "-5", "-o", "-"]);
    assert!(e.contains("--frequency-hz: -5 must be a finite frequency > 0"), "{e}");
    // a partial oscillator file keeps the other defaults and changes the answer
    let osc = file("part.toml", "damping_ns_per_m = 5\n");
    let soft = ok(&["resonance", "--voltage-v", "200", "--frequency-hz", "40900", "-o", "-"]);
    let damped = ok(&["resonance", "--oscillator", &osc, "--voltage-v", "200", "--frequency-hz", "40900", "-o", "-"]);
    let branches = |s: &str| csv_rows(s).1.iter().filter(|r| r[3] != "backbone" && !r[3].starts_with("jump")).count();
    assert_eq!(branches(&soft), 3, "bistable at 40.9 kHz");
    assert_eq!(branches(&damped), 1, "5x damping removes the hysteresis there");
}

const FAST: [&str; 6] = ["--duration-s", "0.004", "--nodes-per-wavelength", "64", "--steps-per-period", "64"];

#[test]
fn step_prints_metrics_against_the_steady_solver_and_writes_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let (series, snaps, plot, splot) = (d.join("s.csv"), d.join("n.csv"), d.join("s.svg"), d.join("n.png"));
    let args = [
        "step",
        "--motor",
        FROZEN_TRUM60A,
        "-o",
        p(&series),
        "--snapshot-at-s",
        "2e-5,0.0035",
        "--snapshots",
        p(&snaps),
        "--plot",
        p(&plot),
        "--snapshot-plot",
        p(&splot),
    ];
    let out = ok(&[&args[..], &FAST[..]].concat());
    snapshot("step_trum60a_fast.txt", &out);
    // settled speed: 0-15 % above the rigid-Coulomb steady solver with the default
    // layer stiffness (docs/DYNAMICS.md); the contact torque balances the rotor loss
    let value = |name: &str| {
        let line = out.lines().find(|l| l.starts_with(&format!("{name} "))).expect("quantity printed");
        num(line.split_whitespace().nth(1).expect("value"))
    };
    assert!(value("speed_difference") > 0.0 && value("speed_difference") < 0.15, "{out}");
    assert!(value("torque_difference").abs() < 0.15, "{out}");
    assert!(value("overshoot") > 0.05 && value("delay_s") < 1e-3, "{out}");
    let (h, rows) = csv_rows(&std::fs::read_to_string(&series).expect("series"));
    assert_eq!(h[0], "time_s");
    assert!(h.contains(&"speed_rpm".to_string()) && h.contains(&"contact_torque_nm".to_string()));
    assert_eq!(num(&rows[0][1]), 0.0, "starts at rest");
    let (h, rows) = csv_rows(&std::fs::read_to_string(&snaps).expect("snapshots"));
    assert_eq!(h.last().map(String::as_str), Some("state"));
    assert_eq!(rows.len(), 2 * 64);
    // Coulomb: |f| <= mu p everywhere, slip nodes at the limit, no-contact nodes unloaded
    let (fi, li) = (4, 5);
    for r in &rows {
        let (f, lim) = (num(&r[fi]), num(&r[li]));
        assert!(f.abs() <= lim * (1.0 + 1e-12), "{r:?}");
        match r[7].as_str() {
            "slip" => assert!((f.abs() - lim).abs() <= 1e-9 * lim, "{r:?}"),
            "no_contact" => assert!(f == 0.0 && lim == 0.0, "{r:?}"),
            s => assert_eq!(s, "stick"),
        }
    }
    // full contact at 20 us, all three zones once running (the bar-type transient paper Fig. 10)
    assert!(rows[..64].iter().all(|r| r[7] != "no_contact"));
    for s in ["stick", "slip", "no_contact"] {
        assert!(rows[64..].iter().any(|r| r[7] == s), "no {s} node at 3.5 ms");
    }
    assert!(std::fs::read_to_string(&plot).expect("svg").starts_with("<svg"));
    assert_eq!(&std::fs::read(&splot).expect("png")[..8], b"\x89PNG\r\n\x1a\n");
}

#[test]
fn step_sweep_over_phase_table() {
    let dir = tempfile::tempdir().expect("tempdir");
    let table = dir.path().join("t.csv");
    let out = ok(&[
        &["step", "--motor", FROZEN_TRUM60A, "--phase-difference-deg", "-90:90:3", "--table", p(&table)][..],
        &FAST[..],
    ]
    .concat());
    assert!(out.contains("not_moving"), "{out}");
    // --json: one run per phase, the standing wave (0 deg) does not move
    let j: serde_json::Value = serde_json::from_str(&ok(&[
        &["step", "--motor", FROZEN_TRUM60A, "--phase-difference-deg", "-90:90:3", "--json", "-q"][..],
        &FAST[..],
    ]
    .concat()))
    .expect("JSON");
    let runs = j["runs"].as_array().expect("runs");
    assert_eq!(runs.len(), 3);
    assert_eq!(runs[1]["phase_difference_deg"], 0.0);
    assert_eq!(runs[1]["status"], "not_moving");
    let fwd = runs[2]["quantities"]["final_speed_rpm"].as_f64().expect("speed");
    let rev = runs[0]["quantities"]["final_speed_rpm"].as_f64().expect("speed");
    assert!(fwd > 0.0 && rev < 0.0 && (fwd + rev).abs() < 0.05 * fwd, "{fwd} {rev}");
    let (h, rows) = csv_rows(&std::fs::read_to_string(&table).expect("table"));
    // -90 deg is motion the other way: status ok, negative speed, the forward run's delay
    assert_eq!((rows[0][3].as_str(), rows[2][3].as_str()), ("ok", "ok"));
    assert_eq!(&h[..4], ["voltage_v", "frequency_hz", "phase_difference_deg", "status"]);
    let col = |name: &str| h.iter().position(|c| c == name).expect("column");
    let speed: Vec<f64> = rows.iter().map(|r| num(&r[col("final_speed_rpm")])).collect();
    // -90 deg reverses the rotor, 0 deg (standing wave) does not turn it
    assert!(speed[2] > 50.0 && (speed[0] + speed[2]).abs() < 1e-6 * speed[2], "{speed:?}");
    assert!(speed[1].abs() < 1e-3 * speed[2], "{speed:?}");
    assert_eq!(rows[1][3], "not_moving");
    assert_eq!(rows[1][col("delay_s")], "", "no metrics for a standing wave: empty, not NaN");
    let delay = |i: usize| num(&rows[i][col("delay_s")]);
    assert!((delay(0) - delay(2)).abs() < 1e-6 * delay(2), "{} vs {}", delay(0), delay(2));
}

/// The steady comparison takes the wave's direction: at -90 deg it is the +90 deg steady
/// solution mirrored (negative speed and contact torque), so the relative differences are
/// those of +90 deg (to 1e-6), not about -2, under a load too (the load brakes either
/// way); at a phase with a standing part (-45, 0, 45 deg) the steady model says nothing:
/// the steady cells are empty, and a note says why.
#[test]
fn step_steady_comparison_follows_the_wave_and_is_empty_where_it_does_not_apply() {
    let dir = tempfile::tempdir().expect("tempdir");
    let table = dir.path().join("t.csv");
    let args = [
        &["step", "--motor", FROZEN_TRUM60A, "--phase-difference-deg", "-90:90:5", "--table", p(&table), "-q"][..],
        &FAST[..],
    ]
    .concat();
    let o = trum(&args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(0), "{err}");
    let (h, rows) = csv_rows(&std::fs::read_to_string(&table).expect("table"));
    let col = |name: &str| h.iter().position(|c| c == name).unwrap_or_else(|| panic!("no column {name}"));
    let at = |i: usize, name: &str| num(&rows[i][col(name)]);
    assert_eq!(rows.iter().map(|r| num(&r[2])).collect::<Vec<_>>(), [-90.0, -45.0, 0.0, 45.0, 90.0]);
    assert!(at(4, "steady_speed_rpm") > 50.0 && at(4, "steady_contact_torque_nm") > 0.0);
    assert_eq!(at(0, "steady_speed_rpm"), -at(4, "steady_speed_rpm"));
    assert_eq!(at(0, "steady_contact_torque_nm"), -at(4, "steady_contact_torque_nm"));
    assert_eq!(at(0, "steady_amplitude_m"), at(4, "steady_amplitude_m"));
    for q in ["speed_difference", "torque_difference"] {
        let (back, fwd) = (at(0, q), at(4, q));
        assert!(fwd.abs() < 0.15 && (back - fwd).abs() < 1e-6, "{q}: {back} at -90 deg, {fwd} at +90 deg");
    }
    let steady_cols =
        ["steady_speed_rpm", "speed_difference", "steady_contact_torque_nm", "torque_difference", "steady_amplitude_m"];
    for (i, r) in rows.iter().enumerate().take(4).skip(1) {
        for q in steady_cols {
            assert_eq!(r[col(q)], "", "row {i} ({} deg), {q}: no number where the steady model does not apply", r[2]);
        }
        assert_ne!(r[col("final_speed_rpm")], "", "the transient itself is still reported");
    }
    assert!(err.contains("note: no steady comparison (steady_* empty) at phase difference -45, 0, 45 deg"), "{err}");
    assert!(err.contains("partly a standing wave"), "{err}");

    // one point: the table says so beside the empty values; --json gives the reason
    let out = ok(&[&["step", "--motor", FROZEN_TRUM60A, "--phase-difference-deg", "45"][..], &FAST[..]].concat());
    assert!(out.contains("(steady solver: not_comparable)") && out.contains("partly a standing wave"), "{out}");
    let json = |deg: &str| -> serde_json::Value {
        let args =
            ["step", "--motor", FROZEN_TRUM60A, "--phase-difference-deg", deg, "--torque-nm", "0.1", "--json", "-q"];
        let j: serde_json::Value = serde_json::from_str(&ok(&[&args[..], &FAST[..]].concat())).expect("JSON");
        j["runs"][0].clone()
    };
    let q = |run: &serde_json::Value, name: &str| run["quantities"][name].as_f64().unwrap_or(f64::NAN);
    // under a load the reversed wave is compared with the mirrored steady solution as well
    let (back, fwd) = (json("-90"), json("90"));
    for run in [&back, &fwd] {
        assert_eq!(run["steady_status"], "ok", "{run}");
        assert!(run["steady_note"].is_null(), "{run}");
    }
    assert!(q(&back, "final_speed_rpm") < 0.0 && q(&back, "steady_speed_rpm") < 0.0, "{back}");
    assert_eq!(q(&back, "steady_speed_rpm"), -q(&fwd, "steady_speed_rpm"));
    assert_eq!(q(&back, "steady_contact_torque_nm"), -q(&fwd, "steady_contact_torque_nm"));
    let (db, df) = (q(&back, "speed_difference"), q(&fwd, "speed_difference"));
    assert!(df.abs() < 0.15 && (db - df).abs() < 1e-6, "speed_difference {db} at -90 deg, {df} at +90 deg");
    assert!((q(&back, "final_speed_rpm") + q(&fwd, "final_speed_rpm")).abs() < 1e-6 * q(&fwd, "final_speed_rpm"));
}

#[test]
fn step_bad_input_and_failed_runs_leave_no_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("s.csv");
    let base = ["step", "--motor", "trum60a", "-o", p(&out)];
    let e = fails(&[&base[..], &["--steps-per-period", "8"]].concat());
    assert!(e.contains("--steps-per-period = 8: must be >= 16"), "{e}");
    let e = fails(&[&base[..], &["--snapshot-at-s", "0.5"]].concat());
    assert!(e.contains("--snapshot-at-s = 0.5: must lie in [0, duration_s]"), "{e}");
    let e = fails(&[&base[..], &["--voltage-v", "-200"]].concat());
    assert!(e.contains("--voltage-v = -200: must be finite and > 0"), "{e}");
    // a run refused by the stability check after the settings were accepted
    let e = fails(&[&base[..], &["--tangential-stiffness-ratio", "1e6"]].concat());
    assert!(e.contains("time step too large") && e.contains("--steps-per-period"), "{e}");
    let e = fails(&[&base[..], &["--effect", "radial_friction=0.5"]].concat());
    assert!(e.contains("does not include unmodelled effects"), "{e}");
    let e = fails(&["step", "--motor", "trum60a", "--voltage-v", "100:200:2", "-o", p(&out)]);
    assert!(e.contains("single operating point"), "{e}");
    let e = fails(&["step", "--motor", "trum61"]);
    assert!(e.contains("unknown preset 'trum61'"), "{e}");
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0, "no partial output");
}

/// `--motor` gives the oscillator the motor's modal parameters: the linear resonance the
/// summary prints is the motor's free resonance, and flags still override it.
#[test]
fn resonance_takes_the_motor_with_overrides() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("r.csv");
    let args = ["resonance", "--motor", "trum60a", "--voltage-v", "1", "--preload-n", "250", "-o", p(&out)];
    let summary = ok(&args);
    let f_r = trum_core::presets::preset("trum60a").expect("preset").stator.resonance_frequency_hz;
    let row = summary.lines().nth(1).expect("a summary row");
    let cells: Vec<&str> = row.split_whitespace().collect();
    assert!((num(cells[3]) - f_r).abs() < 1e-3 * f_r / 1e4, "{summary}");
    let (h, rows) = csv_rows(&std::fs::read_to_string(&out).expect("csv"));
    let (fi, ai) = (
        h.iter().position(|c| c == "frequency_hz").expect("col"),
        h.iter().position(|c| c == "amplitude_m").expect("col"),
    );
    let peak = rows.iter().max_by(|a, b| num(&a[ai]).total_cmp(&num(&b[ai]))).expect("rows");
    assert!((num(&peak[fi]) - f_r).abs() < 0.01 * f_r, "peak at {} Hz, motor resonance {f_r}", peak[fi]);
    let moved = ok(&[&args[..], &["--linear-resonance-hz", "41000"]].concat());
    assert!(moved.lines().nth(1).is_some_and(|l| l.contains("41000")), "{moved}");
    let e = fails(&["resonance", "--motor", "no_such_motor", "-o", p(&out)]);
    assert!(e.contains("unknown preset 'no_such_motor'"), "{e}");
}

/// `identify-hertz --motor` reads a feedback-voltage record through the motor's feedback
/// gain: the displacement amplitude it reports is the record's voltage over that gain.
#[test]
fn identify_hertz_takes_the_motors_feedback_gain() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("w.csv");
    let g = trum_core::presets::preset("generic60").expect("preset").electrical.feedback_gain_v_per_m;
    let f = 40_950.0;
    let mut csv = String::from("time_s,feedback_voltage_v\n");
    for i in 0..768 {
        let t = i as f64 / (64.0 * f);
        csv.push_str(&format!("{t},{}\n", g * (1e-7 + 1.5e-6 * (2.0 * std::f64::consts::PI * f * t - 2.0).cos())));
    }
    std::fs::write(&data, csv).expect("write");
    let args =
        ["identify-hertz", "--motor", "generic60", "--data", p(&data), "--frequency-hz", "40950", "--voltage-v", "200"];
    let out = ok(&[&args[..], &["--json"]].concat());
    let j: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    let a = j["displacement_amplitude_m"].as_f64().expect("amplitude");
    assert!((a - 1.5e-6).abs() < 1e-9, "{a}");
    // without a motor the gain must be given
    let e = fails(&["identify-hertz", "--data", p(&data), "--frequency-hz", "40950", "--voltage-v", "200"]);
    assert!(e.contains("--feedback-gain-v-per-m is needed"), "{e}");
}

/// `trum step --motor bar36`: the bar-type motor at the paper's conditions by default
/// (0.25 N·m, 36.7 kHz, 90 deg), the same numbers as trum-core, a moment sweep with the
/// drive column named for the moment, and clear errors for ring-only flags and commands.
#[test]
fn step_runs_the_bar_type_motor_and_ring_commands_refuse_it() {
    use trum_core::dynamics::bar_type::bar_step_response;
    let dir = tempfile::tempdir().expect("tempdir");
    let series = dir.path().join("s.csv");
    let out = ok(&["step", "--motor", "bar36", "--duration-s", "0.01", "-o", p(&series)]);
    assert!(out.contains("drive    0.25 N·m, 36700 Hz, phase 90 deg, preload 40 N"), "{out}");
    assert!(out.contains("status   ok (bar-type motor: no steady solver)"), "{out}");
    let bar = trum_core::presets::find_bar("bar36").expect("preset").motor();
    let core = bar_step_response(
        &bar,
        &trum_core::dynamics::bar_type::BarStepConfig { duration_s: 0.01, ..bar.step_config() },
    )
    .expect("core");
    let value = |name: &str| {
        let line = out.lines().find(|l| l.starts_with(&format!("{name} "))).expect("quantity printed");
        num(line.split_whitespace().nth(1).expect("value"))
    };
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-5 * b.abs();
    assert!(close(value("final_speed_rpm"), core.averages.speed_rpm));
    assert!(close(value("rise_to_final_s"), core.metrics.rise_to_final_s.expect("rise")));
    let (h, rows) = csv_rows(&std::fs::read_to_string(&series).expect("series"));
    assert_eq!(h[0], "time_s");
    assert_eq!(rows.len(), core.series.time_s.len());

    let table = dir.path().join("t.csv");
    ok(&["step", "--motor", "bar36", "--moment-nm", "0.15:0.35:2", "--duration-s", "0.01", "--table", p(&table)]);
    let (h, rows) = csv_rows(&std::fs::read_to_string(&table).expect("table"));
    assert_eq!(&h[..4], ["moment_nm", "frequency_hz", "phase_difference_deg", "status"]);
    let col = |name: &str| h.iter().position(|c| c == name).expect("column");
    let delay: Vec<f64> = rows.iter().map(|r| num(&r[col("delay_s")])).collect();
    assert!(delay[1] < delay[0], "a larger moment starts sooner: {delay:?}");
    assert_eq!(rows[0][col("steady_speed_rpm")], "", "no steady solver for a bar-type motor");

    let e = fails(&["step", "--motor", "bar36", "--voltage-v", "100"]);
    assert!(e.contains("--moment-nm"), "{e}");
    let e = fails(&["step", "--motor", "bar36", "--moment-nm", "-1"]);
    assert!(e.contains("--moment-nm = -1: must be finite and > 0"), "{e}");
    let e = fails(&["step", "--motor", "trum60a", "--moment-nm", "0.2"]);
    assert!(e.contains("--voltage-v"), "{e}");
    let map = dir.path().join("m.csv");
    let e = fails(&["map", "--motor", "bar36", "-o", p(&map)]);
    assert!(e.contains("bar-type") && e.contains("trum step"), "{e}");
    assert!(!map.exists());
    // a bar-type motor file: overrides on the preset, read by step, refused by point
    let file = dir.path().join("bar.toml");
    std::fs::write(&file, "preset = \"bar36\"\n[stator]\nquality_factor = -5\n").expect("write");
    let e = fails(&["step", "--motor", p(&file)]);
    assert!(e.contains("line 3") && e.contains("stator.quality_factor"), "{e}");
    std::fs::write(&file, "preset = \"bar36\"\n[drive]\npreload_n = 30\n").expect("write");
    let out = ok(&["step", "--motor", p(&file), "--duration-s", "0.005", "--nodes-per-wavelength", "64"]);
    assert!(out.contains("preload 30 N"), "{out}");
    let e = fails(&["point", "--motor", p(&file), "--preload-n", "30"]);
    assert!(e.contains("bar-type motor file"), "{e}");
    let shown = ok(&["presets", "show", "bar36"]);
    assert!(shown.contains("kind = \"bar\"") && shown.contains("natural_frequency_hz = 36500.0"), "{shown}");
}

#[test]
fn step_runs_a_ring_motor_at_its_drive_unless_told() {
    // trum60a's [drive] is its paper's 200 V, 42 kHz; a frozen copy without one runs at 43 kHz
    let short = ["--duration-s", "0.0003", "--nodes-per-wavelength", "32"];
    let at_drive = ok(&[&["step", "--motor", "trum60a"][..], &short].concat());
    assert!(at_drive.contains("drive    200 V, 42000 Hz"), "{at_drive}");
    let told = ok(&[&["step", "--motor", "trum60a", "--frequency-hz", "43500"][..], &short].concat());
    assert!(told.contains("drive    200 V, 43500 Hz"), "{told}");
    let frozen = ok(&[&["step", "--motor", FROZEN_TRUM60A][..], &short].concat());
    assert!(frozen.contains("drive    200 V, 43000 Hz"), "{frozen}");
}
