//! The self-contained HTML report of `trum diagnose --report`: summary, method, ranking
//! charts, where table, held-out residual maps, measured-vs-model curves and notes. All
//! plots are inline SVG; the page loads nothing from outside.

use crate::format::fmt_sig;
use crate::svg::{esc, Bars, Chart, Series, Style, PALETTE};
use crate::verdict::{after_nrmse, verdict_words};
use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use trum_core::bench::BenchData;
use trum_core::calibrate::{Observable, ObservedRow};
use trum_core::diagnose::json::{unit, EVIDENCE_SCALE};
use trum_core::diagnose::Diagnosis;
use trum_core::Motor;

/// Operating coordinates a residual can be plotted against: (column, label, accessor,
/// resolution below which two values count as the same setting).
type Coord = (&'static str, &'static str, fn(&ObservedRow) -> f64, f64);
const COORDS: [Coord; 5] = [
    ("preload_n", "Preload [N]", |r| r.op.preload_n, 10.0),
    ("torque_nm", "Load torque [N·m]", |r| r.op.torque_nm, 0.01),
    ("frequency_hz", "Drive frequency [Hz]", |r| r.op.frequency_hz, 50.0),
    ("elapsed_s", "Time since switch-on [s]", |r| r.op.elapsed_s, 1.0),
    ("voltage_v", "Drive voltage [V]", |r| r.op.voltage_v, 5.0),
];

/// Distinct settings of a coordinate over some rows.
fn settings(rows: &[&ObservedRow], c: &Coord) -> usize {
    let mut v: Vec<i64> = rows.iter().map(|r| ((c.2)(r) / c.3).round() as i64).collect();
    v.sort_unstable();
    v.dedup();
    v.len()
}

fn label_of(o: Observable) -> String {
    let u = unit(o.column());
    let words = words_of(o);
    if u.is_empty() || u == "-" {
        words
    } else {
        format!("{words} [{}]", u.replace("N m", "N·m"))
    }
}

/// The measured quantity in words (`Speed`, `Input power`).
fn words_of(o: Observable) -> String {
    match o.column() {
        "speed_rpm" => "Speed".to_string(),
        "speed_std_rpm" => "Speed fluctuation (std)".to_string(),
        "efficiency" => "Efficiency".to_string(),
        "input_power_w" => "Input power".to_string(),
        "output_power_w" => "Output power".to_string(),
        "current_a" => "Drive current".to_string(),
        "feedback_v" => "Feedback voltage".to_string(),
        "temperature_c" => "Temperature".to_string(),
        other => other.replace('_', " "),
    }
}

/// `"Speed against preload"`: a chart title in words.
fn title_of(o: Observable, c: &Coord) -> String {
    let x = c.1.split(" [").next().unwrap_or(c.0).to_lowercase();
    format!("{} against {x}", words_of(o))
}

const CSS: &str =
    "body{font-family:sans-serif;max-width:1280px;margin:1.5em auto;padding:0 1em;color:#222;line-height:1.45}\
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:1.8em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:3px 8px;text-align:left}\
td.n{text-align:right;font-variant-numeric:tabular-nums}th{background:#f0f0f0}\
.box{background:#f4f7fb;border:1px solid #c9d6e6;padding:.6em 1em;border-radius:4px}\
.verdict{font-size:1.25em;font-weight:bold}.grid{display:flex;flex-wrap:wrap;gap:8px}\
.cap{color:#555;font-size:.9em}code{background:#f2f2f2;padding:0 3px}";

/// The report page.
pub fn html(d: &Diagnosis, motor: &Motor, data: &str, bench: &BenchData) -> String {
    let mut h = String::new();
    let title = format!("trum diagnose: {} against {}", data, motor.name);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{CSS}</style></head><body>\n",
        esc(&title)
    );
    let _ = writeln!(h, "<h1>{}</h1>", esc(&title));
    summary(&mut h, d);
    method(&mut h, d);
    ranking(&mut h, d);
    where_table(&mut h, d);
    residual_maps(&mut h, d, bench);
    curves(&mut h, d, bench);
    limits(&mut h, motor, bench);
    notes(&mut h, d);
    let _ = writeln!(
        h,
        "<p class=\"cap\">{} rows, {} readings, {} folds. Written by trum {}.</p></body></html>",
        d.n_rows,
        d.n_readings,
        d.folds,
        env!("CARGO_PKG_VERSION")
    );
    h
}

