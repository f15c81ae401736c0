#!/usr/bin/env python3
"""Compares the history.csv of every run directory in A with the one of the same name in B.

Usage: bench/compare_histories.py A B

Prints, per run, the number of rows and the largest difference of any column present in both
(the wall-time columns time_* aside), absolute and relative to the column's largest value.
Identical histories print 0. Exit code 1 when a run's row counts differ.
"""
import csv
import os
import sys


def main(a, b):
    status = 0
    for name in sorted(os.listdir(a)):
        pa, pb = os.path.join(a, name, "history.csv"), os.path.join(b, name, "history.csv")
        if not (os.path.exists(pa) and os.path.exists(pb)):
            continue
        ra, rb = list(csv.DictReader(open(pa))), list(csv.DictReader(open(pb)))
        if len(ra) != len(rb):
            print(f"{name}: {len(ra)} rows against {len(rb)}")
            status = 1
            continue
        worst = (0.0, 0.0, "")
        for col in ra[0]:
            if col.startswith("time_") or col not in rb[0]:
                continue
            xs = [float(r[col]) for r in ra]
            ys = [float(r[col]) for r in rb]
            size = max((abs(x) for x in xs), default=0.0)
            diff = max((abs(x - y) for x, y in zip(xs, ys) if x != y), default=0.0)
            rel = diff / size if size > 0 else diff
            if rel > worst[1]:
                worst = (diff, rel, col)
        print(f"{name}: {len(ra)} rows, largest difference {worst[0]:.3e} "
              f"({worst[1]:.3e} of the column's largest value) in {worst[2] or '-'}")
    return status


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
