//! `trum plot`: curves (one line per value of a group column) and heat maps, from a motor
//! (solved here on a small grid) or from a map CSV written by `trum map`.
//!
//! Text is rendered with plotters' `ttf` feature, which needs a system font. When none is
//! found the plot is still drawn, without any text, and a warning says so.

use crate::args::{GridArgs, MotorArgs};
use crate::format::unit_of;
use crate::grid::check_grid;
use crate::output::OutputTarget;
use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, ValueEnum};
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use trum_core::quantities::QUANTITIES;
use trum_core::solve::Prepared;
use trum_core::sweep::{axis_values, chunk_count, chunk_range, solve_range, Axis, Grid, AXES};
use trum_core::{Motor, OperatingPoint, Solution};

/// Largest grid `trum plot --motor` solves in memory; bigger ones go through `trum map`.
const MAX_PLOT_POINTS: u64 = 2_000_000;
const SIZE_PX: (u32, u32) = (1024, 720);

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Kind {
    /// Speed against load torque, one curve per preload.
    SpeedTorque,
    /// Efficiency against load torque, one curve per preload.
    EfficiencyTorque,
    /// Output power against load torque, one curve per preload.
    PowerTorque,
    /// No-load speed against drive frequency, one curve per voltage.
    SpeedFrequency,
    /// Efficiency map over the load torque × speed plane of a torque × preload grid (as
    /// motor makers draw them), with iso-efficiency contours and the stall boundary.
    EfficiencyMap,
    /// Heat map of speed over load torque × preload.
    SpeedMap,
    /// Heat map of steady-state temperature rise over load torque × preload.
    TemperatureMap,
}

impl Kind {
    /// (x, y, group, z) columns.
    fn columns(self) -> (&'static str, &'static str, Option<&'static str>, Option<&'static str>) {
        match self {
            Kind::SpeedTorque => ("torque_nm", "speed_rpm", Some("preload_n"), None),
            Kind::EfficiencyTorque => ("torque_nm", "efficiency", Some("preload_n"), None),
            Kind::PowerTorque => ("torque_nm", "output_power_w", Some("preload_n"), None),
            Kind::SpeedFrequency => ("frequency_hz", "speed_rpm", Some("voltage_v"), None),
            Kind::EfficiencyMap => ("torque_nm", "preload_n", None, Some("efficiency")),
            Kind::SpeedMap => ("torque_nm", "preload_n", None, Some("speed_rpm")),
            Kind::TemperatureMap => ("torque_nm", "preload_n", None, Some("temperature_rise_k")),
        }
    }

    /// Default grid for `--motor` (torque `None`: from zero to just above the largest loaded stall torque).
    fn default_axes(self) -> (Axis, Option<Axis>, Axis, Axis) {
        let (f, v) = (Axis::fixed(43_000.0), Axis::fixed(200.0));
        match self {
            Kind::SpeedTorque | Kind::EfficiencyTorque | Kind::PowerTorque => {
                (Axis::linspace(150.0, 400.0, 6), None, v, f)
            }
            Kind::SpeedFrequency => (
                Axis::fixed(250.0),
                Some(Axis::fixed(0.0)),
                Axis::linspace(100.0, 200.0, 3),
                Axis::linspace(41_000.0, 46_000.0, 101),
            ),
            Kind::EfficiencyMap | Kind::SpeedMap | Kind::TemperatureMap => {
                (Axis::linspace(100.0, 500.0, 41), None, v, f)
            }
        }
    }
}

#[derive(Args, Debug)]
pub struct PlotArgs {
    /// Motor to solve (TOML file or preset name); or use --map.
    #[arg(long, value_name = "FILE|PRESET", conflicts_with = "map", required_unless_present = "map")]
    motor: Option<String>,
    /// Switch an unmodelled effect on (with --motor): NAME=STRENGTH (repeatable).
    #[arg(long = "effect", value_name = "NAME=STRENGTH", requires = "motor")]
    effects: Vec<String>,
    /// A map CSV written by `trum map`.
    #[arg(long, value_name = "CSV")]
    map: Option<PathBuf>,
    /// What to plot (sets --x, --y and --group or --z; each can still be given).
    #[arg(long, value_enum)]
    kind: Option<Kind>,
    /// Column on the horizontal axis.
    #[arg(long)]
    x: Option<String>,
    /// Column on the vertical axis.
    #[arg(long)]
    y: Option<String>,
    /// One curve per distinct value of this column.
    #[arg(long, conflicts_with = "z")]
    group: Option<String>,
    /// Heat-map colour column (x and y are then the cell coordinates).
    #[arg(long)]
    z: Option<String>,
    #[command(flatten)]
    grid: GridArgs,
    /// Plot title (default: motor or file name and the columns).
    #[arg(long)]
    title: Option<String>,
    /// Output image: .png or .svg.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: PathBuf,
}

/// Columns of numbers; NaN marks a missing or invalid value.
struct Data {
    names: Vec<String>,
    cols: Vec<Vec<f64>>,
    /// Per row, whether the point is beyond one of the motor's `[limits]` (points solved
    /// from a motor; `None` for a CSV).
    beyond: Option<Vec<bool>>,
}

impl Data {
    fn col(&self, name: &str, what: &str) -> Result<&[f64]> {
        match self.names.iter().position(|n| n == name) {
            Some(i) => Ok(&self.cols[i]),
            None => {
                let hint = crate::suggest::hint(name, crate::suggest::names(self.names.iter().map(String::as_str)));
                bail!("{what} column '{name}' does not exist{hint}; available columns are: {}", self.names.join(", "))
            }
        }
    }
}

struct Spec {
    x: String,
    y: String,
    group: Option<String>,
    z: Option<String>,
    title: String,
    /// Fixed conditions and effects, under the title.
    subtitle: String,
    /// Draw `z` over the (load torque, speed) plane of a torque × preload map, with
    /// contours and the stall boundary, instead of a heat map over the grid.
    speed_torque_plane: bool,
}

