"""A fleet on Dask: trum.diagnose_fleet / trum.calibrate_fleet over many measurement files,
one summary DataFrame; every row equals the single-file call on that file, a file that
fails is a row with its error, and the [plausible] table of a TOML file travels to the
workers. The cluster test runs on a LocalCluster of two worker processes (small files,
eight rows each, so it stays short).

tests/data/eccentricity_stability.csv: eight rows of a motor with eccentricity
(test_diagnose.py says how it was written); the nominal motor is tests/data/motors/ring60.toml."""
import pathlib
import warnings

import numpy as np
import pytest

import trum

pd = pytest.importorskip("pandas")

DATA = pathlib.Path(__file__).parent / "data" / "eccentricity_stability.csv"
RING_FILE = pathlib.Path(__file__).parents[3] / "tests" / "data" / "motors" / "ring60.toml"
RING = trum.Motor.from_toml_str(RING_FILE.read_text())


def _fleet_dir(tmp_path):
    """m01: the campaign; m02: the same with a column the reader ignores (a warning);
    m03: one speed of 15 000 rpm (outside the default plausible range: an error)."""
    lines = DATA.read_text().splitlines()
    (tmp_path / "m01.csv").write_text("\n".join(lines) + "\n")
    (tmp_path / "m02.csv").write_text("\n".join([lines[0] + ",operator"] + [l + ",ann" for l in lines[1:]]) + "\n")
    head = lines[0].split(",")
    cells = lines[3].split(",")
    cells[head.index("speed_rpm")] = "15000"
    (tmp_path / "m03.csv").write_text("\n".join(lines[:3] + [",".join(cells)] + lines[4:]) + "\n")
    return tmp_path


def test_a_diagnosis_fleet_on_a_local_cluster_of_two_processes(tmp_path):
    distributed = pytest.importorskip("distributed", reason="dask.distributed is not installed")
    d = _fleet_dir(tmp_path)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        with distributed.get_task_stream(client) as ts:
            df = trum.diagnose_fleet(RING, str(d / "*.csv"), client=client)
        workers = {t["worker"] for t in ts.data}
    assert len(workers) == 2, "the files did not spread over both worker processes"
    assert list(df["motor_id"]) == ["m01", "m02", "m03"]
    assert list(df.columns[:4]) == ["file", "motor_id", "status", "rows"]
    assert list(df.columns[4:16]) == list(trum.DIAGNOSE_FLEET_COLUMNS)
    assert list(df.columns[-2:]) == ["warnings", "error"]
    assert list(df["status"]) == ["ok", "ok", "error"]
    # the bad file: its error names the line and column, no figures
    bad = df.iloc[2]
    assert "line 4, column 'speed_rpm'" in bad["error"] and "plausible range" in bad["error"]
    assert pd.isna(bad["rows"]) and bad["verdict"] == "" and np.isnan(bad["baseline_heldout_nrmse"])
    # the injected effect is found in both good files, and the warning is kept
    assert list(df["verdict"][:2]) == ["eccentricity", "eccentricity"]
    assert "operator" in df.iloc[1]["warnings"] and df.iloc[0]["warnings"] == ""
    # every row is what trum.diagnose finds in that file, bitwise (other processes, same code)
    for i in range(2):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # m02's ignored column
            one = trum.diagnose(RING, df.iloc[i]["file"])
        row = df.iloc[i]
        assert row["rows"] == one["n_rows"] == 8
        assert bool(row["complete"]) == one["complete"]
        assert row["baseline_heldout_nrmse"] == one["gap"]["baseline_heldout_nrmse"]
        assert row["remaining_heldout_nrmse"] == one["gap"]["remaining_heldout_nrmse"]
        top = one["ranking"][0]
        assert row["shrink"] == top["shrink"] and row["evidence"] == top["evidence"]
        assert 0 < row["shrink_low"] <= row["shrink"] <= row["shrink_high"]
        for p in one["baseline_params"]:
            assert row[p["name"]] == p["value"], p["name"]


def test_a_calibration_fleet_reads_plausible_ranges_from_a_toml_file(tmp_path):
    d = _fleet_dir(tmp_path)
    ranges = tmp_path / "bench.toml"
    ranges.write_text('preset = "trum60a"\n\n[plausible]\nspeed_rpm = [0, 20000]\n')
    files = [d / "m01.csv", d / "m03.csv", d / "missing.csv"]
    # no client and no running cluster: threads of this process
    df = trum.calibrate_fleet(RING, files, plausible=ranges)
    assert list(df["status"]) == ["ok", "ok", "error"]
    assert "measurement file" in df.iloc[2]["error"] and "does not exist" in df.iloc[2]["error"]
    assert list(df.columns[4:7]) == list(trum.CALIBRATE_FLEET_COLUMNS)
    for i in range(2):
        one = trum.calibrate(RING, files[i], plausible=ranges)
        row = df.iloc[i]
        assert row["chi2_per_reading"] == one.chi2_per_reading and row["rows"] == one.n_rows
        for p in one.params:
            assert row[p["name"]] == p["value"] and row["std_error." + p["name"]] == p["std_error"]
    # the default range refuses the file that the TOML file's range accepts
    df = trum.calibrate_fleet(RING, files[:2])
    assert list(df["status"]) == ["ok", "error"]


def test_a_plausible_table_with_a_bad_key_names_file_line_and_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('preset = "trum60a"\n\n[plausible]\nspeedrpm = [0, 20000]\n')
    with pytest.raises(trum.InputError, match=r"bad.toml: line 4, key 'plausible.speedrpm': unknown key `speedrpm`"):
        trum.diagnose(RING, DATA, plausible=bad)
    bad.write_text('preset = "trum60a"\n\n[plausible]\nspeed_rpm = [2e4, 0]\n')
    with pytest.raises(trum.InputError, match=r"line 4, key 'plausible.speed_rpm': the low end 20000 is above"):
        trum.calibrate(RING, DATA, plausible=bad)
    with pytest.raises(trum.InputError, match="no file matches"):
        trum.diagnose_fleet(RING, str(tmp_path / "*.tsv"))
