#!/usr/bin/env python3
"""Plots of the presets against the figures their papers quote, for docs/PRESETS.md.

    cargo build --release -p trum-cli
    python3 scripts/paper_plots.py            # writes docs/img/papers_*.svg

Each plot is a model curve computed by `trum` (the commands are printed) with the
paper's numbers from tests/data/papers/ drawn beside it: markers for point values,
dashed vertical lines for the preloads of peaks, a shaded band for a region. Standard
library only; the SVG is written by hand.
"""
import csv
import io
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TRUM = os.environ.get("TRUM", os.path.join(ROOT, "target", "release", "trum"))
OUT = os.path.join(ROOT, "docs", "img")


def trum(*args):
    cmd = [TRUM, *args]
    print("$ trum " + " ".join(args), file=sys.stderr)
    return subprocess.run(cmd, check=True, capture_output=True, text=True).stdout


def table(text):
    return list(csv.DictReader(io.StringIO(text)))


def paper(name):
    with open(os.path.join(ROOT, "tests", "data", "papers", name), newline="") as f:
        return list(csv.DictReader(f))


def nice_ticks(lo, hi, n=5):
    span = hi - lo if hi > lo else 1.0
    raw = span / n
    mag = 10 ** int(f"{raw:e}".split("e")[1])
    step = min((m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw), default=10 * mag)
    t = (int(lo / step) - (1 if lo < 0 else 0)) * step
    out = []
    while t <= hi + 1e-9 * span:
        if t >= lo - 1e-9 * span:
            out.append(round(t, 10))
        t += step
    return out


def svg_plot(path, title, xlabel, ylabel, curves, points=(), vlines=(), band=None, ylim=None):
    """curves: [(label, xs, ys, colour)]; points: [(label, x, y, colour)];
    vlines: [(label, x, colour)]; band: (label, x0, x1)."""
    W, H, L, R, T, B = 720, 440, 80, 200, 40, 60
    xs = [x for _, cx, _, _ in curves for x in cx] + [p[1] for p in points] + [v[1] for v in vlines]
    ys = [y for _, _, cy, _ in curves for y in cy if y == y] + [p[2] for p in points]
    x0, x1 = min(xs), max(xs)
    y0, y1 = ylim if ylim else (min(0.0, min(ys)), max(ys) * 1.1)
    sx = lambda x: L + (x - x0) / (x1 - x0) * (W - L - R)
    sy = lambda y: H - B - (y - y0) / (y1 - y0) * (H - T - B)
    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
         f'<rect width="{W}" height="{H}" fill="white"/>',
         f'<text x="{(W - R + L) / 2}" y="22" text-anchor="middle" font-size="14">{title}</text>']
    if band:
        o.append(f'<rect x="{sx(band[1]):.1f}" y="{T}" width="{sx(band[2]) - sx(band[1]):.1f}" height="{H - T - B}" fill="#f4d03f" fill-opacity="0.35"/>')
    for t in nice_ticks(x0, x1):
        o.append(f'<line x1="{sx(t):.1f}" y1="{T}" x2="{sx(t):.1f}" y2="{H - B}" stroke="#ddd"/>')
        o.append(f'<text x="{sx(t):.1f}" y="{H - B + 16}" text-anchor="middle">{t:g}</text>')
    for t in nice_ticks(y0, y1):
        o.append(f'<line x1="{L}" y1="{sy(t):.1f}" x2="{W - R}" y2="{sy(t):.1f}" stroke="#ddd"/>')
        o.append(f'<text x="{L - 6}" y="{sy(t) + 4:.1f}" text-anchor="end">{t:g}</text>')
    o.append(f'<rect x="{L}" y="{T}" width="{W - L - R}" height="{H - T - B}" fill="none" stroke="black"/>')
    o.append(f'<text x="{(W - R + L) / 2}" y="{H - 18}" text-anchor="middle">{xlabel}</text>')
    o.append(f'<text transform="translate(20,{(H - B + T) / 2}) rotate(-90)" text-anchor="middle">{ylabel}</text>')
    legend = []
    for label, cx, cy, colour in curves:
        pts = " ".join(f"{sx(x):.1f},{sy(y):.1f}" for x, y in zip(cx, cy) if y == y)
        o.append(f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="2"/>')
        legend.append((label, colour, "line"))
    for label, x, colour in vlines:
        o.append(f'<line x1="{sx(x):.1f}" y1="{T}" x2="{sx(x):.1f}" y2="{H - B}" stroke="{colour}" stroke-width="2" stroke-dasharray="6,4"/>')
        legend.append((label, colour, "dash"))
    for label, x, y, colour in points:
        o.append(f'<circle cx="{sx(x):.1f}" cy="{sy(y):.1f}" r="5" fill="white" stroke="{colour}" stroke-width="2"/>')
        if label:
            legend.append((label, colour, "dot"))
    if band:
        legend.append((band[0], "#f4d03f", "band"))
    seen = set()
    ly = T + 10
    for label, colour, kind in legend:
        if label in seen:
            continue
        seen.add(label)
        lx = W - R + 12
        if kind == "line":
            o.append(f'<line x1="{lx}" y1="{ly}" x2="{lx + 20}" y2="{ly}" stroke="{colour}" stroke-width="2"/>')
        elif kind == "dash":
            o.append(f'<line x1="{lx}" y1="{ly}" x2="{lx + 20}" y2="{ly}" stroke="{colour}" stroke-width="2" stroke-dasharray="6,4"/>')
        elif kind == "dot":
            o.append(f'<circle cx="{lx + 10}" cy="{ly}" r="5" fill="white" stroke="{colour}" stroke-width="2"/>')
        else:
            o.append(f'<rect x="{lx}" y="{ly - 6}" width="20" height="12" fill="{colour}" fill-opacity="0.35"/>')
        o.append(f'<text x="{lx + 26}" y="{ly + 4}">{label}</text>')
        ly += 20
    o.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(o) + "\n")
    print(f"wrote {os.path.relpath(path, ROOT)}", file=sys.stderr)