pub fn run(a: &PlotArgs, err: &mut dyn Write) -> Result<i32> {
    check_plot_path(&a.output)?;
    let (dx, dy, dg, dz) = match a.kind {
        Some(k) => k.columns(),
        None => ("", "", None, None),
    };
    let x = a.x.clone().unwrap_or_else(|| dx.to_string());
    let y = a.y.clone().unwrap_or_else(|| dy.to_string());
    if x.is_empty() || y.is_empty() {
        bail!("give --kind, or --x and --y (and --group for curves or --z for a heat map)");
    }
    let (group, z) = if a.group.is_some() || a.z.is_some() {
        (a.group.clone(), a.z.clone())
    } else {
        (dg.map(String::from), dz.map(String::from))
    };

    let plane = a.kind == Some(Kind::EfficiencyMap) && a.x.is_none() && a.y.is_none();
    let (data, source, effects) = match (&a.motor, &a.map) {
        (Some(m), _) => {
            let ma = MotorArgs { motor: m.clone(), effects: a.effects.clone() };
            let (motor, sweep) = ma.load()?;
            let grid = plot_grid(&motor, a, &sweep, &x)?;
            (solve_grid(&motor, &grid), motor.name.clone(), Some(motor.effects.to_string()))
        }
        (None, Some(path)) => {
            let mut needed = vec![x.as_str(), y.as_str()];
            needed.extend(group.as_deref());
            needed.extend(z.as_deref());
            if plane {
                needed.push("speed_rpm");
            }
            // the operating-point columns a map always has: for the fixed conditions
            let header = std::fs::read_to_string(path).ok().and_then(|t| t.lines().next().map(str::to_string));
            for c in ["preload_n", "torque_nm", "voltage_v", "frequency_hz"] {
                if !needed.contains(&c) && header.as_deref().is_some_and(|h| h.split(',').any(|n| n.trim() == c)) {
                    needed.push(c);
                }
            }
            needed.dedup();
            (read_csv(path, &needed)?, path.display().to_string(), None)
        }
        (None, None) => bail!("give --motor or --map"),
    };
    let words = |c: &str| {
        let w = display(c).0;
        w[..1].to_string() + &w[1..]
    };
    let what = match (&group, &z) {
        (_, Some(z)) if plane => format!("{} over load torque and speed", words(z)),
        (_, Some(z)) => format!("{} over {} and {}", words(z), words(&x).to_lowercase(), words(&y).to_lowercase()),
        (Some(g), None) => {
            format!("{} against {}, by {}", words(&y), words(&x).to_lowercase(), words(g).to_lowercase())
        }
        (None, None) => format!("{} against {}", words(&y), words(&x).to_lowercase()),
    };
    // conditions that do not vary in the data and are not on an axis, and the effects
    let mut fixed = Vec::new();
    for c in ["preload_n", "torque_nm", "voltage_v", "frequency_hz"] {
        if [Some(x.as_str()), Some(y.as_str()), group.as_deref()].contains(&Some(c)) {
            continue;
        }
        if let Ok(v) = data.col(c, "") {
            let d = distinct_sorted(v);
            if d.len() == 1 {
                fixed.push(condition(c, d[0]));
            }
        }
    }
    let mut subtitle = fixed.join(", ");
    if let Some(e) = effects {
        let e = if e == "none" { "nominal model (no effects)".to_string() } else { format!("effects: {e}") };
        subtitle = if subtitle.is_empty() { e } else { format!("{subtitle}\n{e}") };
    }
    let spec = Spec {
        title: a.title.clone().unwrap_or_else(|| format!("{source}: {what}")),
        subtitle,
        x,
        y,
        group,
        z,
        speed_torque_plane: plane,
    };

    write_figure(&a.output, &SpecFigure { spec: &spec, data: &data }, err)?;
    Ok(0)
}

/// How a figure is drawn: with or without text (no font found), and the scale of the
/// drawing surface over the final image (fonts, strokes and margins grow with it).
#[derive(Clone, Copy, Debug)]
pub struct Look {
    /// False when no font is available: the plot is drawn without text.
    pub labels: bool,
    /// Drawing-surface pixels per image pixel.
    pub k: f64,
}

impl Look {
    /// `v` image pixels in drawing-surface pixels.
    pub fn px(&self, v: f64) -> u32 {
        (v * self.k).round().max(1.0) as u32
    }
    /// A font of `size` image pixels.
    pub fn font(&self, size: f64) -> (&'static str, f64) {
        ("sans-serif", size * self.k)
    }
}

/// Something `write_figure` can draw on either backend.
pub trait Figure {
    /// Draws on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, look: Look, err: &mut dyn Write) -> Result<()>;
}

/// Checks that `output` is a plot file name (.png or .svg, the format follows it).
pub fn check_plot_path(output: &Path) -> Result<String> {
    let ext = output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    if ext != "png" && ext != "svg" {
        bail!("-o '{}': the plot file name must end in .png or .svg", output.display());
    }
    Ok(ext)
}

/// Supersampling of PNG output: drawn at this many times the size and averaged down, so
/// lines and text are anti-aliased (plotters' bitmap backend draws hard pixel edges).
const PNG_SUPERSAMPLE: u32 = 3;
/// SVG output is drawn on a surface this many times the image size and shown at the image
/// size through its `viewBox`: plotters' SVG backend writes whole units, which become
/// quarter pixels.
const SVG_SUBPIXEL: u32 = 4;

/// Draws `fig` into `output` (.png or .svg) through an atomically renamed temporary file.
pub fn write_figure(output: &Path, fig: &impl Figure, err: &mut dyn Write) -> Result<()> {
    let ext = check_plot_path(output)?;
    let labels = fonts_available();
    if !labels {
        writeln!(err, "warning: no usable system font found (plotters' ttf); the plot is drawn without text")?;
    }
    let target = OutputTarget::create(output, &format!(".{ext}"))?;
    let Some(draw_path) = target.draw_path() else { bail!("a plot cannot be written to stdout; give a file name") };
    let (w, h) = SIZE_PX;
    if ext == "svg" {
        let k = SVG_SUBPIXEL;
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, (w * k, h * k)).into_drawing_area();
            root.fill(&WHITE).map_err(de)?;
            fig.draw(&root, Look { labels, k: f64::from(k) }, err)?;
            root.present().map_err(de)?;
        }
        // shown at the image size; the drawing keeps its finer coordinates in the viewBox
        let text = text.replacen(
            &format!("width=\"{}\" height=\"{}\"", w * k, h * k),
            &format!("width=\"{w}\" height=\"{h}\""),
            1,
        );
        std::fs::write(draw_path, text).with_context(|| format!("writing '{}'", output.display()))?;
    } else {
        let k = PNG_SUPERSAMPLE;
        let mut big = vec![0u8; (w * k * h * k * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut big, (w * k, h * k)).into_drawing_area();
            root.fill(&WHITE).map_err(de)?;
            fig.draw(&root, Look { labels, k: f64::from(k) }, err)?;
            root.present().map_err(de)?;
        }
        let small = downsample(&big, (w, h), k);
        let mut out = BitMapBackend::new(draw_path, (w, h));
        out.blit_bitmap((0, 0), (w, h), &small).map_err(de)?;
        out.present().map_err(de)?;
    }
    target.finish()
}

