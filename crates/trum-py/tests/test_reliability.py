"""Bounded resources and absurd inputs from Python: the broadcast size guard of
``Motor.solve``, ``max_points`` checked as a whole number >= 1, masked arrays, control
characters in motor names (every motor pickles and unpickles), and ``trum.diagnose`` on a
DataFrame or CSV text. Property tests (Hypothesis) where it is installed."""
import pickle

import numpy as np
import pytest

import trum

ROWS = (
    "preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n"
    + "".join(f"{p},150,42000,{t},{s}\n" for p, t, s in [
        (150, 0, 120), (200, 0, 140), (250, 0, 142), (300, 0, 131),
        (150, 0.1, 90), (200, 0.1, 112), (250, 0.1, 118), (300, 0.1, 110),
    ])
)


def test_a_huge_broadcast_is_refused_before_allocating(motor):
    p = np.linspace(100, 300, 10_000)
    t = np.linspace(0, 0.5, 10_000)[:, None]
    with pytest.raises(trum.InputError, match=r"100000000 points \(shape \(10000, 10000\)\).*GB.*max_points"):
        motor.solve(preload_n=p, torque_nm=t, voltage_v=200, frequency_hz=43e3)
    r = motor.solve(preload_n=p[:10], torque_nm=t[:3], voltage_v=200, frequency_hz=43e3, max_points=30)
    assert r.shape == (3, 10)
    with pytest.raises(trum.InputError, match="max_points = 29"):
        motor.solve(preload_n=p[:10], torque_nm=t[:3], voltage_v=200, frequency_hz=43e3, max_points=29)


@pytest.mark.parametrize("bad", [-1, 0, 2.5, "10", True, 2**70 * -1])
def test_max_points_must_be_a_whole_number_of_at_least_one(motor, bad):
    with pytest.raises(ValueError, match="max_points must be a whole number >= 1"):
        trum.map(motor, preload_n=250, voltage_v=200, frequency_hz=43e3, max_points=bad)
    with pytest.raises(ValueError, match="max_points must be a whole number >= 1"):
        motor.solve(preload_n=250, voltage_v=200, frequency_hz=43e3, max_points=bad)


def test_a_limit_beyond_the_cores_counter_is_no_limit(motor):
    for big in (2**64, 10**30):
        assert trum.map(motor, preload_n=[150, 250], voltage_v=200, frequency_hz=43e3, max_points=big)["status"].size == 2
        assert motor.solve(preload_n=[150, 250], voltage_v=200, frequency_hz=43e3, max_points=big).status.size == 2


def test_a_masked_map_axis_is_refused_naming_the_axis_and_the_entries(motor):
    p = np.ma.masked_array([100.0, 200.0, 300.0], mask=[False, True, False])
    with pytest.raises(trum.InputError, match=r"^preload_n: masked entries \(at \[1\]\)"):
        trum.map(motor, preload_n=p, voltage_v=200, frequency_hz=43e3)
    # nothing masked: the values
    d = trum.map(motor, preload_n=np.ma.masked_array([100.0, 300.0], mask=False), voltage_v=200, frequency_hz=43e3)
    assert d["preload_n"].tolist() == [100.0, 300.0]


def test_masked_entries_are_invalid_points_not_solved(motor):
    p = np.ma.masked_array([200.0, -5.0, 300.0], mask=[False, True, False])
    r = motor.solve(preload_n=p, voltage_v=200, frequency_hz=43e3)
    assert list(r.status) == ["ok", "invalid_input", "ok"]
    plain = motor.solve(preload_n=np.array([200.0, 300.0]), voltage_v=200, frequency_hz=43e3)
    assert r["speed_rpm"][[0, 2]].tolist() == plain["speed_rpm"].tolist()


@pytest.mark.parametrize("name", ["a\x00b", "a\rb", "\x1b[31mred", "x\x7f"])
def test_control_characters_in_a_name_are_refused(name):
    with pytest.raises(trum.ParameterError, match="name.*control character"):
        trum.Motor.from_dict({"preset": "trum60a", "name": name})


def test_every_printable_name_pickles_and_unpickles():
    for name in ["Motör \"q\" \\ # [x]", "tab-free ✓", "'single'", "a" * 300]:
        m = trum.Motor.from_dict({"preset": "trum60a", "name": name})
        m2 = pickle.loads(pickle.dumps(m))
        assert m2.name == name and m2 == m


