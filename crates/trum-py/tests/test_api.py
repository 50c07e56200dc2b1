"""Motor construction, errors, pickling, registries, map and optimize."""
import csv
import io
import os
import pickle
import shutil
import subprocess

import numpy as np
import pytest

import trum


def test_constructors_agree(motor, tmp_path):
    assert trum.Motor.preset("trum60a") == motor
    assert trum.Motor.from_toml_str('preset = "trum60a"\n') == motor
    f = tmp_path / "m.toml"
    f.write_text(motor.to_toml())
    assert trum.Motor.from_toml(f) == motor
    assert trum.Motor.from_toml(str(f)) == motor
    assert trum.Motor.from_dict(motor.to_dict()) == motor


def test_from_dict_forms(motor):
    flat = trum.Motor.from_dict({"preset": "trum60a", "stator.modal_damping_ns_per_m": 12})
    nested = trum.Motor.from_dict({"preset": "trum60a", "stator": {"modal_damping_ns_per_m": 12.0}})
    assert flat == nested
    assert flat["stator.modal_damping_ns_per_m"] == 12.0
    assert flat == motor.with_params({"stator.modal_damping_ns_per_m": 12})
    assert flat == motor.with_params(stator__modal_damping_ns_per_m=12)
    assert flat.overrides() == {"stator.modal_damping_ns_per_m": 12.0}
    fx = trum.Motor.from_dict({"preset": "trum60a", "effects": {"radial_friction": 0.5}})
    assert fx == motor.with_effects("radial_friction=0.5") == motor.with_effects(radial_friction=0.5)
    # (the preset carries its paper's effects; the added one joins them, replacing the
    # preset's strength of the same effect, its shape parameters at their defaults)
    shapes = {"preload_exponent": 0.0}
    assert fx.active_effects == {**motor.active_effects, "radial_friction": {"radial_velocity_ratio": 0.5, **shapes}}
    assert "preload_stiffening" in motor.active_effects
    hs = {"beta_n_per_m3": 1e19, "preload_gain_per_n": 0.001}
    a = trum.Motor.from_dict({"preset": "trum60a", "effects": {"hertz_softening": hs}})
    b = motor.with_effects("hertz_softening:beta_n_per_m3=1e19,preload_gain_per_n=0.001")
    assert a == b and {k: a.active_effects["hertz_softening"][k] for k in hs} == hs
    # Without a preset every key is required.
    full = {k: motor[k] for k in motor.keys()}
    m2 = trum.Motor.from_dict(full)
    assert m2.preset_name is None and [m2[k] for k in m2.keys()] == [motor[k] for k in motor.keys()]
    del full["rotor.mass_kg"]
    with pytest.raises(trum.ParameterError, match=r"^dict, key 'rotor.mass_kg': missing key"):
        trum.Motor.from_dict(full)


def test_repr_shows_preset_effects_overrides(motor):
    assert repr(motor) == f"Motor(preset='trum60a', effects='{motor.effects}')"
    assert repr(trum.Motor("generic60")) == "Motor(preset='generic60', effects='none')"
    m = motor.with_effects("radial_friction=0.5").with_params({"stator.modal_damping_ns_per_m": 12})
    r = repr(m)
    assert "preset='trum60a'" in r and "radial_friction(radial_velocity_ratio=0.5)" in r
    assert "'stator.modal_damping_ns_per_m': 12.0" in r


def test_pickle_round_trip(motor):
    m = motor.with_effects("hertz_softening=3e19", "radial_friction=0.25").with_params(
        {"friction_layer.friction_coefficient": 0.2123456789012345}
    )
    m2 = pickle.loads(pickle.dumps(m))
    assert m2 == m and m2.to_toml() == m.to_toml() and repr(m2) == repr(m)
    res = m.solve(preload_n=[150.0, 300.0], torque_nm=0.1, voltage_v=200, frequency_hz=43e3)
    res2 = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(res2.speed_rpm, res.speed_rpm)
    assert res2.status.tolist() == res.status.tolist()


def test_unknown_preset_lists_valid_names():
    with pytest.raises(trum.ParameterError) as e:
        trum.Motor("nope")
    names = ", ".join(p.name for p in trum.presets())
    assert str(e.value) == f"presets, key 'preset': unknown preset 'nope'; valid presets are: {names}"
    assert e.value.key == "preset" and isinstance(e.value, ValueError) and isinstance(e.value, trum.TrumError)


