//! The presets against the figures their papers quote (tests/data/papers/): one test per
//! figure, with its tolerance. Rows the calibration reaches assert the target; rows it
//! cannot reach with plausible values (docs/PRESETS.md says why) assert the value the
//! preset reaches, in a band, so that a change which moves it is seen.
//!
//! `TRUM_PAPERS_TABLE=FILE cargo test --release --test papers` also writes every row as
//! a Markdown table line (figure, paper, trum, tolerance) for docs/PRESETS.md.

use std::io::Write as _;
use trum_core::criterion::{evaluate, region_overlap, CriterionConfig, CriterionResult, Edge};
use trum_core::presets::preset;
use trum_core::sweep::Axis;
use trum_core::{solve, Motor, OperatingPoint, Solution, Status};

// Tolerances. Where the target is reached the tolerance is the target; where it is not
// (docs/PRESETS.md, "Targets not reached", says why) the band holds the preset's value
// and is marked "not reached" in the table.
const TOL_XC150: f64 = 0.16; // not reached: -14.3 %
const TOL_XC200: f64 = 0.25; // not reached: -22.3 %
const TOL_SLOPE: f64 = 0.45; // not reached: +39 % (the stator clamps at 570 N, 43 kHz)
const STALL_PEAK_BAND: (f64, f64) = (286.0, 326.0); // not reached: 306 N
const EFFICIENCY_PEAK_BAND: (f64, f64) = (100.0, 120.0); // not reached: 100 N, the lowest candidate
const SPEED_TOL: [f64; 4] = [0.27, 0.10, 0.12, 0.25]; // 100, 300, 400 N not reached: +25, -10.3, +22 %
const FEEDBACK_TOL: [f64; 4] = [0.08, 0.14, 0.05, 0.05]; // 100 and 200 N not reached: +6.8, -12.4 %
const CURRENT50_BAND: (f64, f64) = (0.05, 0.09); // not reached: 0.070 A
const CURRENT400_BAND: (f64, f64) = (0.13, 0.17); // not reached: 0.153 A
const AMPLITUDE_PEAK_N: (f64, f64) = (100.0, 140.0);
const AMPLITUDE_PEAK_UM: (f64, f64) = (1.2, 1.4); // not reached: 1.32 µm
const EFFICIENCY_BAND: (f64, f64) = (0.30, 0.45); // reached: 44 %, a real TRUM's 30-45 %
                                                  // trum60a draws 20.9 W at 400 N, 0.3 N·m, 43 kHz: 5 % above the 20 W the calibration
                                                  // holds (docs/PRESETS.md, "Targets not reached")
const TOP_POWER_W: f64 = 22.0;

fn band(b: (f64, f64), unit: &str, reached: bool) -> String {
    format!("{}-{} {unit}{}", b.0, b.1, if reached { "" } else { " (not reached)" })
}

fn pct(t: f64, reached: bool) -> String {
    format!("{:.0} %{}", 100.0 * t, if reached { "" } else { " (not reached)" })
}

const CHEN: &str = include_str!("data/papers/chen2020_figures.csv");
const SUN: &str = include_str!("data/papers/sun2021_figures.csv");
const TABLE2: &str = include_str!("data/papers/sun2021_table2.csv");

/// The value of `quantity` (at `preload`, if given) in a figure table.
fn paper(table: &str, quantity: &str, preload: Option<&str>) -> f64 {
    let mut lines = table.lines();
    let head: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).expect("column");
    let (q, v, p) = (col("quantity"), col("value"), col("preload_n"));
    lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|c| c[q] == quantity && preload.is_none_or(|f| c[p] == f))
        .map(|c| c[v].parse().expect("number"))
        .unwrap_or_else(|| panic!("{quantity} at {preload:?} not in the table"))
}

/// Sun et al. 2021 Table 2 rows: (preload, speed, feedback voltage).
fn table2() -> Vec<(f64, f64, f64)> {
    TABLE2
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<f64> = l.split(',').take(6).map(|x| x.parse().expect("number")).collect();
            (c[0], c[4], c[5])
        })
        .collect()
}

fn no_load(m: &Motor, f: f64, v: f64, hz: f64) -> Solution {
    solve(m, &OperatingPoint::new(f, 0.0, v, hz))
}

/// Records one row for docs/PRESETS.md when TRUM_PAPERS_TABLE is set.
fn record(figure: &str, paper: &str, trum: String, tolerance: &str) {
    if let Ok(path) = std::env::var("TRUM_PAPERS_TABLE") {
        let mut f = std::fs::OpenOptions::new().create(true).append(true).open(path).expect("table file");
        writeln!(f, "| {figure} | {paper} | {trum} | {tolerance} |").expect("write");
    }
}

/// Preload of the largest value, refined by the parabola through it and its neighbours.
fn peak(xs: &[f64], ys: &[f64]) -> f64 {
    let i = (0..ys.len()).filter(|&j| ys[j].is_finite()).fold(0, |m, j| if ys[j] > ys[m] { j } else { m });
    if i == 0 || i + 1 >= ys.len() {
        return xs[i];
    }
    let (l, c, r) = (ys[i - 1], ys[i], ys[i + 1]);
    let d = 2.0 * c - l - r;
    xs[i] + if d > 0.0 { 0.5 * (xs[i + 1] - xs[i]) * (r - l) / d } else { 0.0 }
}

fn trum60a() -> Motor {
    preset("trum60a").expect("preset")
}

