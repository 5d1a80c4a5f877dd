#!/usr/bin/env bash
# DEM8 Case 3 (penetration, 25 000 M1 grains + the steel ball, 56-triangle steel box,
# Hertz-Mindlin, dt 0.5 us; docs/dem8.md) against YADE 2023.02a -j1 running the same case
# (yade_dem8_impact.py: the benchmark script's engines and materials, the ball placed as in
# data/scenes/dem8_impact_laptop.toml) for the same STEPS steps (default 4000: the ball's first
# 2 ms in the bed), in the same script. Particle-steps count the 25 001 spheres. granoscope runs
# the laptop scene with contact = "yade" (one wall per triangle, as YADE's facets), 1 and 2
# threads, in the file's order and in spatial order ([solver] order = "spatial"), and LIGGGHTS
# 3.8 (liggghts_dem8_impact.py: `gran model hertz`, the same materials, the box as an STL; its
# Hertz damping is its own) when installed. The ball's height at the end is printed beside each
# (the same run: YADE and granoscope in the file's order agree to um). REPEAT=N: LIGGGHTS and
# granoscope N times in turn, the shortest times printed.
#   bench/solver/run_dem8_bench.sh [BUILD_DIR]   (needs yade, optionally liggghts, and ../shared/dem8)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
gs=$build/bin/granoscope
py=/usr/bin/python3
d8=$(cd "$root/../shared/dem8" 2>/dev/null && pwd) || { echo "needs ../shared/dem8"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }
steps=${STEPS:-4000}
sed -e "s#\"../../../shared/dem8/#\"$d8/#" -e 's/^contact = "merged".*/contact = "yade"/' \
  -e "s/^steps = .*/steps = $steps/" -e "s/^checkpoint_every = .*/checkpoint_every = 100000000/" \
  -e "s/^every = .*/every = 100000000/" "$root/data/scenes/dem8_impact_laptop.toml" > "$work/impact.toml"
# (and with the grains renumbered along a Morton curve, [solver] order = "spatial": the bed file
# lists them in random spatial order; the same physics, other round-off)
sed 's/^\[solver\]$/[solver]\norder = "spatial"/' "$work/impact.toml" > "$work/impact_spatial.toml"
if command -v liggghts > /dev/null; then
  "$py" "$here/liggghts_dem8_impact.py" "$d8/case3_penetration/25KParticles.txt" \
    "$d8/case3_penetration/walls.txt" 25000 -0.0455 5.202875166674672 "$steps" 1000 "$work/lig"
fi
# REPEAT rounds (default 1) of LIGGGHTS and the granoscope runs in turn, the shortest time of
# each printed (this VM's speed drifts by tens of per cent over minutes).
rounds=${REPEAT:-1}
for r in $(seq "$rounds"); do
  for t in 1 2; do
    "$gs" simulate "$work/impact.toml" --threads $t -q -o "$work/run$t" > "$work/gs$t.$r.txt"
    "$gs" simulate "$work/impact_spatial.toml" --threads $t -q -o "$work/runs$t" > "$work/gss$t.$r.txt"
  done
  if [ -d "$work/lig" ]; then (cd "$work/lig" && liggghts -in in.impact > "log.$r.txt" 2>&1); fi
done
yade -n -x -j1 "$here/yade_dem8_impact.py" "$d8/case3_penetration/25KParticles.txt" \
  "$d8/case3_penetration/walls.txt" 25000 -0.0455 5.202875166674672 "$($py -c "print($steps*5e-7)")" \
  "$work/yade_ball.csv" > "$work/yade.txt" 2>&1
"$py" - "$work" "$steps" <<'PY'
import csv, re, sys
work, steps = sys.argv[1], int(sys.argv[2])
n = 25001
yt = float(re.search(r"wall time ([0-9.]+)", open(work + "/yade.txt").read()).group(1))
yz = float(list(csv.DictReader(open(work + "/yade_ball.csv")))[-1]["z_m"])
rows = [("YADE 2023.02a -j1", yt, yz)]
import glob
logs = sorted(glob.glob(work + "/lig/log.*.txt"))
if logs:
    lt = min(float(re.findall(r"Loop time of ([0-9.e+-]+) on 1 procs for %d steps" % steps,
                              open(f).read())[-1]) for f in logs)
    lz = float(re.findall(r"^\s+%d\s+\d+\s+\S+\s+(\S+)\s*$" % (steps + 1), open(logs[-1]).read(), re.M)[-1])
    rows.append(("LIGGGHTS 3.8, 1 process", lt, lz))
for tag, name in (("", ""), ("s", ", spatial")):
    for t in (1, 2):
        s = min(float(re.search(r"steps of \d+ particles in ([0-9.]+) s", open(f).read()).group(1))
                for f in glob.glob("%s/gs%s%d.*.txt" % (work, tag, t)))
        h = "%s/run%s%d/history.csv" % (work, tag, t)
        z = float(list(csv.DictReader(open(h)))[-1]["p25000_z_m"])
        rows.append(("granoscope%s, %d thread%s" % (name, t, "s" if t > 1 else ""), s, z))
print("DEM8 Case 3, 25 000 grains + ball, %d steps of 0.5 us (LIGGGHTS and granoscope: best of %d):"
      % (steps, len(logs) or len(glob.glob(work + "/gs1.*.txt"))))
print("  %-35s %8s %16s %7s %14s" % ("run", "time s", "particle-steps/s", "ratio", "ball z (m)"))
base = n * steps / rows[0][1]
for name, t, z in rows:
    print("  %-35s %8.2f %16.3g %6.1fx %14.7f" % (name, t, n * steps / t, n * steps / t / base, z))
PY
