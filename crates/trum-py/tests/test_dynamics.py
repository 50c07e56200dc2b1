"""trum.resonance, trum.identify_hertz and trum.step: physics, errors, agreement with the CLI."""
import csv
import io
import math
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import trum

# The transient tests run on the TRUM60A's values without effects (a frozen copy: the
# preset carries its paper's contact stiffening, which the transient model does not have).
BASE_FILE = pathlib.Path(__file__).parents[3] / "tests" / "data" / "motors" / "trum60a_baseline.toml"
BASE = trum.Motor.from_toml_str(BASE_FILE.read_text())

FAST = dict(duration_s=0.004, nodes_per_wavelength=64)


def test_resonance_branches_jumps_and_trends():
    r = trum.resonance(voltage_v=trum.linspace(100, 300, 3), preload_n=400.0, frequency_hz=trum.linspace(40800, 41050, 251))
    assert [c.voltage_v for c in r.curves] == [100.0, 200.0, 300.0]
    assert r.frequency_hz.shape == (251,)
    c = r.curves[1]
    assert c.status == "ok" and c.reason == ""
    inside = (c.frequency_hz > c.jump_down_hz) & (c.frequency_hz < c.jump_up_hz)
    assert set(c.branch[inside]) == {"lower", "middle", "upper"}
    assert set(c.branch[~inside]) == {"single"}
    assert not c.stable[c.branch == "middle"].any() and c.stable[c.branch != "middle"].all()
    # softening ([Hertz2022] Fig. 11): jump-up above jump-down, backbone bends down
    assert c.jump_up_hz > c.jump_down_hz + 100
    assert np.all(np.diff(c.backbone_frequency_hz) < 0) and c.backbone_amplitude_m[0] == 0.0
    assert c.backbone_frequency_hz[0] == c.linear_resonance_hz
    widths = [x.hysteresis_hz for x in r.curves]
    assert widths[0] < widths[1] < widths[2]
    # preload family: the peak grows with preload (Fig. 12); harmonic balance works too
    p = trum.resonance(voltage_v=200.0, preload_n=np.array([200.0, 300.0, 400.0]), method="harmonic_balance")
    peaks = [x.amplitude_m.max() for x in p.curves]
    assert peaks[0] < peaks[1] < peaks[2]
    assert p.frequency_hz.size == 401


def test_resonance_of_a_motor_has_its_modal_parameters():
    # (a damping at which 1 V keeps the softening contact nearly linear: at the preset's
    # Q of about 460 the curve bends over and a sweep this narrow starts past the fold)
    m = trum.Motor("trum60a").with_params({"stator.modal_damping_ns_per_m": 25.0})
    f_r = m["stator.resonance_frequency_hz"]
    r = trum.resonance(motor=m, voltage_v=1.0, preload_n=250.0, method="harmonic_balance",
                       frequency_hz=trum.linspace(f_r - 200, f_r + 200, 2001))
    c = r.curves[0]
    assert c.linear_resonance_hz == pytest.approx(f_r, rel=1e-12)
    force = m["stator.force_factor_n_per_v"] * 1.0 + trum.hertz_defaults()["dynamic_contact_coefficient"] * 250.0
    assert c.amplitude_m.max() == pytest.approx(force / (m["stator.modal_damping_ns_per_m"] * 2 * np.pi * f_r), rel=1e-4)
    # overrides on top of the motor, and the preset name works too
    o = trum.resonance(motor="trum60a", oscillator={"damping_ns_per_m": 50.0}, voltage_v=1.0, preload_n=250.0,
                       method="harmonic_balance", frequency_hz=trum.linspace(f_r - 200, f_r + 200, 2001))
    assert o.curves[0].amplitude_m.max() == pytest.approx(0.5 * c.amplitude_m.max(), rel=1e-3)