/// The criterion of `trum optimize --motor trum60a --preload-n 100:500:41` (the preset's
/// drive, 200 V and 42 kHz: Chen et al. 2020 Fig. 8).
fn trum60a_criterion() -> CriterionResult {
    let m = trum60a();
    let d = trum_core::presets::find("trum60a").expect("preset").drive().expect("drive");
    let cfg = CriterionConfig {
        preload_n: Axis::linspace(100.0, 500.0, 41),
        voltage_v: d.voltage_v,
        frequency_hz: d.frequency_hz,
        ..CriterionConfig::seed000()
    };
    evaluate(&m, &cfg, &mut |_, _| {}).expect("criterion")
}

/// The criterion at 200 V, 43 kHz (Chen et al. 2020's drive of Fig. 5-7) at `n` preloads
/// from 150 to 450 N, 8 load torques a preload.
fn trum60a_criterion_43khz(n: usize) -> CriterionResult {
    let cfg = CriterionConfig {
        preload_n: Axis::linspace(150.0, 450.0, n),
        voltage_v: 200.0,
        frequency_hz: 43e3,
        torque_samples: 8,
        ..CriterionConfig::seed000()
    };
    evaluate(&trum60a(), &cfg, &mut |_, _| {}).expect("criterion")
}

/// Chen et al. 2020 section 4.3 (Fig. 7, 200 V, 43 kHz): contact angle 24.15° at 150 N and
/// 28.94° at 200 N.
#[test]
fn chen2020_contact_angles() {
    let m = trum60a();
    for (f, tol) in [("150", TOL_XC150), ("200", TOL_XC200)] {
        let want = paper(CHEN, "contact_angle_deg", Some(f));
        let got = no_load(&m, f.parse().expect("n"), 200.0, 43e3).contact_angle_deg;
        record(
            &format!("Chen 2020 § 4.3: contact angle at {f} N"),
            &format!("{want}°"),
            format!("{got:.2}°"),
            &pct(tol, tol <= 0.02),
        );
        assert!((got / want - 1.0).abs() <= tol, "Xc({f} N) = {got}, paper {want}");
    }
}

/// Chen et al. 2020 section 4.1 (Fig. 3a, 200 V, 43 kHz): mean contact-angle slope 0.033°/N
/// over 100-570 N.
#[test]
fn chen2020_contact_angle_slope() {
    let m = trum60a();
    let want = paper(CHEN, "contact_angle_slope_deg_per_n", None);
    let x = |f: f64| no_load(&m, f, 200.0, 43e3).contact_angle_deg;
    let got = (x(570.0) - x(100.0)) / 470.0;
    record(
        "Chen 2020 § 4.1: contact-angle slope 100-570 N",
        &format!("{want} °/N"),
        format!("{got:.4} °/N"),
        &pct(TOL_SLOPE, false),
    );
    assert!((got / want - 1.0).abs() <= TOL_SLOPE, "slope {got}, paper {want}");
}

/// The contact scale s = K_f·ε·R_sc·ξ·(2N/k) [N] that a Winkler contact (Chen et al. 2020
/// eq. 3 and 6, trum's contact) needs for a preload F and a contact angle Xc [deg, full
/// arc, N = 9]: F = s·∫_0^φ0 (cos θ − cos φ0) dθ with φ0 = π·Xc/40, by quadrature.
fn winkler_scale_n(preload_n: f64, contact_angle_deg: f64) -> f64 {
    let phi0 = std::f64::consts::PI * contact_angle_deg / 40.0;
    let (g, _) = trum_core::quad::integrate(|t: f64| t.cos() - phi0.cos(), 0.0, phi0, 1e-14, 1e-12);
    // the closed form of the same integral, sin φ0 − φ0·cos φ0
    assert!((g - (phi0.sin() - phi0 * phi0.cos())).abs() < 1e-10, "{g}");
    preload_n / g
}

/// Chen et al. 2020's contact figures are not one Winkler contact curve at a monotone
/// amplitude: its angles at 150 and 200 N (section 4.3) need the contact scale K_f·ε·ξ to
/// fall by 7 %, and that scale clamps the stator (contact over the whole wave) at about
/// 300 N, where the paper still measures up to 400 N (Fig. 8); its 0.033 °/N from the
/// 150 N angle to 570 N (section 4.1) needs the scale to almost double. A preset whose
/// amplitude rises with preload (the stiffening both papers model) can meet the slope or
/// the two angles, not both (docs/PRESETS.md, "Targets not reached").
#[test]
fn chen2020_contact_figures_need_a_falling_then_rising_contact_scale() {
    let (x150, x200) = (paper(CHEN, "contact_angle_deg", Some("150")), paper(CHEN, "contact_angle_deg", Some("200")));
    let slope = paper(CHEN, "contact_angle_slope_deg_per_n", None);
    let (s150, s200) = (winkler_scale_n(150.0, x150), winkler_scale_n(200.0, x200));
    assert!((s200 / s150 - 0.929).abs() < 0.002, "{s150} -> {s200} N");
    // full contact (φ0 = π) at the 150 N scale: F = π·s
    let clamp = std::f64::consts::PI * s150;
    assert!((290.0..310.0).contains(&clamp), "clamps at {clamp} N");
    let s570 = winkler_scale_n(570.0, x150 + slope * 420.0);
    assert!((1.85..1.97).contains(&(s570 / s150)), "{s150} -> {s570} N");
}

