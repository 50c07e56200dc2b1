"""trum against the same baseline model written in Python, side by side in one run.

    python benches/compare_python.py            # or: bash benches/compare_python.sh

Three implementations of the baseline steady state (docs/MODEL.md; no effects) solve the
same operating points of an effect-free TRUM60A (tests/data/motors/trum60a_baseline.toml;
the shipped preset switches `preload_stiffening` on, which the Python versions do not
model), 200 V, 43 kHz, preload x load torque:

* ``scipy``: per point, the way a user writes it — ``scipy.optimize.brentq`` for the
  contact angle, for the stick angle and for the amplitude, inside a Python loop;
* ``numpy``: vectorised over all points — safeguarded Newton for the two angles and
  bracketed secant for the amplitude, every step an array operation;
* ``trum``: the Rust solver through the Python module (``motor.solve``, cold per point,
  one thread).

It checks that all three give the same status and the same numbers to 1e-9 relative, and
prints the time per point and the ratios (relative differences: against the value, or
against 1e-3 of the quantity's largest value over the grid where the value is smaller). Equations (Chen et al. 2020/001, docs/MODEL.md):

  k = N/R0, k_f = E_f b_f/h_f, A = 2N k_f W/k, y = F/A
  contact: sin φ0 − φ0 cos φ0 = y (φ0 < π, c = cos φ0); y ≥ π: φ0 = π, c = −y/π
  χ(θ) = sin θ − θc, E(θ) = θ/2 + sin 2θ/4 − c sin θ, v0 = k h0 ω W
  stick: R0 μ A [2χ(θs) − χ(φ0)] = T + d_r v0 cos θs / R0, θs ≤ θmax = min(φ0, π/2);
         no root: stall (v_r = 0), except narrow contacts driven below the stall torque,
         where v_r = min(R0 (R0 μ A [2χ(θmax) − χ(φ0)] − T)/d_r, v0 cos θmax)
  amplitude: W = ΘV/|Z|, Z = (k_s − mω²) + i(ωc + 2Nμ k_f h0 [2E(θs) − E(φ0)]),
         the largest fixed point below the bound ΘV/(ωc) (W → 0: clamped)
  losses: friction 2Nμk_f W/k·(v0 [2E(θs) − E(φ0)] − v_r [2χ(θs) − χ(φ0)]),
         damping c ω² W², dielectric ω C0 V² tan δ, rotor d_r Ω²
  input: V·Re(I), I = V ω C0 (tan δ + i) + ω Θ² V Z*/|Z|²;  efficiency T Ω / input
"""

import argparse
import math
import os
import subprocess
import sys
import time
import tomllib

import numpy as np
from scipy.optimize import brentq

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OK, STALL, CLAMPED = "ok", "stall", "clamped"
# Quantities compared (trum's names).
COMPARED = [
    "amplitude_m",
    "contact_half_angle_rad",
    "stick_half_angle_rad",
    "speed_rad_s",
    "stall_torque_nm",
    "input_power_w",
    "friction_loss_w",
    "damping_loss_w",
    "efficiency",
]


def motor_params(trum_bin, motor):
    """Constants of a motor file, or of a preset read from `trum presets show` (the same
    numbers trum uses). The motor must have no effects: the Python versions model none."""
    if os.path.exists(motor):
        with open(motor, "rb") as f:
            t = tomllib.load(f)
    else:
        text = subprocess.run([trum_bin, "presets", "show", motor], check=True, capture_output=True, text=True).stdout
        t = tomllib.loads(text)
    if t.get("effects"):
        sys.exit(f"{motor} switches effects on ({', '.join(t['effects'])}); the Python versions model none")
    g, fl, st, el, ro = t["geometry"], t["friction_layer"], t["stator"], t["electrical"], t["rotor"]
    n = g["wave_number"]
    return dict(
        n=n,
        r0=g["mean_radius_m"],
        k=n / g["mean_radius_m"],
        kf=fl["youngs_modulus_pa"] * g["contact_width_m"] / fl["thickness_m"],
        h0=g["neutral_plane_distance_m"],
        mu=fl["friction_coefficient"],
        m=st["modal_mass_kg"],
        ks=st["modal_mass_kg"] * (2 * math.pi * st["resonance_frequency_hz"]) ** 2,
        c=st["modal_damping_ns_per_m"],
        theta=st["force_factor_n_per_v"],
        c0=el["clamped_capacitance_f"],
        tan_d=el["dielectric_loss_tangent"],
        dr=ro["viscous_damping_nms"],
    )