fn summary(h: &mut String, d: &Diagnosis) {
    let conf = if d.confounded_with.is_empty() { "none".to_string() } else { d.confounded_with.join(", ") };
    let after = match after_nrmse(d) {
        Some(a) => format!(
            " &rarr; <b>{}</b> with <code>{}</code> (shrink {:.0} %)",
            fmt_sig(a, 3),
            esc(&d.verdict),
            100.0 * (1.0 - a / d.baseline_heldout_nrmse)
        ),
        None => String::new(),
    };
    let _ = writeln!(
        h,
        "<div class=\"box\"><div class=\"verdict\">Verdict: {}</div>\
         <p>Confounded with: {}<br>Held-out gap (NRMSE): baseline <b>{}</b>{after}; the noise alone gives {}.<br>\
         Held-out χ² per reading of the baseline: {} (1 = the baseline misses by exactly the noise).</p></div>",
        esc(&verdict_words(d)),
        esc(&conf),
        fmt_sig(d.baseline_heldout_nrmse, 3),
        fmt_sig(d.noise_nrmse, 3),
        fmt_sig(d.baseline_heldout_chi2_per_reading, 3)
    );
}

fn method(h: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        h,
        "<h2>How to read this report</h2>\
<p>The motor model (the <em>baseline</em>) is first <b>calibrated</b> to the data: its uncertain parameters \
(friction coefficient, friction-layer modulus, modal damping, force factor, free resonance, and the feedback \
gain and capacitance when those readings exist) are fitted by least squares, each reading weighted by its noise level.</p>\
<p>The <b>gap</b> is measured on data the fit never saw. The rows are grouped into operating regions (one run, one \
preload level, one frequency band, one time window) and the regions are dealt into {} folds. Each fold in turn is \
held out, the model is calibrated on the others and predicts the held-out fold. The <b>NRMSE</b> is the root-mean-square \
of these held-out errors, each divided by the spread of its quantity; the <b>noise NRMSE</b> is what measurement noise \
alone would give. A baseline at the noise level needs no extra effect (verdict <code>none</code>).</p>\
<p>Each <b>candidate effect</b> (an unmodelled physical effect with one to three parameters) is then added to the \
model and fitted together with the baseline parameters in the same way. <b>Shrink</b> = 1 &minus; NRMSE<sub>after</sub> / \
NRMSE<sub>baseline</sub> is the fraction of the held-out gap it closes; the bracket is a 90 % bootstrap interval over \
the readings. <b>Evidence</b> weighs the better fit of all the data against the extra parameters: {}. \
Evidence near zero or negative means the effect's parameters buy nothing the data can see. The verdict is the best effect \
when it is strong and brings the held-out error to about the noise level; two effects joined with <code>+</code> when only \
the pair does; <code>unexplained</code> when a real gap remains that no candidate closes. <b>Confounded</b> effects explain \
the data about as well as the verdict and cannot be told apart from it with these operating points.</p>\
<p><b>Where</b>: the residuals (measured &minus; model) of the calibrated baseline are grouped by quantity and by thirds of \
each operating coordinate; a group is listed when its mean is more than 3.5 standard errors from zero.</p>",
        d.folds,
        esc(EVIDENCE_SCALE)
    );
}