/// Chen et al. 2020 Fig. 8c (200 V, 42 kHz): the stall torque peaks at 260 N.
#[test]
fn chen2020_stall_torque_peak() {
    let r = trum60a_criterion();
    let xs: Vec<f64> = r.rows.iter().map(|r| r.preload_n).collect();
    let ys: Vec<f64> = r.rows.iter().map(|r| r.stall_torque_nm).collect();
    let got = peak(&xs, &ys);
    let want = paper(CHEN, "stall_torque_peak_n", None);
    record(
        "Chen 2020 Fig. 8c: stall-torque peak",
        &format!("{want} N"),
        format!("{got:.0} N"),
        &band(STALL_PEAK_BAND, "N", false),
    );
    assert!(STALL_PEAK_BAND.0 <= got && got <= STALL_PEAK_BAND.1, "stall-torque peak at {got} N, paper {want} N");
    // the stall torque is where the loaded rotor stops: just below it the rotor turns
    let m = trum60a();
    let row = &r.rows[20];
    let at = |t: f64| solve(&m, &OperatingPoint::new(row.preload_n, t, 200.0, 42e3)).status;
    assert_eq!(at(row.stall_torque_nm * (1.0 - 1e-6)), Status::Ok, "{row:?}");
    assert_eq!(at(row.stall_torque_nm * (1.0 + 1e-6)), Status::Stall, "{row:?}");
}

/// Chen et al. 2020 Fig. 8c (200 V, 42 kHz): the maximum efficiency peaks at 320 N.
#[test]
fn chen2020_max_efficiency_peak() {
    let r = trum60a_criterion();
    let xs: Vec<f64> = r.rows.iter().map(|r| r.preload_n).collect();
    let ys: Vec<f64> = r.rows.iter().map(|r| r.max_efficiency).collect();
    let got = peak(&xs, &ys);
    let want = paper(CHEN, "max_efficiency_peak_n", None);
    record(
        "Chen 2020 Fig. 8c: max-efficiency peak",
        &format!("{want} N"),
        format!("{got:.0} N"),
        &band(EFFICIENCY_PEAK_BAND, "N", false),
    );
    assert!(
        EFFICIENCY_PEAK_BAND.0 <= got && got <= EFFICIENCY_PEAK_BAND.1,
        "max-efficiency peak at {got} N, paper {want} N"
    );
}

/// Chen et al. 2020 section 5: optimum region 260-320 N; the preset's criterion region
/// covers at least half of it and its optimum is not on the edge of the searched range.
#[test]
fn chen2020_optimum_region() {
    let r = trum60a_criterion();
    let want = (paper(CHEN, "optimum_region_low_n", None), paper(CHEN, "optimum_region_high_n", None));
    let (_, frac) = region_overlap(r.region_n, want);
    record(
        "Chen 2020 § 5: optimum region",
        &format!("{}-{} N", want.0, want.1),
        format!(
            "{}-{} N (optimum {} N; {:.0} % of the paper's region)",
            r.region_n.0,
            r.region_n.1,
            r.optimum_preload_n,
            100.0 * frac
        ),
        "overlap ≥ 50 %",
    );
    assert!(frac >= 0.5, "region {:?} covers {frac} of {want:?}", r.region_n);
    assert_eq!(r.optimum_edge(), Edge::Interior, "optimum {} on the edge", r.optimum_preload_n);
}

/// Chen et al. 2020 section 4.3 (Fig. 6, 200 V, 43 kHz): the speed fluctuation falls as
/// the preload rises (up to 475 N).
#[test]
fn chen2020_speed_fluctuation_falls() {
    let r = trum60a_criterion_43khz(7);
    let sd: Vec<f64> = r.rows.iter().map(|r| r.speed_std_rpm).collect();
    record(
        "Chen 2020 § 4.3: speed fluctuation 150 → 450 N",
        "falls",
        format!("{:.3} → {:.3} rpm (350 N), {:.3} rpm (450 N)", sd[0], sd[4], sd[6]),
        "falls at every 50 N step to 350 N; 400-450 N not reached",
    );
    // reached from 150 to 350 N; above, the stator nears clamping at 43 kHz and the
    // fluctuation rises again (the paper: from 475 N)
    assert!(sd[..5].windows(2).all(|w| w[1] < w[0]), "{sd:?}");
    assert!(sd[6] > sd[4], "{sd:?}");
}

// ---- Sun et al. 2021, TRUM-60 at 150 V, 42 kHz ----

fn qut() -> Motor {
    preset("trum60-qut").expect("preset")
}

/// Sun et al. 2021 Table 2: no-load speeds and feedback voltages at 100-400 N.
#[test]
fn sun2021_table2_speeds_and_feedback() {
    let m = qut();
    for (i, (f, rpm, fb)) in table2().into_iter().enumerate() {
        let s = no_load(&m, f, 150.0, 42e3);
        record(
            &format!("Sun 2021 Table 2: no-load speed at {f} N"),
            &format!("{rpm} rpm"),
            format!("{:.0} rpm", s.speed_rpm),
            &pct(SPEED_TOL[i], SPEED_TOL[i] <= 0.10),
        );
        record(
            &format!("Sun 2021 Table 2: feedback voltage at {f} N"),
            &format!("{fb} V"),
            format!("{:.1} V", s.feedback_v),
            &pct(FEEDBACK_TOL[i], FEEDBACK_TOL[i] <= 0.05),
        );
        assert!((s.speed_rpm / rpm - 1.0).abs() <= SPEED_TOL[i], "speed at {f} N: {} rpm, paper {rpm}", s.speed_rpm);
        assert!(
            (s.feedback_v / fb - 1.0).abs() <= FEEDBACK_TOL[i],
            "feedback at {f} N: {} V, paper {fb}",
            s.feedback_v
        );
    }
    // not reached: the paper's speed rises from 100 to 200 N (106 → 144 rpm); the preset's
    // falls, by at most 5 %
    let (v100, v200) = (no_load(&m, 100.0, 150.0, 42e3).speed_rpm, no_load(&m, 200.0, 150.0, 42e3).speed_rpm);
    record(
        "Sun 2021 Table 2: speed rise 100 → 200 N",
        "+36 %",
        format!("{:+.1} %", 100.0 * (v200 / v100 - 1.0)),
        "rise (not reached)",
    );
    assert!(v200 < v100 && v200 > 0.95 * v100, "{v100} -> {v200} rpm");
}

