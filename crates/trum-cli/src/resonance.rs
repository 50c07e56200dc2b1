//! `trum resonance` (amplitude–frequency response of the Hertzian oscillator, [Hertz2022]
//! eq. 10-12, docs/REFERENCES.md) and `trum identify-hertz` (β from a waveform by harmonic balance, eq. 5-9).
//!
//! Both use the oscillator parameters of `trum_core::dynamics::hertz::HertzOscillator`:
//! those of `--motor` (`HertzOscillator::from_motor`) or, without one, its 60 mm TRUM
//! defaults, overridden by an `--oscillator` TOML file and then by flags.

use crate::data::{num, write_atomic};
use crate::format::{csv_number, fmt_sig};
use crate::grid::parse_axis;
use crate::plot::{series_color, write_figure, Line, LinePlot, Stroke};
use crate::table::{write_table, Align};
use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, ValueEnum};
use plotters::style::RGBColor;
use serde_json::json;
use std::io::Write;
use std::path::{Path, PathBuf};
use trum_core::dynamics::hertz::{
    identify_beta, BetaIdentificationInput, Branch, FamilyCurve, HertzError, HertzOscillator, OperatingPoint,
    ResponseMethod,
};
use trum_core::layout::{response_rows, response_status, response_summary, ResponseCell, RESPONSE_COLUMNS};
use trum_core::sweep::Axis;

/// Oscillator parameters: the motor's (or the defaults), then `--oscillator FILE`, then the flags.
#[derive(Args, Debug, Clone, Default)]
pub struct OscillatorArgs {
    /// Motor (TOML file or preset) whose modal mass, damping, stiffness (free resonance), force factor and hertz_softening the oscillator takes (default: the 60 mm TRUM oscillator of the Hertzian paper).
    #[arg(long, value_name = "FILE|PRESET")]
    motor: Option<String>,
    /// Switch an effect on the motor on (as in `trum point`; only hertz_softening reaches the oscillator).
    #[arg(long = "effect", value_name = "NAME=STRENGTH", requires = "motor")]
    effects: Vec<String>,
    /// TOML file of oscillator parameters (any subset of the keys listed in docs/CLI.md; the rest keep the 60 mm TRUM defaults).
    #[arg(long, value_name = "FILE")]
    oscillator: Option<PathBuf>,
    /// Modal mass m [kg].
    #[arg(long, value_name = "KG")]
    modal_mass_kg: Option<f64>,
    /// Modal viscous damping c [N s/m].
    #[arg(long, value_name = "NS_PER_M")]
    damping_ns_per_m: Option<f64>,
    /// Linear modal stiffness k [N/m].
    #[arg(long, value_name = "N_PER_M", conflicts_with = "linear_resonance_hz")]
    linear_stiffness_n_per_m: Option<f64>,
    /// Linear resonance f0 [Hz], sets k = m (2 pi f0)^2.
    #[arg(long, value_name = "HZ")]
    linear_resonance_hz: Option<f64>,
    /// Cubic coefficient beta at the reference preload and voltage [N/m^3] (negative: softening).
    #[arg(long, value_name = "N_PER_M3", allow_hyphen_values = true)]
    beta_n_per_m3: Option<f64>,
    /// Piezoelectric force factor A of F = A V [N/V].
    #[arg(long, value_name = "N_PER_V")]
    force_factor_n_per_v: Option<f64>,
}

/// 1-based line of the first `key = ...` assignment in `text` (0 if not found).
fn line_of(text: &str, key: &str) -> usize {
    text.lines()
        .position(|l| l.trim_start().strip_prefix(key).is_some_and(|r| r.trim_start().starts_with('=')))
        .map_or(0, |i| i + 1)
}

impl OscillatorArgs {
    /// The motor of `--motor` with its `--effect`s, if given.
    fn motor(&self) -> Result<Option<trum_core::Motor>> {
        self.motor
            .as_ref()
            .map(|m| crate::args::MotorArgs { motor: m.clone(), effects: self.effects.clone() }.load().map(|(m, _)| m))
            .transpose()
    }

