"""trum.diagnose: the sim-to-real diagnosis from Python, the same document as the CLI.

tests/data/eccentricity_stability.csv was written by
`trum synth --motor tests/data/motors/ring60.toml --effect eccentricity=2e-5 --campaign stability --noise 1 --seed 5`
(8 rows, eccentricity in its truth form, which differs from the candidate the diagnosis
fits); the nominal motor is that frozen copy of the TRUM60A values without effects.
"""
import json
import os
import pathlib
import shutil
import subprocess

import pytest

import trum

DATA = pathlib.Path(__file__).parent / "data" / "eccentricity_stability.csv"
RING_FILE = pathlib.Path(__file__).parents[3] / "tests" / "data" / "motors" / "ring60.toml"
RING = trum.Motor.from_toml_str(RING_FILE.read_text())


def test_finds_the_injected_effect_and_says_how_far_the_gap_shrinks():
    d = trum.diagnose(RING, DATA)
    assert d["verdict"] == "eccentricity"
    assert d["confounded_with"] == []
    # only an `unexplained` verdict names a partial explanation
    assert "partial" in d and d["partial"] is None
    top = d["ranking"][0]
    assert top["effect"] == "eccentricity" and top["evidence"] > 5
    # held-out gap: the baseline misses far beyond the noise, the effect closes most of it
    gap = d["gap"]
    # (the bench's speed-std floor, a nuisance parameter, takes a constant part of the spread)
    assert gap["baseline_heldout_nrmse"] > gap["noise_nrmse"]
    assert top["shrink"] == pytest.approx(1 - top["heldout_nrmse_after"] / gap["baseline_heldout_nrmse"], rel=1e-12)
    assert top["shrink"] > 0.6
    # every candidate of the spec was tried, and `where` names quantities with units
    tried = {e for r in d["ranking"] for e in r["effect"].split("+")}
    assert tried == {e.name for e in trum.effects()}
    assert all({"quantity", "region", "mean_residual"} <= set(w) for w in gap["where"])
    assert d["n_rows"] == 8


def test_bytes_give_the_same_document():
    a = trum.diagnose(RING, DATA)
    b = trum.diagnose(RING, DATA.read_bytes())
    assert b["data"] == "<bytes>"
    for k in ("verdict", "ranking", "gap"):
        assert a[k] == b[k]


def test_dataframes_and_open_files_give_the_same_document():
    pd = pytest.importorskip("pandas")
    a = trum.diagnose(RING, DATA)
    with open(DATA, "rb") as f:
        b = trum.diagnose(RING, f)
    c = trum.diagnose(RING, pd.read_csv(DATA))
    assert b["data"] == str(DATA) and c["data"] == "<DataFrame>"
    for k in ("verdict", "gap"):
        assert a[k] == b[k]
    # a DataFrame goes back to CSV at full precision: the same readings, the same verdict
    assert c["verdict"] == a["verdict"]
    assert c["gap"]["baseline_heldout_nrmse"] == pytest.approx(a["gap"]["baseline_heldout_nrmse"], rel=1e-9)
    # tables: the held-out readings with residuals, the ranking, the regions
    h = a.to_pandas()
    assert len(h) == len(a["heldout"]) and "speed_rpm" in set(h["quantity"])
    assert (h["residual_baseline"] == h["measured"] - h["baseline"]).all()
    r = a.to_pandas("ranking")
    assert r["effect"].iloc[0] == "eccentricity" and "evidence" in r
    assert len(repr(a)) < 400 and "eccentricity" in repr(a)


@pytest.mark.skipif(not os.environ.get("TRUM_BIN"), reason="set TRUM_BIN to a trum CLI binary to compare with it")
def test_matches_trum_diagnose_json():
    exe = shutil.which(os.environ["TRUM_BIN"]) or os.environ["TRUM_BIN"]
    out = subprocess.run([exe, "diagnose", "--motor", str(RING_FILE), "--data", str(DATA), "--json", "-"],
                         check=True, capture_output=True, text=True).stdout
    cli = json.loads(out)
    py = trum.diagnose(RING, str(DATA))
    # the same core builds the same document; only float printing could differ
    assert cli.keys() == py.keys()
    assert cli["verdict"] == py["verdict"] and cli["confounded_with"] == py["confounded_with"]
    assert cli["partial"] == py["partial"]
    assert [r["effect"] for r in cli["ranking"]] == [r["effect"] for r in py["ranking"]]
    for rc, rp in zip(cli["ranking"], py["ranking"]):
        assert rc["evidence"] == pytest.approx(rp["evidence"], rel=1e-12)
        assert rc["shrink"] == pytest.approx(rp["shrink"], rel=1e-12, abs=1e-15)
    assert cli["gap"]["baseline_heldout_nrmse"] == pytest.approx(py["gap"]["baseline_heldout_nrmse"], rel=1e-12)