/// Sun et al. 2021 section 3.1 (Fig. 6): no-load input current 0.22 A at 50 N, 0.6 A at 400 N.
#[test]
fn sun2021_input_current() {
    let m = qut();
    let i50 = no_load(&m, 50.0, 150.0, 42e3).current_a;
    let i400 = no_load(&m, 400.0, 150.0, 42e3).current_a;
    let (w50, w400) = (paper(SUN, "current_a", Some("50")), paper(SUN, "current_a", Some("400")));
    record(
        "Sun 2021 § 3.1: input current at 50 N",
        &format!("{w50} A"),
        format!("{i50:.3} A"),
        &band(CURRENT50_BAND, "A", false),
    );
    record(
        "Sun 2021 § 3.1: input current at 400 N",
        &format!("{w400} A"),
        format!("{i400:.3} A"),
        &band(CURRENT400_BAND, "A", false),
    );
    // the trend is reached: the current rises with preload
    assert!(i400 > i50, "{i50} -> {i400} A");
    assert!(CURRENT50_BAND.0 <= i50 && i50 <= CURRENT50_BAND.1, "I(50 N) = {i50} A, paper {w50}");
    assert!(CURRENT400_BAND.0 <= i400 && i400 <= CURRENT400_BAND.1, "I(400 N) = {i400} A, paper {w400}");
}

/// Sun et al. 2021 section 3.2 (Fig. 7c): the amplitude peaks at 1.6 µm near 120 N.
#[test]
fn sun2021_amplitude_peak() {
    let m = qut();
    let xs: Vec<f64> = (0..=38).map(|i| 20.0 + 10.0 * i as f64).collect();
    let ws: Vec<f64> = xs.iter().map(|&f| no_load(&m, f, 150.0, 42e3).amplitude_m * 1e6).collect();
    let at = peak(&xs, &ws);
    let wmax = ws.iter().cloned().fold(f64::NAN, f64::max);
    let want = paper(SUN, "amplitude_peak_um", None);
    record(
        "Sun 2021 § 3.2: amplitude peak",
        &format!("{want} µm at 120 N"),
        format!("{wmax:.2} µm at {at:.0} N"),
        &format!("{}, {}", band(AMPLITUDE_PEAK_N, "N", true), band(AMPLITUDE_PEAK_UM, "µm", false)),
    );
    assert!(AMPLITUDE_PEAK_N.0 <= at && at <= AMPLITUDE_PEAK_N.1, "peak at {at} N");
    assert!(AMPLITUDE_PEAK_UM.0 <= wmax && wmax <= AMPLITUDE_PEAK_UM.1, "peak {wmax} µm");
}

/// Sun et al. 2021 Fig. 9a grid (50-400 N; 0-0.4 N·m, the paper's typical torque 0.2 N·m in
/// the middle): a plausible efficiency (a real TRUM: tens of percent) and few clamped points.
#[test]
fn sun2021_efficiency_grid() {
    let m = qut();
    let (mut clamped, mut total, mut emax) = (0, 0, 0.0f64);
    for i in 1..=8 {
        for j in 0..=8 {
            let s = solve(&m, &OperatingPoint::new(50.0 * i as f64, 0.05 * j as f64, 150.0, 42e3));
            total += 1;
            clamped += usize::from(s.status == Status::Clamped);
            emax = emax.max(s.efficiency);
        }
    }
    let share = clamped as f64 / total as f64;
    record(
        "Sun 2021 Fig. 9a grid: largest efficiency",
        "tens of percent",
        format!("{:.0} %", 100.0 * emax),
        &format!("{:.0}-{:.0} %", 100.0 * EFFICIENCY_BAND.0, 100.0 * EFFICIENCY_BAND.1),
    );
    record("Sun 2021 Fig. 9a grid: clamped points", "none", format!("{clamped} of {total}"), "≤ 10 %");
    assert!(EFFICIENCY_BAND.0 <= emax && emax <= EFFICIENCY_BAND.1, "largest efficiency {emax}");
    assert!(share <= 0.10, "{clamped} of {total} clamped");
}

// ---- `trum optimize`: the drive, the edge and the comparison ----

fn run_cli(args: &[&str]) -> (i32, String, String) {
    let argv = std::iter::once("trum").chain(args.iter().copied());
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = trum_cli::run_with_io(argv, &mut out, &mut err);
    (code, String::from_utf8_lossy(&out).into_owned(), String::from_utf8_lossy(&err).into_owned())
}

