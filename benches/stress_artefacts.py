#!/usr/bin/env python3
"""Bench artefacts that neither half of the blind benchmark simulates, and what the
diagnosis makes of them (docs/DIAGNOSIS.md, "Bench-artefact stress set").

Each case is a `trum synth` file of the frozen reference motor (tests/data/motors/ring60.toml,
every parameter perturbed as in the blind benchmark) that this script then alters as a
bench would: gains of the speed, torque, power, feedback, current or voltage readings, a
zero offset of the preload reading, read-back noise of the preload or the frequency, a quantised torque, an offset or a lag of the temperature sensor,
heavy-tailed speed noise, cells left empty, noise three times the nominal, noise that is
all absolute or all relative, noise correlated within runs; and the logging and slow
changes of the instruments (`LOGGING`): every row logged twice, rows out of order,
readings carried over from the previous row or lagging it, gains that drift over a run or
switch range halfway, a power or frequency offset, a stator still warm at switch-on,
speeds quantised to 2 rpm, efficiencies rounded to two decimals. Null cases
must come out `none`; effect cases (each effect at about twice its typical strength in
its first truth form, with two artefacts drawn at random and the development half's own,
or under noise correlated within runs) should name the effect. The cases are a development set: the diagnosis was changed after
they were first run.

    cargo build --release -p trum-cli
    python3 benches/stress_artefacts.py            # every case, two at a time
    python3 benches/stress_artefacts.py null_      # the cases whose name contains null_
    TRUM=path/to/trum python3 benches/stress_artefacts.py

Prints one line per case (verdict, complete, confounded set, the baseline's held-out NRMSE,
the three strongest candidates) and the counts. The work files (each case's CSV and JSON)
go to a temporary folder, or to the folder named by STRESS_KEEP, which is kept.
"""

import contextlib
import csv
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TRUM = os.environ.get("TRUM", os.path.join(ROOT, "target", "release", "trum"))
MOTOR = os.path.join(ROOT, "tests", "data", "motors", "ring60.toml")
DEV_ARTEFACTS = "readback_rel=0.004,speed_std_floor_rpm=0.3,outlier_fraction=0.01"


def scale(column, factor):
    return lambda rows, rng: alter(rows, column, lambda v: v * factor)


def jitter(column, rel):
    return lambda rows, rng: alter(rows, column, lambda v: v * (1.0 + rel * rng.gauss(0.0, 1.0)))


def alter(rows, column, fn):
    for row in rows:
        if row.get(column, "") != "":
            row[column] = repr(fn(float(row[column])))


def quantised(column, step):
    return lambda rows, rng: alter(rows, column, lambda v: round(v / step) * step)


def offset(column, delta):
    return lambda rows, rng: alter(rows, column, lambda v: v + delta)


def heavy_tail(rows, rng):
    # Student-t noise with 3 degrees of freedom, 0.7 rpm scale, added to the speed
    def noisy(v):
        t = rng.gauss(0.0, 1.0) / math.sqrt(max(1e-3, rng.gammavariate(1.5, 1.0 / 1.5)))
        return max(0.0, v + 0.7 * t)

    alter(rows, "speed_rpm", noisy)


def missing(rows, rng):
    for row in rows:
        for column in ("input_power_w", "current_a", "feedback_v", "efficiency"):
            if column in row and rng.random() < 0.15:
                row[column] = ""


ARTEFACTS = {
    "speed_gain": scale("speed_rpm", 1.03),
    "torque_gain": scale("torque_nm", 1.04),
    "power_gain": scale("input_power_w", 1.05),
    "feedback_gain": scale("feedback_v", 0.95),
    "preload_readback": jitter("preload_n", 0.01),
    "freq_readback": jitter("frequency_hz", 0.0003),
    "torque_quant": quantised("torque_nm", 0.01),
    "temp_offset": offset("temperature_c", 1.5),
    "heavy_tail": heavy_tail,
    "missing": missing,
}

# Artefacts of the preload, current and voltage readings, added after the set above was
# first run and kept apart from it, so that the effect cases' random draws of two artefacts
# stay as they were: the preload load cell's zero 10 N high, a current probe 5 % high, the
# drive voltage read 3 % high.
READINGS = {
    "preload_offset": offset("preload_n", 10.0),
    "current_gain": scale("current_a", 1.05),
    "voltage_gain": scale("voltage_v", 1.03),
}


