"""Vectorised solve: values, broadcasting, dtypes, strides, invalid points."""
import json
import os
import shutil
import subprocess

import numpy as np
import pytest

import trum

OP = dict(voltage_v=200.0, frequency_hz=43e3)


def test_scalar_equals_array_bitwise(motor):
    pre = np.linspace(100.0, 500.0, 37)
    tq = np.linspace(0.0, 1.0, 11)[:, None]
    arr = motor.solve(preload_n=pre, torque_nm=tq, **OP)
    assert arr.shape == (11, 37)
    for i in (0, 3, 10):
        for j in (0, 17, 36):
            s = motor.solve(preload_n=float(pre[j]), torque_nm=float(tq[i, 0]), **OP)
            assert s.shape == ()
            assert s.status.item() == arr.status[i, j]
            for q in trum.QUANTITY_NAMES:
                a, b = s[q].item(), arr[q][i, j]
                assert a == b or (np.isnan(a) and np.isnan(b)), q


def test_parallel_equals_serial_bitwise(motor):
    pre = np.linspace(100.0, 500.0, 5000)
    a = motor.solve(preload_n=pre, torque_nm=0.2, parallel=False, **OP)
    b = motor.solve(preload_n=pre, torque_nm=0.2, **OP)  # parallel (>= 4096 points)
    for q in trum.QUANTITY_NAMES:
        np.testing.assert_array_equal(a[q], b[q])
    np.testing.assert_array_equal(a.status_code, b.status_code)


def test_known_values_match_cli_snapshot(motor):
    # `trum point --motor trum60a --preload-n 250 --torque-nm 0.3` (the CLI's snapshot
    # crates/trum-cli/tests/snapshots/point_trum60a_250n_0.3nm.txt, 6 significant digits).
    r = motor.solve(preload_n=250.0, torque_nm=0.3, voltage_v=200.0, frequency_hz=43000.0)
    expect = dict(speed_rpm=66.7943, speed_rad_s=6.99468, efficiency=0.219263, output_power_w=2.09841,
                  input_power_w=9.57026, stall_torque_nm=1.6211, amplitude_m=1.26498e-6, contact_angle_deg=24.4176,
                  driving_angle_deg=9.13774, driving_ratio=0.374227, contact_half_angle_rad=1.91776,
                  stick_half_angle_rad=0.717677, contact_length_m=0.0111869, crest_speed_m_s=0.24373)
    assert r.status.item() == "ok"
    for q, v in expect.items():
        assert r[q].item() == pytest.approx(v, rel=6e-6), q
    assert r.speed_rad_s.item() == pytest.approx(r.speed_rpm.item() * 2 * np.pi / 60, rel=1e-12)


def test_broadcasting_scalar_vector_column(motor):
    p = np.array([150.0, 250.0, 350.0])
    t = np.array([[0.0], [0.1]])
    r = motor.solve(preload_n=p, torque_nm=t, voltage_v=200.0, frequency_hz=43e3)
    assert r.shape == (2, 3) and r.speed_rpm.shape == (2, 3) and r.status.shape == (2, 3)
    assert r.inputs["preload_n"].shape == (2, 3)
    assert r.speed_rpm.dtype == np.float64
    with pytest.raises(trum.InputError, match=r"could not be broadcast together: preload_n has shape \[3\], torque_nm has shape \[2\]"):
        motor.solve(preload_n=p, torque_nm=np.zeros(2), **OP)
    with pytest.raises(ValueError):
        motor.solve(preload_n=p, torque_nm=np.zeros(2), **OP)
    empty = motor.solve(preload_n=np.zeros((0, 3)), **OP)
    assert empty.shape == (0, 3) and empty.speed_rpm.shape == (0, 3)


def test_integer_and_other_dtypes(motor):
    ref = motor.solve(preload_n=np.array([150.0, 250.0]), torque_nm=0.0, voltage_v=200.0, frequency_hz=43000.0)
    for pre in (np.array([150, 250]), np.array([150, 250], dtype=np.int16), [150, 250], np.array([150, 250], np.float32),
                np.array([150, 250], dtype=">f8"), np.array([150, 250], dtype=np.uint32)):
        r = motor.solve(preload_n=pre, torque_nm=0, voltage_v=200, frequency_hz=43000)
        np.testing.assert_array_equal(r.speed_rpm, ref.speed_rpm)
    with pytest.raises(trum.InputError, match="expected real numbers"):
        motor.solve(preload_n=np.array(["a"]), **OP)
    with pytest.raises(trum.InputError, match="expected real numbers"):
        motor.solve(preload_n=np.array([1 + 2j]), **OP)