def test_resonance_status_instead_of_nan_and_errors():
    r = trum.resonance(voltage_v=200.0, preload_n=[400.0, 1e6], frequency_hz=41000.0)
    assert [c.status for c in r.curves] == ["ok", "no_static_equilibrium"]
    assert "exceeds the largest static force" in r.curves[1].reason
    assert r.curves[1].amplitude_m.size == 0 and r.curves[1].jump_up_hz is None
    d = r.to_dict()
    assert list(d["status"]).count("no_static_equilibrium") == 1
    with pytest.raises(trum.ParameterError, match=r"oscillator, key 'modal_mas_kg': unknown key") as e:
        trum.resonance(oscillator={"modal_mas_kg": 0.05})
    assert e.value.key == "modal_mas_kg"
    with pytest.raises(trum.ParameterError, match=r"key 'damping_ns_per_m': -1 must be finite and > 0"):
        trum.resonance(oscillator={"damping_ns_per_m": -1})
    with pytest.raises(trum.InputError, match="frequency_hz"):
        trum.resonance(frequency_hz=[41000.0, -1.0])
    with pytest.raises(trum.InputError, match="method 'exact'"):
        trum.resonance(method="exact")
    assert trum.hertz_defaults()["modal_mass_kg"] == pytest.approx(0.0577809)


def _one_term_waveform(beta, w_mean, amp, f_hz, periods=12, per_period=64):
    """w = w̄ + X cos(ωt − φ) that satisfies the one-term harmonic balance exactly; returns
    t, w and the drive and static forces that go with it."""
    o = trum.hertz_defaults()
    m, c, k = o["modal_mass_kg"], o["damping_ns_per_m"], o["linear_stiffness_n_per_m"]
    w = 2 * math.pi * f_hz
    re = k - m * w * w + beta * (3 * w_mean**2 + 0.75 * amp**2)
    im = c * w
    force = amp * math.hypot(re, im)
    static = k * w_mean + beta * (w_mean**3 + 1.5 * w_mean * amp**2)
    t = np.arange(periods * per_period) / (per_period * f_hz)
    return t, w_mean + amp * np.cos(w * t - math.atan2(im, re)), force, static


def test_identify_hertz_recovers_beta_exactly_from_a_one_term_solution():
    beta = -1.0e19
    t, w, force, static = _one_term_waveform(beta, 1.0e-7, 1.5e-6, 40950.0)
    r = trum.identify_hertz(t, w, frequency_hz=40950.0, drive_force_n=force, preload_n=static, harmonics=1)
    assert r.beta_n_per_m3 == pytest.approx(beta, rel=1e-6)
    assert r.one_term_beta_n_per_m3 == pytest.approx(beta, rel=1e-6)
    assert r.harmonic_fit_r_squared > 1 - 1e-12 and r.displacement_amplitude_m == pytest.approx(1.5e-6)
    # the same record as a feedback voltage (2 V/µm) gives the same β
    rv = trum.identify_hertz(list(t), 2e6 * w, frequency_hz=40950.0, drive_force_n=force, preload_n=static,
                             feedback_gain_v_per_m=2e6, harmonics=1)
    assert rv.beta_n_per_m3 == pytest.approx(r.beta_n_per_m3, rel=1e-9)
    # a wrong drive force shows up in β (it is what balances the fundamental)
    r2 = trum.identify_hertz(t, w, frequency_hz=40950.0, drive_force_n=1.1 * force, preload_n=static, harmonics=1)
    assert abs(r2.beta_n_per_m3 / beta - 1) > 0.02


def test_identify_hertz_errors():
    t, w, force, static = _one_term_waveform(-1e19, 1e-7, 1.5e-6, 40950.0)
    kw = dict(frequency_hz=40950.0, drive_force_n=force)
    with pytest.raises(trum.InputError, match="input too short"):
        trum.identify_hertz(t[:20], w[:20], **kw)
    bad = w.copy()
    bad[5] = np.nan
    with pytest.raises(trum.InputError, match="non-finite value"):
        trum.identify_hertz(t, bad, **kw)
    with pytest.raises(trum.InputError, match="length mismatch"):
        trum.identify_hertz(t, w[:-1], **kw)
    with pytest.raises(trum.InputError, match="give voltage_v or drive_force_n"):
        trum.identify_hertz(t, w, frequency_hz=40950.0)
    with pytest.raises(trum.InputError, match="1-D"):
        trum.identify_hertz(t.reshape(2, -1), w.reshape(2, -1), **kw)
    with pytest.raises(trum.ParameterError, match="unknown key"):
        trum.identify_hertz(t, w, oscillator={"k": 1.0}, **kw)