def sensor_lag(tau_s):
    """A first-order temperature sensor with time constant `tau_s` [s], run within each run
    over the recorded temperatures in time order, each interval taken as a straight line
    (the exact response to a first-order hold): the sensor starts at the first reading."""

    def apply(rows, rng):
        runs = {}
        for row in rows:
            if row.get("temperature_c", "") != "" and row.get("elapsed_s", "") != "":
                runs.setdefault(row.get("run_id", ""), []).append(row)
        for run in runs.values():
            run.sort(key=lambda r: float(r["elapsed_s"]))
            t0, x0 = float(run[0]["elapsed_s"]), float(run[0]["temperature_c"])
            y = x0
            for row in run[1:]:
                t, x = float(row["elapsed_s"]), float(row["temperature_c"])
                dt = t - t0
                if dt > 0:
                    m = (x - x0) / dt
                    y = x - tau_s * m + (y - x0 + tau_s * m) * math.exp(-dt / tau_s)
                t0, x0 = t, x
                row["temperature_c"] = repr(y)

    return apply


def noise_shape(levels):
    """Gaussian noise of another shape than the simulator's (an absolute floor plus a
    relative part): `levels` maps a column to its (absolute, relative) standard deviation.
    Applied to readings synthesised without noise (`--noise 0`)."""

    def apply(rows, rng):
        for column, (a, r) in levels.items():
            bounded = column not in ("temperature_c",)
            top = 1.0 if column == "efficiency" else math.inf

            def noisy(v):
                x = v + rng.gauss(0.0, a + r * abs(v))
                return min(top, max(0.0, x)) if bounded else x

            alter(rows, column, noisy)

    return apply


def correlated_noise(phi, scale=1.0):
    """Gaussian noise of the simulator's default levels (an absolute floor plus a relative
    part, `DEFAULT_LEVELS`) that is serially correlated within each run, in row order: a
    first-order autoregression with coefficient `phi` and the same marginal standard
    deviation (at 0.95 mostly a random offset per run, as where a run's mounting or layer
    state differs from the next one's), times `scale`. Applied to readings synthesised
    without noise."""

    def apply(rows, rng):
        runs = by_run(rows)
        for column, (a, r) in DEFAULT_LEVELS.items():
            top = 1.0 if column == "efficiency" else math.inf
            for run in runs.values():
                e = rng.gauss(0.0, 1.0)
                for row in run:
                    if row.get(column, "") == "":
                        continue
                    v = float(row[column])
                    e = phi * e + math.sqrt(1.0 - phi * phi) * rng.gauss(0.0, 1.0)
                    row[column] = repr(min(top, max(0.0, v + scale * (a + r * abs(v)) * e)))

    return apply


# the diagnosis' default noise levels (docs/DIAGNOSIS.md, "Noise levels from the data")
DEFAULT_LEVELS = {"speed_rpm": (0.5, 0.01), "input_power_w": (0.05, 0.02), "current_a": (0.002, 0.015),
                  "efficiency": (0.005, 0.03), "feedback_v": (0.2, 0.01)}

# every reading's noise absolute (a bench whose instruments have a fixed resolution), or
# relative (gains of the instruments' ranges), where the simulator and the diagnosis's
# default levels have both parts
ABSOLUTE = {"speed_rpm": (1.2, 0.0), "input_power_w": (0.08, 0.0), "current_a": (0.0015, 0.0),
            "efficiency": (0.006, 0.0), "feedback_v": (0.4, 0.0), "temperature_c": (0.1, 0.0),
            "speed_std_rpm": (0.1, 0.0)}
RELATIVE = {"speed_rpm": (0.0, 0.012), "input_power_w": (0.0, 0.015), "current_a": (0.0, 0.012),
            "efficiency": (0.0, 0.03), "feedback_v": (0.0, 0.008), "temperature_c": (0.1, 0.0),
            "speed_std_rpm": (0.0, 0.1)}

# artefacts of their own cases only (the effect cases of every effect draw theirs from
# ARTEFACTS)
NULL_ONLY = {"temp_lag": sensor_lag(30.0), "abs_noise": noise_shape(ABSOLUTE), "rel_noise": noise_shape(RELATIVE),
             "ar_0.8": correlated_noise(0.8), "ar_0.95": correlated_noise(0.95),
             "ar_0.95_low": correlated_noise(0.95, 0.6)}