    /// The oscillator; every error names the file, line and key (or the flag) and why.
    pub fn load(&self) -> Result<HertzOscillator> {
        let mut o = match self.motor()? {
            Some(m) => HertzOscillator::from_motor(&m),
            None => HertzOscillator::default(),
        };
        if let Some(path) = &self.oscillator {
            let shown = path.display();
            crate::output::note_input(path, &format!("--oscillator '{shown}'"));
            let text =
                std::fs::read_to_string(path).with_context(|| format!("cannot read oscillator file '{shown}'"))?;
            let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
                let before = e.span().and_then(|s| text.get(..s.start)).unwrap_or("");
                let line = before.matches('\n').count() + 1;
                anyhow!("{shown}, line {line}: {}", e.message())
            })?;
            for (k, v) in table {
                let line = line_of(&text, &k);
                let x = match v {
                    toml::Value::Float(x) => x,
                    toml::Value::Integer(i) => i as f64,
                    other => bail!("{shown}, line {line}, key '{k}': expected a number, got {}", other.type_str()),
                };
                set_param(&mut o, &k, x).map_err(|e| anyhow!("{shown}, line {line}, key '{k}': {e}"))?;
            }
        }
        let flags = [
            ("--modal-mass-kg", "modal_mass_kg", self.modal_mass_kg),
            ("--damping-ns-per-m", "damping_ns_per_m", self.damping_ns_per_m),
            ("--linear-stiffness-n-per-m", "linear_stiffness_n_per_m", self.linear_stiffness_n_per_m),
            ("--beta-n-per-m3", "beta_n_per_m3", self.beta_n_per_m3),
            ("--force-factor-n-per-v", "force_factor_n_per_v", self.force_factor_n_per_v),
        ];
        for (flag, key, value) in flags {
            if let Some(v) = value {
                set_param(&mut o, key, v).map_err(|e| anyhow!("{flag} {v}: {e}"))?;
            }
        }
        if let Some(f) = self.linear_resonance_hz {
            o.linear_stiffness_n_per_m =
                trum_core::dynamics::hertz::linear_stiffness_from_resonance_n_per_m(o.modal_mass_kg, f)
                    .map_err(|e| anyhow!("--linear-resonance-hz {f}: {e}"))?;
        }
        o.validate().map_err(|e| anyhow!("oscillator parameters: {e}"))?;
        Ok(o)
    }
}

/// Sets one parameter by name: unknown keys and out-of-range values are errors.
fn set_param(o: &mut HertzOscillator, key: &str, value: f64) -> Result<(), String> {
    match o.set_param(key, value) {
        Ok(true) => Ok(()),
        Ok(false) => Err(format!("unknown key; valid keys are: {}", HertzOscillator::PARAM_KEYS.join(", "))),
        Err(HertzError::InvalidParameter { reason, .. }) => Err(format!("{value} {reason}")),
        Err(e) => Err(e.to_string()),
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Default)]
pub enum Method {
    /// Multiple scales ([Hertz2022] eq. 10-12).
    #[default]
    MultipleScales,
    /// One-term harmonic balance (exact linear FRF for beta = 0).
    HarmonicBalance,
}

impl From<Method> for ResponseMethod {
    fn from(m: Method) -> Self {
        match m {
            Method::MultipleScales => ResponseMethod::MultipleScales,
            Method::HarmonicBalance => ResponseMethod::HarmonicBalance,
        }
    }
}