def test_diagnose_takes_a_dataframe_or_csv_text(motor):
    pd = pytest.importorskip("pandas")
    import io

    from_text = trum.diagnose("trum60a", ROWS)
    df = pd.read_csv(io.StringIO(ROWS))
    from_df = trum.diagnose("trum60a", df)
    from_bytes = trum.diagnose("trum60a", ROWS.encode())
    assert from_text["verdict"] == from_df["verdict"] == from_bytes["verdict"]
    assert from_text["gap"]["baseline_heldout_nrmse"] == from_bytes["gap"]["baseline_heldout_nrmse"]
    assert from_text["data"] == "<text>" and from_df["data"] == "<DataFrame>"
    # an implausible value names its line and column, wherever the data come from
    with pytest.raises(trum.InputError, match=r"line 10, column 'speed_rpm'.*plausible range"):
        trum.diagnose("trum60a", ROWS + "250,150,42000,0,1e300\n")
    # lifted: no confident verdict from an overflow, and every spec figure a number
    d = trum.diagnose("trum60a", ROWS + "250,150,42000,0,1e300\n", plausible={"speed_rpm": None})
    assert d["verdict"] == "unexplained" and d["complete"] is False
    assert all(np.isfinite(d["gap"][k]) for k in ("baseline_heldout_nrmse", "noise_nrmse"))
    assert all(np.isfinite(r[k]) for r in d["ranking"] for k in ("evidence", "heldout_nrmse_after", "shrink"))
    # a wider range, one end open
    trum.diagnose("trum60a", ROWS + "250,150,42000,0,2e4\n", plausible={"speed_rpm": (0, None)})
    with pytest.raises(trum.InputError, match="plausible 'speedrpm=any'.*not a numeric measurement column"):
        trum.diagnose("trum60a", ROWS, plausible={"speedrpm": None})


try:
    from hypothesis import given, settings
    from hypothesis import strategies as st
except ImportError:  # pragma: no cover - Hypothesis is optional
    given = None

if given is not None:

    @settings(max_examples=200, deadline=None)
    @given(
        st.floats(min_value=1e-3, max_value=1e5),
        st.floats(min_value=0.0, max_value=5.0),
        st.floats(min_value=1e-3, max_value=1e4),
        st.floats(min_value=100.0, max_value=1e7),
    )
    def test_solve_never_reports_a_non_finite_valid_point(preload, torque, voltage, frequency):
        r = trum.Motor("generic60").solve(
            preload_n=preload, torque_nm=torque, voltage_v=voltage, frequency_hz=frequency
        )
        if str(np.asarray(r.status).reshape(-1)[0]) in ("ok", "stall", "clamped"):
            for q in ("speed_rpm", "efficiency", "input_power_w", "amplitude_m"):
                assert np.isfinite(r[q]).all(), (q, r[q])
            assert 0.0 <= float(r["efficiency"]) <= 1.0

    @settings(max_examples=100, deadline=None)
    @given(st.text(alphabet=st.characters(blacklist_categories=("Cc", "Cs")), max_size=40))
    def test_any_printable_name_round_trips_through_pickle_and_toml(name):
        m = trum.Motor.from_dict({"preset": "generic60", "name": name})
        assert pickle.loads(pickle.dumps(m)).name == name
        assert trum.Motor.from_toml_str(m.to_toml()).name == name

    @settings(max_examples=25, deadline=None)
    @given(
        st.sampled_from(["trum60a", "trum60-qut", "generic60"]),
        st.floats(min_value=5.0, max_value=600.0),
        st.floats(min_value=5.0, max_value=300.0),
        st.floats(min_value=38e3, max_value=46e3),
    )
    def test_map_status_agrees_with_its_loaded_stall_torque(preset, preload, voltage, frequency):
        # along a torque line: ok below the line's loaded stall torque, not ok above it
        m = trum.Motor(preset)
        d = trum.map(m, preload_n=preload, voltage_v=voltage, frequency_hz=frequency,
                     torque_nm=trum.linspace(0.0, 3.0, 31))
        t = float(d["loaded_stall_torque_nm"][0])
        assert np.all(d["loaded_stall_torque_nm"] == t) or np.isnan(d["loaded_stall_torque_nm"]).all()
        ok = d["status"] == "ok"
        if np.isnan(t):
            assert not ok.any()
        else:
            assert ok[d["torque_nm"] < t * (1 - 1e-6)].all()
            assert not ok[d["torque_nm"] > t * (1 + 1e-6)].any()
