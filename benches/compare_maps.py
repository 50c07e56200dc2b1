"""Compare two `trum map` CSVs of the same grid: identical statuses, numbers within a
relative tolerance (default 1e-9; a column's values below 1e-12 of its largest magnitude
compare absolutely against that floor). Used to check that an optimisation of the solver
changes no status and no number beyond the tolerance:

    python benches/compare_maps.py OLD.csv NEW.csv [--rtol 1e-9]

Exit status 1 when they differ. Standard library only.
"""

import argparse
import csv
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--rtol", type=float, default=1e-9)
    a = ap.parse_args()
    with open(a.old) as f:
        old = list(csv.reader(f))
    with open(a.new) as f:
        new = list(csv.reader(f))
    if old[0] != new[0] or len(old) != len(new):
        print("different headers or row counts")
        return 1
    head = old[0]
    # status and the warnings after it are words, compared exactly
    st = head.index("warnings") if "warnings" in head else head.index("status")
    cols = range(st + 1, len(head))
    peak = [0.0] * len(head)
    for r in old[1:]:
        for j in cols:
            if r[j]:
                peak[j] = max(peak[j], abs(float(r[j])))
    bad_status, worst = 0, {}
    for ro, rn in zip(old[1:], new[1:]):
        if ro[:st + 1] != rn[:st + 1]:
            bad_status += 1
            if bad_status <= 10:
                print("status:", ",".join(ro[:st + 1]), "->", rn[st])
            continue
        for j in cols:
            if ro[j] == rn[j]:
                continue
            if not ro[j] or not rn[j]:
                worst[head[j]] = float("inf")
                continue
            x, y = float(ro[j]), float(rn[j])
            e = abs(x - y) / max(abs(x), 1e-12 * peak[j], 1e-300)
            worst[head[j]] = max(worst.get(head[j], 0.0), e)
    over = {k: v for k, v in worst.items() if v > a.rtol}
    print(f"{len(old) - 1} rows, {bad_status} status changes, largest relative differences:",
          ", ".join(f"{k} {v:.1e}" for k, v in sorted(worst.items(), key=lambda kv: -kv[1])[:4]) or "none")
    return 1 if bad_status or over else 0


if __name__ == "__main__":
    sys.exit(main())
