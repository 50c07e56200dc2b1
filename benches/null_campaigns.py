#!/usr/bin/env python3
"""Null campaigns of perturbed motors: how often the diagnosis names an effect where there
is none (docs/DIAGNOSIS.md, "The fits").

Every case is a campaign of a motor with no effect, its uncertain parameters perturbed
(`trum synth --perturbation`, 3 % by default) and the development half's bench artefacts
(voltage read back with ±0.4 % noise, a speed-stability floor of 0.3 rpm), diagnosed
against the motor's nominal file. Three sets:

  qut-pt     20 preload-torque campaigns of `trum60-qut` at its paper's 150 V, 42 kHz
             (seeds 7152 + 1000 s), whose stator runs near clamping
  four       80 campaigns: `ring60`, `trum60a`, `generic60`, `trum60-qut`, each on a
             preload-torque and a combined campaign, ten seeds each
  wide       40 campaigns of the same four motors perturbed by 6 %, five seeds each

    cargo build --release -p trum-cli
    python3 benches/null_campaigns.py              # every set
    python3 benches/null_campaigns.py qut-pt
    TRUM=path/to/trum python3 benches/null_campaigns.py

Prints every case whose verdict is not `none` (its three strongest candidates with
evidence/shrink) and the count per set. The cases were used while the baseline's search
for other valleys was developed: they are development material, not a held-out score.
"""

import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TRUM = os.environ.get("TRUM", os.path.join(ROOT, "target", "release", "trum"))
MOTORS = {
    "ring60": (os.path.join(ROOT, "tests", "data", "motors", "ring60.toml"), []),
    "generic60": ("generic60", []),
    "trum60a": (os.path.join(ROOT, "tests", "data", "motors", "trum60a_baseline.toml"), []),
    "trum60-qut": (
        os.path.join(ROOT, "tests", "data", "motors", "trum60-qut_baseline.toml"),
        ["--voltage-v", "150", "--frequency-hz", "42000"],
    ),
}
ARTEFACTS = "readback_rel=0.004,speed_std_floor_rpm=0.3"
CAMPAIGNS = ("preload-torque", "combined")


def grid(motors, base, seeds, perturbation, campaigns=CAMPAIGNS):
    """(motor, campaign, seed, perturbation) for every motor, campaign and seed index."""
    return [
        (m, c, base + 17 * i + 5 * j + 1000 * s, perturbation)
        for s in range(seeds)
        for i, m in enumerate(motors)
        for j, c in enumerate(campaigns)
    ]


SETS = {
    "qut-pt": grid(["trum60-qut"], 7152, 20, 0.03, ("preload-torque",)),
    "four": grid(["ring60", "trum60a", "generic60", "trum60-qut"], 8400, 10, 0.03),
    "wide": grid(["ring60", "generic60", "trum60a", "trum60-qut"], 9300, 5, 0.06),
}


def run_case(work, case):
    motor_name, campaign, seed, perturbation = case
    motor, drive = MOTORS[motor_name]
    path = os.path.join(work, f"{motor_name}_{campaign}_{seed}_{perturbation}.csv")
    synth = [TRUM, "synth", "--motor", motor, "--campaign", campaign, "--noise", "1", "--seed", str(seed),
             "--perturbation", str(perturbation), "--artefacts", ARTEFACTS, "-o", path, *drive]
    subprocess.run(synth, check=True, capture_output=True)
    out = path + ".json"
    d = subprocess.run([TRUM, "diagnose", "--motor", motor, "--data", path, "--json", out, "-q"],
                       capture_output=True, text=True)
    if d.returncode:
        return case, None, d.stderr.strip()
    with open(out) as f:
        return case, json.load(f), ""


def main():
    names = sys.argv[1:] or list(SETS)
    unknown = [n for n in names if n not in SETS]
    if unknown:
        sys.exit(f"unknown set(s) {', '.join(unknown)}; the sets are {', '.join(SETS)}")
    with tempfile.TemporaryDirectory() as work, ThreadPoolExecutor(2) as pool:
        for name in names:
            named = 0
            for case, d, err in pool.map(lambda c: run_case(work, c), SETS[name]):
                if d is None:
                    print(name, case, "FAILED:", err[:200])
                    named += 1
                    continue
                if d["verdict"] != "none":
                    named += 1
                    top = ", ".join(f"{r['effect']} {r['evidence']:.0f}/{r['shrink']:.2f}" for r in d["ranking"][:3])
                    print(name, case, "->", d["verdict"], "|", top)
            print(f"{name}: {named} of {len(SETS[name])} null campaigns not `none`")


if __name__ == "__main__":
    main()