def test_bad_input_is_a_clear_error(tmp_path):
    with pytest.raises(trum.InputError, match="does not exist"):
        trum.diagnose(RING, tmp_path / "missing.csv")
    with pytest.raises(trum.InputError, match="is a directory"):
        trum.diagnose(RING, tmp_path)
    with pytest.raises(TypeError, match="path, bytes or text, an open file or a pandas DataFrame"):
        trum.diagnose(RING, 42)
    bad = tmp_path / "bad.csv"
    bad.write_text("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n100,150,42000,0,106\n200,150,42000,0,nan\n")
    with pytest.raises(trum.InputError, match=r"bad\.csv.*line 3.*speed_rpm"):
        trum.diagnose(RING, bad)
    one = tmp_path / "one_region.csv"
    one.write_text("preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm\n"
                   + "".join(f"250,200,43000,{t},{100 - 50 * t}\n" for t in (0.0, 0.1, 0.2, 0.3, 0.4)))
    with pytest.raises(trum.InputError, match="no held-out block"):
        trum.diagnose(RING, one)
    with pytest.raises(trum.ParameterError, match="unknown preset"):
        trum.diagnose("trum61", DATA)


def test_ignored_columns_are_warned_about(tmp_path):
    lines = DATA.read_text().splitlines()
    extra = tmp_path / "extra.csv"
    extra.write_text("\n".join([lines[0] + ",operator"] + [line + ",li" for line in lines[1:]]) + "\n")
    with pytest.warns(UserWarning, match="operator"):
        d = trum.diagnose(RING, extra)
    assert d["verdict"] == "eccentricity"


def test_rows_logged_twice_are_counted_once_with_a_warning(tmp_path):
    lines = DATA.read_text().splitlines()
    twice = tmp_path / "twice.csv"
    twice.write_text("\n".join(lines + lines[1:]) + "\n")
    with pytest.warns(UserWarning, match=r"8 of 16 rows repeat an earlier row .*line 10 repeats line 2"):
        d = trum.diagnose(RING, twice)
    once = trum.diagnose(RING, DATA)
    for k in ("verdict", "ranking", "gap"):
        assert d[k] == once[k]
    with pytest.warns(UserWarning, match="8 of 16 rows repeat"):
        cal = trum.calibrate(RING, twice)
    assert cal.n_rows == 8


def test_calibrate_fits_the_baseline_and_reads_every_data_form():
    c = trum.calibrate(RING, DATA)
    # the eccentric bench is fitted about as well as its noise allows by the baseline alone
    assert 0.2 < c.chi2_per_reading < 2.0 and c.n_rows == 8
    byname = {p["name"]: p for p in c.params}
    mu = byname["friction_layer.friction_coefficient"]
    assert mu["identifiable"] and abs(mu["value"] / mu["nominal"] - 1) < 0.3
    # the calibrated motor carries the fitted values
    for p in c.params:
        if not p["name"].startswith("bench."):
            assert c.motor[p["name"]] == p["value"], p["name"]
    assert len(repr(c)) < 200
    pd = pytest.importorskip("pandas")
    df = c.to_pandas()
    assert list(df.columns) == ["name", "nominal", "value", "std_error", "change", "at_bound", "identifiable"]
    c2 = trum.calibrate(RING, pd.read_csv(DATA))
    # the DataFrame goes back to CSV at full precision: the same fit
    for a, b in zip(c.params, c2.params):
        assert a["name"] == b["name"] and a["value"] == pytest.approx(b["value"], rel=1e-9)


@pytest.mark.skipif(not os.environ.get("TRUM_BIN"), reason="set TRUM_BIN to a trum CLI binary to compare with it")
def test_calibrate_matches_trum_calibrate_json():
    exe = shutil.which(os.environ["TRUM_BIN"]) or os.environ["TRUM_BIN"]
    out = subprocess.run([exe, "calibrate", "--motor", str(RING_FILE), "--data", str(DATA), "--json", "-", "-q"],
                         check=True, capture_output=True, text=True).stdout
    cli = json.loads(out)
    py = trum.calibrate(RING, str(DATA))
    assert py.chi2 == pytest.approx(cli["chi2"], rel=1e-12)
    for a, b in zip(py.params, cli["params"]):
        assert a["name"] == b["name"] and a["value"] == pytest.approx(b["value"], rel=1e-12)
        assert a["std_error"] == pytest.approx(b["std_error"], rel=1e-9)


