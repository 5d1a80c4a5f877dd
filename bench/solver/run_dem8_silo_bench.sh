#!/usr/bin/env bash
# DEM8 Case 1 (silo discharge, M1, large orifice; docs/dem8.md): speed against YADE 2023.02a -j1
# running the benchmark script's engines (yade_dem8_silo.py) on the same spheres for the same
# STEPS steps (default 2000, dt 1.5 us), in the same script. The spheres are a frame of a
# granoscope run of data/scenes/dem8_silo_laptop.toml (RUN_DIR; default its last frame, FRAME),
# started at rest with the orifice open: both codes run the same discharging silo. granoscope
# runs it with 1 and 2 threads (contact = "yade": one wall per triangle, as YADE's facets), and
# LIGGGHTS 3.8 (liggghts_dem8_silo.py: `gran model hertz`, the same materials, the silo as an
# STL, the same Verlet skin as the scene's, 0.4 mm; its Hertz damping is its own) when installed.
# Particle-steps count the spheres at the start; "live" ones the spheres present, summed over the
# steps from the counts every 500 steps (LIGGGHTS and granoscope), which differ once the silo
# discharges (a long STEPS). ORIFICE=small: the small-orifice silo instead (RUN_DIR a run of
# data/scenes/dem8_silo_small_laptop.toml). YADE=0: no YADE run (ratios against LIGGGHTS; YADE
# takes ~40 ms a step here, so a flowing discharge of tens of thousands of steps is hours).
#   bench/solver/run_dem8_silo_bench.sh RUN_DIR [BUILD_DIR]   (needs ../shared/dem8; yade unless YADE=0)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
run=${1:?usage: run_dem8_silo_bench.sh RUN_DIR [BUILD_DIR]}
build=${2:-$root/build}
gs=$build/bin/granoscope
py=/usr/bin/python3
d8=$(cd "$root/../shared/dem8" 2>/dev/null && pwd) || { echo "needs ../shared/dem8"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }
steps=${STEPS:-2000}
. "$here/dem8_silo_orifice.sh"
traj=$run/trajectory.h5
[ -f "$traj" ] || traj=$run/trajectory.h5.partial
"$gs" convert "$traj" "$work/frame.csv" --frame "${FRAME:--1}" > /dev/null
n=$("$py" "$here/dem8_silo_frame_scene.py" "$root/data/scenes/$scene.toml" "$work" "$d8" "$steps" \
  --contact yade)
for t in 1 2; do
  "$gs" simulate "$work/silo.toml" --threads $t -q -o "$work/run$t" > "$work/gs$t.txt"
done
if command -v liggghts > /dev/null; then
  "$py" "$here/liggghts_dem8_silo.py" "$work/packing.csv" "$walls" "$z_orifice" "$steps" 500 \
    "$work/lig"
  (cd "$work/lig" && liggghts -in in.silo > log.txt 2>&1)
fi
if [ "${YADE:-1}" != 0 ]; then
  yade -n -x -j1 "$here/yade_dem8_silo.py" "$work/packing.csv" "$walls" "$z_orifice" M1 "$steps" \
    > "$work/yade.txt" 2>&1
fi
"$py" - "$work" "$steps" "$n" "${ORIFICE:-large}" <<'PY'
import csv, os, re, sys
work, steps, n, orifice = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
def live(counts):  # {step: spheres present after it} -> particle-steps over the run's steps
    s = sorted(counts)
    return sum((counts[a] + counts[b]) / 2 * (b - a) for a, b in zip(s, s[1:]))
rows = []  # (name, seconds, removed, live particle-steps or None)
if os.path.exists(work + "/yade.txt"):
    y = open(work + "/yade.txt").read()
    yt = float(re.search(r"wall time ([0-9.]+)", y).group(1))
    ye = int(re.search(r"erased (\d+)", y).group(1))
    rows.append(("YADE 2023.02a -j1", yt, ye, None))
if os.path.exists(work + "/lig/log.txt"):
    log = open(work + "/lig/log.txt").read()
    lt = float(re.findall(r"Loop time of ([0-9.e+-]+) on 1 procs for %d steps" % steps, log)[-1])
    # (the second run's counts: at its first step, 1, at the multiples of 500, and at steps + 1)
    c = {int(m.group(1)) - 1: int(m.group(2)) for m in
         re.finditer(r"^\s+(\d+)\s+(\d+)\s+\S+\s*$", log.split("run %d" % steps)[-1], re.M)}
    c = {k: v for k, v in c.items() if 0 <= k <= steps}
    rows.append(("LIGGGHTS 3.8, 1 process", lt, n - c[steps], live(c)))
for t in (1, 2):
    out = open("%s/gs%d.txt" % (work, t)).read()
    s = float(re.search(r"steps of \d+ particles in ([0-9.]+) s", out).group(1))
    h = list(csv.DictReader(open("%s/run%d/history.csv" % (work, t))))
    c = {0: n}
    c.update({int(r["step"]): n - round(float(r["removed"])) for r in h})
    rows.append(("granoscope, %d thread%s" % (t, "s" if t > 1 else ""), s, n - c[steps], live(c)))
print("DEM8 Case 1 (%s orifice, M1), %d spheres from rest, %d steps of 1.5 us:" % (orifice, n, steps))
print("  %-26s %8s %16s %7s %8s %14s %7s" % ("run", "time s", "particle-steps/s", "ratio", "removed",
                                              "live p-steps/s", "ratio"))
base = n * steps / rows[0][1]
base_live = rows[0][3] / rows[0][1] if rows[0][3] else None
for name, t, e, lv in rows:
    extra = ""
    if lv is not None:
        extra = " %14.3g" % (lv / t) + (" %6.2fx" % (lv / t / base_live) if base_live else "")
    print("  %-26s %8.2f %16.3g %6.1fx %8d%s" % (name, t, n * steps / t, n * steps / t / base, e, extra))
PY