#[derive(Args, Debug)]
pub struct ResonanceArgs {
    #[command(flatten)]
    osc: OscillatorArgs,
    /// Drive voltage amplitude, zero-to-peak [V]: VALUE or START:STOP:N (one curve each).
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true, default_value = "100:300:3")]
    voltage_v: Axis,
    /// Static preload [N]: VALUE or START:STOP:N (one curve each).
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true, default_value = "400")]
    preload_n: Axis,
    /// Drive frequencies [Hz]: VALUE or START:STOP:N (default: 401 points over a band that holds every peak and jump).
    #[arg(long, value_name = "VALUE|START:STOP:N", value_parser = parse_axis, allow_hyphen_values = true)]
    frequency_hz: Option<Axis>,
    /// First-order approximation of the steady state.
    #[arg(long, value_enum, default_value_t = Method::MultipleScales)]
    method: Method,
    /// Response CSV (`-` for stdout; the summary then goes to stderr).
    #[arg(short = 'o', long = "output", value_name = "CSV")]
    output: Option<PathBuf>,
    /// Plot of the curves (.png or .svg): stable branches solid, unstable dashed, backbones dotted, jumps circled.
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Print the summary of every curve as JSON (resonance, peak, jumps, hysteresis) instead of the table.
    #[arg(long)]
    json: bool,
}

fn axis_values(ax: &Axis, name: &str) -> Result<Vec<f64>> {
    if ax.n == 0 || ax.n > 100_000 {
        bail!("--{name}: between 1 and 100000 points, got {}", ax.n);
    }
    let v: Vec<f64> = (0..ax.n).map(|i| ax.at(i)).collect();
    Ok(v)
}

pub fn run(a: &ResonanceArgs, out: &mut dyn Write, err: &mut dyn Write) -> Result<i32> {
    if a.output.is_none() && a.plot.is_none() && !a.json {
        bail!("nothing to write: give -o CSV, --plot FILE and/or --json");
    }
    if a.json && a.output.as_deref().is_some_and(|p| p.as_os_str() == "-") {
        bail!("-o - and --json cannot both go to stdout");
    }
    if let Some(p) = &a.plot {
        crate::plot::check_plot_path(p)?;
    }
    let osc = a.osc.load()?;
    let method: ResponseMethod = a.method.into();
    let voltages = axis_values(&a.voltage_v, "voltage-v")?;
    let preloads = axis_values(&a.preload_n, "preload-n")?;
    let ops: Vec<OperatingPoint> = voltages
        .iter()
        .flat_map(|&v| preloads.iter().map(move |&n| OperatingPoint { voltage_v: v, preload_n: n }))
        .collect();
    let band = match a.frequency_hz {
        Some(ax) => ax,
        None => {
            let (lo, hi) = osc
                .response_band_hz(&ops, method)
                .ok_or_else(|| anyhow!("no operating point has a static equilibrium; give --frequency-hz"))?;
            Axis::linspace(lo, hi, 401)
        }
    };
    let freqs = axis_values(&band, "frequency-hz")?;
    if let Some(f) = freqs.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
        bail!("--frequency-hz: {f} must be a finite frequency > 0");
    }
    let curves = osc.response_family(&ops, &freqs, method).map_err(|e| anyhow!("--frequency-hz: {e}"))?;
    for c in &curves {
        if let Err(e) = &c.response {
            let op = c.operating_point;
            writeln!(err, "note: {} V, {} N: {} ({e})", op.voltage_v, op.preload_n, response_status(c))?;
        }
    }
    if let Some(path) = &a.output {
        write_atomic(path, ".csv", &response_csv(&curves), out)?;
    }
    if let Some(path) = &a.plot {
        write_figure(path, &response_plot(&curves, voltages.len() > 1, preloads.len() > 1), err)?;
    }
    let summary_to_stderr = a.output.as_deref().is_some_and(|p| p.as_os_str() == "-");
    if a.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&summary_json(&curves))?)?;
        return Ok(0);
    }
    let summary_out: &mut dyn Write = if summary_to_stderr { err } else { out };
    write_summary(&curves, summary_out)?;
    Ok(0)
}

