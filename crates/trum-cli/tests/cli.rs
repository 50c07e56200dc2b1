//! End-to-end tests of the real `trum` binary: output, files, error messages, exit codes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::snapshot;

fn trum(args: &[&str]) -> Output {
    trum_env(args, &[])
}

fn trum_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_trum"));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run trum")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs and expects failure with `code`; returns stderr.
fn fails(args: &[&str], code: i32) -> String {
    let o = trum(args);
    assert_eq!(o.status.code(), Some(code), "{args:?}: stdout {} stderr {}", stdout(&o), stderr(&o));
    stderr(&o)
}

fn ok(args: &[&str]) -> String {
    let o = trum(args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    stdout(&o)
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write test file");
    p.to_string_lossy().into_owned()
}

#[test]
fn point_snapshot_trum60a() {
    let out = ok(&[
        "point",
        "--motor",
        "trum60a",
        "--preload-n",
        "250",
        "--torque-nm",
        "0.3",
        "--voltage-v",
        "200",
        "--frequency-hz",
        "43000",
    ]);
    snapshot("point_trum60a_250n_0.3nm.txt", &out);
}

#[test]
fn point_json_has_every_quantity_and_unit() {
    let out = ok(&["point", "--motor", "trum60a", "--preload-n", "250", "--torque-nm", "0.3", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    assert_eq!(v["status"], "ok");
    for q in trum_core::quantities::QUANTITIES {
        assert!(v["quantities"][q.name].is_number(), "{}", q.name);
        assert_eq!(v["units"][q.name], q.unit);
    }
}

#[test]
fn presets_show_reads_back_to_the_same_numbers() {
    let dir = tempfile::tempdir().expect("tempdir");
    for p in trum_core::presets::PRESETS {
        let toml = ok(&["presets", "show", p.name]);
        let file = write(dir.path(), &format!("{}.toml", p.name), &toml);
        let args = |m: &str| {
            ok(&["point", "--motor", m, "--preload-n", "250", "--torque-nm", "0.3", "--json"])
                .parse::<serde_json::Value>()
                .expect("JSON")
        };
        let (a, b) = (args(p.name), args(&file));
        assert_eq!(a["quantities"], b["quantities"], "{}", p.name);
        assert_eq!(a["status"], b["status"]);
        // the text table too, apart from nothing: both name the same motor and preset
        let t = |m: &str| ok(&["point", "--motor", m, "--preload-n", "250", "--torque-nm", "0.3"]);
        assert_eq!(t(p.name), t(&file), "{}", p.name);
    }
    let list = ok(&["presets"]);
    for p in trum_core::presets::PRESETS {
        assert!(list.contains(p.name) && list.contains(p.sources), "{list}");
    }
}

#[test]
fn example_files_match_presets_show() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    for p in ["trum60a", "trum60-qut", "generic60"] {
        let file = std::fs::read_to_string(root.join(format!("examples/{p}.toml"))).expect("example file");
        assert_eq!(
            file,
            ok(&["presets", "show", p]),
            "examples/{p}.toml is stale: regenerate with `trum presets show`"
        );
    }
    let custom = root.join("examples/custom-motor.toml");
    let out = ok(&["map", "--motor", custom.to_str().unwrap_or_default(), "--columns", "speed_rpm", "-o", "-"]);
    assert_eq!(out.lines().count(), 1 + 6 * 31, "custom-motor [sweep] is 6 preloads x 31 torques");
}

fn parse_csv(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let h = r.headers().expect("header").iter().map(String::from).collect();
    let rows = r.records().map(|x| x.expect("row").iter().map(String::from).collect()).collect();
    (h, rows)
}

#[test]
fn map_columns_rows_and_defaults() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("m.csv");
    let o = out.to_str().unwrap_or_default();
    ok(&["map", "--motor", "trum60a", "--preload-n", "100:300:3", "--torque-nm", "0:1.5:4", "-o", o, "-q"]);
    let (h, rows) = parse_csv(&std::fs::read_to_string(&out).expect("map written"));
    let mut want = vec!["preload_n", "torque_nm", "voltage_v", "frequency_hz", "status", "warnings"];
    want.extend(trum_core::quantities::QUANTITIES.iter().map(|q| q.name));
    want.push("loaded_stall_torque_nm");
    assert_eq!(h, want);
    assert_eq!(rows.len(), 12);
    // torque fastest, the drive defaults to the preset's [drive], 200 V and 42 kHz
    assert_eq!(&rows[1][..4], ["100", "0.5", "200", "42000"]);
    assert_eq!(&rows[11][..2], ["300", "1.5"]);
    // numbers are Rust's shortest round-trip form
    let speed: f64 = rows[0][6].parse().expect("number");
    assert_eq!(format!("{speed}"), rows[0][6]);

    // no axes anywhere: the motor's default map (9 preloads x 25 torques up to just above
    // the largest loaded stall torque, at its drive; generic60 has none: 200 V, 43 kHz),
    // not one point
    let sel =
        ok(&["map", "--motor", "generic60", "--columns", "speed_rpm,efficiency,loaded_stall_torque_nm", "-o", "-"]);
    let (h, rows) = parse_csv(&sel);
    assert_eq!(
        h,
        [
            "preload_n",
            "torque_nm",
            "voltage_v",
            "frequency_hz",
            "status",
            "warnings",
            "speed_rpm",
            "efficiency",
            "loaded_stall_torque_nm"
        ]
    );
    assert_eq!(rows.len(), 9 * 25);
    assert_eq!(&rows[0][..4], ["100", "0", "200", "43000"]);
    assert_eq!(rows[224][0], "500");
    let top: f64 = rows[224][1].parse().expect("number");
    let loaded = rows.iter().filter_map(|r| r[8].parse::<f64>().ok()).fold(0.0, f64::max);
    // 5 % margin, rounded up to two significant digits: at most 1.05 x 1.1 above
    assert!(top >= 1.05 * loaded && top <= 1.16 * loaded, "torque axis ends at {top}, loaded stall {loaded}");
    assert!(rows.iter().any(|r| r[4] != "ok"), "the default map reaches where the loaded motor stops");
    // one axis given: the other axes take their defaults, as before
    let one = ok(&["map", "--motor", "generic60", "--preload-n", "250", "--columns", "speed_rpm", "-o", "-"]);
    assert_eq!(parse_csv(&one).1.len(), 1);
    // ... and the drive is the motor's [drive] (trum60a: its paper's 200 V, 42 kHz), as for `trum point`
    let (_, rows) =
        parse_csv(&ok(&["map", "--motor", "trum60a", "--preload-n", "250", "--columns", "speed_rpm", "-o", "-"]));
    assert_eq!((rows[0][2].as_str(), rows[0][3].as_str()), ("200", "42000"));
    let (_, told) = parse_csv(&ok(&[
        "map",
        "--motor",
        "trum60a",
        "--preload-n",
        "250",
        "--frequency-hz",
        "43000",
        "--columns",
        "speed_rpm",
        "-o",
        "-",
    ]));
    assert_eq!(told[0][3], "43000");
}

/// The default map of trum60a covers where the loaded motor runs: its torque axis ends
/// just above the largest loaded stall torque over its preloads (1.8-1.9 N·m), not at the
/// rotor-at-rest stall torque at 500 N (3.1 N·m), where two rows in three were `stall` or
/// `clamped`. The note on stderr gives the axes it chose.
#[test]
fn map_default_torque_axis_covers_where_the_loaded_motor_runs() {
    let o = trum(&["map", "--motor", "trum60a", "--columns", "stall_torque_nm,loaded_stall_torque_nm", "-o", "-"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (h, rows) = parse_csv(&stdout(&o));
    assert_eq!(h[6..], ["stall_torque_nm", "loaded_stall_torque_nm"]);
    assert_eq!(rows.len(), 9 * 25);
    let num = |s: &str| s.parse::<f64>().unwrap_or(f64::NAN);
    let top = num(&rows[224][1]);
    let loaded = rows.iter().map(|r| num(&r[7])).filter(|v| v.is_finite()).fold(0.0, f64::max);
    let at_rest_500 = num(&rows[200][6]);
    assert!(top >= 1.05 * loaded && top <= 1.16 * loaded, "axis ends at {top} N·m, largest loaded stall {loaded}");
    assert!(at_rest_500 > 1.3 * top, "at rest {at_rest_500} N·m, axis {top} N·m");
    let running = rows.iter().filter(|r| r[4] == "ok").count();
    // (114 of 225; the axis up to the rotor-at-rest torque had 75)
    assert!(running >= 100, "{running} of {} rows running", rows.len());
    // every preload's stop lies on the axis, with a stopped row above it
    for line in rows.chunks(25) {
        let stop = num(&line[0][7]);
        assert!(
            (stop.is_nan() || stop <= top) && line.last().is_some_and(|r| r[4] != "ok"),
            "preload {}: stops at {stop}",
            line[0][0]
        );
    }
    let note = stderr(&o);
    assert!(note.contains(&format!("--torque-nm 0:{}:25", rows[224][1])), "{note}");
}

#[test]
fn grids_outside_the_model_domain_are_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().expect("temp dir");
    let target = dir.path().join("m.csv");
    let t = target.to_str().unwrap_or_default();
    for (axis, value, message) in [
        ("--preload-n", "0:200:3", "preload_n: 0 must be > 0"),
        ("--torque-nm", "-0.5:0.5:3", "torque_nm: -0.5 must be >= 0"),
        ("--voltage-v", "-200", "voltage_v: -200 must be > 0"),
        ("--frequency-hz", "0", "frequency_hz: 0 must be > 0"),
    ] {
        let e = fails(&["map", "--motor", "trum60a", axis, value, "-o", t], 1);
        assert!(e.contains(message), "{axis} {value}: {e}");
        assert!(!target.exists(), "{axis} {value}: an output file was written");
        let e = fails(&["plot", "--motor", "trum60a", "--kind", "speed-torque", axis, value, "-o", "p.svg"], 1);
        assert!(e.contains(message), "plot {axis} {value}: {e}");
    }
    // through stall and clamping, every cell of a valid grid is a number or (for an
    // invalid status) empty, never NaN
    let out = ok(&["map", "--motor", "trum60a", "--preload-n", "50:2000:6", "--torque-nm", "0:3:4", "-o", "-"]);
    assert!(!out.to_lowercase().contains("nan"), "{out}");
    let (_, rows) = parse_csv(&out);
    assert_eq!(rows.len(), 24);
    assert!(rows.iter().any(|r| r[4] == "stall") && rows.iter().any(|r| r[4] == "ok"), "{out}");
}

#[test]
fn map_output_does_not_depend_on_thread_count() {
    // a small chunk size makes many chunks, so the parallel order is really exercised
    let args = [
        "map",
        "--motor",
        "trum60a",
        "--preload-n",
        "100:500:9",
        "--torque-nm",
        "0:1.6:23",
        "--chunk-points",
        "7",
        "-o",
        "-",
    ];
    let one = trum_env(&args, &[("RAYON_NUM_THREADS", "1")]);
    let two = trum_env(&args, &[("RAYON_NUM_THREADS", "2")]);
    let three = trum(&[&args[..], &["--threads", "3"]].concat());
    assert!(one.status.success() && two.status.success() && three.status.success());
    assert_eq!(stdout(&one).lines().count(), 1 + 9 * 23);
    assert_eq!(one.stdout, two.stdout);
    assert_eq!(one.stdout, three.stdout);
}

#[test]
fn failed_map_leaves_no_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("big.csv");
    let o = out.to_str().unwrap_or_default();
    let r = trum_env(
        &[
            "map",
            "--motor",
            "trum60a",
            "--preload-n",
            "100:300:50",
            "--torque-nm",
            "0:1:50",
            "--chunk-points",
            "64",
            "-o",
            o,
        ],
        &[("TRUM_TEST_FAIL_AFTER_POINTS", "500")],
    );
    assert_eq!(r.status.code(), Some(1));
    assert!(stderr(&r).contains("injected failure"), "{}", stderr(&r));
    let left: Vec<_> = std::fs::read_dir(dir.path()).expect("dir").collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
    // a failed run does not touch an existing output either
    std::fs::write(&out, "old").expect("write");
    let r = trum_env(
        &["map", "--motor", "trum60a", "--preload-n", "100:300:50", "--torque-nm", "0:1:50", "-o", o],
        &[("TRUM_TEST_FAIL_AFTER_POINTS", "1")],
    );
    assert_eq!(r.status.code(), Some(1));
    assert_eq!(std::fs::read_to_string(&out).expect("read"), "old");
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 1);
    // bad input fails before anything is created
    std::fs::remove_file(&out).expect("rm");
    fails(&["map", "--motor", "trum60a", "--columns", "nope", "-o", o], 1);
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0);
}