def test_non_contiguous_arrays(motor):
    base = np.linspace(100.0, 500.0, 40).reshape(8, 5)
    views = [base[::2, ::2], base.T, base[:, 1], np.asfortranarray(base)]
    for v in views:
        assert not v.flags.c_contiguous or v is views[-1] or v.ndim == 1
        r = motor.solve(preload_n=v, torque_nm=0.05, **OP)
        ref = motor.solve(preload_n=np.ascontiguousarray(v), torque_nm=0.05, **OP)
        assert r.shape == v.shape
        np.testing.assert_array_equal(r.speed_rpm, ref.speed_rpm)
    # broadcast (stride-0) views
    r = motor.solve(preload_n=np.broadcast_to(np.array([200.0]), (4, 3)), torque_nm=np.arange(3) * 0.1, **OP)
    assert r.shape == (4, 3) and (r.speed_rpm[0] == r.speed_rpm[3]).all()


def test_invalid_points_are_nan_with_status_and_reason(motor):
    r = motor.solve(preload_n=[-10.0, np.nan, 200.0], torque_nm=[0.0, 0.0, -1.0], **OP)
    assert r.status.tolist() == ["invalid_input"] * 3
    assert np.isnan(r.speed_rpm).all() and np.isnan(r.efficiency).all()
    assert r.reason.tolist() == [
        "preload_n = -10 must be > 0",
        "preload_n = NaN is not a finite number",
        "torque_nm = -1 must be >= 0",
    ]
    ok = motor.solve(preload_n=[-10.0, 200.0], **OP)
    assert ok.status.tolist() == ["invalid_input", "ok"] and ok.valid.tolist() == [False, True]
    assert ok.reason.tolist() == ["preload_n = -10 must be > 0", ""]
    stall = motor.solve(preload_n=200.0, torque_nm=50.0, **OP)
    assert stall.status.item() == "stall" and stall.speed_rpm.item() == 0.0


def test_result_containers(motor):
    r = motor.solve(preload_n=[150.0, 250.0], torque_nm=[[0.0], [0.1]], **OP)
    d = r.to_dict()
    assert list(d) == ["preload_n", "torque_nm", "voltage_v", "frequency_hz", "elapsed_s", "status", "warnings",
                       *trum.QUANTITY_NAMES]
    assert all(v.shape == (2, 2) for v in d.values())
    assert "speed_rpm" in dir(r)
    with pytest.raises(AttributeError, match="quantities are"):
        r.speed
    assert r.counts()["ok"] == 4 and "ok=4" in repr(r)
    pd = pytest.importorskip("pandas")
    df = r.to_pandas()
    assert df.shape == (4, len(d)) and str(df["status"].dtype) == "category"
    np.testing.assert_array_equal(df["speed_rpm"].to_numpy(), r.speed_rpm.ravel())


def test_gil_released(motor):
    # Two threads solving at once finish; with the GIL held this would still pass, so
    # check at least that solves run concurrently without error.
    import threading

    out = {}

    def work(k):
        out[k] = motor.solve(preload_n=np.linspace(100, 400, 2000), parallel=False, **OP).speed_rpm

    ts = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    [t.start() for t in ts]
    [t.join() for t in ts]
    np.testing.assert_array_equal(out[0], out[1])


@pytest.mark.skipif(not os.environ.get("TRUM_BIN"), reason="set TRUM_BIN to a trum CLI binary to compare with `trum point --json`")
def test_matches_cli_point_json(motor):
    exe = shutil.which(os.environ["TRUM_BIN"]) or os.environ["TRUM_BIN"]
    args = ["point", "--motor", "trum60a", "--preload-n", "260", "--torque-nm", "0.1", "--voltage-v", "200",
            "--frequency-hz", "43000", "--json"]
    out = json.loads(subprocess.run([exe, *args], check=True, capture_output=True, text=True).stdout)
    r = motor.solve(preload_n=260.0, torque_nm=0.1, **OP)
    assert out["status"] == r.status.item()
    for q in trum.QUANTITY_NAMES:
        if out["quantities"].get(q) is not None:
            # JSON carries full precision (shortest round-trip), so the values are equal.
            assert out["quantities"][q] == r[q].item(), q


def test_huge_broadcast_is_memory_error_not_crash(motor):
    big = np.broadcast_to(np.array(200.0), (2**24, 1))
    tq = np.broadcast_to(np.array(0.1), (1, 2**24))
    # refused by the size guard, naming the limit, before anything is allocated
    with pytest.raises(trum.InputError, match="281474976710656 points.*max_points"):
        motor.solve(preload_n=big, torque_nm=tq, **OP)
    # with the guard lifted, the allocation itself fails cleanly
    with pytest.raises(MemoryError, match="solve in chunks"):
        motor.solve(preload_n=big, torque_nm=tq, max_points=2**62, **OP)