def png_plot(path, name, xcol, ycol, model, paper_pts):
    """The same comparison as a PNG drawn by `trum plot --map`: the model curve is group
    `paper = 0`, the paper's numbers group `paper = 1` (joined by a line; a peak is a
    vertical line from 0 to the curve's maximum)."""
    tmp = os.path.join(OUT, name + ".csv")
    with open(tmp, "w") as f:
        f.write(f"{xcol},{ycol},paper\n")
        for x, y in model:
            if y == y:
                f.write(f"{x},{y},0\n")
        for x, y in paper_pts:
            f.write(f"{x},{y},1\n")
    print(f"$ trum plot --map {name}.csv --x {xcol} --y {ycol} --group paper -o {os.path.basename(path)}", file=sys.stderr)
    subprocess.run([TRUM, "plot", "--map", name + ".csv", "--x", xcol, "--y", ycol, "--group", "paper", "-o", path],
                   check=True, cwd=OUT, capture_output=True)
    os.remove(tmp)
    print(f"wrote {os.path.relpath(path, ROOT)}", file=sys.stderr)


def budget_plot(chen, paper_c):
    """Why the maximum efficiency falls with preload (docs/PRESETS.md): trum's, the same
    with a constant loss floor added to every input, and with Chen et al. 2020 eq. 9's
    viscous loss law in place of trum's interface loss, from the `efficiency_budget`
    example (`cargo build --release -p trum-core --example efficiency_budget`)."""
    exe = os.environ.get("TRUM_BUDGET", os.path.join(ROOT, "target", "release", "examples", "efficiency_budget"))
    if not os.path.exists(exe):
        print(f"skipped papers_trum60a_efficiency_budget.svg: no {exe}", file=sys.stderr)
        return
    print("$ efficiency_budget trum60a 200 42000", file=sys.stderr)
    text = subprocess.run([exe, "trum60a", "200", "42000"], check=True, capture_output=True, text=True).stdout
    rows = [line.replace("|", " ").split() for line in text.splitlines()]
    rows = [r for r in rows if len(r) == 15 and r[0].replace(".", "").isdigit()]
    f = [float(r[0]) for r in rows]
    p_out, p_in = [float(r[6]) for r in rows], [float(r[12]) for r in rows]
    curves = [("trum60a", f, [o / i for o, i in zip(p_out, p_in)], "#1f5fa8")]
    for p0, colour in ((2.0, "#5dade2"), (5.0, "#85c1e9")):
        curves.append((f"+ {p0:g} W floor", f, [o / (i + p0) for o, i in zip(p_out, p_in)], colour))
    curves.append(("eq. 9 loss law", f, [float(r[14]) for r in rows], "#27ae60"))
    svg_plot(os.path.join(OUT, "papers_trum60a_efficiency_budget.svg"),
             "TRUM60A at 200 V, 42 kHz: maximum efficiency and its losses",
             "preload [N]", "maximum efficiency [-]", curves,
             vlines=[("Chen 2020: peak 320 N", float([r for r in chen if r["quantity"] == "max_efficiency_peak_n"][0]["value"]), paper_c)],
             ylim=(0.0, 0.55))