def test_unknown_key_names_the_key(motor):
    with pytest.raises(trum.ParameterError) as e:
        trum.Motor.from_dict({"preset": "trum60a", "stator.modal_mas_kg": 1.0})
    msg = str(e.value)
    assert msg.startswith("dict, key 'stator.modal_mas_kg': unknown parameter; valid keys are: geometry.wave_number")
    assert e.value.key == "stator.modal_mas_kg"
    with pytest.raises(KeyError, match="unknown parameter"):
        motor["stator.nope"]
    assert "stator.modal_mass_kg" in motor and "stator.nope" not in motor


def test_invalid_values_use_core_messages(motor):
    with pytest.raises(trum.ParameterError, match=r"^dict, key 'stator.modal_mass_kg': -1 must be > 0$"):
        trum.Motor.from_dict({"preset": "trum60a", "stator.modal_mass_kg": -1})
    with pytest.raises(trum.ParameterError, match="expected a number, got str"):
        trum.Motor.from_dict({"preset": "trum60a", "stator.modal_mass_kg": "heavy"})
    with pytest.raises(trum.ParameterError, match=r"^with_effects, key 'effects.radial': unknown effect 'radial'"):
        motor.with_effects("radial=0.5")
    with pytest.raises(trum.ParameterError, match="outside the valid range"):
        motor.with_effects("eccentricity=-1")
    toml = 'preset = "trum60a"\n[stator]\nmodal_mass_kg = -2\n'
    with pytest.raises(trum.ParameterError, match=r"^m.toml: line 3, key 'stator.modal_mass_kg': -2 must be > 0$") as e:
        trum.Motor.from_toml_str(toml, "m.toml")
    assert e.value.line == 3 and e.value.reason == "-2 must be > 0"


def test_registries():
    names = [p.name for p in trum.presets()]
    assert "trum60a" in names and all(trum.Motor(n).preset_name == n for n in names)
    assert "preset 'trum60a'" in trum.preset_toml("trum60a")
    fx = {e.name: e for e in trum.effects()}
    assert fx["radial_friction"].params[0].name == "radial_velocity_ratio"
    # preload_stiffening's second parameter is a shape, not a strength, as `trum effects` says
    ps = fx["preload_stiffening"].params
    assert [(p.name, p.shape) for p in ps] == [("stiffness_scale", False), ("modal_fraction", True)]
    # voltage_sag's family: the knee of a current-limited driver, held by the local fits
    sag = fx["voltage_sag"].params
    assert [(p.name, p.shape, p.held) for p in sag] == [
        ("source_resistance_ohm", False, False),
        ("knee_current_a", True, True),
    ]
    assert (ps[1].typical, ps[1].min, ps[1].max) == (0.0, 0.0, 1.0)
    # NAME=STRENGTH keeps Sun et al. 2021 eq. 8 (fraction 0) bit for bit; the modal projection differs
    speed = lambda spec: trum.Motor("trum60a").with_effects(spec).solve(
        preload_n=400.0, voltage_v=200.0, frequency_hz=43e3
    ).speed_rpm.tolist()
    eq8 = speed("preload_stiffening:stiffness_scale=0.5,modal_fraction=0")
    assert speed("preload_stiffening=0.5") == eq8
    assert speed("preload_stiffening:stiffness_scale=0.5,modal_fraction=1") != eq8
    q = trum.quantities()
    assert [x.name for x in q] == list(trum.QUANTITY_NAMES) and q[0].name == "speed_rpm" and q[0].unit == "rpm"
    assert [p.key for p in trum.parameters()] == trum.Motor("trum60a").keys()
    # Every quantity has a typed attribute on Result.
    assert set(trum.QUANTITY_NAMES) <= set(trum.Result.__annotations__)


def test_map_columns_and_values(motor):
    d = trum.map(motor, preload_n=trum.linspace(150, 300, 4), voltage_v=200, frequency_hz=43e3, torque_nm=trum.linspace(0.0, 0.3, 7))
    assert list(d)[:6] == ["preload_n", "torque_nm", "voltage_v", "frequency_hz", "status", "warnings"]
    assert list(d)[6:] == list(trum.QUANTITY_NAMES) + ["loaded_stall_torque_nm"]
    assert all(len(v) == 28 for v in d.values())
    assert d["torque_nm"][:7].tolist() == pytest.approx(np.linspace(0, 0.3, 7).tolist())
    res = motor.solve(preload_n=d["preload_n"], torque_nm=d["torque_nm"], voltage_v=200, frequency_hz=43e3)
    assert d["status"].tolist() == res.status.tolist()
    # warm starts from point to point: equal to the cold solve within the solver tolerance
    np.testing.assert_allclose(d["speed_rpm"], res.speed_rpm, rtol=1e-8, atol=1e-9)
    par = trum.map(motor, preload_n=trum.linspace(150, 300, 4), voltage_v=200, frequency_hz=43e3, torque_nm=trum.linspace(0.0, 0.3, 7), parallel=True)
    for k in trum.QUANTITY_NAMES:
        np.testing.assert_array_equal(par[k], d[k])
    np.testing.assert_array_equal(par["loaded_stall_torque_nm"], d["loaded_stall_torque_nm"])
    assert "loaded_stall_torque_nm" not in trum.map(motor, preload_n=150, torque_nm=0.1, loaded_stall=False)
    pd = pytest.importorskip("pandas")
    assert pd.DataFrame(d).shape == (28, 7 + len(trum.QUANTITY_NAMES))


