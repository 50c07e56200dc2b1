use super::read::{misnamed, parse_number};
use super::*;
use std::path::{Path, PathBuf};

const SUN2021: &str = include_str!("../../../../tests/data/good/measurements/sun2021_table2.csv");

fn corpus_dir(kind: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data").join(kind).join("measurements")
}

fn good(name: &str) -> Measurements {
    let path = corpus_dir("good").join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    parse_measurements(&bytes, name).unwrap_or_else(|e| panic!("{e}"))
}

/// The layout's checks alone (these tests use values such as 1 N and 3 Hz that the
/// default plausible ranges refuse; `implausible_values_are_refused_with_line_and_column`
/// tests those).
fn parse_str(text: &str) -> Result<Measurements, MeasurementError> {
    parse_measurements_with(text.as_bytes(), "t.csv", &PlausibleRanges::unlimited())
}

fn message(text: &[u8]) -> String {
    match parse_measurements_with(text, "t.csv", &PlausibleRanges::unlimited()) {
        Ok(m) => format!("parsed {} rows", m.len()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn column_table_matches_enum() {
    for (i, c) in Column::ALL.into_iter().enumerate() {
        assert_eq!(c as usize, i);
        assert_eq!(COLUMNS[i].column, c);
        assert_eq!(Column::from_name(c.name()), Some(c));
        // The table is self-consistent: each name reads as its own column, correctly spelled.
        assert_eq!(misnamed(c.name()), Some((c, MisnameReason::Spelling)), "{c}");
    }
    let required: Vec<Column> = Column::ALL.into_iter().filter(|c| c.is_required()).collect();
    assert_eq!(required, Column::REQUIRED);
}

#[test]
fn sun2021_table2_parses() {
    let m = parse_measurements(SUN2021.as_bytes(), "sun2021_table2.csv").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.len(), 4);
    assert_eq!(m.preload_n, [100.0, 200.0, 300.0, 400.0]);
    assert_eq!(m.speed_rpm, [106.0, 144.0, 138.0, 89.0]);
    assert_eq!(m.voltage_v, [150.0; 4]);
    assert_eq!(m.frequency_hz, [42000.0; 4]);
    assert_eq!(m.torque_nm, [0.0; 4]);
    assert_eq!(m.feedback_v, Some(vec![Some(38.0), Some(46.0), Some(40.0), Some(34.0)]));
    assert_eq!(m.run_id, Some(vec![Some("sun2021-table2".to_string()); 4]));
    assert!(m.has(Column::FeedbackV) && m.has(Column::RunId) && !m.has(Column::CurrentA));
    assert_eq!(m.lines, [2, 3, 4, 5]);
    assert!(m.warnings.is_empty());
    assert_eq!(m.to_csv_string(), SUN2021.replace("\r\n", "\n"));
}

fn synthetic() -> Measurements {
    let b = Measurements::builder()
        .column(Column::Efficiency)
        .row(
            Row::new(100.0, 150.0, 42e3, 0.0, 106.0)
                .with_input_power_w(12.345678901234567)
                .with_feedback_v(38.0)
                .with_temperature_c(-12.5)
                .with_run_id("sweep, \"A\""),
        )
        .row(
            Row::new(250.5, 1e-300, 41_999.999_999_999_99, 1.5e-3, 0.1 + 0.2).with_elapsed_s(1e20).with_run_id(" lead"),
        )
        .row(Row::new(f64::MIN_POSITIVE, f64::MAX, 5e-324, 0.0, 0.0).with_current_a(0.6).with_speed_std_rpm(0.75))
        .row(Row::new(400.0, 150.0, 42e3, 0.3, 12.0).with_ambient_c(ABSOLUTE_ZERO_C).with_run_id(""));
    b.build().unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn round_trip_write_parse_identity() {
    let m = synthetic();
    assert_eq!(m.len(), 4);
    assert!(m.has(Column::Efficiency) && m.efficiency == Some(vec![None; 4]));
    assert!(!m.has(Column::ElapsedS) || m.elapsed_s.as_ref().is_some_and(|v| v[0].is_none()));
    let text = m.to_csv_string();
    // (extreme values on purpose: the writer's number forms; so no plausibility check)
    let back = parse_measurements_with(text.as_bytes(), "synth.csv", &PlausibleRanges::unlimited())
        .unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(back, m, "{text}");
    assert_eq!(back.to_csv_string(), text);
    assert_eq!(back.run_id_at(0), Some("sweep, \"A\""));
    assert_eq!(back.run_id_at(1), Some(" lead"));
    assert_eq!(back.run_id_at(3), None);
    for row in 0..m.len() {
        assert_eq!(back.row(row), m.row(row));
    }
}

#[test]
fn rows_rebuild_identically() {
    let m = synthetic();
    let mut b = MeasurementsBuilder::new().column(Column::Efficiency);
    for row in 0..m.len() {
        b.push(m.row(row).unwrap_or_default());
    }
    assert_eq!(b.build(), Ok(m));
}

#[test]
fn builder_checks_ranges() {
    let e = Measurements::builder().row(Row::new(100.0, 150.0, 42e3, -0.1, 10.0)).build().err();
    assert_eq!(
        e.map(|e| e.to_string()).as_deref(),
        Some("synthetic data: line 2, column 'torque_nm': \"-0.1\" is negative; load torque must be >= 0 N·m")
    );
    let e = Measurements::builder()
        .row(Row::new(100.0, 150.0, 42e3, 0.0, 10.0))
        .row(Row::new(100.0, 150.0, 42e3, 0.0, f64::NAN))
        .build()
        .err();
    assert_eq!(
        e.map(|e| e.to_string()).as_deref(),
        Some(
            "synthetic data: line 3, column 'speed_rpm': \"NaN\" is not a finite number; rotor speed must be >= 0 rpm"
        )
    );
    let e = Measurements::builder().row(Row::new(1.0, 1.0, 1.0, 0.0, 0.0).with_run_id("a\nb")).build().err();
    assert_eq!(e.map(|e| e.kind), Some(MeasurementErrorKind::LineBreakInText));
    assert_eq!(Measurements::builder().build().err().map(|e| e.kind), Some(MeasurementErrorKind::NoDataRows));
}

#[test]
fn bad_corpus_gives_exact_messages() {
    let dir = corpus_dir("bad");
    let mut entries: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    entries.sort();
    assert!(entries.len() >= 20, "only {} bad files", entries.len());
    let mut failures = Vec::new();
    for path in &entries {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_string();
        let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let expected_path = path.with_extension("expected");
        let expected = std::fs::read_to_string(&expected_path)
            .unwrap_or_else(|e| panic!("{}: {e}", expected_path.display()))
            .trim_end()
            .replace("{source}", &name);
        let got = match parse_measurements(&bytes, &name) {
            Ok(m) => format!("parsed {} rows without error", m.len()),
            Err(e) => {
                // Structured fields agree with the message.
                assert_eq!(e.source_name, name);
                assert!(e.line.is_some(), "{name}: no line");
                e.to_string()
            }
        };
        if got != expected {
            failures.push(format!("{name}:\n  expected: {expected}\n  got:      {got}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_expected_file_has_a_csv() {
    let dir = corpus_dir("bad");
    for e in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{e}")).flatten() {
        let p = e.path();
        let ext = p.extension().and_then(|x| x.to_str()).unwrap_or_default();
        assert!(ext == "csv" || ext == "expected", "stray file {}", p.display());
        assert!(p.with_extension("csv").exists() && p.with_extension("expected").exists(), "{}", p.display());
    }
}

#[test]
fn good_corpus_parses_and_round_trips() {
    let dir = corpus_dir("good");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{e}")).flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        let m = good(&name);
        let back = parse_str(&m.to_csv_string()).unwrap_or_else(|e| panic!("{name}: {e}"));
        for c in Column::ALL {
            assert_eq!(back.has(c), m.has(c), "{name}: {c}");
            for row in 0..m.len() {
                assert_eq!(back.value(c, row), m.value(c, row), "{name}: {c} row {row}");
            }
        }
        assert_eq!(back.run_id, m.run_id, "{name}");
        n += 1;
    }
    assert!(n >= 7);
}

#[test]
fn bom_and_crlf() {
    let m = good("bom_crlf.csv");
    assert_eq!(m.len(), 4);
    assert_eq!(m.lines, [2, 3, 4, 5]);
    assert_eq!(m.run_id_at(3), Some("bench-a"));
    assert!(m.warnings.is_empty());
}

#[test]
fn blank_lines_skipped_and_lines_counted() {
    let m = good("blank_lines.csv");
    assert_eq!(m.len(), 3);
    assert_eq!(m.lines, [4, 6, 9]);
    assert_eq!(m.speed_rpm, [106.0, 144.0, 138.0]);
}

#[test]
fn reordered_columns() {
    let m = good("reordered_columns.csv");
    assert_eq!(m.preload_n, [100.0, 200.0]);
    assert_eq!(m.voltage_v, [150.0, 150.0]);
    assert_eq!(m.speed_rpm, [106.0, 144.0]);
    assert_eq!(m.feedback_v, Some(vec![Some(38.0), Some(46.0)]));
    assert_eq!(
        m.to_csv_string().lines().next(),
        Some("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm,feedback_v,run_id")
    );
}

#[test]
fn unknown_columns_one_warning() {
    let m = good("unknown_columns.csv");
    assert_eq!(m.len(), 2);
    assert_eq!(
        m.warnings,
        ["unknown_columns.csv: line 1: ignoring unknown columns 'operator', 'notes' (not part of the measurement layout)"]
    );
    assert_eq!(m.extra_columns.len(), 2);
    assert_eq!(
        m.extra_columns[1],
        ExtraColumn { name: "notes".into(), cells: vec!["first point".into(), String::new()] }
    );
    assert!(!m.to_csv_string().contains("operator"));
}

#[test]
fn misnamed_column_beside_the_right_one_is_ignored_with_warning() {
    let m = good("misnamed_beside_correct.csv");
    assert_eq!(m.preload_n, [100.0]);
    assert_eq!(m.warnings.len(), 1);
    assert!(m.warnings[0].contains("'preload_kn'"));
}

#[test]
fn optional_cells_quotes_and_whitespace() {
    let m = good("optional_cells.csv");
    assert_eq!(m.len(), 3);
    assert_eq!(m.frequency_hz, [42000.0; 3]);
    assert_eq!(m.torque_nm, [0.05, 0.1, 0.2]);
    assert_eq!(m.speed_rpm, [90.0, 80.0, 60.0]);
    assert_eq!(m.input_power_w, Some(vec![Some(12.5), None, Some(13.75)]));
    assert_eq!(m.current_a, Some(vec![Some(0.22), None, Some(0.6)]));
    assert_eq!(m.efficiency, Some(vec![None, Some(0.31), Some(0.4)]));
    assert_eq!(m.speed_std_rpm, Some(vec![Some(1.5), None, Some(0.8)]));
    assert_eq!(m.run_id, Some(vec![Some("sweep, \"A\"".into()), Some("plain text".into()), None]));
    assert!(!m.has(Column::FeedbackV) && m.feedback_v.is_none());
    assert_eq!(m.value(Column::Efficiency, 0), None);
    assert_eq!(m.value(Column::RunId, 0), None);
    assert_eq!(m.value(Column::PreloadN, 9), None);
}

#[test]
fn time_series() {
    let m = good("time_series.csv");
    assert_eq!(m.elapsed_s, Some(vec![Some(0.0), Some(60.0), Some(120.0), Some(180.0)]));
    assert_eq!(m.temperature_c, Some(vec![Some(22.5), Some(27.25), Some(31.0), Some(-1.5)]));
    assert_eq!(m.ambient_c.as_ref().map(Vec::len), Some(4));
}

#[test]
fn number_grammar() {
    for ok in ["0", "1", "-0", "+2.5", "1.", ".5", "1e3", "1E-3", "1.5e+2", "007", "4.2e4"] {
        assert!(parse_number(ok).is_ok(), "{ok}");
    }
    for (bad, issue) in [
        ("nan", NumberIssue::NotFinite),
        ("NaN", NumberIssue::NotFinite),
        ("-inf", NumberIssue::NotFinite),
        ("Infinity", NumberIssue::NotFinite),
        ("0x10", NumberIssue::Hexadecimal),
        ("1e", NumberIssue::IncompleteExponent),
        ("1.5e-", NumberIssue::IncompleteExponent),
        ("12 N", NumberIssue::UnitInCell),
        ("0.3rpm", NumberIssue::UnitInCell),
        ("1e999", NumberIssue::Overflow),
        ("", NumberIssue::NotANumber),
        (".", NumberIssue::NotANumber),
        ("-", NumberIssue::NotANumber),
        ("e5", NumberIssue::NotANumber),
        ("1_000", NumberIssue::NotANumber),
        ("1 000", NumberIssue::NotANumber),
        ("1..2", NumberIssue::NotANumber),
        ("--1", NumberIssue::NotANumber),
        ("１", NumberIssue::NotANumber),
    ] {
        assert_eq!(parse_number(bad), Err(issue), "{bad}");
    }
}

#[test]
fn misnamed_headers() {
    use MisnameReason::*;
    for (name, expect) in [
        ("preload_kn", Some((Column::PreloadN, WrongUnit))),
        ("Preload (N)", Some((Column::PreloadN, Spelling))),
        ("speed_rad_s", Some((Column::SpeedRpm, WrongUnit))),
        ("speed [rad/s]", Some((Column::SpeedRpm, WrongUnit))),
        ("speed_std_rad_s", Some((Column::SpeedStdRpm, WrongUnit))),
        ("torque_mnm", Some((Column::TorqueNm, WrongUnit))),
        ("Torque (N·m)", Some((Column::TorqueNm, Spelling))),
        ("speed (rev/min)", Some((Column::SpeedRpm, Spelling))),
        ("voltage_vpp", Some((Column::VoltageV, WrongUnit))),
        ("Temperature [°C]", Some((Column::TemperatureC, Spelling))),
        ("input_power_mw", Some((Column::InputPowerW, WrongUnit))),
        ("elapsed_min", Some((Column::ElapsedS, WrongUnit))),
        ("torque", Some((Column::TorqueNm, NoUnit))),
        ("voltage_vrms", Some((Column::VoltageV, WrongUnit))),
        ("temperature_k", Some((Column::TemperatureC, WrongUnit))),
        ("temp_c", Some((Column::TemperatureC, Spelling))),
        ("ambient_temperature_c", Some((Column::AmbientC, Spelling))),
        ("Run ID", Some((Column::RunId, Spelling))),
        ("efficiency_pct", Some((Column::Efficiency, WrongUnit))),
        ("torque_sensor_id", None),
        ("operator", None),
        ("time", None),
        ("notes", None),
    ] {
        assert_eq!(misnamed(name), expect, "{name}");
    }
}

#[test]
fn utf8_error_positions() {
    assert_eq!(
        message(b"preload_\xffn,voltage_v\n"),
        "t.csv: line 1: byte 0xFF at offset 8 is not valid UTF-8; save the file as UTF-8"
    );
    // Truncated multi-byte sequence at the very end.
    assert_eq!(
        message(b"preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n1,2,3,4,\xc3"),
        "t.csv: line 2, column 'speed_rpm': byte 0xC3 at offset 61 is not valid UTF-8; save the file as UTF-8"
    );
    // A quoted comma does not shift the column.
    assert_eq!(
        message(b"run_id,preload_n\r\n\"a,b\",\x80\r\n"),
        "t.csv: line 2, column 'preload_n': byte 0x80 at offset 24 is not valid UTF-8; save the file as UTF-8"
    );
}

#[test]
fn quoted_cells_keep_whitespace_and_line_breaks() {
    let m = parse_str(
        "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm,run_id\n1,2,3,0,0,\"a\nb\"\n2,2,3,0,0, \"  x \" \n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.run_id, Some(vec![Some("a\nb".into()), Some("  x ".into())]));
    assert_eq!(m.lines, [2, 4]);
    // Numbers may be quoted too.
    let m = parse_str("\"preload_n\",voltage_v,frequency_hz,torque_nm,speed_rpm\n\"1.5\",2,3,0,0\r")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.preload_n, [1.5]);
}

#[test]
fn errors_are_structured() {
    let e = parse_str("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n1,2,3,-1,0\n").err();
    let e = e.unwrap_or_else(|| panic!("accepted"));
    assert_eq!(e.source_name, "t.csv");
    assert_eq!(e.line, Some(2));
    assert_eq!(e.column.as_deref(), Some("torque_nm"));
    assert_eq!(e.kind, MeasurementErrorKind::OutOfRange { column: Column::TorqueNm, text: "-1".into(), value: -1.0 });
}

#[test]
fn first_error_in_file_order_wins() {
    // The bad cell on line 2 comes before the ragged row on line 3.
    assert_eq!(
        message(b"preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n1,2,3,0,x\n1,2\n"),
        "t.csv: line 2, column 'speed_rpm': \"x\" is not a number; numbers must be plain decimals such as 12.5 or 1.5e-3"
    );
}

/// Tiny deterministic generator (no dependency) for the no-panic sweep.
fn lcg(state: &mut u64) -> u64 {
    *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    *state >> 33
}

#[test]
fn never_panics_on_mutated_input() {
    let seeds: Vec<Vec<u8>> = std::fs::read_dir(corpus_dir("good"))
        .into_iter()
        .flatten()
        .chain(std::fs::read_dir(corpus_dir("bad")).into_iter().flatten())
        .flatten()
        .filter_map(|e| std::fs::read(e.path()).ok())
        .collect();
    assert!(!seeds.is_empty());
    let alphabet = b",\"\r\n \t0.e-+x\xef\xbb\xbf\xff\xc3";
    let mut s = 42_u64;
    for i in 0..20_000 {
        let mut b = seeds[i % seeds.len()].clone();
        for _ in 0..=(lcg(&mut s) % 4) {
            let pos = if b.is_empty() { 0 } else { (lcg(&mut s) as usize) % (b.len() + 1) };
            let byte = alphabet[(lcg(&mut s) as usize) % alphabet.len()];
            match lcg(&mut s) % 3 {
                0 => b.insert(pos, byte),
                1 if pos < b.len() => {
                    b.remove(pos);
                }
                _ if pos < b.len() => b[pos] = byte,
                _ => b.push(byte),
            }
        }
        match parse_measurements(&b, "fuzz.csv") {
            Ok(m) => {
                let n = m.len();
                assert!(n > 0 && m.lines.len() == n);
                // Whatever parsed writes and reads back to the same values.
                let back = parse_str(&m.to_csv_string()).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(back.len(), n);
            }
            Err(e) => {
                let msg = e.to_string();
                assert!(msg.starts_with("fuzz.csv: line "), "{msg}");
            }
        }
    }
}

#[test]
fn implausible_values_are_refused_with_line_and_column() {
    let head = "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n250,150,42000,0,120\n";
    for (row, column, text) in [
        ("250,150,42000,0,1e5", "speed_rpm", "1e5"),
        ("1e308,150,42000,0,120", "preload_n", "1e308"),
        ("5e-324,150,42000,0,120", "preload_n", "5e-324"),
        ("250,150,42,0,120", "frequency_hz", "42"),
        ("250,150,42000,0,1e300", "speed_rpm", "1e300"),
    ] {
        let e = parse_measurements(format!("{head}{row}\n").as_bytes(), "t.csv")
            .err()
            .unwrap_or_else(|| panic!("{row} accepted"));
        assert_eq!(e.line, Some(3), "{row}");
        assert_eq!(e.column.as_deref(), Some(column), "{row}");
        assert!(matches!(&e.kind, MeasurementErrorKind::Implausible { text: t, .. } if t == text), "{e}");
        assert!(e.to_string().contains("outside the plausible range"), "{e}");
        // lifted: read as written
        let m = parse_measurements_with(format!("{head}{row}\n").as_bytes(), "t.csv", &PlausibleRanges::unlimited())
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.len(), 2);
    }
    // a wider range for one column only
    let mut r = PlausibleRanges::default();
    r.parse_assignment("speed_rpm=0:2e5").unwrap_or_else(|e| panic!("{e}"));
    assert!(parse_measurements_with(format!("{head}250,150,42000,0,1e5\n").as_bytes(), "t.csv", &r).is_ok());
    assert!(parse_measurements_with(format!("{head}1e308,150,42000,0,1\n").as_bytes(), "t.csv", &r).is_err());
    // open ends and `any`
    r.parse_assignment("preload_n=:").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.get(Column::PreloadN), (f64::NEG_INFINITY, f64::INFINITY));
    r.parse_assignment("torque_nm = any").unwrap_or_else(|e| panic!("{e}"));
    assert!(r.contains(Column::TorqueNm, 1e300));
    for (bad, why) in [
        ("speed", "expected COLUMN=LOW:HIGH"),
        ("run_id=0:1", "not a numeric measurement column"),
        ("speedrpm=0:1", "not a numeric measurement column"),
        ("speed_rpm=5:1", "above the high end"),
        ("speed_rpm=0:inf", "not a finite number"),
        ("speed_rpm=10", "expected LOW:HIGH"),
    ] {
        let e = PlausibleRanges::default().parse_assignment(bad).err().unwrap_or_else(|| panic!("{bad} accepted"));
        assert!(e.contains(why), "{bad}: {e}");
    }
    // every default range holds docs/MEASUREMENTS.md's own example values and lies inside the layout's range
    for c in COLUMNS.iter().filter(|c| c.column.is_numeric()) {
        let (lo, hi) = c.plausible;
        assert!(lo < hi && lo.is_finite() && hi.is_finite(), "{}", c.name);
        assert!(c.column.check(hi).is_ok(), "{}", c.name);
    }
}

#[test]
fn another_delimiter_and_utf16_are_named() {
    let e = message(b"preload_n;voltage_v;frequency_hz;torque_nm;speed_rpm\n250;150;42000;0;120\n");
    assert!(e.contains("line 1") && e.contains("separated by ';'") && e.contains("comma-separated"), "{e}");
    let e = message(b"preload_n\tvoltage_v\tfrequency_hz\ttorque_nm\tspeed_rpm\n250\t150\t42000\t0\t120\n");
    assert!(e.contains("separated by '\t'"), "{e}");
    let text = "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n250,150,42000,0,120\n";
    let le: Vec<u8> = text.encode_utf16().flat_map(u16::to_le_bytes).collect();
    let be: Vec<u8> = text.encode_utf16().flat_map(u16::to_be_bytes).collect();
    let with_bom: Vec<u8> = [0xFF, 0xFE].into_iter().chain(le.iter().copied()).collect();
    for (bytes, endian) in [(&le, "little"), (&be, "big"), (&with_bom, "little")] {
        let e = message(bytes);
        assert!(e.contains(&format!("UTF-16 ({endian}-endian), not UTF-8")), "{e}");
    }
}

#[test]
fn ten_thousand_unknown_columns_give_one_short_warning_in_linear_time() {
    let n = 10_000;
    let mut head = String::from("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm");
    let mut row = String::from("250,150,42000,0,120");
    for i in 0..n {
        head += &format!(",x{i}");
        row += ",1";
    }
    let text = format!("{head}\n{row}\n{row}\n");
    let t0 = std::time::Instant::now();
    let m = parse_str(&text).unwrap_or_else(|e| panic!("{e}"));
    // quadratic handling took seconds at this size; linear takes milliseconds
    assert!(t0.elapsed() < std::time::Duration::from_secs(1), "{:?}", t0.elapsed());
    assert_eq!(m.extra_columns.len(), n);
    assert_eq!(m.extra_columns[n - 1].cells, ["1", "1"]);
    assert_eq!(m.warnings.len(), 1);
    assert!(m.warnings[0].len() < 300 && m.warnings[0].contains("and 9990 more"), "{}", m.warnings[0]);
}

/// A motor file's `[plausible]` table replaces the ranges it names (the others keep their
/// defaults), and the reader then accepts what the defaults refuse.
#[test]
fn plausible_table_of_a_motor_file_sets_the_ranges_it_names() {
    let text =
        "preset = \"trum60a\"\n\n[plausible]\nspeed_rpm = [0, 20000]\ntemperature_c = \"any\"\npreload_n = [1, inf]\n";
    let r = crate::params::plausible_from_toml_str(text, "m.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.get(Column::SpeedRpm), (0.0, 20_000.0));
    assert_eq!(r.get(Column::TemperatureC), (f64::NEG_INFINITY, f64::INFINITY));
    assert_eq!(r.get(Column::PreloadN), (1.0, f64::INFINITY));
    let d = PlausibleRanges::default();
    assert_eq!(r.get(Column::VoltageV), d.get(Column::VoltageV));
    assert_eq!(r.get(Column::FrequencyHz), d.get(Column::FrequencyHz));
    let csv = "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n250,150,42000,0,15000\n";
    assert!(parse_measurements(csv.as_bytes(), "t.csv").is_err(), "15000 rev/min passes the default range");
    assert!(parse_measurements_with(csv.as_bytes(), "t.csv", &r).is_ok());
    // the motor reader accepts the table (it is not an unknown section) and ignores it
    let m = crate::Motor::from_toml_str(text, "m.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.preset.as_deref(), Some("trum60a"));
    // no table: the defaults
    assert_eq!(crate::params::plausible_from_toml_str("preset = \"trum60a\"\n", "m.toml").ok(), Some(d));
}

/// Every numeric column of the layout is a key of `[plausible]` (the serde table and the
/// column list agree), and the text column is not.
#[test]
fn every_numeric_column_is_a_plausible_key() {
    let mut text = String::from("preset = \"trum60a\"\n[plausible]\n");
    for c in COLUMNS.iter().filter(|c| c.column.is_numeric()) {
        text.push_str(&format!("{} = \"any\"\n", c.name));
    }
    let r = crate::params::plausible_from_toml_str(&text, "m.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r, PlausibleRanges::unlimited());
    let e = crate::params::plausible_from_toml_str("[plausible]\nrun_id = \"any\"\n", "m.toml")
        .err()
        .unwrap_or_else(|| panic!("run_id accepted"));
    assert_eq!((e.key.as_str(), e.line), ("plausible.run_id", Some(2)), "{e}");
}

/// Bad `[plausible]` entries are errors naming the file, the line and the key.
#[test]
fn bad_plausible_entries_name_file_line_and_key() {
    for (entry, key, words) in [
        ("speedrpm = [0, 1]", "plausible.speedrpm", "unknown key `speedrpm`"),
        ("speed_rpm = [2e4, 0]", "plausible.speed_rpm", "low end 20000 is above the high end 0"),
        ("speed_rpm = [0, nan]", "plausible.speed_rpm", "nan is not a bound"),
        ("speed_rpm = [0]", "plausible.speed_rpm", "expected [LOW, HIGH]"),
        ("speed_rpm = \"some\"", "plausible.speed_rpm", "expected [LOW, HIGH]"),
        ("speed_rpm = 100", "plausible.speed_rpm", "expected [LOW, HIGH]"),
        ("speed_rpm = [inf, inf]", "plausible.speed_rpm", "holds no number"),
    ] {
        let text = format!("preset = \"trum60a\"\n# ranges of this bench\n[plausible]\n{entry}\n");
        let e = crate::params::plausible_from_toml_str(&text, "bench.toml")
            .err()
            .unwrap_or_else(|| panic!("{entry} accepted"));
        let msg = e.to_string();
        assert_eq!(e.key, key, "{entry}: {msg}");
        assert_eq!(e.line, Some(4), "{entry}: {msg}");
        assert!(msg.starts_with("bench.toml: line 4, key '") && msg.contains(words), "{entry}: {msg}");
    }
}