def num(rows, col):
    return [float(r[col]) if r[col] not in ("", "nan", "NaN") else float("nan") for r in rows]


def main():
    os.makedirs(OUT, exist_ok=True)
    trum_c, paper_c = "#1f5fa8", "#c0392b"
    chen = paper("chen2020_figures.csv")
    get = lambda rows, q: [r for r in rows if r["quantity"] == q]

    # TRUM60A: the criterion at its drive (200 V, 42 kHz)
    opt = table(trum("optimize", "--motor", "trum60a", "--preload-n", "100:500:41", "-q", "-o", "-"))
    f = num(opt, "preload_n")
    region = [float(r["preload_n"]) for r in opt if r["in_region"] == "true"]
    svg_plot(os.path.join(OUT, "papers_trum60a_stall_efficiency.svg"),
             "TRUM60A at 200 V, 42 kHz: stall torque and maximum efficiency",
             "preload [N]", "stall torque [N·m] / maximum efficiency × 5 [-]",
             [("trum: stall torque", f, num(opt, "stall_torque_nm"), trum_c),
              ("trum: max efficiency × 5", f, [5 * e for e in num(opt, "max_efficiency")], "#27ae60")],
             vlines=[("Chen 2020: stall peak 260 N", float(get(chen, "stall_torque_peak_n")[0]["value"]), paper_c),
                     ("Chen 2020: efficiency peak 320 N", float(get(chen, "max_efficiency_peak_n")[0]["value"]), "#8e44ad")])
    st = num(opt, "stall_torque_nm")
    top = max(y for y in st if y == y)
    png_plot(os.path.join(OUT, "papers_trum60a_stall_torque.png"), "TRUM60A 200 V 42 kHz (paper 1 = Chen 2020 peak)", "preload_n", "stall_torque_nm",
             list(zip(f, st)), [(260.0, 0.0), (260.0, top)])
    ef = num(opt, "max_efficiency")
    png_plot(os.path.join(OUT, "papers_trum60a_max_efficiency.png"), "TRUM60A 200 V 42 kHz (paper 1 = Chen 2020 peak)", "preload_n", "max_efficiency",
             list(zip(f, ef)), [(320.0, 0.0), (320.0, max(y for y in ef if y == y))])
    budget_plot(chen, paper_c)
    svg_plot(os.path.join(OUT, "papers_trum60a_region.svg"),
             "TRUM60A at 200 V, 42 kHz: criterion score and optimum region",
             "preload [N]", "score [-]",
             [("trum: score", f, num(opt, "score"), trum_c)],
             points=[("trum: optimum region", x, float(r["score"]), trum_c) for r in opt if r["in_region"] == "true" for x in [float(r["preload_n"])]],
             band=("Chen 2020: region 260-320 N", 260.0, 320.0), ylim=(0, 1))
    # contact angle and speed fluctuation at 200 V, 43 kHz
    pts = table(trum("map", "--motor", "trum60a", "--preload-n", "50:600:56", "--torque-nm", "0", "--voltage-v", "200",
                     "--frequency-hz", "43000", "-q", "-o", "-"))
    ang = get(chen, "contact_angle_deg")
    xs = num(pts, "preload_n")
    svg_plot(os.path.join(OUT, "papers_trum60a_contact_angle.svg"),
             "TRUM60A at 200 V, 43 kHz: contact angle at no load",
             "preload [N]", "contact angle Xc [deg]",
             [("trum", xs, num(pts, "contact_angle_deg"), trum_c),
              ("Chen 2020: slope 0.033°/N", [100.0, 570.0],
               [num(pts, "contact_angle_deg")[xs.index(100.0)], num(pts, "contact_angle_deg")[xs.index(100.0)] + 0.033 * 470], paper_c)],
             points=[("Chen 2020: Xc (Fig. 7)", float(r["preload_n"]), float(r["value"]), paper_c) for r in ang],
             ylim=(0, 42))
    png_plot(os.path.join(OUT, "papers_trum60a_contact_angle.png"), "TRUM60A 200 V 43 kHz (paper 1 = Chen 2020 Fig. 7)", "preload_n", "contact_angle_deg",
             list(zip(xs, num(pts, "contact_angle_deg"))), [(float(r["preload_n"]), float(r["value"])) for r in ang])
    running = [r for r in pts if r["status"] == "ok"]
    rx = num(running, "preload_n")
    svg_plot(os.path.join(OUT, "papers_trum60a_driving_share.svg"),
             "TRUM60A at 200 V, 43 kHz: driving share at no load",
             "preload [N]", "driving zone / contact zone [-]",
             [("trum", rx, num(running, "driving_ratio"), trum_c), ("Chen 2020: falls", [], [], paper_c)], ylim=(0.25, 0.35))
    loss = [d + f for d, f in zip(num(running, "damping_loss_w"), num(running, "friction_loss_w"))]
    svg_plot(os.path.join(OUT, "papers_trum60a_losses.svg"),
             "TRUM60A at 200 V, 43 kHz, no load: losses against preload",
             "preload [N]", "loss [W]",
             [("trum: damping + friction", rx, loss, trum_c),
              ("trum: dielectric", rx, num(running, "dielectric_loss_w"), "#27ae60")],
             vlines=[("Chen 2020: to 460 N", float(get(chen, "loss_rise_limit_n")[0]["value"]), paper_c)])
    fl = table(trum("optimize", "--motor", "trum60a", "--preload-n", "150:500:36", "--frequency-hz", "43000", "-q", "-o", "-"))
    svg_plot(os.path.join(OUT, "papers_trum60a_temperature.svg"),
             "TRUM60A at 200 V, 43 kHz: temperature rise after a 10 s run",
             "preload [N]", "temperature rise [K]",
             [("trum", num(fl, "preload_n"), num(fl, "temperature_rise_after_run_k"), trum_c)],
             vlines=[("Chen 2020: smallest", float(get(chen, "temperature_rise_min_n")[0]["value"]), paper_c),
                     ("Chen 2020: largest", float(get(chen, "temperature_rise_max_n")[0]["value"]), "#8e44ad")])
    svg_plot(os.path.join(OUT, "papers_trum60a_fluctuation.svg"),
             "TRUM60A at 200 V, 43 kHz: speed fluctuation from a 5 µm runout",
             "preload [N]", "speed standard deviation [rpm]",
             [("trum", num(fl, "preload_n"), num(fl, "speed_std_rpm"), trum_c)],
             vlines=[("Chen 2020: falls up to 475 N", 475.0, paper_c)])

    # TRUM-60 (QUT): Table 2 and the section 3 figures at 150 V, 42 kHz
    sun = paper("sun2021_figures.csv")
    with open(os.path.join(ROOT, "tests", "data", "papers", "sun2021_table2.csv"), newline="") as fh:
        t2 = list(csv.DictReader(fh))
    q = table(trum("map", "--motor", "trum60-qut", "--preload-n", "20:420:41", "--torque-nm", "0", "--voltage-v", "150",
                   "--frequency-hz", "42000", "-q", "-o", "-"))
    qx = num(q, "preload_n")
    svg_plot(os.path.join(OUT, "papers_qut_table2.svg"),
             "TRUM-60 at 150 V, 42 kHz: no-load speed and feedback voltage",
             "preload [N]", "speed [rpm] / feedback voltage [V]",
             [("trum: speed", qx, num(q, "speed_rpm"), trum_c), ("trum: feedback", qx, num(q, "feedback_v"), "#27ae60")],
             points=[("Sun 2021 Table 2: speed", float(r["preload_n"]), float(r["speed_rpm"]), paper_c) for r in t2]
             + [("Sun 2021 Table 2: feedback", float(r["preload_n"]), float(r["feedback_v"]), "#8e44ad") for r in t2])
    png_plot(os.path.join(OUT, "papers_qut_speed.png"), "TRUM-60 150 V 42 kHz (paper 1 = Sun 2021 Table 2)", "preload_n", "speed_rpm",
             list(zip(qx, num(q, "speed_rpm"))), [(float(r["preload_n"]), float(r["speed_rpm"])) for r in t2])
    png_plot(os.path.join(OUT, "papers_qut_feedback.png"), "TRUM-60 150 V 42 kHz (paper 1 = Sun 2021 Table 2)", "preload_n", "feedback_v",
             list(zip(qx, num(q, "feedback_v"))), [(float(r["preload_n"]), float(r["feedback_v"])) for r in t2])
    # the paper's slope drawn from the contact its wording implies at 50 N (a quarter
    # wavelength, 5.24 mm, reached at 400 N: tests/papers.rs, sun2021_contact_length_slope)
    slope = float(get(sun, "contact_length_slope_mm_per_n")[0]["value"])
    quarter = 2 * 3.141592653589793 * 30.0 / 9 / 4
    svg_plot(os.path.join(OUT, "papers_qut_contact_length.svg"),
             "TRUM-60 at 150 V, 42 kHz, no load: contact length",
             "preload [N]", "contact length [mm]",
             [("trum", qx, [1e3 * c for c in num(q, "contact_length_m")], trum_c),
              ("Sun 2021: 1.8e-3 mm/N", [50.0, 400.0], [quarter - 350 * slope, quarter], paper_c),
              ("quarter wave", [20.0, 420.0], [quarter, quarter], "#7f8c8d")])
    cur = get(sun, "current_a")
    amp = get(sun, "amplitude_peak_um")[0]
    svg_plot(os.path.join(OUT, "papers_qut_current_amplitude.svg"),
             "TRUM-60 at 150 V, 42 kHz, no load: current and amplitude",
             "preload [N]", "current [A] / amplitude [µm]",
             [("trum: current", qx, num(q, "current_a"), trum_c),
              ("trum: amplitude", qx, [a * 1e6 for a in num(q, "amplitude_m")], "#27ae60")],
             points=[("Sun 2021: current (Fig. 6)", float(r["preload_n"]), float(r["value"]), paper_c) for r in cur]
             + [("Sun 2021: amplitude peak", float(amp["preload_n"]), float(amp["value"]), "#8e44ad")])


if __name__ == "__main__":
    main()