def by_run(rows):
    """The rows of each run (by `run_id`), in file order."""
    runs = {}
    for row in rows:
        runs.setdefault(row.get("run_id", ""), []).append(row)
    return runs


# the reference motor's thermal time constant C/(h·A) [s] (tests/data/motors/ring60.toml)
THERMAL_TAU_S = 150.0 / (10.0 * 0.02366)


def warm_start(excess_k):
    """A stator still `excess_k` warmer than ambient at switch-on (the previous run's heat),
    decaying with the motor's thermal time constant: the readings of a motor that was not
    left to cool."""

    def apply(rows, rng):
        for row in rows:
            if row.get("temperature_c", "") != "" and row.get("elapsed_s", "") != "":
                t = float(row["elapsed_s"])
                row["temperature_c"] = repr(float(row["temperature_c"]) + excess_k * math.exp(-t / THERMAL_TAU_S))

    return apply


def drift(column, rel):
    """A reading whose gain drifts linearly by `rel` over each run, in row order."""

    def apply(rows, rng):
        for run in by_run(rows).values():
            n = max(1, len(run) - 1)
            for i, row in enumerate(run):
                if row.get(column, "") != "":
                    row[column] = repr(float(row[column]) * (1.0 + rel * i / n))

    return apply


def successive_readings(rows, column):
    """(previous, current) pairs of the rows that have a reading of `column`, run by run in
    row order."""
    for run in by_run(rows).values():
        present = [row for row in run if row.get(column, "") != ""]
        yield from zip(present, present[1:])


def lagged(column, share):
    """A slow instrument: each reading carries `share` of the previous row's true value."""

    def apply(rows, rng):
        # last pair first, so that each previous reading is still the true one
        for prev, row in reversed(list(successive_readings(rows, column))):
            row[column] = repr((1.0 - share) * float(row[column]) + share * float(prev[column]))

    return apply


def stale(column, share):
    """An instrument polled faster than it updates: a `share` of rows carries the previous
    row's reading of `column` (as logged, so a value can be carried over several rows)."""

    def apply(rows, rng):
        for prev, row in successive_readings(rows, column):
            if rng.random() < share:
                row[column] = prev[column]

    return apply


def range_switch(column, gain):
    """An instrument that switches range halfway through each run, the second range's gain
    off by `gain`."""

    def apply(rows, rng):
        for run in by_run(rows).values():
            for i, row in enumerate(run):
                if i >= len(run) // 2 and row.get(column, "") != "":
                    row[column] = repr(float(row[column]) * gain)

    return apply


def logged_twice(rows, rng):
    """Every row written twice by the logger."""
    rows[:] = [copy for row in rows for copy in (row, dict(row))]


def shuffled(rows, rng):
    """Rows written in another order than they were measured."""
    rng.shuffle(rows)


# Artefacts of the logging and of slow changes of the instruments, added after every set
# above and kept apart with seeds of their own; each is a null case on two campaigns, and
# each effect case draws two of them. The rows logged twice led to dropping rows that repeat
# an earlier row (crate::observations); the others changed nothing.
LOGGING = {
    "warm_start_5K": warm_start(5.0),
    "voltage_drift": drift("voltage_v", 0.01),
    "speed_gain_drift": drift("speed_rpm", 0.02),
    "preload_drift": drift("preload_n", 0.03),
    "torque_lag": lagged("torque_nm", 0.2),
    "speed_quant_2rpm": quantised("speed_rpm", 2.0),
    "freq_offset": offset("frequency_hz", 100.0),
    "logged_twice": logged_twice,
    "shuffled_rows": shuffled,
    "efficiency_2dp": lambda rows, rng: alter(rows, "efficiency", lambda v: round(v, 2)),
    "current_range_switch": range_switch("current_a", 1.02),
    "power_offset": offset("input_power_w", 0.3),
    "stale_power": stale("input_power_w", 0.3),
    "stale_speed": stale("speed_rpm", 0.2),
}
# Seven readings in ten of one instrument carried over, null cases of their own: they led
# to leaving stale readings out (diagnose::bench::drop_stale_readings).
STALE_70 = {f"stale_70_{c}": stale(c, 0.7) for c in ("input_power_w", "speed_rpm", "current_a", "temperature_c")}

