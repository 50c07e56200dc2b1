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
use trum_core::solve::{solve_prepared, Prepared};
use trum_core::sweep::{solve_range, Axis, Grid};
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
    /// Heat map of efficiency over load torque × preload.
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

    /// Default grid for `--motor` (torque `None`: from zero to just above the stall torque).
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
            None => bail!("{what} column '{name}' does not exist; available columns are: {}", self.names.join(", ")),
        }
    }
}

struct Spec {
    x: String,
    y: String,
    group: Option<String>,
    z: Option<String>,
    title: String,
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

    let (data, source) = match (&a.motor, &a.map) {
        (Some(m), _) => {
            let ma = MotorArgs { motor: m.clone(), effects: a.effects.clone() };
            let (motor, sweep) = ma.load()?;
            let grid = plot_grid(&motor, a, &sweep, &x)?;
            (solve_grid(&motor, &grid), motor.name.clone())
        }
        (None, Some(path)) => {
            let mut needed = vec![x.as_str(), y.as_str()];
            needed.extend(group.as_deref());
            needed.extend(z.as_deref());
            (read_csv(path, &needed)?, path.display().to_string())
        }
        (None, None) => bail!("give --motor or --map"),
    };
    let what = match (&group, &z) {
        (_, Some(z)) => format!("{z} over {x} × {y}"),
        (Some(g), None) => format!("{y} vs {x} by {g}"),
        (None, None) => format!("{y} vs {x}"),
    };
    let spec = Spec { title: a.title.clone().unwrap_or_else(|| format!("{source}: {what}")), x, y, group, z };

    write_figure(&a.output, &SpecFigure { spec: &spec, data: &data }, err)?;
    Ok(0)
}

/// Something `write_figure` can draw on either backend.
pub trait Figure {
    /// Draws on `root`; `labels` is false when no font is available.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, labels: bool, err: &mut dyn Write) -> Result<()>;
}

/// Checks that `output` is a plot file name (.png or .svg, the format follows it).
pub fn check_plot_path(output: &Path) -> Result<String> {
    let ext = output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    if ext != "png" && ext != "svg" {
        bail!("-o '{}': the plot file name must end in .png or .svg", output.display());
    }
    Ok(ext)
}

/// Draws `fig` into `output` (.png or .svg) through an atomically renamed temporary file.
pub fn write_figure(output: &Path, fig: &impl Figure, err: &mut dyn Write) -> Result<()> {
    let ext = check_plot_path(output)?;
    let labels = fonts_available();
    if !labels {
        writeln!(err, "warning: no usable system font found (plotters' ttf); the plot is drawn without text")?;
    }
    let target = OutputTarget::create(output, &format!(".{ext}"))?;
    let Some(draw_path) = target.draw_path() else { bail!("a plot cannot be written to stdout; give a file name") };
    if ext == "svg" {
        let root = SVGBackend::new(draw_path, SIZE_PX).into_drawing_area();
        root.fill(&WHITE).map_err(de)?;
        fig.draw(&root, labels, err)?;
        root.present().map_err(de)?;
    } else {
        let root = BitMapBackend::new(draw_path, SIZE_PX).into_drawing_area();
        root.fill(&WHITE).map_err(de)?;
        fig.draw(&root, labels, err)?;
        root.present().map_err(de)?;
    }
    target.finish()
}

struct SpecFigure<'a> {
    spec: &'a Spec,
    data: &'a Data,
}

impl Figure for SpecFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, labels: bool, err: &mut dyn Write) -> Result<()> {
        draw(root, self.spec, self.data, labels, err)
    }
}

/// One polyline of a [`LinePlot`]; non-finite points break it.
pub struct Line {
    /// Legend text (`None`: not in the legend).
    pub label: Option<String>,
    /// Colour.
    pub color: RGBColor,
    /// Points in drawing order.
    pub points: Vec<(f64, f64)>,
    /// Dashed instead of solid (unstable branches, backbones, limits).
    pub dashed: bool,
}

/// Explicit lines against named (unit-suffixed) axes.
pub struct LinePlot {
    /// Title.
    pub title: String,
    /// Horizontal axis column name (its unit is looked up for the label).
    pub x: String,
    /// Vertical axis column name.
    pub y: String,
    /// The lines.
    pub lines: Vec<Line>,
}

