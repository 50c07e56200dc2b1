"""Benchmark: N operating points through ``Motor.solve`` vs the Rust baseline
(``examples/bench_solve.rs``: the same points solved cold into quantity columns).

    python crates/trum-py/bench/bench_solve.py [N] [repeats]

Builds and runs the Rust example with cargo (release), then times ``Motor.solve`` serial
and parallel on the same inputs, interleaved with the Rust runs (best of ``repeats``) and prints the ratios. Target:
Python ≤ 1.2 × Rust.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import trum

ROOT = Path(__file__).resolve().parents[3]


def inputs(n: int):
    """The Rust example's points: preload 100-400 N × torque 0-0.3 N·m."""
    rows = max(min(1000, n), 1)
    cols = -(-n // rows)
    i = np.arange(n)
    r, c = (i // cols).astype(np.float64), (i % cols).astype(np.float64)
    preload = 100.0 + 300.0 * r / (max(rows, 2) - 1)
    torque = 0.3 * c / (max(cols, 2) - 1)
    return preload, torque


def rust(n: int, repeats: int) -> dict:
    cmd = ["cargo", "run", "-q", "--release", "-p", "trum-py", "--example", "bench_solve", "--", str(n), str(repeats)]
    out = subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, text=True, env=os.environ).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    m = trum.Motor("trum60a")
    preload, torque = inputs(n)
    best = {False: float("inf"), True: float("inf")}
    r = {"serial_s": float("inf"), "parallel_s": float("inf")}
    res = None
    for _ in range(repeats):  # interleaved, so a busy machine slows both sides alike
        for parallel in (False, True):
            t0 = time.perf_counter()
            res = m.solve(preload_n=preload, torque_nm=torque, voltage_v=200.0, frequency_hz=43e3, parallel=parallel)
            best[parallel] = min(best[parallel], time.perf_counter() - t0)
        one = rust(n, 1)
        r = {**one, "serial_s": min(r["serial_s"], one["serial_s"]), "parallel_s": min(r["parallel_s"], one["parallel_s"])}
    s = float(np.sum(res.speed_rpm))
    assert abs(s - r["speed_rpm_sum"]) <= 1e-9 * abs(s), (s, r["speed_rpm_sum"])
    print(f"points: {n}  (status: {res.counts()})")
    print(f"serial:   python {best[False]:.3f} s  rust {r['serial_s']:.3f} s  ratio {best[False] / r['serial_s']:.3f}")
    print(
        f"parallel: python {best[True]:.3f} s  rust {r['parallel_s']:.3f} s  ratio {best[True] / r['parallel_s']:.3f}"
        f"  ({r['threads']} threads)"
    )
    print(f"per point (python, parallel): {best[True] / n * 1e6:.2f} us")


if __name__ == "__main__":
    main()