# ---------------------------------------------------------------- per point, SciPy


def scipy_point(P, F, T, V, f):
    w_ = 2 * math.pi * f
    xtol = dict(xtol=1e-300, rtol=4 * sys.float_info.epsilon, maxiter=200)

    def trial(W):
        A = 2 * P["n"] * P["kf"] * W / P["k"]
        y = F / A
        if y >= math.pi:
            phi, c, full = math.pi, -y / math.pi, True
        else:
            phi = brentq(lambda p: math.sin(p) - p * math.cos(p) - y, 0.0, math.pi, **xtol)
            c, full = math.cos(phi), False
        chi = lambda t: math.sin(t) - t * c
        E = lambda t: 0.5 * t + 0.25 * math.sin(2 * t) - c * math.sin(t)
        v0 = P["k"] * P["h0"] * w_ * W
        ts_scale = P["r0"] * P["mu"] * A
        visc = P["dr"] * v0 / P["r0"]
        tmax = min(phi, 0.5 * math.pi)
        bal = lambda t: ts_scale * (2 * chi(t) - chi(phi)) - T - visc * math.cos(t)
        tf0 = 2 * chi(tmax) - chi(phi)
        stalled = False
        if bal(tmax) >= 0:
            ts = brentq(bal, 0.0, tmax, **xtol)
            vr = v0 * math.cos(ts)
        else:
            ts = tmax
            drive = ts_scale * tf0
            if tmax < 0.5 * math.pi and P["dr"] > 0 and T < drive:
                vr = min((drive - T) / P["dr"] * P["r0"], v0 * math.cos(tmax))
            else:
                vr, stalled = 0.0, True
        pf = 2 * E(ts) - E(phi)
        tf = 2 * chi(ts) - chi(phi)
        z = (P["ks"] - P["m"] * w_ * w_, w_ * P["c"] + 2 * P["n"] * P["mu"] * P["kf"] * P["h0"] * pf)
        w_next = P["theta"] * V / math.hypot(*z)
        return dict(W=W, A=A, phi=phi, ts=ts, vr=vr, v0=v0, stalled=stalled, pf=pf, tf=tf, tf0=tf0, z=z, w_next=w_next)

    # Amplitude: fixed-point steps from the bound descend onto the largest fixed point;
    # brentq polishes it inside a bracket found below the last iterate.
    bound = P["theta"] * V / (w_ * P["c"])
    W = bound
    for _ in range(10_000):
        Wn = trial(W)["w_next"]
        if Wn < 1e-9 * bound:
            return "clamped", None
        if abs(W - Wn) <= 1e-6 * W:
            break
        W = Wn
    r = lambda W: W - trial(W)["w_next"]
    lo = W
    while r(lo) > 0:
        lo *= 0.999
    W = brentq(r, lo, W / 0.999 if r(W) <= 0 else W, xtol=1e-300, rtol=1e-14)
    t = trial(W)
    speed = 0.0 if t["stalled"] else t["vr"] / P["r0"]
    z2 = t["z"][0] ** 2 + t["z"][1] ** 2
    ire = V * w_ * P["c0"] * P["tan_d"] + w_ * P["theta"] ** 2 * V / z2 * t["z"][1]
    inp = V * ire
    scale = 2 * P["n"] * P["mu"] * P["kf"] * W / P["k"]
    out = dict(
        amplitude_m=W,
        contact_half_angle_rad=t["phi"],
        stick_half_angle_rad=t["ts"],
        speed_rad_s=speed,
        stall_torque_nm=P["r0"] * P["mu"] * t["A"] * t["tf0"],
        input_power_w=inp,
        friction_loss_w=max(scale * (t["v0"] * t["pf"] - speed * P["r0"] * t["tf"]), 0.0),
        damping_loss_w=P["c"] * w_ * w_ * W * W,
        efficiency=min(max(T * speed / inp, 0.0), 1.0),
    )
    return (STALL if t["stalled"] else OK), out


