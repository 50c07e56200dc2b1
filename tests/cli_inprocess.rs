//! The CLI run in-process through `trum_cli::run_with_io` (no subprocess): exit codes and
//! captured output.

fn run(args: &[&str]) -> (i32, String, String) {
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let argv = std::iter::once("trum").chain(args.iter().copied());
    let code = trum_cli::run_with_io(argv, &mut out, &mut err);
    (code, String::from_utf8_lossy(&out).into_owned(), String::from_utf8_lossy(&err).into_owned())
}

#[test]
fn point_json_matches_the_library() {
    let (code, out, err) = run(&["point", "--motor", "trum60a", "--preload-n", "300", "--torque-nm", "0.2", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    let m = trum_core::presets::preset("trum60a").expect("preset");
    // without --voltage-v and --frequency-hz the point runs at the preset's [drive]
    let d = trum_core::presets::find("trum60a").expect("preset").drive().expect("a [drive] table");
    let s = trum_core::solve(&m, &trum_core::OperatingPoint::new(300.0, 0.2, d.voltage_v, d.frequency_hz));
    assert_eq!(v["status"], s.status.as_str());
    for q in trum_core::quantities::QUANTITIES {
        // serde_json's default float parser may be one ulp off, so allow a few ulps
        let (got, want) = (v["quantities"][q.name].as_f64().expect("number"), (q.get)(&s));
        assert!((got - want).abs() <= 4.0 * f64::EPSILON * want.abs(), "{}: {got} vs {want}", q.name);
    }
}

#[test]
fn exit_codes() {
    assert_eq!(run(&["--help"]).0, 0);
    assert_eq!(run(&["--version"]).0, 0);
    assert_eq!(run(&["point"]).0, 2);
    assert_eq!(run(&["map", "--motor", "trum60a", "--torque-nm", "1:2", "-o", "-"]).0, 2);
    let (code, _, err) = run(&["point", "--motor", "no-such-motor", "--preload-n", "250"]);
    assert_eq!(code, 1);
    assert!(err.starts_with("error: unknown preset 'no-such-motor'"), "{err}");
}

#[test]
fn map_to_file_in_process_is_identical_for_any_thread_count() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let path = dir.path().join(format!("m{threads}.csv"));
        let p = path.to_str().unwrap_or_default();
        let args = [
            "map",
            "--motor",
            "trum60-qut",
            "--preload-n",
            "50:400:8",
            "--torque-nm",
            "0:0.8:9",
            "--chunk-points",
            "5",
        ];
        let (code, _, err) = run(&[&args[..], &["--threads", threads, "-q", "-o", p]].concat());
        assert_eq!(code, 0, "{err}");
        outputs.push(std::fs::read(&path).expect("written"));
    }
    assert_eq!(outputs[0], outputs[1]);
    assert_eq!(String::from_utf8_lossy(&outputs[0]).lines().count(), 1 + 8 * 9);
}