fn ranking(h: &mut String, d: &Diagnosis) {
    let _ = writeln!(h, "<h2>Ranking of the candidate effects</h2>");
    let _ = writeln!(
        h,
        "<table><tr><th>effect</th><th>evidence</th><th>held-out NRMSE after</th><th>shrink</th><th>90 % interval</th><th>fitted parameters</th></tr>"
    );
    let p = |x: f64| if x.is_finite() { format!("{:.1} %", 100.0 * x) } else { "-".into() };
    for r in &d.ranking {
        let params: Vec<String> = r
            .params
            .iter()
            .map(|(n, v)| format!("{} = {}", n.rsplit('.').next().unwrap_or(n), fmt_sig(*v, 3)))
            .collect();
        let b = if r.effect == d.verdict { " style=\"font-weight:bold\"" } else { "" };
        let _ = writeln!(
            h,
            "<tr{b}><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">[{}, {}]</td><td>{}</td></tr>",
            esc(&r.effect),
            fmt_sig(r.evidence, 3),
            fmt_sig(r.heldout_nrmse_after, 3),
            p(r.shrink),
            p(r.shrink_interval.0),
            p(r.shrink_interval.1),
            esc(&params.join(", "))
        );
    }
    let _ = writeln!(h, "</table>");
    let labels: Vec<String> = d.ranking.iter().map(|r| r.effect.clone()).collect();
    let hl = d.ranking.iter().position(|r| r.effect == d.verdict);
    let big = d.ranking.iter().any(|r| r.evidence.abs() > 60.0);
    let ev = Bars {
        title: "Evidence (½·ΔBIC)".into(),
        x_label: if big { "Evidence, ½·ΔBIC (signed log axis)".into() } else { "Evidence, ½·ΔBIC".into() },
        labels: labels.clone(),
        values: d.ranking.iter().map(|r| r.evidence).collect(),
        intervals: None,
        refs: vec![(3.0, "3 strong".into()), (5.0, "5".into())],
        color: PALETTE[0],
        highlight: hl,
        symlog: big,
        clamp: None,
    };
    let sh = Bars {
        title: "Shrink of the held-out gap".into(),
        x_label: "Shrink = 1 − NRMSE after / NRMSE baseline (clipped to [−1, 1])".into(),
        labels,
        values: d.ranking.iter().map(|r| r.shrink).collect(),
        intervals: Some(d.ranking.iter().map(|r| r.shrink_interval).collect()),
        refs: vec![(1.0, "closed".into())],
        color: PALETTE[4],
        highlight: hl,
        symlog: false,
        clamp: Some((-1.0, 1.0)),
    };
    let _ = writeln!(h, "<div class=\"grid\">{}{}</div>", ev.svg(), sh.svg());
}

fn where_table(h: &mut String, d: &Diagnosis) {
    let _ = writeln!(h, "<h2>Where the baseline misses</h2>");
    if d.gap_where.is_empty() {
        let _ = writeln!(
            h,
            "<p>No quantity and region where the calibrated baseline misses by more than the noise explains.</p>"
        );
        return;
    }
    let _ = writeln!(
        h,
        "<table><tr><th>quantity</th><th>region</th><th>mean residual (measured − model)</th><th>unit</th><th>n</th><th>z</th></tr>"
    );
    for g in &d.gap_where {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td class=\"n\">{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{:.1}</td></tr>",
            esc(&g.quantity),
            esc(&g.region),
            fmt_sig(g.mean_residual, 3),
            esc(unit(&g.quantity)),
            g.n,
            g.z
        );
    }
    let _ = writeln!(h, "</table>");
}

fn has_after(d: &Diagnosis) -> bool {
    after_nrmse(d).is_some()
}

fn residual_maps(h: &mut String, d: &Diagnosis, bench: &BenchData) {
    let _ = writeln!(h, "<h2>Held-out residual maps</h2>");
    let after_txt = if has_after(d) {
        format!(" Filled dots: with <code>{}</code> added (also held out).", esc(&d.verdict))
    } else {
        String::new()
    };
    let _ = writeln!(
        h,
        "<p class=\"cap\">Residual = measured − model prediction (for a speed std clipped at zero, the expected reading of clipped noise), where every prediction comes from a fit that did not see \
         that reading's operating region. Rings: calibrated baseline.{after_txt} Shaded band: ±2 noise standard deviations.</p>"
    );
    let all: Vec<&ObservedRow> = bench.rows.iter().collect();
    let coords: Vec<&Coord> = COORDS.iter().filter(|c| settings(&all, c) >= 2).collect();
    for o in Observable::ALL {
        let items: Vec<_> = d.heldout.iter().filter(|x| x.observable == o).collect();
        if items.is_empty() {
            continue;
        }
        let sig = (items.iter().map(|x| o.default_sigma(x.measured).powi(2)).sum::<f64>() / items.len() as f64).sqrt();
        let _ = writeln!(h, "<div class=\"grid\">");
        for c in &coords {
            let xy = |pick: fn(&trum_core::diagnose::HeldOut) -> f64| -> Vec<(f64, f64)> {
                items.iter().map(|x| ((c.2)(&bench.rows[x.row]), x.measured - pick(x))).collect()
            };
            let mut ch = Chart::new(&title_of(o, c), c.1, &format!("Residual of {}", label_of(o).to_lowercase()));
            ch.width = 380.0;
            ch.height = 260.0;
            ch.hline = Some(0.0);
            ch.band = Some((-2.0 * sig, 2.0 * sig));
            ch.series.push(Series {
                name: "baseline".into(),
                color: PALETTE[2],
                points: xy(|x| x.baseline),
                style: Style::Rings,
            });
            if has_after(d) {
                ch.series.push(Series {
                    name: format!("with {}", d.verdict),
                    color: PALETTE[0],
                    points: xy(|x| x.after),
                    style: Style::Dots,
                });
            }
            h.push_str(&ch.svg());
        }
        let _ = writeln!(h, "</div>");
    }
}