/// A bare `trum optimize --motor trum60a` runs at the preset's drive (200 V, 42 kHz) and
/// compares its region with the paper's by overlap; an optimum on the edge of the range is
/// reported with a wider range to try; the CLI's numbers are the library's.
#[test]
fn optimize_uses_the_drive_reports_edges_and_compares() {
    let (code, out, err) = run_cli(&["optimize", "--motor", "trum60a", "--preload-n", "150:450:7", "-q"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("at 200 V, 42000 Hz (the motor's [drive])"), "{out}");
    let m = trum60a();
    let cfg = CriterionConfig {
        preload_n: Axis::linspace(150.0, 450.0, 7),
        voltage_v: 200.0,
        frequency_hz: 42e3,
        ..CriterionConfig::seed000()
    };
    let r = evaluate(&m, &cfg, &mut |_, _| {}).expect("criterion");
    let (ov, frac) = region_overlap(r.region_n, (260.0, 320.0));
    assert!(out.contains(&format!("optimum region {}-{} N", r.region_n.0, r.region_n.1)), "{out}");
    // the summary prints the share to 3 significant digits
    let printed: f64 = out
        .split_once(&format!("overlap {ov} N ("))
        .and_then(|(_, rest)| rest.split_once("% of the paper's region"))
        .and_then(|(p, _)| p.parse().ok())
        .unwrap_or_else(|| panic!("no overlap of {ov} N in {out}"));
    assert!((printed - 100.0 * frac).abs() <= 0.05, "{printed} vs {frac}: {out}");
    // the command line wins over the drive
    let (_, out43, _) =
        run_cli(&["optimize", "--motor", "trum60a", "--preload-n", "150:450:4", "--frequency-hz", "43000", "-q"]);
    assert!(out43.contains("at 200 V, 43000 Hz (voltage from the motor's [drive]):"), "{out43}");
    // a range whose best candidate is its lowest (the stall torque alone, from 300 N up)
    let (_, edge, _) =
        run_cli(&["optimize", "--motor", "trum60a", "--preload-n", "360:500:8", "--weights", "1,0,0,0", "-q"]);
    assert!(edge.contains("warning: the optimum is the lowest running candidate (360 N)"), "{edge}");
    // generic60 has no drive and no published region
    let (_, g, _) = run_cli(&["optimize", "--motor", "generic60", "--preload-n", "150:450:4", "-q"]);
    assert!(g.contains("at 200 V, 43000 Hz:") && !g.contains("paper ("), "{g}");
}

// ---- plausibility of the whole operating range ----

/// The presets stay where a 60 mm TRUM works over their paper's operating range (the
/// bounds the calibration holds, crates/trum-core/examples/fit_presets.rs, with their
/// sources): no-load speed 60-180 rpm, amplitude at most 3 µm, input power at most 15 W
/// and steady temperature rise at most 60 K below the top preload (20 W and 80 K at it),
/// every point running or stalled, never clamped.
#[test]
fn presets_are_plausible_over_their_operating_range() {
    for (name, v, hzs, preloads) in [
        ("trum60a", 200.0, &[42e3, 43e3][..], [150.0, 260.0, 400.0]),
        ("trum60-qut", 150.0, &[42e3][..], [100.0, 250.0, 400.0]),
    ] {
        let m = preset(name).expect("preset");
        for &hz in hzs {
            for f in preloads {
                for torque in [0.0, 0.3] {
                    let s = solve(&m, &OperatingPoint::new(f, torque, v, hz));
                    let at = format!("{name} at {f} N, {torque} N·m, {v} V, {hz} Hz: {s:?}");
                    assert!(matches!(s.status, Status::Ok | Status::Stall), "{at}");
                    if torque == 0.0 {
                        assert!((60.0..=180.0).contains(&s.speed_rpm), "{at}");
                    }
                    assert!(s.amplitude_m <= 3e-6, "{at}");
                    let (p, t) = if f < 400.0 { (15.0, 60.0) } else { (TOP_POWER_W, 80.0) };
                    assert!(s.input_power_w <= p && s.temperature_rise_k <= t, "{at}");
                }
            }
        }
    }
    // the point a designer tries first: 250 N, 0.3 N·m at the paper's 43 kHz
    let s = solve(&trum60a(), &OperatingPoint::new(250.0, 0.3, 200.0, 43e3));
    assert!(s.speed_rpm < 150.0 && s.input_power_w < 15.0 && s.temperature_rise_k < 60.0, "{s:?}");
}

// ---- every other figure of the papers' text ----

/// Solutions at no load over `preloads` [N].
fn no_load_curve(m: &Motor, preloads: &[f64], v: f64, hz: f64) -> Vec<Solution> {
    preloads.iter().map(|&f| no_load(m, f, v, hz)).collect()
}

/// Preloads from `lo` to `hi` [N] in steps of `step`.
fn preloads(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let n = ((hi - lo) / step).round() as usize;
    (0..=n).map(|i| lo + step * i as f64).collect()
}

/// The preload of the largest of `ys` on the curve `xs`, unrefined [N].
fn argmax(xs: &[f64], ys: &[f64]) -> f64 {
    xs[(0..ys.len()).fold(0, |m, j| if ys[j] > ys[m] { j } else { m })]
}

fn argmin(xs: &[f64], ys: &[f64]) -> f64 {
    xs[(0..ys.len()).fold(0, |m, j| if ys[j] < ys[m] { j } else { m })]
}

/// Chen et al. 2020 Fig. 3b (200 V, 43 kHz, no load, simulated): the proportion of the
/// driving zone in the contact zone falls as the preload rises. Reached from 200 N; below
/// it the preset's share is flat within 2 % (near 0.30), while the same motor without its
/// effects falls throughout: the preset's radial slip and stiffening hold it up at low
/// preload.
#[test]
fn chen2020_driving_share_falls_with_preload() {
    assert_eq!(paper(CHEN, "driving_share_trend", None), -1.0);
    let xs = preloads(50.0, 450.0, 25.0);
    let share: Vec<f64> = no_load_curve(&trum60a(), &xs, 200.0, 43e3).iter().map(|s| s.driving_ratio).collect();
    let top = argmax(&xs, &share);
    record(
        "Chen 2020 § 4.1 Fig. 3b: driving share of the contact, 50 → 450 N (no load, 43 kHz)",
        "falls",
        format!(
            "{:.3} → {:.3} ({top:.0} N) → {:.3}",
            share[0],
            share.iter().cloned().fold(f64::MIN, f64::max),
            share[share.len() - 1]
        ),
        "falls above 200 N; flat within 2 % below it (not reached)",
    );
    let from = xs.iter().position(|&f| f >= 200.0).expect("200 N");
    assert!(share[from..].windows(2).all(|w| w[1] < w[0]), "{share:?}");
    assert!(share[..=from].iter().all(|&r| (r / share[0] - 1.0).abs() < 0.02), "{share:?}");
    // the effect-free motor: the share falls at every step (rotor drag needs a larger
    // driving zone where the contact forces are small)
    let b = Motor::from_toml_str(include_str!("data/motors/trum60a_baseline.toml"), "trum60a_baseline.toml")
        .expect("motor");
    let plain: Vec<f64> =
        no_load_curve(&b, &[5.0, 20.0, 100.0, 250.0], 200.0, 43e3).iter().map(|s| s.driving_ratio).collect();
    assert!(plain.windows(2).all(|w| w[1] < w[0]), "{plain:?}");
}

/// Chen et al. 2020 Fig. 3c (200 V, 43 kHz, 0-0.9 N·m, simulated): the load changes the
/// contact length little (its eq. 2), the driving length grows with the load until the
/// rotor stops, and at the stall the whole wave's driving half drives.
#[test]
fn chen2020_load_moves_the_driving_zone_not_the_contact() {
    assert_eq!(paper(CHEN, "driving_angle_load_trend", None), 1.0);
    let m = trum60a();
    let at = |t: f64| solve(&m, &OperatingPoint::new(250.0, t, 200.0, 43e3));
    let ts: Vec<f64> = (0..=6).map(|i| 0.15 * i as f64).collect();
    let s: Vec<Solution> = ts.iter().map(|&t| at(t)).collect();
    let xc = (s[0].contact_angle_deg, s[6].contact_angle_deg);
    let xs: Vec<f64> = s.iter().map(|s| s.driving_angle_deg).collect();
    record(
        "Chen 2020 § 4.1 Fig. 3c: contact and driving angle, 0 → 0.9 N·m at 250 N",
        "contact barely moves; driving grows",
        format!("contact {:.1}° → {:.1}°; driving {:.1}° → {:.1}°", xc.0, xc.1, xs[0], xs[6]),
        "contact within 10 %; driving rises at every step",
    );
    assert!(s.iter().all(|s| s.status == Status::Ok), "{s:?}");
    assert!((xc.1 / xc.0 - 1.0).abs() < 0.10, "{xc:?}");
    assert!(xs.windows(2).all(|w| w[1] > w[0]), "{xs:?}");
    // rotor at rest: the stator surface drives wherever it moves forward, |θ| < π/2 of the
    // contact (a contact wider than that, as here, brakes beyond it)
    let stalled = at(2.0);
    assert_eq!(stalled.status, Status::Stall, "{stalled:?}");
    let want = stalled.contact_angle_deg.min(20.0);
    assert!((stalled.driving_angle_deg - want).abs() < 1e-9, "{stalled:?}");
}

/// Chen et al. 2020 Fig. 4 (200 V, 43 kHz, no load, simulated): the dielectric loss does
/// not depend on the preload; the stator damping and friction losses grow with it up to
/// 460 N.
#[test]
fn chen2020_losses_grow_with_preload_to_460_n() {
    let want = paper(CHEN, "loss_rise_limit_n", None);
    let xs = preloads(50.0, 500.0, 25.0);
    let c = no_load_curve(&trum60a(), &xs, 200.0, 43e3);
    let running: Vec<&Solution> = c.iter().take_while(|s| s.status == Status::Ok).collect();
    let n = running.len();
    let loss: Vec<f64> = running.iter().map(|s| s.damping_loss_w + s.friction_loss_w).collect();
    let top = argmax(&xs[..n], &loss);
    record(
        "Chen 2020 § 4.2 Fig. 4: losses grow with preload (no load, 43 kHz)",
        &format!("up to {want} N"),
        format!(
            "damping + friction {:.1} W → {:.1} W at {top:.0} N; dielectric {:.3} W at every preload",
            loss[0],
            loss[n - 1],
            running[0].dielectric_loss_w
        ),
        "rise at every step to the last running preload, 425-475 N",
    );
    assert!(running.iter().all(|s| s.dielectric_loss_w == running[0].dielectric_loss_w), "{running:?}");
    assert!(loss.windows(2).all(|w| w[1] > w[0]), "{loss:?}");
    assert!((425.0..=475.0).contains(&top), "losses peak at {top} N");
}

/// Chen et al. 2020 Fig. 5c (measured, 10 s runs from 28 °C): the temperature rise after
/// the run is largest at 400 N and smallest at 300 N. Not reached: the preset's rise grows
/// with the preload throughout, as its losses do (docs/PRESETS.md, "Why the paper's
/// efficiency rises with preload and trum's falls": the measured no-load loss falls from
/// 150 to 300 N, the loss of a Coulomb contact grows).
#[test]
fn chen2020_temperature_rise_after_a_run() {
    let (hi, lo) = (paper(CHEN, "temperature_rise_max_n", None), paper(CHEN, "temperature_rise_min_n", None));
    let r = trum60a_criterion_43khz(13);
    let xs: Vec<f64> = r.rows.iter().map(|r| r.preload_n).collect();
    let dt: Vec<f64> = r.rows.iter().map(|r| r.temperature_rise_after_run_k).collect();
    record(
        "Chen 2020 § 4.2 Fig. 5c: temperature rise after 10 s, 150-450 N (43 kHz)",
        &format!("largest at {hi} N, smallest at {lo} N"),
        format!(
            "smallest at {:.0} N ({:.2} K), largest at {:.0} N ({:.2} K)",
            argmin(&xs, &dt),
            dt[0],
            argmax(&xs, &dt),
            dt[dt.len() - 1]
        ),
        "rises at every step (not reached)",
    );
    assert!(dt.windows(2).all(|w| w[1] > w[0]), "{dt:?}");
}

/// Chen et al. 2020 section 4.3 (Fig. 7, 200 V, 43 kHz): the contact angle swings over
/// 1.01° at 150 N and 0.9° at 200 N once a revolution (the paper's ratio for 150 N,
/// 2.53 %, is 0.61° of 24.15°; 1.01° is 4.18 % of it, so one of the two is misprinted).
/// The swing follows the preload ripple of the rotor's axial runout
/// (`trum_core::fluctuation`); the paper does not give the runout. The one runout that
/// reproduces the 200 N swing, 70 µm through the preset's preload path, reproduces the
/// 150 N swing of 1.01° too: the paper's swing falls with the preload, as trum's does.
#[test]
fn chen2020_contact_angle_swing_over_a_revolution() {
    let m = trum60a();
    let swing = |f: f64, runout_m: f64| {
        let op = OperatingPoint::new(f, 0.0, 200.0, 43e3);
        let fl = trum_core::fluctuation::speed_fluctuation(&m, &op, runout_m, 16).expect("fluctuation");
        assert_eq!(fl.status, Status::Ok, "{fl:?}");
        fl.contact_angle_range_deg.1 - fl.contact_angle_range_deg.0
    };
    let (w150, w200) =
        (paper(CHEN, "fluctuation_zone_deg", Some("150")), paper(CHEN, "fluctuation_zone_deg", Some("200")));
    // the runout that gives the paper's 200 N swing (the swing is linear in a small runout;
    // one correction step)
    let mut runout = 5e-6 * w200 / swing(200.0, 5e-6);
    runout *= w200 / swing(200.0, runout);
    let (s150, s200) = (swing(150.0, runout), swing(200.0, runout));
    record(
        "Chen 2020 § 4.3 Fig. 7: contact-angle swing over a revolution at 150 / 200 N",
        &format!("{w150}° / {w200}°"),
        format!("{s150:.2}° / {s200:.2}° (runout {:.0} µm, fitted at 200 N)", runout * 1e6),
        "150 N within 15 % with the 200 N runout",
    );
    assert!((60e-6..80e-6).contains(&runout), "runout {runout}");
    assert!((s200 / w200 - 1.0).abs() < 1e-3, "{s200}");
    assert!((s150 / w150 - 1.0).abs() < 0.15, "{s150} against {w150}");
    assert!(s150 > s200, "{s150} -> {s200}");
}

/// Sun et al. 2021 section 3.2 (Fig. 7a, 150 V, 42 kHz): above 50 N the contact length
/// grows by about 1.8e-3 mm/N until it nears a quarter wavelength. Not reached: the
/// preset's grows six times as fast. At that slope a quarter wavelength (5.24 mm for nine
/// waves on a 30 mm radius) reached by 400 N means a 4.6 mm contact at 50 N, and a Winkler
/// contact (Chen et al. 2020 eq. 3, 6; trum's) that wide at 50 N covers the whole wave at
/// about 220 N at the same amplitude, where the paper runs to 400 N (Table 2): the paper's
/// contact curve is not a Winkler contact at the preset's stiff layer.
#[test]
fn sun2021_contact_length_slope() {
    let want = paper(SUN, "contact_length_slope_mm_per_n", None);
    let m = qut();
    let len = |f: f64| no_load(&m, f, 150.0, 42e3).contact_length_m * 1e3;
    let got = (len(250.0) - len(50.0)) / 200.0;
    record(
        "Sun 2021 § 3.2 Fig. 7a: contact-length slope above 50 N",
        &format!("{want} mm/N"),
        format!("{got:.2e} mm/N (50-250 N)"),
        "8-14e-3 mm/N (not reached)",
    );
    assert!((8e-3..14e-3).contains(&got), "slope {got} mm/N");
    // the arithmetic of the docstring: 4.6 mm at 50 N, full contact at ~220 N
    let g = &m.geometry;
    let quarter_mm = 2.0 * std::f64::consts::PI * g.mean_radius_m * 1e3 / g.wave_number / 4.0;
    let at50_mm = quarter_mm - want * 350.0;
    let phi0 = std::f64::consts::PI * at50_mm / (2.0 * quarter_mm);
    let scale_n = 50.0 / (phi0.sin() - phi0 * phi0.cos());
    let clamp_n = std::f64::consts::PI * scale_n;
    assert!((4.5..4.7).contains(&at50_mm) && (200.0..240.0).contains(&clamp_n), "{at50_mm} mm, {clamp_n} N");
}

/// Sun et al. 2021 section 3.2 (Fig. 7c, 150 V, 42 kHz): the amplitude rises slightly from
/// 0 to 100 N, falls rapidly from 100 to 300 N and more slowly above. The first two are
/// reached (the peak sits at 124 N, test `sun2021_amplitude_peak`); the last is not: the
/// preset's amplitude falls faster above 300 N, as the stiff layer's contact nears the
/// whole wave.
#[test]
fn sun2021_amplitude_trends() {
    let m = qut();
    let w = |f: f64| no_load(&m, f, 150.0, 42e3).amplitude_m * 1e6;
    let (w25, w100, w300, w400) = (w(25.0), w(100.0), w(300.0), w(400.0));
    let (early, late) = ((w300 / w100 - 1.0) / 200.0, (w400 / w300 - 1.0) / 100.0);
    record(
        "Sun 2021 § 3.2 Fig. 7c: amplitude 25 → 100 → 300 → 400 N",
        "rises slightly; falls; falls more slowly",
        format!("{w25:.3} → {w100:.3} → {w300:.3} → {w400:.3} µm"),
        "rise ≤ 3 %; falls; slower above 300 N not reached",
    );
    assert!(w100 > w25 && w100 < 1.03 * w25, "{w25} -> {w100}");
    assert!(w300 < w100 && w400 < w300, "{w100} -> {w300} -> {w400}");
    assert!(late < early, "falls by {early}/N to 300 N, {late}/N above");
}

/// Sun et al. 2021 section 3.1 and 3.3 (Fig. 5a, 8a): the driver's voltage falls from
/// 141 V at 50 N to 106 V at 350 N and rises again, and the dielectric loss has its valley
/// at the same 350 N: eq. 15 makes that loss ω·C0·tan δ·V², so it follows the voltage the
/// driver holds. trum's is the same law; the preset is driven at the set 150 V, so its
/// dielectric loss is constant over preload, and at the paper's measured voltages it falls
/// by (106/141)².
#[test]
fn sun2021_dielectric_loss_follows_the_drive_voltage() {
    let (v50, v350) = (paper(SUN, "drive_voltage_v", Some("50")), paper(SUN, "drive_voltage_v", Some("350")));
    let valley = paper(SUN, "dielectric_loss_min_n", None);
    assert_eq!(valley, paper(SUN, "drive_voltage_min_n", None));
    let m = qut();
    let (d50, d350) =
        (no_load(&m, 50.0, v50, 42e3).dielectric_loss_w, no_load(&m, 350.0, v350, 42e3).dielectric_loss_w);
    record(
        "Sun 2021 § 3.3 Fig. 8a: dielectric-loss valley",
        &format!("{valley} N, with the drive voltage's (Fig. 5a)"),
        format!("{d50:.3} W at 50 N, {v50} V → {d350:.3} W at 350 N, {v350} V"),
        "ratio (106/141)² to 1e-9",
    );
    assert!((d350 / d50 - (v350 / v50).powi(2)).abs() < 1e-9, "{d50} -> {d350}");
    let at_set: Vec<f64> =
        [50.0, 200.0, 350.0].iter().map(|&f| no_load(&m, f, 150.0, 42e3).dielectric_loss_w).collect();
    assert!(at_set.iter().all(|&d| d == at_set[0]), "{at_set:?}");
}

/// Sun et al. 2021 section 3.3 (Fig. 8b): the composite stator's damping loss "per cycle"
/// tends to 5e-3 J at high preload. Not comparable as printed: 5e-3 J a cycle at 42 kHz is
/// 210 W, over ten times the motor's whole input (Table 2's motor draws a few watts to
/// about 15 W). The preset's damping loss, c·ω²·W² (eq. 17-21), is a few watts, 6-9e-5 J a
/// cycle, falling with the amplitude above 125 N.
#[test]
fn sun2021_damping_loss_per_cycle() {
    let want = paper(SUN, "damping_loss_limit_j", None);
    let m = qut();
    let s = no_load(&m, 400.0, 150.0, 42e3);
    let per_cycle = s.damping_loss_w / 42e3;
    record(
        "Sun 2021 § 3.3 Fig. 8b: damping loss per cycle at high preload",
        &format!("{want} J ({:.0} W at 42 kHz)", want * 42e3),
        format!("{per_cycle:.1e} J ({:.1} W) at 400 N", s.damping_loss_w),
        "not comparable (the paper's value is over ten times the input)",
    );
    assert!(want * 42e3 > 10.0 * s.input_power_w, "{s:?}");
    assert!((5e-5..1e-4).contains(&per_cycle), "{per_cycle} J");
}

/// Sun et al. 2021 Table 2: the conversion factor (feedback volts per metre of amplitude)
/// identified at each preload, 2.86-3.24e7 V/m; the preset uses their mean.
#[test]
fn sun2021_conversion_factor() {
    let got = qut().electrical.feedback_gain_v_per_m;
    let f: Vec<f64> =
        ["100", "200", "300", "400"].iter().map(|p| paper(SUN, "conversion_factor_v_per_m", Some(p))).collect();
    let mean = f.iter().sum::<f64>() / 4.0;
    record(
        "Sun 2021 Table 2: conversion factor",
        "2.86-3.24e7 V/m (four preloads)",
        format!("{got:.3e} V/m"),
        "the mean of the four, to 0.5 %",
    );
    assert!((got / mean - 1.0).abs() < 0.005, "{got} against {mean}");
}

/// Sun et al. 2021 section 3.1 (Fig. 5a-b, no load, 42 kHz): the driver's voltage falls from
/// 141 V at 50 N to 106 V at 350 N, and the motor runs there (Fig. 5b loads it at 350 N).
/// Not reached at 350 N: the preset, calibrated at the set 150 V, clamps below 111 V
/// at 350 N (docs/PRESETS.md, "Targets not reached").
#[test]
fn sun2021_runs_at_the_drivers_voltages() {
    let (v50, v350) = (paper(SUN, "drive_voltage_v", Some("50")), paper(SUN, "drive_voltage_v", Some("350")));
    let m = qut();
    let (s50, s350) = (no_load(&m, 50.0, v50, 42e3), no_load(&m, 350.0, v350, 42e3));
    // the lowest voltage, in steps of 1 V, at which the preset runs at 350 N
    let lowest = (100..=150).map(f64::from).find(|&v| no_load(&m, 350.0, v, 42e3).status == Status::Ok).expect("runs");
    record(
        "Sun 2021 § 3.1 Fig. 5: running at the driver's no-load voltages",
        &format!("runs at 50 N, {v50} V and at 350 N, {v350} V"),
        format!("{:.0} rpm at 50 N; {} at 350 N (runs from {lowest:.0} V)", s50.speed_rpm, s350.status.as_str()),
        "50 N runs; 350 N not reached",
    );
    assert_eq!(s50.status, Status::Ok, "{s50:?}");
    assert_eq!(s350.status, Status::Clamped, "{s350:?}");
    assert!((110.0..=120.0).contains(&lowest), "runs from {lowest} V");
}