# ---------------------------------------------------------------- vectorised, NumPy


def newton_increasing(f, lo, hi, x):
    """Safeguarded Newton on arrays: f(x) -> (value, derivative), increasing on [lo, hi]."""
    lo, hi, x = lo.copy(), hi.copy(), x.copy()
    for _ in range(100):
        v, d = f(x)
        hi = np.where(v > 0, x, hi)
        lo = np.where(v > 0, lo, x)
        with np.errstate(divide="ignore", invalid="ignore"):
            nx = x - v / d
        bad = ~((nx > lo) & (nx < hi))
        nx = np.where(bad, 0.5 * (lo + hi), nx)
        done = np.abs(nx - x) <= 1e-15 * (1 + np.abs(x))
        x = nx
        if done.all():
            break
    return x


def numpy_points(P, F, T, V, f):
    w_ = 2 * np.pi * f
    bound = P["theta"] * V / (w_ * P["c"])

    def trial(W):
        A = 2 * P["n"] * P["kf"] * W / P["k"]
        y = F / A
        full = y >= np.pi
        yp = np.minimum(y, np.pi * (1 - 1e-16))
        start = np.where(yp < 1.5, np.minimum(np.cbrt(3 * yp), 0.999 * np.pi), np.pi - np.sqrt(np.maximum(2 * (np.pi - yp) / np.pi, 0)))
        phi = newton_increasing(
            lambda p: (np.sin(p) - p * np.cos(p) - yp, p * np.sin(p)), np.zeros_like(yp), np.full_like(yp, np.pi), start
        )
        phi = np.where(full, np.pi, phi)
        c = np.where(full, -y / np.pi, np.cos(phi))
        chi = lambda t: np.sin(t) - t * c
        E = lambda t: 0.5 * t + 0.25 * np.sin(2 * t) - c * np.sin(t)
        v0 = P["k"] * P["h0"] * w_ * W
        tsc = P["r0"] * P["mu"] * A
        visc = P["dr"] * v0 / P["r0"]
        tmax = np.minimum(phi, 0.5 * np.pi)
        chi0 = chi(phi)
        bal = lambda t: (tsc * (2 * chi(t) - chi0) - T - visc * np.cos(t), 2 * tsc * (np.cos(t) - c) + visc * np.sin(t))
        has_root = bal(tmax)[0] >= 0
        ts = newton_increasing(bal, np.zeros_like(tmax), tmax, 0.5 * tmax)
        tf0 = 2 * chi(tmax) - chi0
        drive = tsc * tf0
        narrow = (tmax < 0.5 * np.pi) & (P["dr"] > 0) & (T < drive)
        ts = np.where(has_root, ts, tmax)
        vr = np.where(has_root, v0 * np.cos(ts), np.where(narrow, np.minimum((drive - T) / P["dr"] * P["r0"], v0 * np.cos(tmax)), 0.0))
        stalled = ~has_root & ~narrow
        pf = 2 * E(ts) - E(phi)
        tf = 2 * chi(ts) - chi0
        z0 = P["ks"] - P["m"] * w_ * w_
        z1 = w_ * P["c"] + 2 * P["n"] * P["mu"] * P["kf"] * P["h0"] * pf
        w_next = P["theta"] * V / np.hypot(z0, z1)
        return dict(W=W, A=A, phi=phi, ts=ts, vr=vr, v0=v0, stalled=stalled, pf=pf, tf=tf, tf0=tf0, z=(z0, z1), w_next=w_next)

    # Amplitude: from the bound, secant steps that only descend until a point below the
    # root is found, then Illinois regula falsi inside the bracket (as trum does).
    hi_w = np.full(F.shape, bound)
    hi_r = hi_w - trial(hi_w)["w_next"]
    lo_w = np.full_like(hi_w, np.nan)
    lo_r = np.full_like(hi_w, np.nan)
    x = hi_w - hi_r  # one fixed-point step
    prev_w, prev_r = hi_w, hi_r
    active = np.ones(x.shape, bool)
    clamped = np.zeros(x.shape, bool)
    for _ in range(200):
        r = x - trial(x)["w_next"]
        conv = np.abs(r) <= 1e-13 * x
        clamped |= active & (x < 1e-9 * bound) & (r > 0) & np.isnan(lo_w)
        active &= ~conv & ~clamped
        if not active.any():
            break
        above = r > 0
        hi_w, hi_r = np.where(active & above, x, hi_w), np.where(active & above, r, hi_r)
        lo_w, lo_r = np.where(active & ~above, x, lo_w), np.where(active & ~above, r, lo_r)
        with np.errstate(divide="ignore", invalid="ignore"):
            sec = x - r * (x - prev_w) / (r - prev_r)
            rf = lo_w - lo_r * (hi_w - lo_w) / (hi_r - lo_r)
        desc = np.where(np.isfinite(sec) & (sec > 0) & (sec < x), sec, x - r)
        br = np.where((rf > lo_w) & (rf < hi_w), rf, 0.5 * (lo_w + hi_w))
        nx = np.where(np.isnan(lo_w), desc, br)
        prev_w, prev_r = np.where(active, x, prev_w), np.where(active, r, prev_r)
        x = np.where(active, nx, x)
    t = trial(x)
    W = x
    speed = np.where(t["stalled"], 0.0, t["vr"] / P["r0"])
    z0, z1 = t["z"]
    ire = V * w_ * P["c0"] * P["tan_d"] + w_ * P["theta"] ** 2 * V / (z0 * z0 + z1 * z1) * z1
    inp = V * ire
    scale = 2 * P["n"] * P["mu"] * P["kf"] * W / P["k"]
    out = dict(
        amplitude_m=W,
        contact_half_angle_rad=t["phi"],
        stick_half_angle_rad=t["ts"],
        speed_rad_s=speed,
        stall_torque_nm=P["r0"] * P["mu"] * t["A"] * t["tf0"],
        input_power_w=inp,
        friction_loss_w=np.maximum(scale * (t["v0"] * t["pf"] - speed * P["r0"] * t["tf"]), 0.0),
        damping_loss_w=P["c"] * w_ * w_ * W * W,
        efficiency=np.clip(T * speed / inp, 0.0, 1.0),
    )
    status = np.where(clamped, CLAMPED, np.where(active, "no_convergence", np.where(t["stalled"], STALL, OK)))
    return status, out