/// Runs: the file's run ids, else the operating settings other than the swept one.
fn run_groups(bench: &BenchData) -> BTreeMap<String, Vec<usize>> {
    let mut g: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (i, r) in bench.rows.iter().enumerate() {
        let name = match bench.groups.get(i).filter(|s| !s.is_empty()) {
            Some(s) => s.clone(),
            None => format!(
                "{:.0} N, {:.0} V{}",
                (r.op.preload_n / 10.0).round() * 10.0,
                (r.op.voltage_v / 5.0).round() * 5.0,
                if r.op.elapsed_s > 0.0 { ", time series" } else { "" }
            ),
        };
        g.entry(name).or_default().push(i);
    }
    g
}

fn curves(h: &mut String, d: &Diagnosis, bench: &BenchData) {
    let _ = writeln!(h, "<h2>Measured against model, run by run</h2>");
    let after_txt =
        if has_after(d) { format!(", solid line: with <code>{}</code> added", esc(&d.verdict)) } else { String::new() };
    let _ = writeln!(
        h,
        "<p class=\"cap\">Dots: measured. Dashed line: calibrated baseline{after_txt}. Model values are the held-out \
         predictions at the measured operating points (fits that did not see that region). One colour per run.</p>"
    );
    let held: HashMap<(usize, Observable), (f64, f64)> =
        d.heldout.iter().map(|x| ((x.row, x.observable), (x.baseline, x.after))).collect();
    // each run is plotted against its swept coordinate
    let mut by_coord: BTreeMap<usize, Vec<(String, Vec<usize>)>> = BTreeMap::new();
    for (name, idx) in run_groups(bench) {
        let rows: Vec<&ObservedRow> = idx.iter().map(|&i| &bench.rows[i]).collect();
        let best = (0..4).map(|k| (settings(&rows, &COORDS[k]), k)).max_by_key(|&(n, k)| (n, usize::MAX - k));
        if let Some((n, k)) = best {
            if n >= 3 {
                by_coord.entry(k).or_default().push((name, idx));
            }
        }
    }
    if by_coord.is_empty() {
        let _ = writeln!(h, "<p>No run sweeps an operating coordinate over three or more settings.</p>");
        return;
    }
    let _ = writeln!(h, "<div class=\"grid\">");
    for (k, runs) in &by_coord {
        let c = &COORDS[*k];
        let mut quantities = vec![Observable::SpeedRpm];
        if c.0 == "elapsed_s" {
            quantities.push(Observable::TemperatureC);
        }
        if c.0 == "preload_n" {
            quantities.push(Observable::SpeedStdRpm);
        }
        if c.0 == "torque_nm" {
            quantities.push(Observable::Efficiency);
        }
        for o in quantities {
            let mut ch = Chart::new(&title_of(o, c), c.1, &label_of(o));
            ch.width = 620.0;
            ch.height = 360.0;
            for (ri, (name, idx)) in runs.iter().enumerate() {
                let color = PALETTE[ri % PALETTE.len()];
                let mut pts: Vec<(f64, f64, f64, f64)> = idx
                    .iter()
                    .filter_map(|&i| {
                        let r = &bench.rows[i];
                        let m = r.readings.iter().find(|x| x.0 == o)?.1;
                        let (b, a) = held.get(&(i, o)).copied().unwrap_or((f64::NAN, f64::NAN));
                        Some(((c.2)(r), m, b, a))
                    })
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                pts.sort_by(|p, q| p.0.total_cmp(&q.0));
                ch.series.push(Series {
                    name: name.clone(),
                    color,
                    points: pts.iter().map(|p| (p.0, p.1)).collect(),
                    style: Style::Dots,
                });
                ch.series.push(Series {
                    name: String::new(),
                    color,
                    points: pts.iter().map(|p| (p.0, p.2)).collect(),
                    style: Style::Dashed,
                });
                if has_after(d) {
                    ch.series.push(Series {
                        name: String::new(),
                        color,
                        points: pts.iter().map(|p| (p.0, p.3)).collect(),
                        style: Style::Line,
                    });
                }
            }
            if !ch.series.is_empty() {
                h.push_str(&ch.svg());
            }
        }
    }
    let _ = writeln!(h, "</div>");
}

