"""Plot helpers and compact reprs: labels in words with units, titles with the fixed
conditions and effects, the unstable branch told apart, stalled points not drawn as 0 %."""
import warnings

import numpy as np
import pytest

import trum

plt = pytest.importorskip("matplotlib.pyplot", reason="the plot helpers need the optional dependency matplotlib")


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


def test_speed_torque_labels_and_title_name_the_conditions_and_effects():
    m = trum.Motor("generic60")
    grid = trum.map(m, preload_n=[150, 250], torque_nm=trum.linspace(0, 0.4, 9))
    ax = grid.plot()
    assert ax.get_xlabel() == "Load torque [N·m]" and ax.get_ylabel() == "Speed [rpm]"
    assert "drive voltage 200 V" in ax.get_title() and "drive frequency 43 kHz" in ax.get_title()
    assert "nominal model (no effects)" in ax.get_title()
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["preload 150 N", "preload 250 N"]
    # a motor with an effect does not look like the nominal one
    fx = trum.map(m.with_effects("radial_friction=0.5"), preload_n=[150, 250], torque_nm=trum.linspace(0, 0.4, 9))
    assert "radial_friction" in fx.plot().get_title()
    # the lines are the data (speed in rpm against torque in N·m)
    x, y = ax.get_lines()[0].get_data()
    np.testing.assert_array_equal(x, grid["torque_nm"][:9])
    np.testing.assert_array_equal(y, grid["speed_rpm"][:9])


def test_efficiency_map_leaves_stalled_points_out_and_draws_the_stall_boundary():
    m = trum.Motor("trum60a")
    grid = trum.map(m, preload_n=trum.linspace(150, 400, 6), torque_nm=trum.linspace(0, 1.6, 33))
    assert grid.counts()["stall"] > 0
    ax = grid.plot("efficiency_map")
    assert ax.get_xlabel() == "Load torque [N·m]" and ax.get_ylabel() == "Speed [rpm]"
    # the filled contours start above 0 %: a stalled point (efficiency 0) is not in them
    cs = [c for c in ax.collections if hasattr(c, "levels")][0]
    running = grid["efficiency"][grid["status"] == "ok"] * 100
    assert cs.levels[0] <= running.min() and cs.levels[-1] >= running.max()
    boundary = [ln for ln in ax.get_lines() if ln.get_label() == "stall boundary"]
    assert boundary, "the stall boundary is drawn"
    bt, bv = boundary[0].get_data()
    assert np.all(bv >= 0) and bt.min() > 0.5  # every preload still turns up to several tenths of a N·m
    with pytest.raises(trum.InputError, match="torque_nm and one other axis"):
        trum.map(m, preload_n=260.0, torque_nm=trum.linspace(0, 1, 5)).plot("efficiency_map")


def test_resonance_plot_tells_the_unstable_branch_and_marks_the_jumps():
    r = trum.resonance(voltage_v=[200.0], preload_n=400.0, frequency_hz=trum.linspace(40800, 41050, 251))
    ax = r.plot()
    assert ax.get_ylabel() == "Vibration amplitude [µm]" and ax.get_xlabel() == "Drive frequency [kHz]"
    c = r.curves[0]
    dashed = [ln for ln in ax.get_lines() if ln.get_linestyle() == "--" and len(ln.get_xdata()) > 1]
    assert dashed, "the unstable branch is dashed"
    y = np.asarray(dashed[0].get_ydata())
    mid = np.sort(c.amplitude_m[c.branch == "middle"]) * 1e6
    np.testing.assert_allclose(np.sort(y[np.isfinite(y)]), mid)
    arrows = [a for a in ax.texts if getattr(a, "arrow_patch", None) is not None]
    assert len(arrows) == 2  # jump up and jump down, both inside the band
    assert c.hysteresis_hz > 0


def test_step_optimum_diagnosis_plots_and_compact_reprs():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = trum.step("trum60a", duration_s=2e-3, nodes_per_wavelength=64)
    ax = s.plot()
    assert ax.get_xlabel() == "Time [ms]" and "preload 260 N" in ax.get_title()
    assert "steady-state solver" in ax.get_legend_handles_labels()[1]
    assert len(repr(s)) < 600 and "StepResult" in repr(s)
    # no steady line where there is no steady comparison: a standing part, a bar-type motor
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        partly = trum.step("trum60a", phase_difference_deg=45.0, duration_s=2e-3, nodes_per_wavelength=64)
    bar = trum.step("bar36", duration_s=2e-3, nodes_per_wavelength=64)
    for r in (partly, bar):
        assert "steady-state solver" not in r.plot().get_legend_handles_labels()[1]
    r = trum.resonance(voltage_v=[100, 200, 300], preload_n=400.0)
    assert len(repr(r)) < 400 and all(len(repr(c)) < 200 for c in r.curves)
    o = trum.optimize("trum60a", preload_n=trum.linspace(150, 500, 8), torque_samples=8)
    axs = o.plot()
    assert axs[-1].get_xlabel() == "Preload [N]" and axs[1].get_ylabel() == "Maximum efficiency [%]"
