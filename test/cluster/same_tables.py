#!/usr/bin/env python3
"""Checks that two `ofv compare` output folders hold the same results.

Usage: same_tables.py REFERENCE OTHER

Compares episodes.csv, summary.csv and the data of the plots (plots/*.csv)
cell by cell. Wall-clock timings differ from run to run and are left out:
columns ending in `_ms` (and `_ms_ci95`), the trajectory columns render_s,
perception_s, estimate_s and control_s, and the charts of those timings
(plots/mean_estimate_ms.csv, plots/mean_step_ms.csv, ...). Exit 0 when the
same, 1 with the first differences on stderr.
"""
import csv
import pathlib
import sys

TIMINGS = {"render_s", "perception_s", "estimate_s", "control_s"}


def timing(column):
    return column in TIMINGS or column.endswith("_ms") or column.endswith("_ms_ci95")


def table(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return [], []
    keep = [i for i, c in enumerate(rows[0]) if not timing(c)]
    return [rows[0][i] for i in keep], [[r[i] for i in keep] for r in rows[1:]]


def main(reference, other):
    reference, other = pathlib.Path(reference), pathlib.Path(other)
    names = ["episodes.csv", "summary.csv"]
    plots = sorted(p.name for p in (reference / "plots").glob("*.csv") if not timing(p.stem))
    names += ["plots/" + p for p in plots]
    problems = []
    if len(plots) == 0:
        problems.append(f"{reference}/plots: no plot data")
    for name in names:
        a, b = reference / name, other / name
        if not b.exists():
            problems.append(f"{b}: missing")
            continue
        (ha, ra), (hb, rb) = table(a), table(b)
        if ha != hb:
            problems.append(f"{name}: columns {ha} vs {hb}")
        elif len(ra) != len(rb):
            problems.append(f"{name}: {len(ra)} rows vs {len(rb)}")
        else:
            for k, (x, y) in enumerate(zip(ra, rb)):
                if x != y:
                    diff = [f"{c}: {u} vs {v}" for c, u, v in zip(ha, x, y) if u != v]
                    problems.append(f"{name} row {k + 1}: " + "; ".join(diff[:4]))
                    break
    extra = sorted(p.name for p in (other / "plots").glob("*.csv") if not timing(p.stem) and p.name not in plots)
    if extra:
        problems.append(f"{other}/plots: data not in the reference: {extra}")
    if (other / "missing.csv").exists():
        problems.append(f"{other}/missing.csv: episodes missing")
    for p in problems:
        print("same_tables: " + p, file=sys.stderr)
    if not problems:
        print(f"same_tables: {other} = {reference} ({len(names)} tables, timings left out)")
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
