#!/usr/bin/env python3
"""The diagnosis on motors other than the blind benchmark's frozen one (docs/DIAGNOSIS.md,
"Other motors").

The blind benchmark synthesises every case from one motor (tests/data/motors/ring60.toml).
This script runs the same kind of case on three other motors — the `generic60` preset and
the effect-free motor files of the two paper presets, `trum60a` at 200 V, 43 kHz and
`trum60-qut` at its paper's 150 V, 42 kHz — each effect in its first truth form on a
preload-torque and a combined campaign, at about twice its typical strength (`--set
moderate`) or at ten to twenty times, the top of its range for some (`--set strong`), plus
two null cases a motor. Every case has the development half's bench artefacts (voltage
read back with ±0.4 % noise, a speed-stability floor of 0.3 rpm) and its own motor seed.
A `thermal_drift` on a preload-torque campaign (no time series) cannot act: `none` is
right there. The cases were used while the diagnosis was developed; they show how far it
carries to other motors, not a held-out score.

    cargo build --release -p trum-cli
    python3 benches/other_motors.py                       # both sets, every motor
    python3 benches/other_motors.py --set strong generic60
    python3 benches/other_motors.py --set moderate --campaigns frequency-sweep,warm-up,stability trum60a
    python3 benches/other_motors.py --set moderate --omit feedback_v,current_a,input_power_w trum60a
    TRUM=path/to/trum python3 benches/other_motors.py

`--campaigns` replaces the two campaign kinds (a `thermal_drift` on a campaign without a
time series cannot act: `none` is right there); `--omit` leaves columns out of every file,
as a poorer bench records fewer quantities.

Prints one line per case (verdict, complete, confounded set, the three strongest
candidates with evidence/shrink) and, per motor and set, the cases right (the verdict is
the effect, or the effect is in `confounded_with`). An effect case whose own candidate
reaches no evidence (½ΔBIC ≤ 5) is marked `weak`: its signal may be under the noise, and
it is counted apart. Work files go to a temporary folder, or to OTHER_MOTORS_KEEP.
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
    "generic60": ("generic60", []),
    "trum60a": (os.path.join(ROOT, "tests", "data", "motors", "trum60a_baseline.toml"), []),
    "trum60-qut": (
        os.path.join(ROOT, "tests", "data", "motors", "trum60-qut_baseline.toml"),
        ["--voltage-v", "150", "--frequency-hz", "42000"],
    ),
}
SETS = {
    "moderate": {
        "radial_friction": "radial_friction=2",
        "preload_stiffening": "preload_stiffening=0.1",
        "hertz_softening": "hertz_softening:beta_n_per_m3=2e18,preload_gain_per_n=0.008",
        "thermal_drift": "thermal_drift:stiffness_coefficient_per_k=-8e-4,friction_coefficient_per_k=-4e-3,damping_coefficient_per_k=4e-3",
        "voltage_sag": "voltage_sag=300",
        "eccentricity": "eccentricity=4e-5",
        "tangential_compliance": "tangential_compliance=2",
    },
    "strong": {
        "radial_friction": "radial_friction=3",
        "preload_stiffening": "preload_stiffening:stiffness_scale=1,modal_fraction=1",
        "hertz_softening": "hertz_softening:beta_n_per_m3=1e19,preload_gain_per_n=0.004",
        "thermal_drift": "thermal_drift:stiffness_coefficient_per_k=-4e-3,friction_coefficient_per_k=-1e-2,damping_coefficient_per_k=1e-2",
        "voltage_sag": "voltage_sag=1500",
        "eccentricity": "eccentricity=1e-4",
        "tangential_compliance": "tangential_compliance=8",
    },
}
CAMPAIGNS = ("preload-torque", "combined")
ARTEFACTS = "readback_rel=0.004,speed_std_floor_rpm=0.3"


def run_case(work, motor_name, set_name, effect, campaign, seed, omit=None):
    motor, drive = MOTORS[motor_name]
    base = os.path.join(work, f"{motor_name}_{set_name}_{effect}_{campaign}_{seed}")
    synth = [TRUM, "synth", "--motor", motor, "--campaign", campaign, "--noise", "1", "--seed", str(seed),
             "--motor-seed", str(seed), "--artefacts", ARTEFACTS, "-o", base + ".csv", *drive]
    if omit:
        synth += ["--omit", omit]
    if effect != "none":
        synth += ["--effect", SETS[set_name][effect]]
    r = subprocess.run(synth, capture_output=True, text=True)
    if r.returncode:
        return None, f"synth failed: {r.stderr.strip()[:300]}"
    r = subprocess.run([TRUM, "diagnose", "--motor", motor, "--data", base + ".csv", "--json", base + ".json", "-q"],
                       capture_output=True, text=True)
    if r.returncode:
        return None, f"diagnose failed: {r.stderr.strip()[:300]}"
    with open(base + ".json") as f:
        return json.load(f), None


def judge(d, effect, campaign):
    # (thermal_drift acts through a time series: the warm-up, alone or in the combined campaign)
    time_series = campaign in ("warm-up", "combined")
    truth = "none" if effect == "none" or (effect == "thermal_drift" and not time_series) else effect
    right = d["verdict"] == truth or truth in d["confounded_with"]
    own = [r for r in d["ranking"] if r["effect"] == truth]
    weak = truth != "none" and not right and (not own or own[0]["evidence"] <= 5.0)
    return truth, right, weak


def main():
    args = sys.argv[1:]
    sets = list(SETS)
    campaigns = CAMPAIGNS
    omit = None
    if "--set" in args:
        i = args.index("--set")
        sets = [args[i + 1]]
        del args[i:i + 2]
    if "--campaigns" in args:
        i = args.index("--campaigns")
        campaigns = tuple(args[i + 1].split(","))
        del args[i:i + 2]
    if "--omit" in args:
        i = args.index("--omit")
        omit = args[i + 1]
        del args[i:i + 2]
    motors = args or list(MOTORS)
    for m in motors:
        if m not in MOTORS:
            sys.exit(f"unknown motor {m!r}: one of {', '.join(MOTORS)}")
    for s in sets:
        if s not in SETS:
            sys.exit(f"unknown set {s!r}: one of {', '.join(SETS)}")
    keep = os.environ.get("OTHER_MOTORS_KEEP")
    work = keep or tempfile.mkdtemp(prefix="trum-other-motors-")
    os.makedirs(work, exist_ok=True)
    jobs = []
    for m in motors:
        for s in sets:
            seed = 400 if s == "moderate" else 500
            for k, e in enumerate(list(SETS[s]) + ["none", "none"]):
                for ci, c in enumerate(campaigns):
                    jobs.append((m, s, e, c, seed + len(campaigns) * k + ci))
    tally = {}
    with ThreadPoolExecutor(2) as ex:
        for (m, s, e, c, seed), (d, err) in zip(jobs, ex.map(lambda j: run_case(work, *j, omit=omit), jobs)):
            t = tally.setdefault((m, s), [0, 0, 0, 0, 0])  # effect right, effect cases, weak, null right, nulls
            if err:
                print(f"{m:<10} {s:<8} {e:<22} {c:<15} ERROR {err}", flush=True)
                continue
            truth, right, weak = judge(d, e, c)
            top = ", ".join(f"{r['effect']} {r['evidence']:.0f}/{r['shrink']:.2f}" for r in d["ranking"][:3])
            mark = "" if right else ("  <- weak" if weak else "  <- miss")
            print(f"{m:<10} {s:<8} {e:<22} {c:<15} -> {d['verdict']} complete={d['complete']} "
                  f"confounded={d['confounded_with']} | {top}{mark}", flush=True)
            if truth == "none":
                t[3] += right
                t[4] += 1
            elif weak:
                t[2] += 1
            else:
                t[0] += right
                t[1] += 1
    print()
    print("| motor | set | effect cases right | weak (own evidence ≤ 5, missed) | `none` where nothing can act |")
    print("|---|---|---|---|---|")
    for (m, s), t in tally.items():
        print(f"| {m} | {s} | {t[0]} of {t[1]} | {t[2]} | {t[3]} of {t[4]} |")
    if not keep:
        print(f"\n(work files in {work})")


if __name__ == "__main__":
    main()
