#!/usr/bin/python3
"""Compares two trees of femb-solve outputs (results.h5, checkpoint.h5 and every .csv) file by file.

Usage: /usr/bin/python3 scripts/compare_runs.py BASE NEW [--tolerance 1e-12]

For each numeric dataset (HDF5) or column (CSV) it prints the largest difference relative to the
largest magnitude of that dataset in BASE; files and datasets that are byte-identical count as
identical. Exit 1 when a file is missing on one side, a shape differs, or a relative difference is
above the tolerance. The companion of a change that must keep every result: run the examples with
both builds (each run.sh takes FEMB_BIN), then compare the two output trees.
"""
import argparse
import csv
import os
import sys

import h5py
import numpy as np


def relative(a, b):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape:
        return float("inf")
    if a.size == 0:
        return 0.0
    scale = np.nanmax(np.abs(a)) if np.isfinite(a).any() else 0.0
    diff = np.abs(a - b)
    diff = diff[np.isfinite(diff)] if np.isfinite(a).all() == np.isfinite(b).all() else np.array([np.inf])
    worst = float(diff.max()) if diff.size else 0.0
    return worst / scale if scale > 0 else worst


def h5_datasets(path):
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fiu":
                out[name] = obj[()]
        f.visititems(visit)
    return out


def csv_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    columns = {}
    for i, name in enumerate(header):
        try:
            columns[name] = [float(r[i]) for r in body]
        except (ValueError, IndexError):
            continue
    return columns


def compare_file(base, new):
    with open(base, "rb") as a, open(new, "rb") as b:
        if a.read() == b.read():
            return 0.0, []
    read = h5_datasets if base.endswith(".h5") else csv_columns
    da, db = read(base), read(new)
    worst, notes = 0.0, []
    for name in sorted(set(da) | set(db)):
        if name not in da or name not in db:
            notes.append(f"{name}: only in {'new' if name in db else 'base'}")
            worst = float("inf")
            continue
        r = relative(da[name], db[name])
        if r > 0:
            notes.append(f"{name}: {r:.3g}")
        worst = max(worst, r)
    return worst, notes


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("base")
    parser.add_argument("new")
    parser.add_argument("--tolerance", type=float, default=1e-12)
    args = parser.parse_args()
    status, files, identical = 0, 0, 0
    for root, _, names in os.walk(args.base):
        for name in sorted(names):
            if not (name.endswith(".csv") or name in ("results.h5", "checkpoint.h5")):
                continue
            base = os.path.join(root, name)
            new = os.path.join(args.new, os.path.relpath(base, args.base))
            files += 1
            if not os.path.exists(new):
                print(f"{new}: missing")
                status = 1
                continue
            worst, notes = compare_file(base, new)
            if worst == 0.0 and not notes:
                identical += 1
                continue
            flag = "ABOVE" if worst > args.tolerance else "within"
            print(f"{os.path.relpath(base, args.base)}: largest relative difference {worst:.3g} ({flag} {args.tolerance:g})")
            for n in notes[:8]:
                print(f"    {n}")
            if worst > args.tolerance:
                status = 1
    print(f"{files} files compared: {identical} identical, {files - identical} differ")
    return status


if __name__ == "__main__":
    sys.exit(main())
