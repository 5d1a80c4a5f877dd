#!/usr/bin/python3
"""DEM8 Case 1: the discharge rate of a silo run (docs/dem8.md).

Reads a run's history (history.csv, or history.csv.partial while it runs) and prints when the
orifice opened, the particles above the orifice plane every 0.1 s from then (the benchmark's
output), and the discharge rate: the least-squares slope of the removed count against time from
`--skip` seconds after the opening to the end, with the fit's R^2 and the largest deviation of
N(t) from the line (in particles). The opening is the first history row after the last one in
which the lid (`--lid`, default "lid") carried a force: the lid holds the fill until it settles.

    dem8_silo_rate.py OUT_DIR [--total N] [--skip 0.05] [--lid lid]
"""
import argparse
import csv
import os
import sys


def fill_count(out):
    """The [fill] count of the run's scene: its copy beside the checkpoints while it runs, or the
    trajectory's metadata once it has ended."""
    text = None
    scene = os.path.join(out, "checkpoint-scene.toml")
    if os.path.exists(scene):
        text = open(scene).read()
    else:
        for name in ("trajectory.h5", "trajectory.h5.partial"):
            path = os.path.join(out, name)
            if os.path.exists(path):
                try:
                    import h5py
                    with h5py.File(path, "r") as f:
                        v = f["metadata"].attrs.get("scene.toml")
                        text = v.decode() if isinstance(v, bytes) else v
                except (ImportError, OSError, KeyError):
                    text = None
                break
    if not text:
        return None
    section = None
    for line in text.splitlines():
        line = line.split("#")[0].strip()
        if line.startswith("["):
            section = line.strip("[]").strip()
        elif section == "fill" and line.startswith("count") and "=" in line:
            return int(line.split("=")[1])
    return None


def fit_rate(xs, ys):
    """The least-squares line through the removed count ys against time xs (s): its slope (the
    discharge rate, particles/s), R^2 (nan when ys is constant) and the largest |N - fit|."""
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    sxy = sum((x - mx) * (y - my) for x, y in zip(xs, ys))
    slope = sxy / sxx
    icpt = my - slope * mx
    res = [y - (icpt + slope * x) for x, y in zip(xs, ys)]
    syy = sum((y - my) ** 2 for y in ys)
    r2 = 1 - sum(r * r for r in res) / syy if syy > 0 else float("nan")
    return slope, r2, max(map(abs, res))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="the run's output folder")
    ap.add_argument("--total", type=int, default=None,
                    help="particles filled (default: from the scene copy's [fill] count)")
    ap.add_argument("--skip", type=float, default=0.05, help="s after opening left out of the fit")
    ap.add_argument("--lid", default="lid", help="the lid wall's name")
    a = ap.parse_args()
    path = os.path.join(a.out, "history.csv")
    if not os.path.exists(path):
        path += ".partial"
    try:
        rows = list(csv.DictReader(open(path)))
    except OSError as e:
        sys.exit(f"error: {path}: cannot read ({e.strerror})")
    col = a.lid + "_fz_N"
    if not rows or col not in rows[0] or "removed" not in rows[0]:
        sys.exit(f"error: {path}: no '{col}' or 'removed' column ({a.lid})")
    t = [float(r["time_s"]) for r in rows]
    removed = [float(r["removed"]) for r in rows]
    lid = [float(r[col]) for r in rows]
    loaded = [i for i, f in enumerate(lid) if f != 0.0]
    if not loaded or loaded[-1] + 1 >= len(rows):
        sys.exit(f"error: {path}: the lid has not opened yet ({len(rows)} rows)")
    k0 = loaded[-1] + 1
    t0 = t[k0]
    total = a.total
    if total is None:
        total = fill_count(a.out)
    if total is None:
        sys.exit(f"error: {a.out}: no [fill] count found (give --total)")
    print(f"history: {path}, {len(rows)} rows; opened at t = {t0:.6f} s (step {rows[k0]['step']})")
    print("t since opening (s)   particles above the orifice")
    step = 0.1
    nxt = 0.0
    for i in range(k0, len(rows)):
        if t[i] - t0 >= nxt - 1e-9:
            print(f"  {t[i] - t0:8.4f}            {total - removed[i]:8.0f}")
            nxt += step
    sel = [i for i in range(k0, len(rows)) if t[i] - t0 >= a.skip]
    if len(sel) < 3:
        sys.exit(f"error: {path}: fewer than 3 rows after the first {a.skip} s")
    xs = [t[i] - t0 for i in sel]
    slope, r2, dev = fit_rate(xs, [removed[i] for i in sel])
    print(f"discharged {removed[-1]:.0f} of {total} in {t[-1] - t0:.4f} s")
    print(f"rate (fit over {xs[0]:.3f}..{xs[-1]:.3f} s after opening, {len(xs)} rows): "
          f"{slope:.1f} particles/s  R^2 = {r2:.6f}  max |N - fit| = {dev:.1f}")


if __name__ == "__main__":
    main()