def test_calibrate_takes_tolerances_from_a_mapping_or_a_motor_files_table(tmp_path):
    free = {p["name"]: p for p in trum.calibrate(RING, DATA).params}
    mu = "friction_layer.friction_coefficient"
    assert free[mu]["value"] != free[mu]["nominal"]  # the data move it when it is free
    # tolerance 0 holds a parameter at the motor's value, from a mapping ...
    held = {p["name"]: p for p in trum.calibrate(RING, DATA, tolerances={mu: 0}).params}
    assert held.get(mu, {"value": RING[mu]})["value"] == RING[mu]
    # ... and from the [tolerances] table of a TOML file (the motor file itself), identically
    f = tmp_path / "ring60_tol.toml"
    f.write_text(RING_FILE.read_text() + '\n[tolerances]\n"friction_layer.friction_coefficient" = 0\n')
    by_file = trum.calibrate(trum.Motor.from_toml(str(f)), DATA, tolerances=str(f)).params
    assert [(p["name"], p["value"]) for p in by_file] == [(p["name"], p["value"]) for p in held.values()]


def test_a_bad_tolerance_names_the_key_and_the_valid_ones(tmp_path):
    with pytest.raises(trum.InputError, match=r"tolerances\.geometry\.radius_m.*valid keys are: .*geometry\.mean_radius_m"):
        trum.calibrate(RING, DATA, tolerances={"geometry.radius_m": 0.02})
    with pytest.raises(trum.InputError, match=r"must be >= 0"):
        trum.diagnose(RING, DATA, tolerances={"geometry.mean_radius_m": -1})
    f = tmp_path / "bad.toml"
    f.write_text('[tolerances]\n"stator.modal_mass" = 0.1\n')
    with pytest.raises(trum.InputError, match=r"bad\.toml: line 2, key 'tolerances\.stator\.modal_mass'"):
        trum.calibrate(RING, DATA, tolerances=str(f))
    with pytest.raises(trum.InputError, match=r"expected a number"):
        trum.calibrate(RING, DATA, tolerances={"geometry.mean_radius_m": "tight"})


@pytest.mark.skipif(not os.environ.get("TRUM_BIN"), reason="set TRUM_BIN to a trum CLI binary to compare with it")
def test_tolerances_from_a_motor_file_give_the_clis_calibration(tmp_path):
    f = tmp_path / "ring60_tol.toml"
    f.write_text(RING_FILE.read_text() + '\n[tolerances]\n"geometry.neutral_plane_distance_m" = 0.005\n'
                 '"bench.speed_std_floor_rpm" = 0\n')
    exe = shutil.which(os.environ["TRUM_BIN"]) or os.environ["TRUM_BIN"]
    out = subprocess.run([exe, "calibrate", "--motor", str(f), "--data", str(DATA), "--json", "-", "-q"],
                         check=True, capture_output=True, text=True).stdout
    cli = json.loads(out)
    py = trum.calibrate(trum.Motor.from_toml(str(f)), str(DATA), tolerances=str(f))
    assert py.chi2 == pytest.approx(cli["chi2"], rel=1e-12)
    assert [p["name"] for p in py.params] == [p["name"] for p in cli["params"]]
    for a, b in zip(py.params, cli["params"]):
        assert a["value"] == pytest.approx(b["value"], rel=1e-12)


def test_stated_sensor_noise_replaces_the_estimate():
    d = trum.diagnose(RING, DATA, sensor_noise={"speed_rpm": (0.5, 0.01), "speed_std_rpm": 0.05})
    note = next(n for n in d["notes"] if n.startswith("noise levels as stated"))
    assert "speed_rpm σ = 0.5 + 0.01 × reading" in note and "speed_std_rpm σ = 0.05 + 0 × reading" in note
    assert all(q["quantity"] not in ("speed_rpm", "speed_std_rpm") for q in d["gap"]["noise_scale"])
    with pytest.raises(trum.InputError, match="unknown column 'speed'"):
        trum.diagnose(RING, DATA, sensor_noise={"speed": 1.0})
    with pytest.raises(trum.InputError, match="> 0"):
        trum.diagnose(RING, DATA, sensor_noise={"speed_rpm": 0.0})
    with pytest.raises(TypeError):
        trum.diagnose(RING, DATA, sensor_noise={"speed_rpm": (1.0, 2.0, 3.0)})
