"""The transient stick-slip model of trum-core (the bar-type transient paper; crates/trum-core/src/dynamics/
transient.rs) written again with SciPy's solve_ivp, to compare speed and the settled result
with the Rust integrator (called through `trum.step`).

    python benches/transient_scipy.py [--duration-s 0.01] [--nodes 256] [--method RK45] [--repeat 3]

Same equations, continuous form (docs/DYNAMICS.md, "Transient response"):

    m q̈_A + c q̇_A + k_s q_A = Θ V cos ωt        + Q_A
    m q̈_B + c q̇_B + k_s q_B = Θ V cos(ωt − Δφ) + Q_B
    m_r z̈ + d_z ż + k_sp (z − z0) = F_c − F_N
    J_r Ω̇ + d_r Ω = T_c − T_load

with N_nodes Winkler springs p_j = k_f Δx max(0, w_j − z) and tangential springs of
deflection δ_j. Rust advances δ_j by a return mapping once per step; an ODE solver needs a
rate form, which is the continuous limit of that mapping (an elastic-perfectly-plastic
element, Moreau's sweeping process): with the slip limit L_j = μ p_j / (k_t Δx),

    δ̇_j = v_rel,j                      inside |δ_j| < L_j          (stick)
    δ̇_j = min(v_rel,j,  L̇_j)          on δ_j ≥ L_j                (slip, +)
    δ̇_j = max(v_rel,j, −L̇_j)          on δ_j ≤ −L_j               (slip, −)
    δ̇_j = −δ_j / τ                     out of contact (Rust resets δ_j to 0; τ = 1 µs)

and the force k_t Δx clip(δ_j, −L_j, L_j). v_rel,j = h0 k (q̇_B cos kx_j − q̇_A sin kx_j) − R0 Ω.
The right-hand side is vectorised over the nodes with NumPy. Rust's Verlet corrects the
stator stiffness and damping for its time step so that its forced response equals this
continuous one; the remaining differences are the O(h²) contact discretisation.
"""
from __future__ import annotations

import argparse
import math
import platform
import time

import numpy as np
import scipy
from scipy.integrate import solve_ivp

import trum

RAD_S_TO_RPM = 60.0 / (2.0 * math.pi)


def model(motor: trum.Motor, nodes: int, voltage_v: float, frequency_hz: float, phase_deg: float,
          preload_n: float, torque_nm: float, kt_ratio: float, axial_damping: float = 1.5e4):
    g = lambda k: motor[k]  # noqa: E731
    n_waves = g("geometry.wave_number")
    r0 = g("geometry.mean_radius_m")
    k = n_waves / r0
    dx = 2 * math.pi / k / nodes
    kf = g("friction_layer.youngs_modulus_pa") * g("geometry.contact_width_m") / g("friction_layer.thickness_m")
    m = g("stator.modal_mass_kg")
    ks = m * (2 * math.pi * g("stator.resonance_frequency_hz")) ** 2
    x = np.arange(nodes) * dx
    return dict(
        n=n_waves, r0=r0, h0k=g("geometry.neutral_plane_distance_m") * k, kf_node=kf * dx, kt_node=kt_ratio * kf * dx,
        mu=g("friction_layer.friction_coefficient"), m=m, ks=ks, c=g("stator.modal_damping_ns_per_m"),
        drive=g("stator.force_factor_n_per_v") * voltage_v, omega=2 * math.pi * frequency_hz,
        dphi=math.radians(phase_deg), j_r=g("rotor.inertia_kg_m2"), d_r=g("rotor.viscous_damping_nms"),
        m_r=g("rotor.mass_kg"), k_sp=g("assembly.axial_spring_stiffness_n_per_m"), d_z=axial_damping,
        preload=preload_n, load=torque_nm, cos=np.cos(k * x), sin=np.sin(k * x),
        z0=-preload_n / (kf * 2 * math.pi * r0), tau=1e-6,
    )


