//! Small hand-made SVG charts for the HTML report (no fonts or files needed: the browser
//! draws the text). Scatter/line charts and horizontal bar charts.

use std::fmt::Write as _;

/// Ten distinguishable colours (Tableau 10).
pub const PALETTE: [&str; 10] =
    ["#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f", "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"];

/// How a series is drawn.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Filled circles.
    Dots,
    /// Open circles.
    Rings,
    /// Solid polyline (points in the given order).
    Line,
    /// Dashed polyline.
    Dashed,
}

/// One data series.
pub struct Series {
    /// Legend label (empty: not in the legend).
    pub name: String,
    /// CSS colour.
    pub color: &'static str,
    /// Points; non-finite ones are skipped (and break a line).
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub style: Style,
}

/// An x-y chart.
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub width: f64,
    pub height: f64,
    pub series: Vec<Series>,
    /// A horizontal reference line (e.g. zero residual).
    pub hline: Option<f64>,
    /// A shaded horizontal band (e.g. ±2σ of the noise).
    pub band: Option<(f64, f64)>,
}

/// Escapes text for HTML and SVG.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A round step of about `span / n`.
pub fn nice_step(span: f64, n: f64) -> f64 {
    let raw = (span / n).max(1e-300);
    let mag = 10f64.powf(raw.log10().floor());
    let f = raw / mag;
    let nice = if f < 1.5 {
        1.0
    } else if f < 3.0 {
        2.0
    } else if f < 7.0 {
        5.0
    } else {
        10.0
    };
    nice * mag
}

/// Tick label with as many decimals as the step needs.
fn tick_label(v: f64, step: f64) -> String {
    let dec = (-step.log10().floor()).max(0.0) as usize;
    let v = if v.abs() < 1e-9 * step { 0.0 } else { v };
    if v.abs() >= 1e6 || (v != 0.0 && v.abs() < 1e-4) {
        format!("{v:.2e}")
    } else {
        format!("{v:.dec$}")
    }
}

/// Data range of finite values, padded; a degenerate range is widened.
fn range(vals: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) =
        vals.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |a, v| (a.0.min(v), a.1.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let span = hi - lo;
    if span <= 1e-12 * hi.abs().max(1e-300) {
        let d = if hi.abs() > 0.0 { 0.1 * hi.abs() } else { 1.0 };
        return (lo - d, hi + d);
    }
    (lo - 0.05 * span, hi + 0.05 * span)
}