EFFECTS = {
    "radial_friction": "radial_friction=2",
    "preload_stiffening": "preload_stiffening=0.1",
    "hertz_softening": "hertz_softening:beta_n_per_m3=2e18,preload_gain_per_n=0.008",
    "thermal_drift": "thermal_drift:stiffness_coefficient_per_k=-8e-4,friction_coefficient_per_k=-4e-3,"
    "damping_coefficient_per_k=4e-3",
    "voltage_sag": "voltage_sag=300",
    "eccentricity": "eccentricity=4e-5",
    "tangential_compliance": "tangential_compliance=2",
}


def cases():
    """(name, truth, artefacts, campaign, seed, effect argument, noise, synth extras)."""
    out = []
    seed = 7100
    for art in ARTEFACTS:
        for campaign in ("preload-torque", "combined"):
            seed += 1
            out.append((f"null_{art}_{campaign}", "none", [art], campaign, seed, None, 1, []))
    out.append(("null_noise3_preload-torque", "none", [], "preload-torque", 7201, None, 3, []))
    out.append(("null_noise3_combined", "none", [], "combined", 7202, None, 3, []))
    out.append(("null_freq_sweep_gain", "none", ["feedback_gain", "freq_readback"], "frequency-sweep", 7203, None, 1, []))
    out.append(("null_warm_up_temp_offset", "none", ["temp_offset"], "warm-up", 7204, None, 1, []))
    out.append(("null_warm_up_temp_lag", "none", ["temp_lag"], "warm-up", 7205, None, 1, []))
    out.append(("null_combined_temp_lag", "none", ["temp_lag"], "combined", 7206, None, 1, []))
    # noise of other shapes, on readings synthesised without noise
    seed = 7210
    for shape in ("abs_noise", "rel_noise"):
        for campaign in ("preload-torque", "combined"):
            seed += 1
            out.append((f"null_{shape}_{campaign}", "none", [shape], campaign, seed, None, 0, []))
        seed += 1
        out.append((f"tangential_compliance_{shape}", "tangential_compliance", [shape], "preload-torque", seed,
                    EFFECTS["tangential_compliance"], 0, []))
    seed = 7300
    for art in READINGS:
        for campaign in ("preload-torque", "combined"):
            seed += 1
            out.append((f"null_{art}_{campaign}", "none", [art], campaign, seed, None, 1, ["--artefacts", DEV_ARTEFACTS]))
    # the effects a reading's offset or gain could pass for: a stiffening with the preload
    # under a preload offset, a source impedance under a current gain
    for effect, art in (("preload_stiffening", "preload_offset"), ("voltage_sag", "current_gain"),
                        ("voltage_sag", "voltage_gain")):
        for campaign in ("preload-torque", "combined"):
            seed += 1
            out.append((f"{effect}_{art}_{campaign}", effect, [art], campaign, seed, EFFECTS[effect], 1,
                        ["--artefacts", DEV_ARTEFACTS]))
    # noise correlated within runs, on readings synthesised without noise (kept apart, with
    # seeds of their own, so the other cases keep their draws)
    seed = 7400
    for art in ("ar_0.8", "ar_0.95"):
        for campaign in ("preload-torque", "combined"):
            seed += 1
            out.append((f"null_{art}_{campaign}", "none", [art], campaign, seed, None, 0, []))
    for campaign in ("preload-torque", "combined"):
        for _ in range(3):
            seed += 1
            out.append((f"null_ar_0.95_low_{campaign}_{seed}", "none", ["ar_0.95_low"], campaign, seed, None, 0, []))
    # every effect under noise correlated within runs (mostly an offset per run): a gap
    # the runs' scatter could pass for, or hide
    seed = 7500
    for effect, arg in EFFECTS.items():
        for campaign in ("combined", "preload-torque"):
            seed += 1
            truth = "none" if (effect, campaign) == ("thermal_drift", "preload-torque") else effect
            out.append((f"{effect}_ar_0.95_{campaign}", truth, ["ar_0.95"], campaign, seed, arg, 0, []))
    # logging and slow instrument changes (LOGGING), with the development half's artefacts
    seed = 9100
    for art in LOGGING:
        for campaign in ("warm-up", "combined") if art == "warm_start_5K" else ("preload-torque", "combined"):
            seed += 1
            out.append((f"null_{art}_{campaign}", "none", [art], campaign, seed, None, 1, ["--artefacts", DEV_ARTEFACTS]))
    draw = random.Random(5)
    for effect, arg in EFFECTS.items():
        for campaign in ("combined", "preload-torque"):
            if (effect, campaign) == ("thermal_drift", "preload-torque"):
                continue
            seed += 1
            arts = draw.sample(sorted(a for a in LOGGING if a != "warm_start_5K"), 2)
            out.append((f"{effect}_logging_{campaign}", effect, arts, campaign, seed, arg, 1,
                        ["--artefacts", DEV_ARTEFACTS]))
    # most readings of one instrument carried over (an instrument that updates at a third
    # of the logging rate), null cases only
    seed = 9700
    for column in ("input_power_w", "speed_rpm", "current_a", "temperature_c"):
        for campaign in ("warm-up", "combined", "preload-torque"):
            seed += 1
            out.append((f"null_stale_70_{column}_{campaign}", "none", [f"stale_70_{column}"], campaign, seed, None, 1,
                        ["--artefacts", DEV_ARTEFACTS]))
    rng = random.Random(11)
    seed = 8100
    for effect, arg in EFFECTS.items():
        for campaign in ("combined", "preload-torque"):
            seed += 1
            arts = rng.sample(sorted(ARTEFACTS), 2)
            # (a preload-torque campaign has no time series: thermal_drift cannot act there)
            truth = "none" if (effect, campaign) == ("thermal_drift", "preload-torque") else effect
            out.append((f"{effect}_{campaign}", truth, arts, campaign, seed, arg, 1, ["--artefacts", DEV_ARTEFACTS]))
    return out