# ---------------------------------------------------------------- comparison


def rel_err(a, b, scale):
    return np.abs(a - b) / np.maximum(np.abs(b), scale)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--motor", default=os.path.join(ROOT, "tests", "data", "motors", "trum60a_baseline.toml"),
                    help="an effect-free motor file (every key given) or preset")
    ap.add_argument("--grid", type=int, nargs=2, default=[200, 100], metavar=("NF", "NT"),
                    help="preload x torque points for numpy and trum (default 200 x 100)")
    ap.add_argument("--scipy-points", type=int, default=2000, help="points the per-point SciPy version solves")
    ap.add_argument("--trum-bin", default=os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "trum"))
    a = ap.parse_args()
    import trum

    P = motor_params(a.trum_bin, a.motor)
    V, f = 200.0, 43e3
    nf, nt = a.grid
    F, T = np.meshgrid(np.linspace(100.0, 500.0, nf), np.linspace(0.0, 1.2, nt), indexing="ij")
    F, T = F.ravel(), T.ravel()
    n = F.size
    motor = trum.Motor.from_toml(a.motor) if os.path.exists(a.motor) else trum.Motor(a.motor)

    def best_of(k, fn):
        ts = []
        for _ in range(k):
            t0 = time.perf_counter()
            r = fn()
            ts.append(time.perf_counter() - t0)
        return min(ts), r

    t_trum, res = best_of(5, lambda: motor.solve(preload_n=F, torque_nm=T, voltage_v=V, frequency_hz=f, parallel=False))
    # The same points as a grid (what a user making a map calls): rows along the torque
    # axis are warm-started sweeps; the grid's order is the meshgrid's above.
    t_map, res_map = best_of(5, lambda: trum.map(motor, preload_n=trum.linspace(100.0, 500.0, nf), torque_nm=trum.linspace(0.0, 1.2, nt),
                                                 voltage_v=V, frequency_hz=f, parallel=False))
    # ... and on every core (the default): the same numbers, rows start cold whatever the threads
    t_par, res_par = best_of(5, lambda: trum.map(motor, preload_n=trum.linspace(100.0, 500.0, nf), torque_nm=trum.linspace(0.0, 1.2, nt),
                                                 voltage_v=V, frequency_hz=f, parallel=True))
    t_np, (st_np, out_np) = best_of(3, lambda: numpy_points(P, F, T, V, f))
    # SciPy: an evenly spread subset of the same points (the whole grid would take minutes).
    idx = np.linspace(0, n - 1, min(a.scipy_points, n)).round().astype(int)
    t0 = time.perf_counter()
    sp = [scipy_point(P, F[i], T[i], V, f) for i in idx]
    t_sp = time.perf_counter() - t0

    st_trum = np.asarray(res.status)
    worst = {}
    ok = True
    if not (np.asarray(res_map["status"]) == st_trum).all() or not np.allclose(res_map["preload_n"], F, rtol=1e-15) \
            or not np.allclose(res_map["torque_nm"], T, rtol=1e-15, atol=1e-15):
        ok = False
        print("trum.map differs from motor.solve in its points or statuses")
    if any(not np.array_equal(np.asarray(res_par[q]), np.asarray(res_map[q])) for q in ("status", *COMPARED)):
        ok = False
        print("trum.map on every core differs from trum.map on one thread")
    if not (st_np == st_trum).all():
        ok = False
        print(f"numpy status differs at {(st_np != st_trum).sum()} points")
    for q in COMPARED:
        tv = np.asarray(getattr(res, q), float)
        valid = st_trum != CLAMPED
        # Relative to the value, or to 1e-3 of the column's largest magnitude for values
        # below that: speed and efficiency fall to zero at the stall torque, where trum's
        # 1e-12 amplitude tolerance is amplified (the speed is a difference of nearly equal
        # torques) and a plain relative error of a near-zero number means nothing.
        floor = 1e-3 * np.nanmax(np.abs(tv[valid]))
        e_np = rel_err(out_np[q][valid], tv[valid], floor).max()
        e_sp = 0.0
        for j, i in enumerate(idx):
            s, o = sp[j]
            if s != st_trum[i]:
                ok = False
                print(f"scipy status {s} != trum {st_trum[i]} at F={F[i]} T={T[i]}")
            elif o is not None:
                e_sp = max(e_sp, rel_err(o[q], tv[i], floor))
        e_map = rel_err(np.asarray(res_map[q], float)[valid], tv[valid], floor).max()
        worst[q] = (e_np, e_sp, e_map)
        if max(e_np, e_sp, e_map) > 1e-9:
            ok = False

    per = lambda t, k: t / k * 1e6
    print(f"{os.path.basename(a.motor)}, {V:g} V, {f:g} Hz, preload 100-500 N x torque 0-1.2 N m; statuses: "
          + ", ".join(f"{s} {int((st_trum == s).sum())}" for s in (OK, STALL, CLAMPED)))
    tp = per(t_trum, n)
    tm = per(t_map, n)
    print(f"{'implementation':34} {'points':>8} {'us/point':>10} {'trum is x faster':>17} {'trum.map is x faster':>21}")
    print(f"{'trum (Rust, motor.solve, 1 thread)':34} {n:8d} {tp:10.3f} {1.0:17.1f} {tp / tm:21.1f}")
    print(f"{'trum.map (grid sweep, 1 thread)':34} {n:8d} {tm:10.3f} {tm / tp:17.1f} {1.0:21.1f}")
    tpar = per(t_par, n)
    cores = f"{os.cpu_count()} cores"
    print(f"{'trum.map (grid sweep, ' + cores + ')':34} {n:8d} {tpar:10.3f} {tpar / tp:17.1f} {tpar / tm:21.1f}")
    for name, k, t in (("NumPy, vectorised", n, t_np), ("SciPy brentq, per point", len(idx), t_sp)):
        print(f"{name:34} {k:8d} {per(t, k):10.3f} {per(t, k) / tp:17.1f} {per(t, k) / tm:21.1f}")
    print("largest relative difference to trum motor.solve (numpy, scipy, trum.map):")
    for q, (e1, e2, e3) in worst.items():
        print(f"  {q:24} {e1:9.2e} {e2:9.2e} {e3:9.2e}")
    print("agreement to 1e-9 relative, identical statuses:", "yes" if ok else "NO")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