/// The summary table as JSON: one object per curve, `null` for numbers a curve lacks.
fn summary_json(curves: &[FamilyCurve]) -> serde_json::Value {
    let num = crate::data::num;
    let list: Vec<_> = curves
        .iter()
        .map(|c| {
            let op = c.operating_point;
            let mut o = json!({
                "voltage_v": op.voltage_v,
                "preload_n": op.preload_n,
                "status": response_status(c),
            });
            if let Err(e) = &c.response {
                o["reason"] = json!(e.to_string());
            }
            let m = c.response.is_ok().then(|| response_summary(c));
            for (k, f) in [
                ("linear_resonance_hz", m.as_ref().map(|m| m.linear_resonance_hz)),
                ("equivalent_beta_n_per_m3", m.as_ref().map(|m| m.equivalent_beta_n_per_m3)),
                ("peak_amplitude_m", m.as_ref().map(|m| m.peak_amplitude_m)),
                ("jump_up_hz", m.as_ref().map(|m| m.jump_up_hz)),
                ("jump_down_hz", m.as_ref().map(|m| m.jump_down_hz)),
                ("hysteresis_hz", m.as_ref().map(|m| m.hysteresis_hz)),
            ] {
                o[k] = num(f.unwrap_or(f64::NAN));
            }
            o
        })
        .collect();
    json!({ "curves": list })
}