def rhs_factory(p):
    cos, sin = p["cos"], p["sin"]
    n, r0, h0k, kfn, ktn, mu = p["n"], p["r0"], p["h0k"], p["kf_node"], p["kt_node"], p["mu"]
    m, ks, c, drive, om_d, dphi = p["m"], p["ks"], p["c"], p["drive"], p["omega"], p["dphi"]
    j_r, d_r, m_r, k_sp, d_z = p["j_r"], p["d_r"], p["m_r"], p["k_sp"], p["d_z"]
    preload, load, z0, tau = p["preload"], p["load"], p["z0"], p["tau"]
    lim_rate = mu * kfn / ktn

    def rhs(t, y):
        qa, qb, va, vb, z, vz, om = y[:7]
        delta = y[7:]
        pen = qa * cos + qb * sin - z
        contact = pen > 0.0
        pres = kfn * np.where(contact, pen, 0.0)
        lim = mu * pres / ktn
        f = ktn * np.clip(delta, -lim, lim)
        v_rel = h0k * (vb * cos - va * sin) - r0 * om
        lim_dot = np.where(contact, lim_rate * (va * cos + vb * sin - vz), 0.0)
        dd = np.where(delta >= lim, np.minimum(v_rel, lim_dot), v_rel)
        dd = np.where(delta <= -lim, np.maximum(dd, -lim_dot), dd)
        dd = np.where(contact, dd, -delta / tau)
        qa_c = n * h0k * np.dot(f, sin)
        qb_c = -n * h0k * np.dot(f, cos)
        fz = n * pres.sum()
        torque = n * r0 * f.sum()
        ph = om_d * t
        out = np.empty_like(y)
        out[0], out[1] = va, vb
        out[2] = (drive * math.cos(ph) + qa_c - ks * qa - c * va) / m
        out[3] = (drive * math.cos(ph - dphi) + qb_c - ks * qb - c * vb) / m
        out[4] = vz
        out[5] = (fz - preload - k_sp * (z - z0) - d_z * vz) / m_r
        out[6] = (torque - load - d_r * om) / j_r
        out[7:] = dd
        return out

    return rhs


def run_scipy(p, duration_s: float, method: str, rtol: float):
    nodes = p["cos"].size
    y0 = np.zeros(7 + nodes)
    y0[4] = p["z0"]
    f = p["omega"] / (2 * math.pi)
    periods = int(round(duration_s * f))
    avg_periods = max(1, round(0.2 * periods))
    # the last whole periods (at least 20 %), sampled 64 times per period like Rust's mean
    t_avg = (periods - avg_periods + np.arange(avg_periods * 64 + 1) / 64) / f
    atol = np.concatenate([[1e-12, 1e-12, 1e-6, 1e-6, 1e-12, 1e-6, 1e-6], np.full(nodes, 1e-12)])
    t0 = time.perf_counter()
    sol = solve_ivp(rhs_factory(p), (0.0, t_avg[-1]), y0, method=method, t_eval=t_avg, rtol=rtol, atol=atol)
    wall = time.perf_counter() - t0
    if not sol.success:
        raise RuntimeError(sol.message)
    speed = sol.y[6][1:].mean() * RAD_S_TO_RPM
    return wall, speed, sol.nfev


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--motor", default="trum60a")
    ap.add_argument("--duration-s", type=float, default=10e-3)
    ap.add_argument("--nodes", type=int, default=256)
    ap.add_argument("--method", default="RK45")
    ap.add_argument("--rtol", type=float, default=1e-5)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    motor = trum.Motor(a.motor)
    op = dict(voltage_v=200.0, frequency_hz=43e3, phase_deg=90.0, preload_n=260.0, torque_nm=0.0)
    p = model(motor, a.nodes, kt_ratio=300.0, **op)
    print(f"machine: {platform.machine()} {platform.platform()}, python {platform.python_version()}, "
          f"numpy {np.__version__}, scipy {scipy.__version__}")
    print(f"{a.motor}, 200 V, 43 kHz, 90 deg, 260 N, no load, {a.nodes} nodes per wavelength, "
          f"{a.duration_s * 1e3:g} ms of motor time")
    rust = []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        r = trum.step(motor, voltage_v=200.0, frequency_hz=43e3, phase_difference_deg=90.0, preload_n=260.0,
                      duration_s=a.duration_s, nodes_per_wavelength=a.nodes)
        rust.append(time.perf_counter() - t0)
    rust_speed = r.averages["speed_rpm"]
    print(f"rust (trum.step, Verlet, 64 steps/period, {r.steps} steps): best {min(rust):.3f} s, "
          f"settled speed {rust_speed:.3f} rpm")
    walls = []
    for _ in range(max(1, min(a.repeat, 2))):
        wall, speed, nfev = run_scipy(p, a.duration_s, a.method, a.rtol)
        walls.append(wall)
    print(f"scipy (solve_ivp {a.method}, rtol {a.rtol:g}, {nfev} right-hand-side evaluations): best {min(walls):.2f} s, "
          f"settled speed {speed:.3f} rpm")
    diff = (speed - rust_speed) / rust_speed
    print(f"ratio scipy/rust: {min(walls) / min(rust):.0f}x; settled speed difference {diff * 100:+.2f} %")
    # Same equations: the settled speeds must agree within 1 % (Rust's O(h²) contact
    # discretisation at 64 steps/period and the ODE tolerance; docs/PERFORMANCE.md).
    if a.duration_s >= 4e-3 and abs(diff) > 0.01:
        raise SystemExit(f"settled speeds differ by {diff * 100:+.2f} % (> 1 %)")


if __name__ == "__main__":
    main()