impl Figure for LinePlot {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, labels: bool, _: &mut dyn Write) -> Result<()> {
        draw_lines(root, self, labels)
    }
}

fn de<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("drawing failed: {e}")
}

fn fonts_available() -> bool {
    ("sans-serif", 16).into_font().box_size("0.5 N m").is_ok()
}

/// The grid for `--motor`: command line, then `[sweep]`, then the kind's defaults. An unset
/// torque axis runs from zero to 5 % above the largest no-load stall torque.
fn plot_grid(motor: &Motor, a: &PlotArgs, sweep: &trum_core::params::SweepTable, x: &str) -> Result<Grid> {
    let (p, t, v, f) = match a.kind {
        Some(k) => k.default_axes(),
        None => {
            let d = crate::grid::default_grid();
            let t = if x == "torque_nm" { None } else { Some(d.torque_nm) };
            (d.preload_n, t, d.voltage_v, d.frequency_hz)
        }
    };
    let mut grid =
        a.grid.resolve(sweep, &Grid { preload_n: p, torque_nm: Axis::fixed(0.0), voltage_v: v, frequency_hz: f });
    if a.grid.torque_nm.is_none() && sweep.torque_nm.is_none() {
        if let Some(t) = t {
            grid.torque_nm = t;
        } else {
            let prep = Prepared::new(motor);
            let stall = (0..grid.preload_n.n)
                .map(|i| {
                    let op =
                        OperatingPoint::new(grid.preload_n.at(i), 0.0, grid.voltage_v.start, grid.frequency_hz.start);
                    solve_prepared(&prep, motor, &op, None).stall_torque_nm
                })
                .filter(|s| s.is_finite())
                .fold(0.0, f64::max);
            let top = if stall > 0.0 { 1.05 * stall } else { 1.0 };
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
    const CHUNK: u64 = 512;
    let total = grid.len();
    let prep = Prepared::new(motor);
    let chunks: Vec<Vec<(OperatingPoint, Solution)>> = (0..total.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut v = Vec::new();
            solve_range(motor, &prep, grid, c * CHUNK..((c + 1) * CHUNK).min(total), |_, op, s| {
                v.push((*op, s.clone()))
            });
            v
        })
        .collect();
    let mut names: Vec<String> = ["preload_n", "torque_nm", "voltage_v", "frequency_hz"].map(String::from).to_vec();
    names.extend(QUANTITIES.iter().map(|q| q.name.to_string()));
    let mut cols = vec![Vec::with_capacity(total as usize); names.len()];
    let beyond = chunks.iter().flatten().map(|(_, s)| !s.warnings.is_empty()).collect();
    for (op, s) in chunks.iter().flatten() {
        let valid = s.status.is_valid();
        let row = [op.preload_n, op.torque_nm, op.voltage_v, op.frequency_hz]
            .into_iter()
            .chain(QUANTITIES.iter().map(|q| if valid { (q.get)(s) } else { f64::NAN }));
        for (c, v) in cols.iter_mut().zip(row) {
            c.push(v);
        }
    }
    Data { names, cols, beyond: Some(beyond) }
}

/// Reads the needed columns of a CSV; empty cells are missing values.
fn read_csv(path: &Path, needed: &[&str]) -> Result<Data> {
    let shown = path.display();
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
            None => bail!("{shown}: column '{n}' does not exist; the columns are: {}", all.join(", ")),
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

/// `name [unit]`, with `N m` printed as `N·m`.
fn axis_label(name: &str) -> String {
    match unit_of(name) {
        Some(u) => format!("{name} [{}]", u.replace(' ', "·")),
        None => name.to_string(),
    }
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

fn tick(v: &f64) -> String {
    crate::format::fmt_sig(*v, 4)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    spec: &Spec,
    data: &Data,
    labels: bool,
    err: &mut dyn Write,
) -> Result<()> {
    let xs = data.col(&spec.x, "--x")?;
    let ys = data.col(&spec.y, "--y")?;
    match &spec.z {
        Some(z) => {
            let zs = data.col(z, "--z")?;
            heat_map(root, spec, xs, ys, zs, data.beyond.as_deref(), labels, err)
        }
        None => {
            let gs = match &spec.group {
                Some(g) => Some(data.col(g, "--group")?),
                None => None,
            };
            curves(root, spec, xs, ys, gs, labels)
        }
    }
}

fn curves<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    spec: &Spec,
    xs: &[f64],
    ys: &[f64],
    gs: Option<&[f64]>,
    labels: bool,
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
            let label = spec.group.as_deref().map(|gname| {
                let unit = unit_of(gname).map(|u| format!(" {}", u.replace(' ', "·"))).unwrap_or_default();
                format!("{gname} = {}{unit}", crate::format::fmt_sig(g, 6))
            });
            Line { label, color: series_color(gi, n), points, dashed: false }
        })
        .collect();
    let plot = LinePlot { title: spec.title.clone(), x: spec.x.clone(), y: spec.y.clone(), lines };
    draw_lines(root, &plot, labels)
}