/// The response table (`trum_core::layout::response_rows`, the layout Python's
/// `Resonance.to_dict` has too) as CSV; numbers a row does not have are empty cells.
fn response_csv(curves: &[FamilyCurve]) -> String {
    let mut s = RESPONSE_COLUMNS.join(",");
    s.push('\n');
    for r in response_rows(curves) {
        let cells: Vec<String> = r
            .cells()
            .iter()
            .map(|c| match *c {
                ResponseCell::Number(x) => csv_number(x),
                ResponseCell::Word(w) => w.to_string(),
                ResponseCell::Flag(f) => f.map(|b| b.to_string()).unwrap_or_default(),
            })
            .collect();
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}

fn response_plot(curves: &[FamilyCurve], by_voltage: bool, by_preload: bool) -> LinePlot {
    let n = curves.len();
    let mut lines = Vec::new();
    for (i, c) in curves.iter().enumerate() {
        let Ok(r) = &c.response else { continue };
        let op = c.operating_point;
        let color = series_color(i, n);
        let mut label = Vec::new();
        if by_voltage || !by_preload {
            label.push(format!("{} V", fmt_sig(op.voltage_v, 6)));
        }
        if by_preload {
            label.push(format!("{} N", fmt_sig(op.preload_n, 6)));
        }
        let pts = |b: Branch| r.points.iter().filter(move |p| p.branch == b).map(|p| (p.frequency_hz, p.amplitude_m));
        let (mut lower, mut middle, mut upper): (Vec<_>, Vec<_>, Vec<_>) =
            (pts(Branch::Lower).collect(), pts(Branch::Middle).collect(), pts(Branch::Upper).collect());
        let mut single: Vec<(f64, f64)> = pts(Branch::Single).collect();
        if let Some(j) = &r.jumps {
            // The lower branch ends at the jump-up saddle and continues, past the
            // jump-down saddle, into the single-valued part on that side; the upper
            // branch the other way round. The middle (unstable) joins the two saddles.
            let (up, down) = ((j.jump_up_hz, j.jump_up_amplitude_m), (j.jump_down_hz, j.jump_down_amplitude_m));
            let dir = (down.0 - up.0).signum();
            let (beyond_down, beyond_up): (Vec<_>, Vec<_>) = single.drain(..).partition(|p| (p.0 - down.0) * dir > 0.0);
            lower.extend(beyond_down);
            lower.push(up);
            upper.extend(beyond_up);
            upper.push(down);
            middle.extend([up, down]);
        }
        let sorted = |mut v: Vec<(f64, f64)>| {
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            v
        };
        let solid = |points, label| Line { label, color, points, stroke: Stroke::Solid };
        // the legend entry goes on the first line that has points
        let label = Some(label.join(", "));
        let (single_label, lower_label) = if lower.is_empty() { (label, None) } else { (None, label) };
        lines.push(solid(sorted(single), single_label));
        lines.push(solid(sorted(lower), lower_label));
        lines.push(solid(sorted(upper), None));
        lines.push(Line { label: None, color, points: sorted(middle), stroke: Stroke::Dashed });
        let backbone = c.backbone.iter().map(|b| (b.frequency_hz, b.amplitude_m)).collect();
        lines.push(Line { label: None, color, points: backbone, stroke: Stroke::Dotted });
        if let Some(j) = &r.jumps {
            // each jump: the saddle node (circle) and the drop or rise to the other stable
            // branch at the same frequency (a thin vertical line)
            for (f, a, up) in
                [(j.jump_up_hz, j.jump_up_amplitude_m, true), (j.jump_down_hz, j.jump_down_amplitude_m, false)]
            {
                let other = r
                    .points
                    .iter()
                    .filter(|p| p.stable && p.branch != Branch::Middle)
                    .min_by(|p, q| (p.frequency_hz - f).abs().total_cmp(&(q.frequency_hz - f).abs()))
                    .map(|near| {
                        r.points
                            .iter()
                            .filter(|p| p.stable && p.frequency_hz == near.frequency_hz)
                            .map(|p| p.amplitude_m)
                            .fold(if up { f64::NEG_INFINITY } else { f64::INFINITY }, |m, v| {
                                if up {
                                    m.max(v)
                                } else {
                                    m.min(v)
                                }
                            })
                    });
                lines.push(Line { label: None, color, points: vec![(f, a)], stroke: Stroke::Circles });
                if let Some(b) = other.filter(|b| b.is_finite()) {
                    lines.push(Line { label: None, color, points: vec![(f, a), (f, b)], stroke: Stroke::Dotted });
                }
            }
        }
    }
    if !lines.is_empty() {
        let gray = RGBColor(90, 90, 90);
        lines.push(Line { label: Some("unstable branch".into()), color: gray, points: vec![], stroke: Stroke::Dashed });
        lines.push(Line { label: Some("backbone".into()), color: gray, points: vec![], stroke: Stroke::Dotted });
        lines.push(Line {
            label: Some("jump (saddle node)".into()),
            color: gray,
            points: vec![],
            stroke: Stroke::Circles,
        });
    }
    LinePlot {
        title: "Amplitude-frequency response of the Hertzian oscillator".into(),
        subtitle: "solid: stable branches; dashed: unstable branch; dotted: backbone; circles: jumps".into(),
        x: "frequency_hz".into(),
        y: "amplitude_m".into(),
        lines,
    }
}

fn write_summary(curves: &[FamilyCurve], out: &mut dyn Write) -> Result<()> {
    let header = [
        "voltage_v [V]",
        "preload_n [N]",
        "status",
        "linear_resonance_hz [Hz]",
        "equivalent_beta_n_per_m3 [N/m³]",
        "peak_amplitude_m [m]",
        "jump_up_hz [Hz]",
        "jump_down_hz [Hz]",
        "hysteresis_hz [Hz]",
    ];
    let mut rows = Vec::new();
    for c in curves {
        let mut row = vec![fmt_sig(c.operating_point.voltage_v, 6), fmt_sig(c.operating_point.preload_n, 6)];
        row.push(response_status(c).into());
        if c.response.is_ok() {
            let m = response_summary(c);
            row.extend(
                [
                    m.linear_resonance_hz,
                    m.equivalent_beta_n_per_m3,
                    m.peak_amplitude_m,
                    m.jump_up_hz,
                    m.jump_down_hz,
                    m.hysteresis_hz,
                ]
                .map(|x| fmt_sig(x, 7)),
            );
        } else {
            row.extend(std::iter::repeat_n("-".to_string(), 6));
        }
        rows.push(row);
    }
    let mut align = vec![Align::Right; header.len()];
    align[2] = Align::Left;
    write_table(out, &header, &align, &rows)?;
    Ok(())
}

// ---------------------------------------------------------------------------- identify

#[derive(Args, Debug)]
pub struct IdentifyArgs {
    /// Waveform CSV: a `time_s` column and either `feedback_voltage_v` (with --feedback-gain-v-per-m) or `displacement_m`.
    #[arg(long, value_name = "CSV")]
    data: PathBuf,
    #[command(flatten)]
    osc: OscillatorArgs,
    /// Drive frequency of the record [Hz].
    #[arg(long, value_name = "HZ")]
    frequency_hz: f64,
    /// Drive voltage amplitude [V]: sets the drive force F = A V + k_c N (or give --drive-force-n).
    #[arg(long, value_name = "V", required_unless_present = "drive_force_n")]
    voltage_v: Option<f64>,
    /// Static preload N [N]: the DC balance (and F's contact part). Without it only the harmonics n >= 1 are balanced.
    #[arg(long, value_name = "N")]
    preload_n: Option<f64>,
    /// Harmonic drive force amplitude F [N] (instead of --voltage-v).
    #[arg(long, value_name = "N", conflicts_with = "voltage_v")]
    drive_force_n: Option<f64>,
    /// Feedback gain g of v = g w [V/m] (for a `feedback_voltage_v` column; default: the motor's electrical.feedback_gain_v_per_m).
    #[arg(long, value_name = "V_PER_M", allow_hyphen_values = true)]
    feedback_gain_v_per_m: Option<f64>,
    /// Harmonics H in the Fourier fit (1-16).
    #[arg(long, default_value_t = 3)]
    harmonics: usize,
    /// Print JSON instead of the table.
    #[arg(long)]
    json: bool,
}

/// The waveform: times and samples, and whether the samples are a voltage.
struct Waveform {
    time_s: Vec<f64>,
    samples: Vec<f64>,
    column: &'static str,
}

fn read_waveform(path: &Path) -> Result<Waveform> {
    let shown = path.display();
    crate::output::note_input(path, &format!("--data '{shown}'"));
    let mut rdr = csv::ReaderBuilder::new()
        .flexible(false)
        .comment(Some(b'#'))
        .from_path(path)
        .with_context(|| format!("cannot read waveform '{shown}'"))?;
    let headers: Vec<String> = rdr
        .headers()
        .with_context(|| format!("{shown}: cannot read the header line"))?
        .iter()
        .map(|h| h.trim().into())
        .collect();
    let find = |n: &str| headers.iter().position(|h| h == n);
    let Some(it) = find("time_s") else {
        bail!("{shown}, line 1: no 'time_s' column; the columns are: {}", headers.join(", "));
    };
    let (is, column) = match (find("feedback_voltage_v"), find("displacement_m")) {
        (Some(_), Some(_)) => bail!("{shown}, line 1: give either 'feedback_voltage_v' or 'displacement_m', not both"),
        (Some(i), None) => (i, "feedback_voltage_v"),
        (None, Some(i)) => (i, "displacement_m"),
        (None, None) => bail!(
            "{shown}, line 1: no 'feedback_voltage_v' or 'displacement_m' column; the columns are: {}",
            headers.join(", ")
        ),
    };
    let mut w = Waveform { time_s: Vec::new(), samples: Vec::new(), column };
    for rec in rdr.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            anyhow!("{shown}, line {line}: malformed CSV ({e})")
        })?;
        let line = rec.position().map_or(0, |p| p.line());
        for (i, name, dst) in [(it, "time_s", &mut w.time_s), (is, column, &mut w.samples)] {
            let cell = rec.get(i).unwrap_or("").trim();
            let v = cell
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| anyhow!("{shown}, line {line}, column '{name}': '{cell}' is not a finite number"))?;
            if name == "time_s" && dst.last().is_some_and(|&prev| v <= prev) {
                bail!(
                    "{shown}, line {line}, column 'time_s': {v} is not after the previous time (times must increase)"
                );
            }
            dst.push(v);
        }
    }
    if w.time_s.is_empty() {
        bail!("{shown}: no data rows");
    }
    Ok(w)
}