/// The bench rows whose operating point the motor model puts beyond one of its `[limits]`
/// (the model at the read operating point, `trum point`'s warnings).
fn limits(h: &mut String, motor: &Motor, bench: &BenchData) {
    use trum_core::limits::LIMIT_KEYS;
    let _ = writeln!(h, "<h2>Physical limits</h2>");
    let p = trum_core::solve::Prepared::new(motor);
    let mut beyond: Vec<(usize, Option<usize>)> = vec![(0, None); LIMIT_KEYS.len()];
    for (i, r) in bench.rows.iter().enumerate() {
        let w = trum_core::solve::solve_prepared(&p, motor, &r.op, None).warnings;
        for (k, slot) in beyond.iter_mut().enumerate() {
            if w.contains(LIMIT_KEYS[k]) {
                slot.0 += 1;
                slot.1.get_or_insert(i);
            }
        }
    }
    if beyond.iter().all(|b| b.0 == 0) {
        let _ = writeln!(
            h,
            "<p>No bench point is beyond the motor's <code>[limits]</code> (the model at the read operating points).</p>"
        );
        return;
    }
    let _ = writeln!(
        h,
        "<p class=\"cap\">Bench points the model (at the read operating points) puts beyond the motor's <code>[limits]</code> \
         (docs/MOTOR_FILE.md): its numbers there describe a motor no real one survives running continuously.</p>\
         <table><tr><th>limit</th><th>value</th><th>rows beyond it</th><th>first such row (preload, torque, voltage, frequency)</th></tr>"
    );
    let maxima = [
        motor.limits.max_voltage_v,
        motor.limits.max_amplitude_m,
        motor.limits.max_stator_temperature_c,
        motor.limits.max_input_power_w,
    ];
    for (k, (n, first)) in beyond.iter().enumerate() {
        let Some(i) = first else { continue };
        let op = &bench.rows[*i].op;
        let _ = writeln!(
            h,
            "<tr><td><code>{}</code></td><td class=\"n\">{}</td><td class=\"n\">{n}</td><td>{} N, {} N·m, {} V, {} Hz</td></tr>",
            LIMIT_KEYS[k],
            fmt_sig(maxima[k], 4),
            fmt_sig(op.preload_n, 5),
            fmt_sig(op.torque_nm, 4),
            fmt_sig(op.voltage_v, 4),
            fmt_sig(op.frequency_hz, 6)
        );
    }
    let _ = writeln!(h, "</table>");
}

fn notes(h: &mut String, d: &Diagnosis) {
    let _ = writeln!(h, "<h2>What these data can and cannot show</h2>");
    if d.notes.is_empty() {
        let _ = writeln!(h, "<p>No limitations noted.</p>");
    } else {
        let _ = writeln!(h, "<ul>");
        for n in &d.notes {
            let _ = writeln!(h, "<li>{}</li>", esc(n));
        }
        let _ = writeln!(h, "</ul>");
    }
    let _ = writeln!(
        h,
        "<h2>Calibrated baseline parameters (all data)</h2><table><tr><th>parameter</th><th>value</th></tr>"
    );
    for (n, v) in &d.baseline_params {
        let _ = writeln!(h, "<tr><td>{}</td><td class=\"n\">{}</td></tr>", esc(n), fmt_sig(*v, 5));
    }
    let _ = writeln!(h, "</table>");
}