def test_step_settles_near_the_steady_solver_and_reverses():
    r = trum.step(BASE, snapshot_at_s=[2e-5, 3.5e-3], **FAST)
    assert r.status == "ok" and r.steady["status"] == "ok"
    # default layer stiffness: 0-15 % above the rigid-Coulomb steady model (docs/DYNAMICS.md)
    assert 0.0 < r.speed_difference() < 0.15
    assert r.metrics["overshoot"] > 0.05 and 0 < r.metrics["delay_s"] < r.metrics["settling_time_s"] < 4e-3
    s = r.series
    assert set(s) >= {"time_s", "speed_rpm", "speed_period_mean_rpm", "contact_torque_nm", "amplitude_m"}
    assert s["time_s"].shape == s["speed_rpm"].shape and s["speed_rpm"][0] == 0.0
    first, late = r.snapshots
    assert set(first.state) <= {"stick", "slip"} and set(late.state) == {"stick", "slip", "no_contact"}
    f, lim = late.tangential_force_n_per_m, late.friction_limit_n_per_m
    assert np.all(np.abs(f) <= lim * (1 + 1e-12))
    slip = late.state == "slip"
    np.testing.assert_allclose(np.abs(f[slip]), lim[slip], rtol=1e-9)
    back = trum.step(BASE, phase_difference_deg=-90.0, **FAST)
    assert back.averages["speed_rpm"] == pytest.approx(-r.averages["speed_rpm"], rel=1e-6)
    # -90 deg is motion the other way: ok, negative speed, the same delay
    assert back.status == "ok" and back.metrics["final_speed_rpm"] < 0
    assert back.metrics["delay_s"] == pytest.approx(r.metrics["delay_s"], rel=1e-6)
    # ... compared with the mirrored steady solution: the forward run's difference, not about -2
    assert back.steady["status"] == "ok" and back.steady["note"] is None and r.steady["note"] is None
    assert back.steady["speed_rpm"] == -r.steady["speed_rpm"]
    assert back.steady["contact_torque_nm"] == -r.steady["contact_torque_nm"]
    assert back.speed_difference() == pytest.approx(r.speed_difference(), abs=1e-6)
    # a standing part (0 deg) is outside the steady model: NaN, with the reason, and a warning
    with pytest.warns(UserWarning, match="partly a standing wave"):
        standing = trum.step(BASE, phase_difference_deg=0.0, **FAST)
    assert standing.status == "not_moving" and standing.metrics["delay_s"] is None
    assert abs(standing.averages["speed_rpm"]) < 1e-3 * r.averages["speed_rpm"]
    assert standing.steady["status"] == "not_comparable" and "standing wave" in standing.steady["note"]
    assert math.isnan(standing.steady["speed_rpm"]) and math.isnan(standing.speed_difference())
    # the load brakes either way: under a load -90 deg mirrors +90 deg, steady comparison included
    fwd_l = trum.step(BASE, torque_nm=0.1, **FAST)
    back_l = trum.step(BASE, phase_difference_deg=-90.0, torque_nm=0.1, **FAST)
    assert back_l.averages["speed_rpm"] == pytest.approx(-fwd_l.averages["speed_rpm"], rel=1e-6)
    assert 0 < fwd_l.averages["speed_rpm"] < r.averages["speed_rpm"]
    assert back_l.steady["status"] == "ok" and back_l.steady["note"] is None
    assert back_l.steady["speed_rpm"] == -fwd_l.steady["speed_rpm"]
    assert back_l.steady["contact_torque_nm"] == -fwd_l.steady["contact_torque_nm"]
    assert back_l.speed_difference() == pytest.approx(fwd_l.speed_difference(), abs=1e-6)


def test_step_runs_the_bar_type_motor_at_the_papers_conditions():
    r = trum.step("bar36", duration_s=10e-3, nodes_per_wavelength=128)
    # the bar-type transient paper: rises in about 2 ms with overshoot (docs/DYNAMICS.md)
    assert r.status == "ok" and r.steady is None and np.isnan(r.speed_difference())
    assert 1.5e-3 < r.metrics["rise_to_final_s"] < 2.5e-3 < r.metrics["peak_time_s"]
    assert r.metrics["overshoot"] > 0.05 and r.averages["speed_rpm"] > 100
    stronger = trum.step("bar36", moment_nm=0.4, duration_s=10e-3, nodes_per_wavelength=128)
    assert stronger.metrics["delay_s"] < r.metrics["delay_s"]
    assert stronger.metrics["overshoot"] > r.metrics["overshoot"]
    back = trum.step("bar36", phase_difference_deg=-90, duration_s=10e-3, nodes_per_wavelength=128)
    assert back.status == "ok" and back.averages["speed_rpm"] == pytest.approx(-r.averages["speed_rpm"], rel=1e-6)
    with pytest.raises(trum.InputError, match="moment_nm"):
        trum.step("bar36", voltage_v=100)
    with pytest.raises(trum.InputError, match=r"moment_nm = -1: must be finite and > 0"):
        trum.step("bar36", moment_nm=-1)
    with pytest.raises(trum.InputError, match="voltage_v"):
        trum.step("trum60a", moment_nm=0.2)
    with pytest.raises(trum.ParameterError, match="bar-type"):
        trum.Motor("bar36")