pub fn identify(a: &IdentifyArgs, out: &mut dyn Write) -> Result<i32> {
    let osc = a.osc.load()?;
    let w = read_waveform(&a.data)?;
    let shown = a.data.display();
    let motor_gain = a.osc.motor()?.map(|m| m.electrical.feedback_gain_v_per_m).filter(|g| *g > 0.0);
    let gain = match (w.column, a.feedback_gain_v_per_m.or(motor_gain)) {
        ("displacement_m", None) => 1.0,
        ("displacement_m", Some(_)) if a.feedback_gain_v_per_m.is_none() => 1.0,
        ("displacement_m", Some(_)) => bail!("--feedback-gain-v-per-m: '{shown}' holds displacement_m, not a voltage"),
        (_, Some(g)) => g,
        (_, None) => bail!(
            "--feedback-gain-v-per-m is needed: '{shown}' holds feedback_voltage_v (or give --motor with a feedback gain)"
        ),
    };
    let force = match (a.drive_force_n, a.voltage_v) {
        (Some(f), _) => f,
        (None, Some(v)) => osc
            .forcing_amplitude_n(&OperatingPoint { voltage_v: v, preload_n: a.preload_n.unwrap_or(0.0) })
            .map_err(|e| anyhow!("--voltage-v/--preload-n: {e}"))?,
        (None, None) => bail!("give --voltage-v or --drive-force-n"),
    };
    let input = BetaIdentificationInput {
        sample_times_s: &w.time_s,
        samples_v: &w.samples,
        drive_frequency_hz: a.frequency_hz,
        feedback_gain_v_per_m: gain,
        drive_force_amplitude_n: force,
        static_force_n: a.preload_n,
        modal_mass_kg: osc.modal_mass_kg,
        damping_ns_per_m: osc.damping_ns_per_m,
        linear_stiffness_n_per_m: osc.linear_stiffness_n_per_m,
        harmonics: a.harmonics,
    };
    let id = identify_beta(&input).map_err(|e| anyhow!("{shown}: {e}"))?;
    let rows: [(&str, f64, &str, &str); 9] = [
        ("beta_n_per_m3", id.beta_n_per_m3, "N/m³", "cubic coefficient, multi-harmonic balance"),
        ("one_term_beta_n_per_m3", id.one_term_beta_n_per_m3, "N/m³", "cubic coefficient, fundamental balance only"),
        ("harmonic_fit_r_squared", id.harmonic_fit_r_squared, "-", "R² of the harmonic fit to the samples"),
        ("waveform_residual_rms", id.waveform_residual_rms_v, unit_of_column(w.column), "RMS residual of that fit"),
        ("balance_residual_rms_m", id.balance_residual_rms_m, "m", "RMS harmonic-balance residual (displacement)"),
        ("balance_relative_residual", id.balance_relative_residual, "-", "balance residual / harmonic amplitudes"),
        ("displacement_amplitude_m", id.displacement_amplitude_m, "m", "fundamental displacement amplitude"),
        ("periods_spanned", id.periods_spanned, "-", "drive periods in the record"),
        ("drive_force_n", force, "N", "harmonic drive force amplitude used"),
    ];
    if a.json {
        let mut m = serde_json::Map::new();
        m.insert("data".into(), json!(a.data.display().to_string()));
        m.insert("column".into(), json!(w.column));
        m.insert("samples".into(), json!(w.time_s.len()));
        for (name, v, _, _) in rows {
            let key = if name == "waveform_residual_rms" {
                format!("waveform_residual_rms_{}", suffix(w.column))
            } else {
                name.into()
            };
            m.insert(key, num(v));
        }
        writeln!(out, "{}", serde_json::to_string_pretty(&serde_json::Value::Object(m))?)?;
    } else {
        let table: Vec<Vec<String>> = rows
            .iter()
            .map(|(n, v, u, what)| {
                let name =
                    if *n == "waveform_residual_rms" { format!("{n}_{}", suffix(w.column)) } else { n.to_string() };
                vec![name, fmt_sig(*v, 7), u.to_string(), what.to_string()]
            })
            .collect();
        writeln!(out, "waveform {} ({} samples of {})", shown, w.time_s.len(), w.column)?;
        write_table(out, &["quantity", "value", "unit", "meaning"], &[Align::Left, Align::Right, Align::Left], &table)?;
    }
    Ok(0)
}

fn unit_of_column(column: &str) -> &'static str {
    if column == "displacement_m" {
        "m"
    } else {
        "V"
    }
}

fn suffix(column: &str) -> &'static str {
    if column == "displacement_m" {
        "m"
    } else {
        "v"
    }
}