impl Chart {
    /// A chart with no series yet.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Chart {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            width: 420.0,
            height: 300.0,
            series: Vec::new(),
            hline: None,
            band: None,
        }
    }

    /// The chart as an `<svg>` element.
    pub fn svg(&self) -> String {
        let pts = || self.series.iter().flat_map(|s| s.points.iter());
        let (x0, x1) = range(pts().map(|p| p.0));
        let extra: Vec<f64> = self.hline.into_iter().chain(self.band.into_iter().flat_map(|b| [b.0, b.1])).collect();
        let (y0, y1) = range(pts().map(|p| p.1).chain(extra.iter().copied()));
        // legend rows above the plot
        let legend: Vec<&Series> = self.series.iter().filter(|s| !s.name.is_empty()).collect();
        let mut rows: Vec<Vec<(&Series, f64)>> = vec![Vec::new()];
        let mut cx = 0.0;
        let avail = self.width - 70.0;
        for s in &legend {
            let w = 26.0 + 6.2 * s.name.chars().count() as f64 + 12.0;
            if cx + w > avail && cx > 0.0 {
                rows.push(Vec::new());
                cx = 0.0;
            }
            if let Some(r) = rows.last_mut() {
                r.push((s, cx));
            }
            cx += w;
        }
        let n_leg = if legend.is_empty() { 0 } else { rows.len() };
        let (ml, mr, mb) = (62.0, 12.0, 42.0);
        let mt = 26.0 + 16.0 * n_leg as f64;
        let (w, h) = (self.width, self.height + 16.0 * n_leg as f64);
        let (pw, ph) = (w - ml - mr, h - mt - mb);
        let sx = |x: f64| ml + (x - x0) / (x1 - x0) * pw;
        let sy = |y: f64| mt + ph - (y - y0) / (y1 - y0) * ph;
        let mut s = String::new();
        let _ = write!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="sans-serif" font-size="11">"#
        );
        let _ = write!(s, r##"<rect x="0" y="0" width="{w:.0}" height="{h:.0}" fill="#fff"/>"##);
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="16" text-anchor="middle" font-size="13" font-weight="bold">{}</text>"#,
            w / 2.0,
            esc(&self.title)
        );
        for (i, row) in rows.iter().enumerate() {
            let y = 30.0 + 16.0 * i as f64;
            for (ser, x) in row {
                let x = ml + x;
                s.push_str(&marker(ser, x + 10.0, y - 4.0, true));
                let _ = write!(s, r#"<text x="{:.1}" y="{y:.1}">{}</text>"#, x + 24.0, esc(&ser.name));
            }
        }
        let _ =
            write!(s, r##"<rect x="{ml}" y="{mt}" width="{pw:.1}" height="{ph:.1}" fill="#fafafa" stroke="#999"/>"##);
        if let Some((b0, b1)) = self.band {
            let (ya, yb) = (sy(b1.max(b0)), sy(b1.min(b0)));
            let _ = write!(
                s,
                r##"<rect x="{ml}" y="{ya:.1}" width="{pw:.1}" height="{:.1}" fill="#dde8f3" opacity="0.7"/>"##,
                yb - ya
            );
        }
        // ticks and grid
        let xs = nice_step(x1 - x0, 5.0);
        let mut t = (x0 / xs).ceil() * xs;
        while t <= x1 + 1e-9 * xs {
            let x = sx(t);
            let _ = write!(s, r##"<line x1="{x:.1}" y1="{mt}" x2="{x:.1}" y2="{:.1}" stroke="#e4e4e4"/>"##, mt + ph);
            let _ = write!(
                s,
                r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
                mt + ph + 14.0,
                tick_label(t, xs)
            );
            t += xs;
        }
        let ys = nice_step(y1 - y0, 5.0);
        let mut t = (y0 / ys).ceil() * ys;
        while t <= y1 + 1e-9 * ys {
            let y = sy(t);
            let _ = write!(s, r##"<line x1="{ml}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e4e4e4"/>"##, ml + pw);
            let _ = write!(
                s,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
                ml - 4.0,
                y + 4.0,
                tick_label(t, ys)
            );
            t += ys;
        }
        if let Some(y) = self.hline {
            let y = sy(y);
            let _ = write!(s, r##"<line x1="{ml}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#333"/>"##, ml + pw);
        }
        let _ = write!(s, r#"<g clip-path="none">"#);
        for ser in &self.series {
            match ser.style {
                Style::Line | Style::Dashed => {
                    let dash = if ser.style == Style::Dashed { r#" stroke-dasharray="5,3""# } else { "" };
                    for seg in ser.points.split(|p| !(p.0.is_finite() && p.1.is_finite())) {
                        if seg.len() < 2 {
                            continue;
                        }
                        let d: Vec<String> = seg.iter().map(|p| format!("{:.1},{:.1}", sx(p.0), sy(p.1))).collect();
                        let _ = write!(
                            s,
                            r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="1.6"{dash}/>"#,
                            d.join(" "),
                            ser.color
                        );
                    }
                }
                Style::Dots | Style::Rings => {
                    for p in ser.points.iter().filter(|p| p.0.is_finite() && p.1.is_finite()) {
                        s.push_str(&marker(ser, sx(p.0), sy(p.1), false));
                    }
                }
            }
        }
        s.push_str("</g>");
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            ml + pw / 2.0,
            h - 8.0,
            esc(&self.x_label)
        );
        let (lx, ly) = (14.0, mt + ph / 2.0);
        let _ = write!(
            s,
            r#"<text x="{lx}" y="{ly:.1}" text-anchor="middle" transform="rotate(-90 {lx} {ly:.1})">{}</text>"#,
            esc(&self.y_label)
        );
        s.push_str("</svg>");
        s
    }
}

/// A marker (or a legend swatch) for a series at (x, y).
fn marker(ser: &Series, x: f64, y: f64, legend: bool) -> String {
    match ser.style {
        Style::Dots => format!(r#"<circle cx="{x:.1}" cy="{y:.1}" r="3" fill="{}"/>"#, ser.color),
        Style::Rings => {
            format!(
                r#"<circle cx="{x:.1}" cy="{y:.1}" r="3.5" fill="none" stroke="{}" stroke-width="1.3"/>"#,
                ser.color
            )
        }
        Style::Line | Style::Dashed if legend => {
            let dash = if ser.style == Style::Dashed { r#" stroke-dasharray="5,3""# } else { "" };
            format!(
                r#"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{}" stroke-width="1.6"{dash}/>"#,
                x - 9.0,
                x + 9.0,
                ser.color
            )
        }
        _ => String::new(),
    }
}

/// A horizontal bar chart: one bar per label, optional interval whiskers and reference
/// lines. With `symlog`, the axis is sign(x)·log10(1 + |x|) (for evidence spanning decades).
pub struct Bars {
    pub title: String,
    pub x_label: String,
    pub labels: Vec<String>,
    pub values: Vec<f64>,
    pub intervals: Option<Vec<(f64, f64)>>,
    pub refs: Vec<(f64, String)>,
    pub color: &'static str,
    pub highlight: Option<usize>,
    pub symlog: bool,
    pub clamp: Option<(f64, f64)>,
}

impl Bars {
    pub fn svg(&self) -> String {
        let tf = |v: f64| if self.symlog { v.signum() * v.abs().ln_1p() / std::f64::consts::LN_10 } else { v };
        let cl = |v: f64| match self.clamp {
            Some((a, b)) => v.clamp(a, b),
            None => v,
        };
        let mut vals: Vec<f64> = self.values.iter().map(|&v| tf(cl(v))).collect();
        if let Some(iv) = &self.intervals {
            vals.extend(iv.iter().flat_map(|i| [tf(cl(i.0)), tf(cl(i.1))]));
        }
        vals.extend(self.refs.iter().map(|r| tf(r.0)));
        vals.push(0.0);
        let (x0, x1) = range(vals.into_iter());
        let label_w = 8.0 + 6.6 * self.labels.iter().map(|l| l.chars().count()).max().unwrap_or(4) as f64;
        let (ml, mr, mt, mb) = (label_w, 50.0, 40.0, 40.0);
        let bh = 22.0;
        let ph = bh * self.labels.len().max(1) as f64;
        let w = 520.0f64.max(ml + 300.0);
        let h = mt + ph + mb;
        let pw = w - ml - mr;
        let sx = |v: f64| ml + (v - x0) / (x1 - x0) * pw;
        let mut s = String::new();
        let _ = write!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="sans-serif" font-size="11">"#
        );
        let _ = write!(s, r##"<rect x="0" y="0" width="{w:.0}" height="{h:.0}" fill="#fff"/>"##);
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="16" text-anchor="middle" font-size="13" font-weight="bold">{}</text>"#,
            w / 2.0,
            esc(&self.title)
        );
        let _ = write!(
            s,
            r##"<rect x="{ml:.1}" y="{mt}" width="{pw:.1}" height="{ph:.1}" fill="#fafafa" stroke="#999"/>"##
        );
        // ticks
        let ticks: Vec<f64> = if self.symlog {
            let mut t = vec![0.0];
            for m in [1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1e3, 3e3, 1e4, 3e4, 1e5, 3e5, 1e6] {
                t.push(m);
                t.push(-m);
            }
            t.into_iter().filter(|&v| (x0..=x1).contains(&tf(v))).collect()
        } else {
            let st = nice_step(x1 - x0, 5.0);
            let mut t = Vec::new();
            let mut v = (x0 / st).ceil() * st;
            while v <= x1 + 1e-9 * st {
                t.push(v);
                v += st;
            }
            t
        };
        let st = nice_step(x1 - x0, 5.0);
        // labels closer than their own width to the previous one are left out (a signed
        // log axis crowds 1, 3, 10 near zero)
        let mut last_x = f64::NEG_INFINITY;
        let mut ticks = ticks;
        ticks.sort_by(|a, b| tf(*a).total_cmp(&tf(*b)));
        for t in ticks {
            let x = sx(tf(t));
            let lab = if self.symlog { format!("{t}") } else { tick_label(t, st) };
            if x - last_x < 8.0 + 6.5 * lab.chars().count() as f64 {
                continue;
            }
            last_x = x;
            let _ = write!(s, r##"<line x1="{x:.1}" y1="{mt}" x2="{x:.1}" y2="{:.1}" stroke="#e4e4e4"/>"##, mt + ph);
            let _ = write!(s, r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{lab}</text>"#, mt + ph + 14.0);
        }
        let zx = sx(0.0);
        for (i, (lab, &v)) in self.labels.iter().zip(&self.values).enumerate() {
            let y = mt + bh * i as f64;
            let _ = write!(
                s,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="end"{}>{}</text>"#,
                ml - 6.0,
                y + bh / 2.0 + 4.0,
                if self.highlight == Some(i) { r#" font-weight="bold""# } else { "" },
                esc(lab)
            );
            if !v.is_finite() {
                let _ =
                    write!(s, r##"<text x="{:.1}" y="{:.1}" fill="#777">n/a</text>"##, zx + 4.0, y + bh / 2.0 + 4.0);
                continue;
            }
            let xv = sx(tf(cl(v)));
            let (a, b) = (xv.min(zx), xv.max(zx));
            let op = if self.highlight.is_none() || self.highlight == Some(i) { "1" } else { "0.55" };
            let _ = write!(
                s,
                r#"<rect x="{a:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{}" opacity="{op}"/>"#,
                y + 4.0,
                (b - a).max(0.5),
                bh - 8.0,
                self.color
            );
            if let Some(iv) = self.intervals.as_ref().and_then(|iv| iv.get(i)) {
                if iv.0.is_finite() && iv.1.is_finite() {
                    let (p, q) = (sx(tf(cl(iv.0))), sx(tf(cl(iv.1))));
                    let yc = y + bh / 2.0;
                    let _ = write!(
                        s,
                        r##"<path d="M{p:.1},{:.1}V{:.1}M{p:.1},{yc:.1}H{q:.1}M{q:.1},{:.1}V{:.1}" stroke="#222" fill="none"/>"##,
                        yc - 4.0,
                        yc + 4.0,
                        yc - 4.0,
                        yc + 4.0
                    );
                }
            }
            let txt = crate::format::fmt_sig(v, 3);
            // the value goes right of the bar and of its interval whisker, never over them
            let whisker = self
                .intervals
                .as_ref()
                .and_then(|iv| iv.get(i))
                .filter(|iv| iv.0.is_finite() && iv.1.is_finite())
                .map_or(b, |iv| b.max(sx(tf(cl(iv.0)))).max(sx(tf(cl(iv.1)))));
            let _ = write!(
                s,
                r#"<text x="{:.1}" y="{:.1}" font-size="10">{txt}</text>"#,
                whisker + 4.0,
                y + bh / 2.0 + 4.0
            );
        }
        let _ = write!(s, r##"<line x1="{zx:.1}" y1="{mt}" x2="{zx:.1}" y2="{:.1}" stroke="#333"/>"##, mt + ph);
        // reference lines; two labels closer than their width go to either side of their lines
        let xs: Vec<f64> = self.refs.iter().map(|(v, _)| sx(tf(*v))).collect();
        let width = |lab: &str| 6.0 * lab.chars().count() as f64 + 6.0;
        for (i, (_, lab)) in self.refs.iter().enumerate() {
            let x = xs[i];
            let near = |j: usize| (xs[j] - x).abs() < 0.5 * (width(lab) + width(&self.refs[j].1));
            let (anchor, dx) = if i + 1 < xs.len() && near(i + 1) && xs[i + 1] >= x {
                ("end", -2.0)
            } else if i > 0 && near(i - 1) && xs[i - 1] <= x {
                ("start", 2.0)
            } else {
                ("middle", 0.0)
            };
            let _ = write!(
                s,
                r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#c00" stroke-dasharray="4,3"/>"##,
                mt - 4.0,
                mt + ph
            );
            let _ = write!(
                s,
                r##"<text x="{:.1}" y="{:.1}" fill="#c00" font-size="10" text-anchor="{anchor}">{}</text>"##,
                x + dx,
                mt - 7.0,
                esc(lab)
            );
        }
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            ml + pw / 2.0,
            h - 8.0,
            esc(&self.x_label)
        );
        s.push_str("</svg>");
        s
    }
}