def test_map_status_agrees_with_the_loaded_stall_torque():
    # generic60 near clamping: at 26.87 N, 6.63 V, 40 456.6 Hz the rotor-at-rest torque at
    # no load is about three times the load at which the loaded motor stops; at 100 N the
    # stator clamps (no loaded stall torque, no running point)
    g = trum.Motor("generic60")
    t = trum.linspace(0.0, 0.1, 201)
    d = trum.map(g, preload_n=[26.87, 100.0], voltage_v=6.63, frequency_hz=40456.6, torque_nm=t)
    loaded = d["loaded_stall_torque_nm"]
    # one value per line
    np.testing.assert_array_equal(loaded.reshape(2, 201), np.repeat(loaded[::201, None], 201, axis=1))
    first = loaded[0]
    assert 0 < first < 0.5 * d["stall_torque_nm"][0], (first, d["stall_torque_nm"][0])
    assert np.isnan(loaded[201]) and not np.any(d["status"][201:] == "ok")
    ok = d["status"] == "ok"
    tq = d["torque_nm"]
    assert np.all(ok[tq < loaded * (1 - 1e-6)]) and not np.any(ok[tq > loaded * (1 + 1e-6)])
    assert ok.any() and not ok.all()
    # explicit (unevenly spaced) values are solved point by point: the same line values
    u = trum.map(g, preload_n=[26.87, 100.0], voltage_v=6.63, frequency_hz=40456.6, torque_nm=[0.0, 0.001, 0.08])
    np.testing.assert_array_equal(u["loaded_stall_torque_nm"], np.repeat(loaded[::201], 3))


@pytest.mark.skipif(not os.environ.get("TRUM_BIN"), reason="set TRUM_BIN to a trum CLI binary to compare with it")
def test_map_is_the_clis_map_bit_for_bit(motor):
    # 3 × 2 × 700 = 4200 points: two of the core's chunks, the second starting mid-row
    cli = shutil.which(os.environ["TRUM_BIN"]) or os.environ["TRUM_BIN"]
    out = subprocess.run([cli, "map", "--motor", "trum60a", "--preload-n", "100:400:3", "--voltage-v", "180:220:2",
                          "--frequency-hz", "43000", "--torque-nm", "0:1.4:700", "--columns", "speed_rpm,efficiency,amplitude_m", "-o", "-"],
                         check=True, capture_output=True, text=True).stdout
    rows = list(csv.DictReader(io.StringIO(out)))
    d = trum.map(motor, preload_n=trum.linspace(100, 400, 3), voltage_v=trum.linspace(180, 220, 2), frequency_hz=43e3, torque_nm=trum.linspace(0, 1.4, 700))
    assert len(rows) == d["speed_rpm"].size == 4200
    for i, row in enumerate(rows):
        assert row["status"] == d["status"][i], i
        assert row["warnings"] == d["warnings"][i], i
        for col in ("preload_n", "torque_nm", "voltage_v", "speed_rpm", "efficiency", "amplitude_m"):
            # shortest round-trip CSV numbers: equal bit for bit; empty cells are NaN here
            want = d[col][i]
            assert (row[col] == "" and np.isnan(want)) or float(row[col]) == want, (i, col)