/// Averages `k` × `k` blocks of an RGB image of `k` times `size`.
fn downsample(big: &[u8], (w, h): (u32, u32), k: u32) -> Vec<u8> {
    let (w, h, k) = (w as usize, h as usize, k as usize);
    let bw = w * k;
    let mut out = vec![0u8; w * h * 3];
    for y in 0..h {
        for x in 0..w {
            let mut acc = [0u32; 3];
            for dy in 0..k {
                let row = ((y * k + dy) * bw + x * k) * 3;
                for dx in 0..k {
                    for (c, a) in acc.iter_mut().enumerate() {
                        *a += u32::from(big[row + dx * 3 + c]);
                    }
                }
            }
            let n = (k * k) as u32;
            for (c, a) in acc.iter().enumerate() {
                out[(y * w + x) * 3 + c] = ((a + n / 2) / n) as u8;
            }
        }
    }
    out
}

struct SpecFigure<'a> {
    spec: &'a Spec,
    data: &'a Data,
}

impl Figure for SpecFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, look: Look, err: &mut dyn Write) -> Result<()> {
        draw(root, self.spec, self.data, look, err)
    }
}

/// How a [`Line`] is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stroke {
    /// A solid line.
    Solid,
    /// A dashed line (unstable branches, limits).
    Dashed,
    /// A thin dotted line (backbones, references).
    Dotted,
    /// Open circles at the points, no line (jumps, saddle nodes).
    Circles,
}

/// One polyline of a [`LinePlot`]; non-finite points break it.
pub struct Line {
    /// Legend text (`None`: not in the legend).
    pub label: Option<String>,
    /// Colour.
    pub color: RGBColor,
    /// Points in drawing order.
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub stroke: Stroke,
}

/// Explicit lines against named (unit-suffixed) axes.
pub struct LinePlot {
    /// Title.
    pub title: String,
    /// Second title line: the fixed conditions and the effects switched on (may be empty).
    pub subtitle: String,
    /// Horizontal axis column name (its unit is looked up for the label).
    pub x: String,
    /// Vertical axis column name.
    pub y: String,
    /// The lines.
    pub lines: Vec<Line>,
}

impl Figure for LinePlot {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, look: Look, _: &mut dyn Write) -> Result<()> {
        draw_lines(root, self, look)
    }
}

fn de<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("drawing failed: {e}")
}

fn fonts_available() -> bool {
    ("sans-serif", 16).into_font().box_size("0.5 N·m").is_ok()
}

/// The grid for `--motor`: command line, then `[sweep]`, then the kind's defaults. An unset
/// torque axis runs from zero to 5 % above the largest loaded stall torque over the
/// preload axis, as `trum map`'s default grid ([`crate::grid::running_torque_top`]).
fn plot_grid(motor: &Motor, a: &PlotArgs, sweep: &trum_core::params::SweepTable, x: &str) -> Result<Grid> {
    let (p, t, mut v, mut f) = match a.kind {
        Some(k) => k.default_axes(),
        None => {
            let d = crate::grid::default_grid();
            let t = if x == "torque_nm" { None } else { Some(d.torque_nm) };
            (d.preload_n, t, d.voltage_v, d.frequency_hz)
        }
    };
    // a fixed drive defaults to the motor's own (its [drive], as `trum map` and `trum optimize`)
    if let Some(d) = a.motor.as_deref().map(crate::optimize::motor_drive).transpose()?.flatten() {
        if v.n == 1 {
            v = Axis::fixed(d.voltage_v);
        }
        if f.n == 1 {
            f = Axis::fixed(d.frequency_hz);
        }
    }
    let mut grid =
        a.grid.resolve(sweep, &Grid { preload_n: p, torque_nm: Axis::fixed(0.0), voltage_v: v, frequency_hz: f });
    if a.grid.torque_nm.is_none() && sweep.torque_nm.is_none() {
        if let Some(t) = t {
            grid.torque_nm = t;
        } else {
            let top =
                crate::grid::running_torque_top(motor, &grid.preload_n, grid.voltage_v.start, grid.frequency_hz.start)
                    .unwrap_or(1.0);
            grid.torque_nm = Axis::linspace(0.0, top, 61);
        }
    }
    check_grid(&grid)?;
    if grid.len() > MAX_PLOT_POINTS {
        bail!(
            "the plot grid has {} points (more than {MAX_PLOT_POINTS}); write it with `trum map` and plot with --map",
            grid.len()
        );
    }
    Ok(grid)
}

fn solve_grid(motor: &Motor, grid: &Grid) -> Data {
    // Smaller chunks than a map's (`trum_core::sweep::CHUNK_POINTS`): a plot grid of a few
    // thousand points is then still solved on every core.
    const CHUNK: u64 = 512;
    let total = grid.len();
    let prep = Prepared::new(motor);
    let chunks: Vec<Vec<(OperatingPoint, Solution)>> = (0..chunk_count(total, CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut v = Vec::new();
            solve_range(motor, &prep, grid, chunk_range(total, CHUNK, c), |_, op, s| v.push((*op, s.clone())));
            v
        })
        .collect();
    let mut names: Vec<String> = AXES.map(String::from).to_vec();
    names.extend(QUANTITIES.iter().map(|q| q.name.to_string()));
    let mut cols = vec![Vec::with_capacity(total as usize); names.len()];
    let beyond = chunks.iter().flatten().map(|(_, s)| !s.warnings.is_empty()).collect();
    for (op, s) in chunks.iter().flatten() {
        let valid = s.status.is_valid();
        let row =
            axis_values(op).into_iter().chain(QUANTITIES.iter().map(|q| if valid { (q.get)(s) } else { f64::NAN }));
        for (c, v) in cols.iter_mut().zip(row) {
            c.push(v);
        }
    }
    Data { names, cols, beyond: Some(beyond) }
}

