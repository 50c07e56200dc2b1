"""Benchmark: a diagnosis fleet on Dask, 1 → 2 worker processes (not part of the test suite).

    python crates/trum-py/bench/bench_fleet.py [files] [repeats] [--rayon]

Writes ``files`` measurement files (default 16) into a temporary directory: campaigns of
the ``trum60a`` design at nine preloads and three load torques (27 rows each), each motor
with its own small parameter spread and eccentricity, read with 1 % speed noise. Then
runs ``trum.diagnose_fleet`` on a ``LocalCluster`` of 1 and of 2 single-threaded worker
processes (cluster start-up not timed; best of ``repeats``), checks that both tables are
identical, and prints the wall times, files a second and the speed-up. On a machine with
two idle cores the ideal speed-up is 2; other work on the cores lowers it.

The workers run with ``RAYON_NUM_THREADS=1``: one diagnosis otherwise spreads its
candidate fits over every core with rayon, so that a single worker process already
keeps both cores busy and two processes oversubscribe them; one single-threaded process
per core is the fleet's layout (docs/PYTHON.md). ``--rayon`` leaves rayon's default, to
see what a file's own parallelism gives.
"""
from __future__ import annotations

import glob
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import trum


def write_fleet(directory: Path, n: int) -> None:
    rng = np.random.default_rng(2026)
    preload = np.repeat(np.linspace(150.0, 450.0, 9), 3)
    torque = np.tile([0.0, 0.05, 0.1], 9)
    nominal = trum.Motor("trum60a")
    for i in range(n):
        m = nominal.with_params({
            "stator.modal_damping_ns_per_m": nominal["stator.modal_damping_ns_per_m"] * (1 + 0.03 * rng.standard_normal()),
            "friction_layer.friction_coefficient": nominal["friction_layer.friction_coefficient"] * (1 + 0.03 * rng.standard_normal()),
        }).with_effects(f"eccentricity={rng.uniform(1e-5, 3e-5):.3e}")
        r = m.solve(preload_n=preload, torque_nm=torque, voltage_v=200.0, frequency_hz=43e3)
        speed = r.speed_rpm * (1 + 0.01 * rng.standard_normal(preload.size))
        lines = ["preload_n,voltage_v,frequency_hz,torque_nm,speed_rpm"]
        lines += [f"{p},200,43000,{t},{s:.3f}" for p, t, s in zip(preload, torque, speed)]
        (directory / f"motor{i:04d}.csv").write_text("\n".join(lines) + "\n")


def timed(files: str, workers: int, repeats: int, env: dict):
    from dask.distributed import Client, LocalCluster

    best, df = float("inf"), None
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None, env=env) as cluster, \
            Client(cluster) as client:
        first = sorted(glob.glob(files))[:1]
        client.run(lambda: __import__("trum"))  # every worker imports trum before the clock starts
        trum.diagnose_fleet("trum60a", first, client=client)
        for _ in range(repeats):
            t0 = time.perf_counter()
            df = trum.diagnose_fleet("trum60a", files, client=client)
            best = min(best, time.perf_counter() - t0)
    return best, df


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    env = {} if "--rayon" in sys.argv else {"RAYON_NUM_THREADS": "1"}
    n = int(args[0]) if args else 16
    repeats = int(args[1]) if len(args) > 1 else 2
    with tempfile.TemporaryDirectory() as tmp:
        write_fleet(Path(tmp), n)
        pattern = str(Path(tmp) / "*.csv")
        t1, df1 = timed(pattern, 1, repeats, env)
        t2, df2 = timed(pattern, 2, repeats, env)
    assert df1.equals(df2), "the table depends on the number of workers"
    ok = int((df1["status"] == "ok").sum())
    print(f"{n} files ({ok} diagnosed), 27 rows each; best of {repeats}; worker env {env or 'rayon default'}")
    print(f"1 worker : {t1:7.2f} s  {n / t1:6.2f} files/s")
    print(f"2 workers: {t2:7.2f} s  {n / t2:6.2f} files/s")
    print(f"speed-up : {t1 / t2:.2f}")
    print(df1["verdict"].value_counts().to_string())


if __name__ == "__main__":
    main()