def test_map_errors(motor):
    with pytest.raises(trum.InputError, match=r"^preload_n: 0 must be > 0$"):
        trum.map(motor, preload_n=trum.linspace(0, 100, 3), voltage_v=200, frequency_hz=43e3)
    # the same words as `trum map` for a negative torque
    with pytest.raises(trum.InputError, match=r"^torque_nm: -0.5 must be >= 0$"):
        trum.map(motor, preload_n=100, voltage_v=200, frequency_hz=43e3, torque_nm=trum.linspace(-0.5, 0.5, 3))
    with pytest.raises(trum.InputError, match="must be a whole number"):
        trum.linspace(100, 200, 2.5)
    with pytest.raises(trum.InputError, match="must be >= 1"):
        trum.linspace(100, 200, 0)
    with pytest.raises(trum.InputError, match="non-empty 1-D"):
        trum.map(motor, preload_n=[], voltage_v=200, frequency_hz=43e3)
    with pytest.raises(trum.InputError, match="max_points"):
        trum.map(motor, preload_n=trum.linspace(100, 200, 10**5), voltage_v=200, frequency_hz=43e3, torque_nm=trum.linspace(0, 1, 10**4))
    # a tuple is neither read as a range nor as values: the error says how to write both
    with pytest.raises(trum.InputError, match=r"trum.linspace\(150, 400, 6\).*\[150, 400, 6\]"):
        trum.map(motor, preload_n=(150, 400, 6), voltage_v=200, frequency_hz=43e3)
    with pytest.raises(trum.InputError, match="tuple"):
        trum.resonance(voltage_v=(100, 300, 3))
    with pytest.raises(trum.InputError, match="evenly spaced"):
        trum.optimize(motor, preload_n=[150, 200, 400])


def test_lists_and_arrays_are_values_everywhere(motor):
    # three preloads, whether a list, an array or a Series: not a range 150..250 of 350 points
    for spec in ([150, 250, 350], np.array([150.0, 250.0, 350.0])):
        d = trum.map(motor, preload_n=spec, voltage_v=200, frequency_hz=43e3)
        assert d["preload_n"].tolist() == [150.0, 250.0, 350.0]
        r = trum.resonance(voltage_v=spec, preload_n=400.0, frequency_hz=41000.0)
        assert [c.voltage_v for c in r.curves] == [150.0, 250.0, 350.0]
    # unevenly spaced values are solved point by point: equal to Motor.solve bit for bit
    d = trum.map(motor, preload_n=[150, 200, 400], torque_nm=[0.0, 0.1], voltage_v=200, frequency_hz=43e3)
    assert d["preload_n"].tolist() == [150, 150, 200, 200, 400, 400]
    assert d["torque_nm"].tolist() == [0.0, 0.1] * 3
    res = motor.solve(preload_n=d["preload_n"], torque_nm=d["torque_nm"], voltage_v=200, frequency_hz=43e3)
    assert d["speed_rpm"].tobytes() == res.speed_rpm.tobytes()
    # np.linspace and trum.linspace give the same grid (the CLI's START:STOP:N)
    a = trum.map(motor, preload_n=np.linspace(150, 300, 4), torque_nm=np.linspace(0, 0.3, 7))
    b = trum.map(motor, preload_n=trum.linspace(150, 300, 4), torque_nm=trum.linspace(0, 0.3, 7))
    assert a["speed_rpm"].tobytes() == b["speed_rpm"].tobytes()
    assert trum.linspace(0, 0.3, 7).tolist() == [0.3 * i / 6 for i in range(7)]


def test_drive_defaults_are_the_motors(motor):
    # trum60a's [drive] is 200 V, 42 kHz (the preset's source figures); generic60 has none
    assert motor.drive == (200.0, 42000.0)
    assert trum.Motor("generic60").drive is None
    a = motor.solve(preload_n=260.0, torque_nm=0.1)
    b = motor.solve(preload_n=260.0, torque_nm=0.1, voltage_v=200.0, frequency_hz=42e3)
    assert a.speed_rpm.tobytes() == b.speed_rpm.tobytes()
    assert a.inputs["frequency_hz"].tolist() == 42e3
    g = trum.Motor("generic60").solve(preload_n=260.0)
    assert (g.inputs["voltage_v"].item(), g.inputs["frequency_hz"].item()) == (200.0, 43e3)
    # the drive travels with the motor: TOML text and pickle
    import pickle

    assert pickle.loads(pickle.dumps(motor)).drive == motor.drive
    assert trum.Motor.from_toml_str(motor.to_toml()).drive == motor.drive
    d = trum.map(motor, preload_n=260.0)
    assert (d["voltage_v"][0], d["frequency_hz"][0]) == (200.0, 42e3)