/// Reads the needed columns of a CSV; empty cells are missing values.
fn read_csv(path: &Path, needed: &[&str]) -> Result<Data> {
    let shown = path.display();
    crate::output::note_input(path, &format!("--map '{shown}'"));
    let mut rdr = csv::ReaderBuilder::new()
        .flexible(false)
        .from_path(path)
        .with_context(|| format!("cannot read map '{shown}'"))?;
    let headers = rdr.headers().with_context(|| format!("{shown}: cannot read the header line"))?.clone();
    let all: Vec<String> = headers.iter().map(|h| h.trim().to_string()).collect();
    let mut idx = Vec::new();
    for n in needed {
        match all.iter().position(|h| h == n) {
            Some(i) => idx.push(i),
            None => {
                let hint = crate::suggest::hint(n, crate::suggest::names(all.iter().map(String::as_str)));
                bail!("{shown}: column '{n}' does not exist{hint}; the columns are: {}", all.join(", "))
            }
        }
    }
    let mut cols = vec![Vec::new(); needed.len()];
    for rec in rdr.records() {
        let rec = rec.with_context(|| format!("{shown}: malformed CSV"))?;
        let line = rec.position().map(|p| p.line()).unwrap_or(0);
        for (k, &i) in idx.iter().enumerate() {
            let cell = rec.get(i).unwrap_or("").trim();
            let v = if cell.is_empty() {
                f64::NAN
            } else {
                cell.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                    anyhow!("{shown}: line {line}, column '{}': '{cell}' is not a finite number", needed[k])
                })?
            };
            cols[k].push(v);
        }
    }
    if cols.first().is_none_or(|c| c.is_empty()) {
        bail!("{shown}: no data rows");
    }
    Ok(Data { names: needed.iter().map(|s| s.to_string()).collect(), cols, beyond: None })
}

/// How a column is shown on an axis: words, the unit shown and the factor from the
/// column's SI unit to it (amplitudes in µm, efficiencies in %, frequencies in kHz).
pub fn display(name: &str) -> (String, String, f64) {
    let known: Option<(&str, &str, f64)> = match name {
        "preload_n" => Some(("Preload", "N", 1.0)),
        "torque_nm" => Some(("Load torque", "N·m", 1.0)),
        "voltage_v" => Some(("Drive voltage", "V", 1.0)),
        "frequency_hz" => Some(("Drive frequency", "kHz", 1e-3)),
        "elapsed_s" => Some(("Time since switch-on", "s", 1.0)),
        "speed_rpm" => Some(("Speed", "rpm", 1.0)),
        "speed_rad_s" => Some(("Angular speed", "rad/s", 1.0)),
        "efficiency" => Some(("Efficiency", "%", 100.0)),
        "output_power_w" => Some(("Output power", "W", 1.0)),
        "input_power_w" => Some(("Input power", "W", 1.0)),
        "stall_torque_nm" => Some(("Stall torque", "N·m", 1.0)),
        "amplitude_m" => Some(("Vibration amplitude", "µm", 1e6)),
        "contact_angle_deg" => Some(("Contact angle", "°", 1.0)),
        "driving_angle_deg" => Some(("Driving angle", "°", 1.0)),
        "temperature_rise_k" => Some(("Temperature rise", "K", 1.0)),
        "speed_std_rpm" => Some(("Speed fluctuation (std)", "rpm", 1.0)),
        "current_a" => Some(("Drive current", "A", 1.0)),
        "feedback_v" => Some(("Feedback voltage", "V", 1.0)),
        "time_s" => Some(("Time", "ms", 1e3)),
        "position_m" => Some(("Position along the wavelength", "mm", 1e3)),
        "tangential_force_n_per_m" => Some(("Tangential force per length", "N/m", 1.0)),
        _ => None,
    };
    if let Some((w, u, f)) = known {
        return (w.to_string(), u.to_string(), f);
    }
    // other quantities: their meaning from the registry, their unit as the CLI writes it
    let words = QUANTITIES
        .iter()
        .find(|q| q.name == name)
        .map(|q| {
            let d = q.doc.split(',').next().unwrap_or(q.doc);
            let mut c = d.chars();
            c.next().map(|f| f.to_uppercase().collect::<String>() + c.as_str()).unwrap_or_default()
        })
        .unwrap_or_else(|| name.replace('_', " "));
    let unit = unit_of(name).filter(|u| *u != "-").map(|u| u.replace("N m", "N·m")).unwrap_or_default();
    (words, unit, 1.0)
}

/// `"Speed [rpm]"`: words and unit, for an axis.
pub fn axis_label(name: &str) -> String {
    let (w, u, _) = display(name);
    if u.is_empty() {
        w
    } else {
        format!("{w} [{u}]")
    }
}

/// `"preload 250 N"`: a fixed condition in words.
pub fn condition(name: &str, v: f64) -> String {
    let (w, u, f) = display(name);
    format!("{} {} {u}", w.to_lowercase(), crate::format::fmt_sig(v * f, 6)).trim_end().to_string()
}

fn padded(lo: f64, hi: f64, from_zero: bool) -> (f64, f64) {
    let (mut lo, hi) = (lo, hi);
    if from_zero && lo >= 0.0 && lo < 0.5 * hi {
        lo = 0.0;
    }
    if hi <= lo {
        let d = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        return (lo - d, hi + d);
    }
    let d = 0.03 * (hi - lo);
    (if lo == 0.0 { 0.0 } else { lo - d }, hi + d)
}

fn finite_range(v: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    v.filter(|x| x.is_finite()).fold(None, |acc, x| match acc {
        None => Some((x, x)),
        Some((a, b)) => Some((a.min(x), b.max(x))),
    })
}