fn draw_lines<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, plot: &LinePlot, labels: bool) -> Result<()> {
    let pts = || plot.lines.iter().flat_map(|l| l.points.iter());
    let xr = finite_range(pts().map(|p| p.0)).ok_or_else(|| anyhow!("no finite values in column '{}'", plot.x))?;
    let yr = finite_range(pts().map(|p| p.1))
        .ok_or_else(|| anyhow!("no valid values of '{}' to plot (every point is invalid)", plot.y))?;
    let (x0, x1) = padded(xr.0, xr.1, false);
    let (y0, y1) = padded(yr.0, yr.1, true);

    let mut cb = ChartBuilder::on(root);
    cb.margin(20);
    if labels {
        cb.caption(&plot.title, ("sans-serif", 22)).x_label_area_size(55).y_label_area_size(80);
    }
    let mut chart = cb.build_cartesian_2d(x0..x1, y0..y1).map_err(de)?;
    let mut mesh = chart.configure_mesh();
    if labels {
        mesh.x_desc(axis_label(&plot.x))
            .y_desc(axis_label(&plot.y))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw().map_err(de)?;
    let mut legend = false;
    for line in &plot.lines {
        let color = line.color;
        let style = color.stroke_width(2);
        // invalid points (NaN) break the line instead of being joined across
        let mut labelled = false;
        for seg in line.points.split(|p| !p.0.is_finite() || !p.1.is_finite()).filter(|s| !s.is_empty()) {
            let pts = seg.iter().copied();
            let series = if line.dashed {
                chart.draw_series(DashedLineSeries::new(pts, 8, 5, style)).map_err(de)?
            } else {
                chart.draw_series(LineSeries::new(pts, style)).map_err(de)?
            };
            if let (false, true, Some(label)) = (labelled, labels, &line.label) {
                series
                    .label(label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3)));
                labelled = true;
                legend = true;
            }
        }
    }
    if legend {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(("sans-serif", 15))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
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
    labels: bool,
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

    let (w, _) = root.dim_in_pixel();
    let (main, bar) = root.split_horizontally(w.saturating_sub(130));
    let mut cb = ChartBuilder::on(&main);
    cb.margin(20);
    let any_marked = marked.iter().any(|&m| m);
    let title = if any_marked { format!("{} (x: beyond [limits])", spec.title) } else { spec.title.clone() };
    if labels {
        cb.caption(&title, ("sans-serif", 22)).x_label_area_size(55).y_label_area_size(80);
    }
    let mut chart = cb.build_cartesian_2d(ex[0]..ex[ex.len() - 1], ey[0]..ey[ey.len() - 1]).map_err(de)?;
    let mut mesh = chart.configure_mesh();
    mesh.disable_mesh();
    if labels {
        mesh.x_desc(axis_label(&spec.x))
            .y_desc(axis_label(&spec.y))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
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

    // colour bar
    let mut cb = ChartBuilder::on(&bar);
    cb.margin_top(if labels { 60 } else { 20 }).margin_bottom(if labels { 75 } else { 20 }).margin_right(10);
    if labels {
        cb.y_label_area_size(75);
    }
    let (b0, b1) = if z1 > z0 { (z0, z1) } else { (z0 - 0.5, z0 + 0.5) };
    let mut bc = cb.build_cartesian_2d(0.0..1.0, b0..b1).map_err(de)?;
    let mut bm = bc.configure_mesh();
    bm.disable_mesh().disable_x_axis();
    if labels {
        bm.y_desc(axis_label(z_name))
            .y_label_formatter(&tick)
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16));
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