def test_tables_and_reprs(motor):
    pd = pytest.importorskip("pandas")
    d = trum.map(motor, preload_n=[150, 250, 350], torque_nm=trum.linspace(0, 0.6, 7), voltage_v=200, frequency_hz=43e3)
    df = d.to_pandas()
    assert df.shape == (21, 7 + len(trum.QUANTITY_NAMES)) and str(df["status"].dtype) == "category"
    assert d.shape == (3, 1, 1, 7) and d.swept == ["preload_n", "torque_nm"]
    assert d.fixed == {"voltage_v": 200.0, "frequency_hz": 43e3}
    text = repr(d)
    assert len(text) < 400 and "preload_n[3]" in text and "torque_nm[7]" in text
    # a Series' index survives solve().to_pandas()
    s = pd.Series([200.0, 260.0, 320.0], index=pd.Index(["a", "b", "c"], name="run"))
    out = motor.solve(preload_n=s, voltage_v=200, frequency_hz=43e3).to_pandas()
    assert out.index.tolist() == ["a", "b", "c"] and out.index.name == "run"
    assert out.loc["b", "preload_n"] == 260.0
    o = trum.optimize(motor, preload_n=trum.linspace(150, 500, 8), torque_samples=8)
    assert len(repr(o)) < 500 and "optimum_preload_n" in repr(o)
    assert len(repr(motor.solve(preload_n=np.linspace(100, 400, 1000)))) < 300


def test_map_to_xarray(motor):
    xr = pytest.importorskip("xarray")
    d = trum.map(motor, preload_n=[150, 250, 350], torque_nm=trum.linspace(0, 0.6, 7), voltage_v=200, frequency_hz=43e3)
    ds = d.to_xarray()
    assert isinstance(ds, xr.Dataset)
    assert dict(ds.sizes) == {"preload_n": 3, "torque_nm": 7}
    assert ds["speed_rpm"].attrs["units"] == "rpm" and ds["preload_n"].attrs["units"] == "N"
    assert float(ds["voltage_v"]) == 200.0
    # the grid cell is the flat row: preload 250 N, torque 0.2 N·m is row 1 * 7 + 2
    assert float(ds["speed_rpm"].isel(preload_n=1, torque_nm=2)) == d["speed_rpm"][9]
    assert ds["status"].sel(preload_n=350).values.tolist() == d["status"][14:21].tolist()


def test_optimize(motor):
    o = trum.optimize(motor, preload_n=trum.linspace(150, 500, 8), torque_samples=8)
    t = o.table
    assert o.within_limits and list(t["warnings"]) == [""] * 8
    capped = motor.with_params({"limits.max_voltage_v": 150})
    c = trum.optimize(capped, preload_n=trum.linspace(150, 500, 8), torque_samples=8)
    assert not c.within_limits and all(w == "max_voltage_v" for w in c.table["warnings"])
    assert len(t["preload_n"]) == 8 and o.optimum_preload_n in t["preload_n"]
    assert o.region_n[0] <= o.optimum_preload_n <= o.region_n[1]
    assert o.config["weights"] == {"stall_torque": 1.0, "efficiency": 1.0, "temperature_rise": 2.0, "speed_fluctuation": 2.0}
    o2 = trum.optimize(motor, preload_n=trum.linspace(150, 500, 8), torque_samples=8, weights={"stall_torque": 5})
    assert o2.config["weights"]["stall_torque"] == 5.0
    with pytest.raises(trum.InputError, match="weights must be finite"):
        trum.optimize(motor, weights=[0, 0, 0, 0])
    with pytest.raises(trum.InputError, match="unknown weight"):
        trum.optimize(motor, weights={"speed": 1})
    pytest.importorskip("pandas")
    assert o.to_pandas().shape[0] == 8


def test_warnings_name_each_limit_a_point_exceeds(motor):
    assert trum.LIMIT_KEYS == ("max_voltage_v", "max_amplitude_m", "max_stator_temperature_c", "max_input_power_w")
    g = trum.Motor("generic60")
    # inside; beyond the voltage; near resonance beyond amplitude and temperature
    res = g.solve(preload_n=250.0, voltage_v=[200.0, 350.0, 200.0], frequency_hz=[43e3, 43e3, 40e3])
    assert res.warnings.tolist() == ["", "max_voltage_v", "max_amplitude_m;max_stator_temperature_c"]
    assert res.within_limits.tolist() == [True, False, False]
    assert res.status.tolist() == ["ok", "ok", "ok"]
    assert res["warnings"].tolist() == res.warnings.tolist() and "warnings" in res.keys()
    df = res.to_pandas()
    assert df["warnings"].tolist() == res.warnings.tolist()
    assert res.to_dict()["warnings"].tolist() == res.warnings.tolist()
    # a limit of the motor file, changed like any parameter
    capped = g.with_params({"limits.max_input_power_w": 1.0})
    assert capped.solve(preload_n=250.0, voltage_v=200.0, frequency_hz=43e3).warnings.item() == "max_input_power_w"
    with pytest.raises(trum.ParameterError, match="limits.max_voltage"):
        trum.Motor.from_toml_str('preset = "generic60"\n[limits]\nmax_voltage = 1\n')