/// Axis titles in words with units and tick labels on a chart's mesh, or no labels at all
/// for an unlabelled picture.
fn label_mesh<X, Y, DB>(mesh: &mut plotters::chart::MeshStyle<'_, '_, X, Y, DB>, x: &str, y: &str, look: Look)
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
    DB: DrawingBackend,
{
    if look.labels {
        mesh.x_desc(axis_label(x))
            .y_desc(axis_label(y))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .label_style(look.font(15.0))
            .axis_desc_style(look.font(17.0));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
}

fn tick(v: &f64) -> String {
    crate::format::fmt_sig(*v, 4)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    spec: &Spec,
    data: &Data,
    look: Look,
    err: &mut dyn Write,
) -> Result<()> {
    let xs = data.col(&spec.x, "--x")?;
    let ys = data.col(&spec.y, "--y")?;
    if spec.speed_torque_plane {
        let z = spec.z.as_deref().unwrap_or("efficiency");
        return efficiency_plane(root, spec, data, z, look);
    }
    match &spec.z {
        Some(z) => {
            let zs = data.col(z, "--z")?;
            heat_map(root, spec, xs, ys, zs, data.beyond.as_deref(), look, err)
        }
        None => {
            let gs = match &spec.group {
                Some(g) => Some(data.col(g, "--group")?),
                None => None,
            };
            curves(root, spec, xs, ys, gs, look)
        }
    }
}

fn curves<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    spec: &Spec,
    xs: &[f64],
    ys: &[f64],
    gs: Option<&[f64]>,
    look: Look,
) -> Result<()> {
    // group value (as bits, so it can be a key; ordered by value below) → points
    let mut groups: BTreeMap<u64, (f64, Vec<(f64, f64)>)> = BTreeMap::new();
    for i in 0..xs.len() {
        let g = gs.map_or(0.0, |g| g[i]);
        if !g.is_finite() || !xs[i].is_finite() {
            continue;
        }
        groups.entry(g.to_bits()).or_insert_with(|| (g, Vec::new())).1.push((xs[i], ys[i]));
    }
    let mut groups: Vec<(f64, Vec<(f64, f64)>)> = groups.into_values().collect();
    groups.sort_by(|a, b| a.0.total_cmp(&b.0));
    let n = groups.len();
    let lines = groups
        .into_iter()
        .enumerate()
        .map(|(gi, (g, mut points))| {
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            let label = spec.group.as_deref().map(|gname| condition(gname, g));
            Line { label, color: series_color(gi, n), points, stroke: Stroke::Solid }
        })
        .collect();
    let plot = LinePlot {
        title: spec.title.clone(),
        subtitle: spec.subtitle.clone(),
        x: spec.x.clone(),
        y: spec.y.clone(),
        lines,
    };
    draw_lines(root, &plot, look)
}

/// The title area: `title` in bold-ish large type, `subtitle` (conditions, effects) below
/// in smaller type; returns the area left for the chart.
fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    subtitle: &str,
    look: Look,
) -> Result<DrawingArea<DB, Shift>> {
    if !look.labels {
        return Ok(root.clone());
    }
    let mut area = root.titled(title, look.font(22.0)).map_err(de)?;
    for line in subtitle.lines().filter(|l| !l.trim().is_empty()) {
        area = area.titled(line, look.font(15.0)).map_err(de)?;
    }
    Ok(area)
}

fn draw_lines<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, plot: &LinePlot, look: Look) -> Result<()> {
    let (_, _, fx) = display(&plot.x);
    let (_, _, fy) = display(&plot.y);
    let pts = || plot.lines.iter().flat_map(|l| l.points.iter()).map(move |p| (p.0 * fx, p.1 * fy));
    let xr = finite_range(pts().map(|p| p.0)).ok_or_else(|| anyhow!("no finite values in column '{}'", plot.x))?;
    let yr = finite_range(pts().map(|p| p.1))
        .ok_or_else(|| anyhow!("no valid values of '{}' to plot (every point is invalid)", plot.y))?;
    let (x0, x1) = padded(xr.0, xr.1, false);
    let (y0, y1) = padded(yr.0, yr.1, true);

    let area = titled(root, &plot.title, &plot.subtitle, look)?;
    let mut cb = ChartBuilder::on(&area);
    cb.margin(look.px(20.0));
    if look.labels {
        cb.x_label_area_size(look.px(55.0)).y_label_area_size(look.px(80.0));
    }
    let mut chart = cb.build_cartesian_2d(x0..x1, y0..y1).map_err(de)?;
    let mut mesh = chart.configure_mesh();
    let grid_line = RGBColor(225, 225, 225).stroke_width(look.px(1.0));
    mesh.light_line_style(WHITE.mix(0.0)).bold_line_style(grid_line).axis_style(BLACK.stroke_width(look.px(1.0)));
    label_mesh(&mut mesh, &plot.x, &plot.y, look);
    mesh.draw().map_err(de)?;
    let mut legend = false;
    for line in &plot.lines {
        let color = line.color;
        let width = if line.stroke == Stroke::Dotted { 1.2 } else { 2.0 };
        let style = color.stroke_width(look.px(width));
        let points: Vec<(f64, f64)> = line.points.iter().map(|p| (p.0 * fx, p.1 * fy)).collect();
        let (dash, gap) = match line.stroke {
            Stroke::Dotted => (look.px(2.0), look.px(4.0)),
            _ => (look.px(9.0), look.px(5.0)),
        };
        let (k, stroke) = (look.k, line.stroke);
        // one element type for every stroke: the parts a stroke does not use are transparent
        let swatch = move |(x, y): (i32, i32)| {
            let px = |v: f64| (v * k).round() as i32;
            let on = |b: bool| ShapeStyle {
                color: if b { color.to_rgba() } else { TRANSPARENT },
                filled: false,
                stroke_width: (2.0 * k).round().max(1.0) as u32,
            };
            let ((a0, a1), (b0, b1)) = match stroke {
                Stroke::Solid => ((0.0, 22.0), (22.0, 22.0)),
                Stroke::Dashed => ((0.0, 8.0), (14.0, 22.0)),
                Stroke::Dotted => ((0.0, 3.0), (19.0, 22.0)),
                Stroke::Circles => ((0.0, 0.0), (0.0, 0.0)),
            };
            let line = stroke != Stroke::Circles;
            EmptyElement::at((x, y))
                + Circle::new((px(11.0), 0), px(4.0), on(!line))
                + PathElement::new(vec![(px(a0), 0), (px(a1), 0)], on(line))
                + PathElement::new(vec![(px(b0), 0), (px(b1), 0)], on(line))
        };
        // a legend-only entry (no points) still gets its swatch
        if points.is_empty() {
            if let (true, Some(label)) = (look.labels, &line.label) {
                chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                    .map_err(de)?
                    .label(label.clone())
                    .legend(swatch);
                legend = true;
            }
            continue;
        }
        // invalid points (NaN) break the line instead of being joined across
        let mut labelled = false;
        for seg in points.split(|p| !p.0.is_finite() || !p.1.is_finite()).filter(|s| !s.is_empty()) {
            let pts = seg.iter().copied();
            let series = match line.stroke {
                Stroke::Solid => chart.draw_series(LineSeries::new(pts, style)).map_err(de)?,
                Stroke::Dashed | Stroke::Dotted => {
                    chart.draw_series(DashedLineSeries::new(pts, dash, gap, style)).map_err(de)?
                }
                Stroke::Circles => chart
                    .draw_series(pts.map(|p| Circle::new(p, look.px(5.0), color.stroke_width(look.px(1.8)))))
                    .map_err(de)?,
            };
            if let (false, true, Some(label)) = (labelled, look.labels, &line.label) {
                series.label(label.clone()).legend(swatch);
                labelled = true;
                legend = true;
            }
        }
    }
    if legend {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(look.font(15.0))
            .legend_area_size(look.px(30.0))
            .margin(look.px(8.0))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.stroke_width(look.px(1.0)))
            .draw()
            .map_err(de)?;
    }
    Ok(())
}