def test_step_errors():
    with pytest.raises(trum.InputError, match=r"steps_per_period = 8: must be >= 16"):
        trum.step("trum60a", steps_per_period=8)
    with pytest.raises(trum.InputError, match=r"snapshot_at_s = 1: must lie in \[0, duration_s\]"):
        trum.step("trum60a", snapshot_at_s=[1.0], **FAST)
    with pytest.raises(trum.InputError, match="time step too large"):
        trum.step("trum60a", tangential_stiffness_ratio=1e6, **FAST)
    with pytest.raises(trum.InputError, match="unmodelled effects"):
        trum.step(trum.Motor("trum60a").with_effects("radial_friction=0.5"), **FAST)
    with pytest.raises(trum.InputError, match="whole number"):
        trum.step("trum60a", steps_per_period=64.5)
    with pytest.raises(trum.ParameterError, match="unknown preset"):
        trum.step("trum61")


def _cli():
    return shutil.which(os.environ["TRUM_BIN"]) or os.environ["TRUM_BIN"]


@pytest.mark.skipif(not os.environ.get("TRUM_BIN"), reason="set TRUM_BIN to a trum CLI binary to compare with it")
def test_matches_cli_resonance_and_step():
    out = subprocess.run([_cli(), "resonance", "--voltage-v", "100:300:3", "--preload-n", "300:400:2",
                          "--frequency-hz", "40850:41000:31", "-o", "-"],
                         check=True, capture_output=True, text=True).stdout
    rows = list(csv.DictReader(io.StringIO(out)))
    d = trum.resonance(voltage_v=trum.linspace(100, 300, 3), preload_n=trum.linspace(300, 400, 2), frequency_hz=trum.linspace(40850, 41000, 31)).to_dict()
    assert len(rows) == d["frequency_hz"].size
    for i, row in enumerate(rows):
        assert row["branch"] == d["branch"][i] and row["status"] == d["status"][i]
        for col in ("voltage_v", "preload_n", "frequency_hz", "amplitude_m", "phase_lag_rad"):
            # shortest round-trip CSV numbers: equal bit for bit; empty cells are NaN here
            want = d[col][i]
            assert (row[col] == "" and math.isnan(want)) or float(row[col]) == want, (i, col)
    out = subprocess.run([_cli(), "step", "--motor", str(BASE_FILE), "--duration-s", "0.004", "--nodes-per-wavelength",
                          "64", "--voltage-v", "150:200:2", "--table", "-"],
                         check=True, capture_output=True, text=True).stdout
    rows = list(csv.DictReader(io.StringIO(out)))
    for row, v in zip(rows, (150.0, 200.0)):
        r = trum.step(BASE, voltage_v=v, **FAST)
        assert row["status"] == r.status
        assert float(row["final_speed_rpm"]) == r.averages["speed_rpm"]
        assert float(row["delay_s"]) == r.metrics["delay_s"]
        assert float(row["steady_speed_rpm"]) == r.steady["speed_rpm"]


def test_step_runs_a_ring_motor_at_its_drive_unless_told():
    short = dict(duration_s=3e-4, nodes_per_wavelength=32)
    with pytest.warns(UserWarning, match="no unmodelled effects"):
        r = trum.step("trum60a", **short)
    assert trum.Motor("trum60a").drive == (200.0, 42e3)
    assert r.conditions["voltage_v"] == 200.0 and r.conditions["frequency_hz"] == 42e3
    with pytest.warns(UserWarning):
        told = trum.step("trum60a", frequency_hz=43.5e3, **short)
    assert told.conditions["frequency_hz"] == 43.5e3