/// `-o /dev/null` or a named pipe is written in place: the atomic rename used for regular
/// files would replace the special file with a regular one (a FIFO stands in for
/// /dev/null so that a regression cannot damage the machine running the test).
#[cfg(unix)]
#[test]
fn special_output_files_are_written_in_place() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().expect("tempdir");
    let fifo = dir.path().join("pipe.csv");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo");
    assert!(made.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).expect("read fifo"))
    };
    let args = ["map", "--motor", "trum60a", "--preload-n", "100:300:3", "--torque-nm", "0:1:4"];
    let o = fifo.to_str().unwrap_or_default();
    let r = trum(&[&args[..], &["-o", o]].concat());
    assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
    let kind = std::fs::symlink_metadata(&fifo).expect("stat").file_type();
    assert!(kind.is_fifo(), "the FIFO was replaced by {kind:?}");
    let text = reader.join().expect("reader");
    assert_eq!(text, ok(&[&args[..], &["-o", "-"]].concat()));
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 1, "no temporary file left");
    // and /dev/null itself stays a character device
    if std::fs::metadata("/dev/null").is_ok_and(|m| m.file_type().is_char_device()) {
        ok(&[&args[..], &["-o", "/dev/null"]].concat());
        assert!(std::fs::metadata("/dev/null").expect("stat").file_type().is_char_device());
    }
}
#[test]
fn motor_file_errors_name_file_line_and_key() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let cases = [
        (
            "unknown.toml",
            "preset = \"trum60a\"\n\n[stator]\nmodal_masss_kg = 1\n",
            "line 4, key 'stator.modal_masss_kg': unknown key",
        ),
        (
            "negative.toml",
            "preset = \"trum60a\"\n[rotor]\nmass_kg = -0.03\n",
            "line 3, key 'rotor.mass_kg': -0.03 must be > 0",
        ),
        (
            "nan.toml",
            "preset = \"trum60a\"\n[rotor]\nmass_kg = nan\n",
            "line 3, key 'rotor.mass_kg': NaN is not a finite number",
        ),
        (
            "wave.toml",
            "preset = \"trum60a\"\n[geometry]\nwave_number = 9.5\n",
            "line 3, key 'geometry.wave_number': 9.5 must be a positive whole number",
        ),
        (
            "preset.toml",
            "preset = \"trum60x\"\n",
            "line 1, key 'preset': unknown preset 'trum60x'; valid presets are: trum60a",
        ),
        (
            "effect.toml",
            "preset = \"trum60a\"\n[effects]\nradial = 0.5\n",
            "unknown effect 'radial'; valid effects are: radial_friction",
        ),
    ];
    for (name, text, want) in cases {
        let f = write(d, name, text);
        let err = fails(&["point", "--motor", &f, "--preload-n", "250"], 1);
        assert!(err.contains(&f), "{err}");
        assert!(err.contains(want), "{name}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn command_line_errors_and_exit_codes() {
    let e = fails(&["point", "--motor", "trum61", "--preload-n", "250"], 1);
    assert!(e.contains("unknown preset 'trum61'") && e.contains("trum60a, trum60-qut, generic60"), "{e}");
    let e = fails(&["point", "--motor", "missing/motor.toml", "--preload-n", "250"], 1);
    assert!(e.contains("motor file 'missing/motor.toml' does not exist"), "{e}");
    let e = fails(&["map", "--motor", "trum60a", "--preload-n", "100:200", "-o", "-"], 2);
    assert!(e.contains("START:STOP:N"), "{e}");
    let e = fails(&["map", "--motor", "trum60a", "--preload-n", "100:200:x", "-o", "-"], 2);
    assert!(e.contains("whole number"), "{e}");
    let e = fails(&["point", "--motor", "trum60a", "--preload-n", "250", "--effect", "radial=0.5"], 1);
    assert!(e.contains("unknown effect 'radial'"), "{e}");
    for name in trum_core::effects::EFFECTS.iter().map(|e| e.name) {
        assert!(e.contains(name), "{e}");
    }
    let e = fails(&["point", "--motor", "trum60a", "--preload-n", "250", "--effect", "eccentricity=1"], 1);
    assert!(e.contains("outside the valid range"), "{e}");
    let e = fails(&["point", "--motor", "trum60a", "--preload-n", "-5"], 1);
    assert!(e.contains("preload_n = -5 must be > 0"), "{e}");
    let e = fails(&["point", "--motor", "trum60a", "--preload-n", "nan"], 1);
    assert!(e.contains("not a finite number"), "{e}");
    fails(&["point", "--motor", "trum60a"], 2);
    fails(&["frobnicate"], 2);
    fails(&[], 2);
    let e = fails(&["map", "--motor", "trum60a", "--columns", "speed", "-o", "-"], 1);
    assert!(e.contains("unknown quantity 'speed'") && e.contains("speed_rpm"), "{e}");
    let e = fails(&["presets", "show", "nope"], 1);
    assert!(e.contains("unknown preset 'nope'"), "{e}");
    let e = fails(&["plot", "--motor", "trum60a", "--kind", "speed-torque", "-o", "x.jpg"], 1);
    assert!(e.contains(".png or .svg"), "{e}");
    assert!(ok(&["--help"]).contains("Usage"));
}

#[test]
fn effects_lists_the_registry() {
    let out = ok(&["effects"]);
    for e in trum_core::effects::EFFECTS.iter() {
        assert!(out.contains(e.name) && out.contains(e.source), "{}", e.name);
        for (i, p) in e.params.iter().enumerate() {
            assert!(out.contains(p.name), "{}", p.name);
            // the primary is marked a strength, a shape parameter as such
            let tag = if i == 0 {
                " (strength)"
            } else if p.shape {
                " (shape)"
            } else {
                ""
            };
            assert!(out.contains(&format!("  {}{tag} ", p.name)), "{}: {tag:?}", p.name);
        }
    }
    assert!(out.contains("modal_fraction (shape)"));
}

#[test]
fn optimize_table_and_summary() {
    let dir = tempfile::tempdir().expect("tempdir");
    let csv_path = dir.path().join("opt.csv");
    let out = ok(&[
        "optimize",
        "--motor",
        "trum60a",
        "--preload-n",
        "150:450:7",
        "-o",
        csv_path.to_str().unwrap_or_default(),
    ]);
    assert!(out.contains("optimum preload") && out.contains("260-320 N"), "{out}");
    let (h, rows) = parse_csv(&std::fs::read_to_string(&csv_path).expect("csv"));
    assert_eq!(h.len(), 11);
    assert_eq!(h[0], "preload_n");
    assert_eq!(h[9], "in_region");
    assert_eq!(h[10], "warnings");
    assert_eq!(rows.len(), 7);
    // at the paper's drive every candidate is within the preset's limits
    assert!(rows.iter().all(|r| r[10].is_empty()), "{rows:?}");
    assert!(!out.contains("[limits]"), "{out}");
    // a voltage cap below the drive: every candidate flagged, and the summary says so
    let capped = dir.path().join("capped.toml");
    std::fs::write(&capped, "preset = \"trum60a\"\n[limits]\nmax_voltage_v = 150\n").expect("write");
    let out = ok(&["optimize", "--motor", capped.to_str().unwrap_or_default(), "--preload-n", "150:450:4"]);
    assert!(out.contains("every running candidate exceeds the motor's [limits]"), "{out}");
    assert!(out.contains("max_voltage_v"), "{out}");
    let g = ok(&["optimize", "--motor", "generic60", "--preload-n", "150:450:4"]);
    assert!(!g.contains("260-320"), "{g}");
}

#[test]
fn plots_png_and_svg() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let png = d.join("st.png");
    ok(&[
        "plot",
        "--motor",
        "trum60a",
        "--kind",
        "speed-torque",
        "--preload-n",
        "150:350:3",
        "-o",
        png.to_str().unwrap_or_default(),
    ]);
    let bytes = std::fs::read(&png).expect("png");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // anti-aliased: pixels of the 150 N curve (viridis' first colour) blended with the
    // white background, against those of the full colour. Drawn without supersampling the
    // ratio is 0.23 (plotters blends a little at line joins); anti-aliased, 0.73.
    let (w, h, rgb) = decode_png(&bytes);
    assert_eq!((w, h), (1024, 720));
    let c = [68.0, 1.0, 84.0];
    let (mut core, mut blended) = (0usize, 0usize);
    for p in rgb.chunks(3) {
        let a = (f64::from(p[1]) - c[1]) / (255.0 - c[1]);
        if (0..3).all(|k| (f64::from(p[k]) - (c[k] + a * (255.0 - c[k]))).abs() <= 6.0) {
            if a < 0.15 {
                core += 1;
            } else if a < 0.85 {
                blended += 1;
            }
        }
    }
    assert!(
        core > 500 && blended as f64 > 0.45 * core as f64,
        "{blended} blended edge pixels, {core} full-colour pixels"
    );
    let svg = d.join("em.svg");
    ok(&[
        "plot",
        "--motor",
        "generic60",
        "--kind",
        "efficiency-map",
        "--preload-n",
        "100:400:7",
        "--torque-nm",
        "0:1:11",
        "-o",
        svg.to_str().unwrap_or_default(),
    ]);
    let text = std::fs::read_to_string(&svg).expect("svg");
    assert!(text.starts_with("<svg") && text.contains("<rect"), "{}", &text[..200.min(text.len())]);
    // shown at 1024 x 720, drawn in quarter pixels: the lines are not stair-stepped
    assert!(text.starts_with(r#"<svg width="1024" height="720" viewBox="0 0 4096 2880""#), "{}", &text[..120]);
    if text.contains("<text") {
        // the efficiency map over the speed-torque plane: words, units, conditions, effects
        for words in
            ["Load torque [N·m]", "Speed [rpm]", "Efficiency [%]", "drive voltage 200 V", "nominal model (no effects)"]
        {
            assert!(text.contains(words), "{words} missing from the efficiency map");
        }
    }
    assert!(!text.contains("beyond [limits]"), "generic60 at 200 V, 43 kHz is within its limits");
    // a heat map over a band that crosses the resonance marks the cells beyond a limit
    let hot = d.join("hot.svg");
    ok(&[
        "plot",
        "--motor",
        "generic60",
        "--x",
        "frequency_hz",
        "--y",
        "preload_n",
        "--z",
        "temperature_rise_k",
        "--frequency-hz",
        "39500:43000:15",
        "--preload-n",
        "100:400:4",
        "-o",
        hot.to_str().unwrap_or_default(),
    ]);
    let marked = std::fs::read_to_string(&hot).expect("svg");
    let lines = marked.matches("<line").count();
    assert!(lines > text.matches("<line").count() + 8, "crosses drawn: {lines} lines");
    assert!(marked.contains("beyond [limits]") || !marked.contains("<text"), "the title says what x means");
    // from a map CSV
    let map = d.join("m.csv");
    ok(&[
        "map",
        "--motor",
        "trum60a",
        "--preload-n",
        "100:300:3",
        "--torque-nm",
        "0:1.5:16",
        "-o",
        map.to_str().unwrap_or_default(),
    ]);
    let from_csv = d.join("c.svg");
    let m = map.to_str().unwrap_or_default();
    ok(&[
        "plot",
        "--map",
        m,
        "--x",
        "torque_nm",
        "--y",
        "speed_rpm",
        "--group",
        "preload_n",
        "-o",
        from_csv.to_str().unwrap_or_default(),
    ]);
    let text = std::fs::read_to_string(&from_csv).expect("svg");
    assert!(text.contains("Load torque [N·m]") || !text.contains("<text"), "axis label in words with unit");
    let e = fails(
        &["plot", "--map", m, "--x", "torque", "--y", "speed_rpm", "-o", from_csv.to_str().unwrap_or_default()],
        1,
    );
    assert!(e.contains("column 'torque' does not exist") && e.contains("torque_nm"), "{e}");
}

#[test]
fn motor_file_doc_lists_every_key() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let doc = std::fs::read_to_string(root.join("docs/MOTOR_FILE.md")).expect("docs/MOTOR_FILE.md");
    for k in trum_core::Motor::all_keys() {
        assert!(doc.contains(&format!("| `[{}]` | `{}` |", k.section, k.key)), "{}.{} missing", k.section, k.key);
    }
}

#[test]
fn completions_for_bash_zsh_and_fish_name_every_command() {
    for shell in ["bash", "zsh", "fish"] {
        let s = ok(&["completions", shell]);
        for cmd in ["map", "diagnose", "resonance", "completions"] {
            assert!(s.contains(cmd), "{shell} completions lack {cmd}");
        }
    }
    assert!(fails(&["completions", "tcsh"], 2).contains("invalid value 'tcsh'"));
}

#[test]
fn json_on_presets_effects_and_optimize() {
    let p: serde_json::Value = serde_json::from_str(&ok(&["presets", "--json"])).expect("JSON");
    let trum60a = p.as_array().and_then(|l| l.iter().find(|x| x["name"] == "trum60a")).expect("trum60a listed");
    assert_eq!(trum60a["display_name"], "TRUM60A");
    assert_eq!(trum60a["drive"]["frequency_hz"], 42000.0);
    let e: serde_json::Value = serde_json::from_str(&ok(&["effects", "--json"])).expect("JSON");
    let names: Vec<&str> = e.as_array().expect("list").iter().filter_map(|x| x["name"].as_str()).collect();
    let want: Vec<&str> = trum_core::effects::EFFECTS.iter().map(|x| x.name).collect();
    assert_eq!(names, want);
    assert_eq!(e[0]["params"][0]["role"], "strength");
    let o: serde_json::Value =
        serde_json::from_str(&ok(&["optimize", "--motor", "generic60", "--preload-n", "150:450:7", "--json", "-q"]))
            .expect("JSON");
    let rows = o["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 7);
    // the optimum is a candidate inside its region, and the in-region rows span it
    let best = o["optimum_preload_n"].as_f64().expect("number");
    assert!(rows.iter().any(|r| r["preload_n"].as_f64() == Some(best)));
    let (lo, hi) = (o["region_n"][0].as_f64().expect("lo"), o["region_n"][1].as_f64().expect("hi"));
    assert!(lo <= best && best <= hi);
    for r in rows {
        let p = r["preload_n"].as_f64().expect("preload");
        assert_eq!(r["in_region"].as_bool(), Some(lo <= p && p <= hi), "{r}");
    }
}

#[test]
fn did_you_mean_for_presets_effects_and_columns() {
    let e = fails(&["point", "--motor", "TRUM60A", "--preload-n", "250"], 1);
    assert!(e.contains("did you mean 'trum60a'?"), "{e}");
    let e = fails(&["presets", "show", "generc60"], 1);
    assert!(e.contains("did you mean 'generic60'?"), "{e}");
    let e = fails(&["point", "--motor", "trum60a", "--effect", "radial_frction=1", "--preload-n", "250"], 1);
    assert!(e.contains("did you mean 'radial_friction'?"), "{e}");
    let e = fails(&["map", "--motor", "trum60a", "--preload-n", "250", "--columns", "speed_rmp", "-o", "-"], 1);
    assert!(e.contains("did you mean 'speed_rpm'?"), "{e}");
    // nothing close: no guess
    let e = fails(&["point", "--motor", "shinsei", "--preload-n", "250"], 1);
    assert!(!e.contains("did you mean"), "{e}");
}

#[test]
fn csv_numbers_are_readable_and_round_trip() {
    let s = ok(&[
        "map",
        "--motor",
        "trum60a",
        "--preload-n",
        "250",
        "--columns",
        "amplitude_m,modal_stiffness_n_per_m",
        "-o",
        "-",
    ]);
    let (h, rows) = parse_csv(&s);
    let amp = &rows[0][h.iter().position(|c| c == "amplitude_m").expect("column")];
    // micrometre amplitudes in exponent form, not 0.00000441...
    assert!(amp.contains("e-6") && !amp.starts_with("0.0"), "{amp}");
    let v: f64 = amp.parse().expect("number");
    assert_eq!(format!("{v:e}"), *amp);
    for r in &rows {
        assert!(r.iter().all(|c| c.len() < 26), "{r:?}");
    }
}

/// Width, height and RGB bytes of an 8-bit RGB PNG.
fn decode_png(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
    let mut reader = png::Decoder::new(bytes).read_info().expect("png header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("png frame");
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// A map's statuses agree with its `loaded_stall_torque_nm` column (one value per torque
/// line): running below it, stopped above it, to the bisection's tolerance. generic60 near
/// clamping (26.87 N, 6.63 V, 40 456.6 Hz: the rotor-at-rest torque 0.181 N·m, the loaded
/// motor stops at about 0.06 N·m), a line that clamps at no load (100 N: empty column, no
/// running point), and trum60a at its drive; chunks of 50 points split the lines.
#[test]
fn map_statuses_agree_with_the_loaded_stall_torque_column() {
    let runs = [
        ["generic60", "26.87", "0:0.1:101", "6.63", "40456.6"],
        ["generic60", "100", "0:0.1:101", "6.63", "40456.6"],
        ["trum60a", "100:500:5", "0:2.5:101", "200", "42000"],
    ];
    let (mut lines, mut crossings, mut empty) = (0, 0, 0);
    for [motor, p, torque, v, f] in runs {
        let out = ok(&[
            "map",
            "--motor",
            motor,
            "--preload-n",
            p,
            "--torque-nm",
            torque,
            "--voltage-v",
            v,
            "--frequency-hz",
            f,
            "--columns",
            "stall_torque_nm,loaded_stall_torque_nm",
            "--chunk-points",
            "50",
            "-o",
            "-",
        ]);
        let (h, rows) = parse_csv(&out);
        assert_eq!(h[6..], ["stall_torque_nm", "loaded_stall_torque_nm"]);
        for line in rows.chunks(101) {
            lines += 1;
            let cell = &line[0][7];
            assert!(line.iter().all(|r| &r[7] == cell), "{motor} {}: one value per line", line[0][0]);
            if cell.is_empty() {
                empty += 1;
                assert!(
                    line.iter().all(|r| r[4] != "ok"),
                    "{motor} {}: runs without a loaded stall torque",
                    line[0][0]
                );
                continue;
            }
            let t: f64 = cell.parse().expect("number");
            for r in line {
                let tq: f64 = r[1].parse().expect("torque");
                if tq < t * (1.0 - 1e-6) {
                    assert_eq!(r[4], "ok", "{motor} {r:?} below {t}");
                } else if tq > t * (1.0 + 1e-6) {
                    assert_ne!(r[4], "ok", "{motor} {r:?} above {t}");
                }
            }
            crossings += usize::from(line.iter().any(|r| r[4] != "ok"));
        }
    }
    assert_eq!(lines, 7);
    assert_eq!(empty, 1, "the 100 N line of generic60 clamps");
    assert!(crossings >= 5, "{crossings} lines reach their loaded stall torque");
    // the point of the column: its loaded stall torque is far below the rotor-at-rest torque
    let out = ok(&[
        "map",
        "--motor",
        "generic60",
        "--preload-n",
        "26.87",
        "--torque-nm",
        "0",
        "--voltage-v",
        "6.63",
        "--frequency-hz",
        "40456.6",
        "--columns",
        "stall_torque_nm,loaded_stall_torque_nm",
        "-o",
        "-",
    ]);
    let (_, rows) = parse_csv(&out);
    let (at_rest, loaded): (f64, f64) = (rows[0][6].parse().expect("at rest"), rows[0][7].parse().expect("loaded"));
    assert!(loaded < 0.5 * at_rest, "{loaded} against {at_rest}");
    // the same number as `trum point` reports for the point
    let point = ok(&[
        "point",
        "--motor",
        "generic60",
        "--preload-n",
        "26.87",
        "--voltage-v",
        "6.63",
        "--frequency-hz",
        "40456.6",
        "--json",
    ]);
    let v: serde_json::Value = point.parse().expect("JSON");
    assert_eq!(v["loaded_stall_torque_nm"].as_f64(), Some(loaded));
    let unknown = fails(
        &["map", "--motor", "generic60", "--preload-n", "100", "--columns", "loaded_stall_torqe_nm", "-o", "-"],
        1,
    );
    assert!(unknown.contains("loaded_stall_torque_nm"), "{unknown}");
}

/// Near clamping the loaded motor stops far below the rotor-at-rest torque at the no-load
/// amplitude (generic60 at 26.87 N, 6.63 V, 40 456.6 Hz: 0.181 N·m at rest, clamped from
/// about 0.06 N·m). `trum point` reports where the loaded motor stops, says why it differs,
/// and that torque is where the point's own status turns from running to stopped.
#[test]
fn point_reports_the_loaded_stall_torque_where_the_status_turns() {
    let at = |t: f64| {
        let out = ok(&[
            "point",
            "--motor",
            "generic60",
            "--preload-n",
            "26.87",
            "--voltage-v",
            "6.63",
            "--frequency-hz",
            "40456.6",
            "--torque-nm",
            &t.to_string(),
            "--json",
        ]);
        out.parse::<serde_json::Value>().expect("JSON")
    };
    let v = at(0.0);
    let loaded = v["loaded_stall_torque_nm"].as_f64().expect("loaded stall torque");
    let at_rest = v["quantities"]["stall_torque_nm"].as_f64().expect("stall torque");
    assert!(loaded < 0.5 * at_rest, "loaded {loaded} against at rest {at_rest}");
    let note = v["notes"][0].as_str().expect("a note");
    assert!(note.contains("loaded_stall_torque_nm") && note.contains("clamps"), "{note}");
    assert_eq!(at(0.98 * loaded)["status"], "ok");
    let beyond = at(1.02 * loaded);
    assert!(beyond["status"] == "clamped" || beyond["status"] == "stall", "{}", beyond["status"]);
}

#[test]
fn point_runs_at_the_motors_drive_unless_given() {
    let out = ok(&["point", "--motor", "trum60a", "--preload-n", "250"]);
    assert!(out.contains("the motor's [drive]"), "{out}");
    let v = |extra: &[&str]| {
        let mut a = vec!["point", "--motor", "trum60a", "--preload-n", "250", "--json"];
        a.extend_from_slice(extra);
        ok(&a).parse::<serde_json::Value>().expect("JSON")
    };
    let drive = trum_core::presets::find("trum60a").expect("preset").drive().expect("a [drive] table");
    let bare = v(&[]);
    assert_eq!(bare["inputs"]["voltage_v"].as_f64(), Some(drive.voltage_v));
    assert_eq!(bare["inputs"]["frequency_hz"].as_f64(), Some(drive.frequency_hz));
    assert_eq!(v(&["--frequency-hz", "43000"])["inputs"]["frequency_hz"].as_f64(), Some(43000.0));
    // a motor without [drive] keeps the documented 200 V, 43 kHz
    let g = ok(&["point", "--motor", "generic60", "--preload-n", "250", "--json"])
        .parse::<serde_json::Value>()
        .expect("JSON");
    assert_eq!(g["inputs"]["frequency_hz"].as_f64(), Some(43000.0));
    assert_eq!(g["inputs"]["voltage_v"].as_f64(), Some(200.0));
}