/// Distinct colours: a viridis-like ramp for ordered groups (preloads, voltages).
pub fn series_color(i: usize, n: usize) -> RGBColor {
    let t = if n <= 1 { 0.0 } else { i as f64 / (n - 1) as f64 };
    // stop short of viridis' pale yellow end, which is hard to see on white
    colormap(0.9 * t)
}

/// Viridis, linearly interpolated between nine anchors (t in [0, 1]).
fn colormap(t: f64) -> RGBColor {
    const A: [(u8, u8, u8); 9] = [
        (68, 1, 84),
        (71, 44, 122),
        (59, 81, 139),
        (44, 113, 142),
        (33, 144, 141),
        (39, 173, 129),
        (92, 200, 99),
        (170, 220, 50),
        (253, 231, 37),
    ];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let s = t * (A.len() - 1) as f64;
    let i = (s.floor() as usize).min(A.len() - 2);
    let f = s - i as f64;
    let mix = |a: u8, b: u8| (a as f64 + f * (b as f64 - a as f64)).round() as u8;
    RGBColor(mix(A[i].0, A[i + 1].0), mix(A[i].1, A[i + 1].1), mix(A[i].2, A[i + 1].2))
}

/// Cell edges around sorted distinct values: midpoints, half a step beyond the ends.
fn edges(v: &[f64]) -> Vec<f64> {
    if v.len() == 1 {
        let d = if v[0] == 0.0 { 0.5 } else { 0.05 * v[0].abs() };
        return vec![v[0] - d, v[0] + d];
    }
    let mut e = Vec::with_capacity(v.len() + 1);
    e.push(v[0] - 0.5 * (v[1] - v[0]));
    for w in v.windows(2) {
        e.push(0.5 * (w[0] + w[1]));
    }
    let n = v.len();
    e.push(v[n - 1] + 0.5 * (v[n - 1] - v[n - 2]));
    e
}

fn distinct_sorted(v: &[f64]) -> Vec<f64> {
    let mut d: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    d.sort_by(f64::total_cmp);
    d.dedup();
    d
}

#[allow(clippy::too_many_arguments)]
fn heat_map<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    spec: &Spec,
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    beyond: Option<&[bool]>,
    look: Look,
    err: &mut dyn Write,
) -> Result<()> {
    let z_name = spec.z.as_deref().unwrap_or("");
    let ux = distinct_sorted(xs);
    let uy = distinct_sorted(ys);
    if ux.is_empty() || uy.is_empty() {
        bail!("no finite values in columns '{}' and '{}'", spec.x, spec.y);
    }
    if ux.len() * uy.len() > 4_000_000 {
        bail!("the heat map would have {} cells; plot a coarser map", ux.len() * uy.len());
    }
    let mut cell = vec![f64::NAN; ux.len() * uy.len()];
    let mut marked = vec![false; cell.len()];
    let mut repeated = false;
    for i in 0..xs.len() {
        let (Ok(ix), Ok(iy)) =
            (ux.binary_search_by(|v| v.total_cmp(&xs[i])), uy.binary_search_by(|v| v.total_cmp(&ys[i])))
        else {
            continue;
        };
        let c = &mut cell[iy * ux.len() + ix];
        repeated |= !c.is_nan();
        *c = zs[i];
        marked[iy * ux.len() + ix] = beyond.is_some_and(|b| b[i]);
    }
    if repeated {
        writeln!(
            err,
            "warning: several rows fall in one ({}, {}) cell (another column varies too); the last one is drawn",
            spec.x, spec.y
        )?;
    }
    let (z0, z1) = finite_range(cell.iter().copied())
        .ok_or_else(|| anyhow!("no valid values of '{z_name}' to plot (every point is invalid)"))?;
    let zspan = if z1 > z0 { z1 - z0 } else { 1.0 };
    let ex = edges(&ux);
    let ey = edges(&uy);

    let (_, _, fz) = display(z_name);
    let (fx, fy) = (display(&spec.x).2, display(&spec.y).2);
    let ex: Vec<f64> = ex.iter().map(|v| v * fx).collect();
    let ey: Vec<f64> = ey.iter().map(|v| v * fy).collect();
    let any_marked = marked.iter().any(|&m| m);
    let title = if any_marked { format!("{} (x: beyond [limits])", spec.title) } else { spec.title.clone() };
    let area = titled(root, &title, &spec.subtitle, look)?;
    let (w, _) = area.dim_in_pixel();
    let (main, bar) = area.split_horizontally(w.saturating_sub(look.px(130.0)));
    let mut cb = ChartBuilder::on(&main);
    cb.margin(look.px(20.0));
    if look.labels {
        cb.x_label_area_size(look.px(55.0)).y_label_area_size(look.px(80.0));
    }
    let mut chart = cb.build_cartesian_2d(ex[0]..ex[ex.len() - 1], ey[0]..ey[ey.len() - 1]).map_err(de)?;
    let mut mesh = chart.configure_mesh();
    mesh.disable_mesh();
    label_mesh(&mut mesh, &spec.x, &spec.y, look);
    mesh.draw().map_err(de)?;
    let invalid = RGBColor(215, 215, 215);
    chart
        .draw_series((0..uy.len()).flat_map(|iy| {
            let (ex, ey, cell, nx) = (&ex, &ey, &cell, ux.len());
            (0..nx).map(move |ix| {
                let z = cell[iy * nx + ix];
                let color = if z.is_finite() { colormap((z - z0) / zspan) } else { invalid };
                Rectangle::new([(ex[ix], ey[iy]), (ex[ix + 1], ey[iy + 1])], color.filled())
            })
        }))
        .map_err(de)?;
    // cells beyond a limit: a cross at the centre, sized to the cell
    if any_marked {
        let (w_px, h_px) = main.dim_in_pixel();
        let size = ((w_px.min(h_px) as f64) / (2.5 * ux.len().max(uy.len()) as f64)).clamp(2.0, 8.0) as i32;
        chart
            .draw_series((0..cell.len()).filter(|&k| marked[k]).map(|k| {
                let (ix, iy) = (k % ux.len(), k / ux.len());
                Cross::new((0.5 * (ex[ix] + ex[ix + 1]), 0.5 * (ey[iy] + ey[iy + 1])), size, BLACK.stroke_width(1))
            }))
            .map_err(de)?;
    }

    colour_bar(&bar, z_name, (z0, z1), fz, look)
}