def run(case, work):
    name, truth, arts, campaign, seed, effect, noise, extra = case
    path = os.path.join(work, name + ".csv")
    cmd = [TRUM, "synth", "--motor", MOTOR, "--campaign", campaign, "--noise", str(noise), "--seed", str(seed)]
    cmd += ["-o", path] + extra + (["--effect", effect] if effect else [])
    subprocess.run(cmd, check=True, capture_output=True)
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    rng = random.Random(seed)
    for art in arts:
        {**ARTEFACTS, **NULL_ONLY, **READINGS, **LOGGING, **STALE_70}[art](rows, rng)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    out = os.path.join(work, name + ".json")
    t0 = time.time()
    done = subprocess.run([TRUM, "diagnose", "--motor", MOTOR, "--data", path, "--json", out, "-q"], capture_output=True, text=True)
    seconds = time.time() - t0
    if done.returncode != 0:
        return name, truth, arts, None, seconds, done.stderr.strip()
    with open(out) as f:
        return name, truth, arts, json.load(f), seconds, ""


def main():
    wanted = sys.argv[1:]
    todo = [c for c in cases() if not wanted or any(w in c[0] for w in wanted)]
    right = {"null": [0, 0], "effect": [0, 0]}
    keep = os.environ.get("STRESS_KEEP")
    if keep:
        os.makedirs(keep, exist_ok=True)
    with (contextlib.nullcontext(keep) if keep else tempfile.TemporaryDirectory()) as work, ThreadPoolExecutor(2) as pool:
        for name, truth, arts, d, seconds, err in pool.map(lambda c: run(c, work), todo):
            if d is None:
                print(f"{name}: diagnosis failed: {err}")
                continue
            kind = "null" if truth == "none" else "effect"
            ok = d["verdict"] == truth or truth in d["confounded_with"]
            right[kind][0] += ok
            right[kind][1] += 1
            top = ", ".join(f"{r['effect']} {r['evidence']:.0f}/{r['shrink']:.2f}" for r in d["ranking"][:3])
            print(
                f"{name} [{'+'.join(arts) or '-'}]: {d['verdict']} complete={d['complete']} "
                f"confounded={d['confounded_with']} base NRMSE {d['gap']['baseline_heldout_nrmse']:.3f} "
                f"| {top} | {seconds:.1f} s{'' if ok else '  <- miss'}",
                flush=True,
            )
    for kind, (ok, n) in right.items():
        if n:
            print(f"{kind} cases right: {ok} of {n}")


if __name__ == "__main__":
    main()