/// A vertical colour bar for `z` values in `z0..z1` (shown times `fz`, in the unit of
/// [`display`]).
fn colour_bar<DB: DrawingBackend>(
    bar: &DrawingArea<DB, Shift>,
    z_name: &str,
    (z0, z1): (f64, f64),
    fz: f64,
    look: Look,
) -> Result<()> {
    let zspan = if z1 > z0 { z1 - z0 } else { 1.0 };
    let mut cb = ChartBuilder::on(bar);
    cb.margin_top(look.px(20.0))
        .margin_bottom(look.px(if look.labels { 75.0 } else { 20.0 }))
        .margin_right(look.px(10.0));
    if look.labels {
        cb.y_label_area_size(look.px(75.0));
    }
    let (b0, b1) = if z1 > z0 { (z0 * fz, z1 * fz) } else { (z0 * fz - 0.5, z0 * fz + 0.5) };
    let (z0, zspan) = (z0 * fz, zspan * fz);
    let mut bc = cb.build_cartesian_2d(0.0..1.0, b0..b1).map_err(de)?;
    let mut bm = bc.configure_mesh();
    bm.disable_mesh().disable_x_axis();
    if look.labels {
        bm.y_desc(axis_label(z_name))
            .y_label_formatter(&tick)
            .label_style(look.font(14.0))
            .axis_desc_style(look.font(16.0));
    } else {
        bm.y_labels(0);
    }
    bm.draw().map_err(de)?;
    let steps = 200;
    bc.draw_series((0..steps).map(|k| {
        let a = b0 + (b1 - b0) * k as f64 / steps as f64;
        let b = b0 + (b1 - b0) * (k + 1) as f64 / steps as f64;
        Rectangle::new([(0.0, a), (1.0, b)], colormap((0.5 * (a + b) - z0) / zspan).filled())
    }))
    .map_err(de)?;
    Ok(())
}

/// `z` (efficiency) over the (load torque, speed) plane of a torque × preload grid, as
/// motor makers draw efficiency maps: each quadrilateral between two neighbouring preload
/// curves and two neighbouring torques is filled with its mean `z`, iso-`z` contours are
/// drawn through it, and the stall boundary (the last running torque of each preload,
/// before the rotor stalls or friction clamps the stator) is a dashed line. Cells with a stalled or invalid corner are left blank, not drawn as 0.
fn efficiency_plane<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    spec: &Spec,
    data: &Data,
    z_name: &str,
    look: Look,
) -> Result<()> {
    let (t, p, v, z) = (
        data.col("torque_nm", "--x")?,
        data.col("preload_n", "--y")?,
        data.col("speed_rpm", "speed")?,
        data.col(z_name, "--z")?,
    );
    let ut = distinct_sorted(t);
    let up = distinct_sorted(p);
    if ut.len() < 2 || up.len() < 2 {
        bail!(
            "an efficiency map needs at least 2 load torques and 2 preloads (this grid has {} and {})",
            ut.len(),
            up.len()
        );
    }
    // grid[ip][it] = (torque, speed, z), NaN where the motor does not run
    let nan = (f64::NAN, f64::NAN, f64::NAN);
    let mut g = vec![vec![nan; ut.len()]; up.len()];
    for i in 0..t.len() {
        let (Ok(it), Ok(ip)) =
            (ut.binary_search_by(|x| x.total_cmp(&t[i])), up.binary_search_by(|x| x.total_cmp(&p[i])))
        else {
            continue;
        };
        let running = v[i].is_finite() && v[i] > 0.0 && z[i].is_finite();
        g[ip][it] = if running { (t[i], v[i], z[i]) } else { (t[i], f64::NAN, f64::NAN) };
    }
    let (fz, fx, fy) = (display(z_name).2, display("torque_nm").2, display("speed_rpm").2);
    let zr = finite_range(g.iter().flatten().map(|c| c.2))
        .ok_or_else(|| anyhow!("no running point to draw an efficiency map from"))?;
    let xr = (ut[0] * fx, ut[ut.len() - 1] * fx);
    let yr = finite_range(g.iter().flatten().map(|c| c.1 * fy)).unwrap_or((0.0, 1.0));
    let (x0, x1) = padded(xr.0, xr.1, true);
    let (y0, y1) = padded(yr.0, yr.1, true);

    let area = titled(root, &spec.title, &spec.subtitle, look)?;
    let (w, _) = area.dim_in_pixel();
    let (main, bar) = area.split_horizontally(w.saturating_sub(look.px(130.0)));
    let mut cb = ChartBuilder::on(&main);
    cb.margin(look.px(20.0));
    if look.labels {
        cb.x_label_area_size(look.px(55.0)).y_label_area_size(look.px(80.0));
    }
    let mut chart = cb.build_cartesian_2d(x0..x1, y0..y1).map_err(de)?;
    let mut mesh = chart.configure_mesh();
    mesh.disable_mesh();
    label_mesh(&mut mesh, "torque_nm", "speed_rpm", look);
    mesh.draw().map_err(de)?;
    let zspan = if zr.1 > zr.0 { zr.1 - zr.0 } else { 1.0 };
    let xy = |c: (f64, f64, f64)| (c.0 * fx, c.1 * fy);
    // filled cells (a thin outline of the same colour closes the seams between them)
    let mut cells = Vec::new();
    for ip in 0..up.len() - 1 {
        for it in 0..ut.len() - 1 {
            let q = [g[ip][it], g[ip][it + 1], g[ip + 1][it + 1], g[ip + 1][it]];
            if q.iter().any(|c| !c.1.is_finite()) {
                continue;
            }
            let zm = q.iter().map(|c| c.2).sum::<f64>() / 4.0;
            let color = colormap((zm - zr.0) / zspan);
            cells.push(Polygon::new(q.iter().map(|&c| xy(c)).collect::<Vec<_>>(), color.filled()));
            cells.push(Polygon::new(q.iter().map(|&c| xy(c)).collect::<Vec<_>>(), color.stroke_width(look.px(1.0))));
        }
    }
    chart.draw_series(cells).map_err(de)?;
    // every fifth preload curve, thin, so the grid can be read off
    let every = (up.len() / 8).max(1);
    for row in g.iter().step_by(every) {
        let pts: Vec<(f64, f64)> = row.iter().filter(|c| c.1.is_finite()).map(|&c| xy(c)).collect();
        chart.draw_series(LineSeries::new(pts, WHITE.mix(0.35).stroke_width(look.px(1.0)))).map_err(de)?;
    }
    // contours: marching squares on the (preload, torque) grid, mapped into the plane
    let step = crate::svg::nice_step(zspan * fz, 8.0);
    let mut level = (zr.0 * fz / step).ceil() * step;
    let mut labels = Vec::new();
    while level <= zr.1 * fz {
        let lz = level / fz;
        let mut longest: Option<(f64, (f64, f64))> = None;
        for ip in 0..up.len() - 1 {
            for it in 0..ut.len() - 1 {
                let q = [g[ip][it], g[ip][it + 1], g[ip + 1][it + 1], g[ip + 1][it]];
                if q.iter().any(|c| !c.1.is_finite()) {
                    continue;
                }
                let mut cross = Vec::new();
                for e in 0..4 {
                    let (a, b) = (q[e], q[(e + 1) % 4]);
                    if (a.2 - lz) * (b.2 - lz) < 0.0 || (a.2 == lz && b.2 != lz) {
                        let f = (lz - a.2) / (b.2 - a.2);
                        cross.push(((a.0 + f * (b.0 - a.0)) * fx, (a.1 + f * (b.1 - a.1)) * fy));
                    }
                }
                for pair in cross.chunks(2).filter(|c| c.len() == 2) {
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            vec![pair[0], pair[1]],
                            WHITE.stroke_width(look.px(1.4)),
                        )))
                        .map_err(de)?;
                    let mid = ((pair[0].0 + pair[1].0) / 2.0, (pair[0].1 + pair[1].1) / 2.0);
                    let len = (pair[0].0 - pair[1].0).hypot(pair[0].1 - pair[1].1);
                    if longest.is_none_or(|(l, _)| len > l) {
                        longest = Some((len, mid));
                    }
                }
            }
        }
        if let Some((_, at)) = longest {
            labels.push((at, format!("{} %", crate::format::fmt_sig(level, 3))));
        }
        level += step;
    }
    if look.labels {
        let style = TextStyle::from(look.font(13.0)).color(&WHITE);
        chart.draw_series(labels.into_iter().map(|(at, text)| Text::new(text, at, style.clone()))).map_err(de)?;
    }
    // edge of the running region: per preload, the last running torque before the rotor
    // stops (stall) or the stator is clamped
    let mut boundary = Vec::new();
    for row in &g {
        if let Some(last) = row.iter().rposition(|c| c.1.is_finite()) {
            if row[last + 1..].iter().any(|c| c.0.is_finite() && !c.1.is_finite()) {
                boundary.push(xy(row[last]));
            }
        }
    }
    let k = look.k;
    if boundary.len() >= 2 {
        chart
            .draw_series(DashedLineSeries::new(boundary, look.px(9.0), look.px(5.0), BLACK.stroke_width(look.px(2.0))))
            .map_err(de)?
            .label("stall (or clamp) boundary")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + (22.0 * k) as i32, y)], BLACK.stroke_width((2.0 * k) as u32))
            });
        if look.labels {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .label_font(look.font(15.0))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.stroke_width(look.px(1.0)))
                .draw()
                .map_err(de)?;
        }
    }
    colour_bar(&bar, z_name, zr, fz, look)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        plot: PlotArgs,
    }

    /// An unset torque axis ends 5 % above the largest loaded stall torque over the
    /// preloads (where the loaded motor stops), not at the rotor-at-rest stall torque,
    /// which for trum60a lies far beyond where it runs.
    #[test]
    fn default_torque_axis_ends_just_above_the_largest_loaded_stall_torque() {
        let cli = Cli::try_parse_from(["plot", "--motor", "trum60a", "--kind", "speed-torque", "-o", "p.svg"])
            .expect("arguments");
        let (motor, sweep) = crate::motor::load_motor("trum60a").expect("preset");
        let grid = plot_grid(&motor, &cli.plot, &sweep, "torque_nm").expect("grid");
        let (v, f) = (grid.voltage_v.start, grid.frequency_hz.start);
        assert_eq!((v, f), (200.0, 42_000.0), "the preset's [drive]");
        let prep = Prepared::new(&motor);
        let (mut loaded, mut at_rest) = (0.0f64, 0.0f64);
        for i in 0..grid.preload_n.n {
            let p = grid.preload_n.at(i);
            loaded = loaded.max(trum_core::criterion::loaded_stall_torque_nm(&prep, &motor, p, v, f));
            at_rest = at_rest.max(trum_core::solve(&motor, &OperatingPoint::new(p, 0.0, v, f)).stall_torque_nm);
        }
        let top = grid.torque_nm.stop;
        assert!((top / (1.05 * loaded) - 1.0).abs() < 1e-12, "axis ends at {top} N·m, largest loaded stall {loaded}");
        // the rotor-at-rest torque is well above it here, so the old axis was mostly stopped rows
        assert!(at_rest > 1.3 * loaded, "at rest {at_rest}, loaded {loaded}");
        assert_eq!((grid.torque_nm.start, grid.torque_nm.n), (0.0, 61));
    }
}
