#!/usr/bin/env bash
# DEM8 Case 2 (rotating drum: 30 000 M1 grains of r = 1 mm and 8 000 M2 of r = 2 mm in the
# 1 200-triangle steel drum turning at 2 rad/s, Hertz-Mindlin, dt 0.8 us; docs/dem8.md) against
# YADE 2023.02a -j1 running the benchmark script's engines (yade_dem8_drum.py, its own Verlet
# distance 0.1 mm) for the same STEPS steps (default 2000) from the benchmark's bed, in the same
# script. Particle-steps count the 38 000 grains. granoscope runs data/scenes/dem8_drum_laptop.toml
# (order = "spatial": the grains renumbered along a Morton curve) with contact = "yade" (one wall
# per triangle, as YADE's facets; its default skin, half the smallest radius), 1 and 2 threads;
# LIGGGHTS 3.8 (liggghts_dem8_drum.py: `gran model hertz`, the same materials and pair table, the
# drum as an STL turned by `fix move/mesh`, granoscope's skin; its Hertz damping is its own) when
# installed. REPEAT=N: LIGGGHTS and granoscope N times in turn, the shortest times printed.
#   bench/solver/run_dem8_drum_bench.sh [BUILD_DIR]   (needs yade, optionally liggghts, and ../shared/dem8)
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
steps=${STEPS:-2000}
sed -e "s#\"../../../shared/dem8/#\"$d8/#" -e 's/^contact = "merged".*/contact = "yade"/' \
  -e "s/^steps = .*/steps = $steps/" -e "s/^checkpoint_every = .*/checkpoint_every = 100000000/" \
  -e "s/^every = .*/every = 100000000/" -e "s/^history_every = .*/history_every = $steps/" \
  "$root/data/scenes/dem8_drum_laptop.toml" > "$work/drum.toml"
if command -v liggghts > /dev/null; then
  "$py" "$here/liggghts_dem8_drum.py" "$d8/case2_drum/PartCoordinates.txt" \
    "$d8/case2_drum/walls.txt" 0.0005 "$steps" "$work/lig"
fi
# REPEAT rounds (default 1) of LIGGGHTS and the granoscope runs in turn, the shortest time of
# each printed (this VM's speed drifts by tens of per cent over minutes).
rounds=${REPEAT:-1}
for r in $(seq "$rounds"); do
  for t in 1 2; do
    "$gs" simulate "$work/drum.toml" --threads $t -q -o "$work/run$t" > "$work/gs$t.$r.txt"
  done
  if [ -d "$work/lig" ]; then (cd "$work/lig" && liggghts -in in.drum > "log.$r.txt" 2>&1); fi
done
yade -n -x -j1 "$here/yade_dem8_drum.py" "$d8/case2_drum/PartCoordinates.txt" \
  "$d8/case2_drum/walls.txt" "$steps" > "$work/yade.txt" 2>&1
"$py" - "$work" "$steps" <<'PY'
import os, re, sys
work, steps = sys.argv[1], int(sys.argv[2])
n = 38000
rows = [("YADE 2023.02a -j1", float(re.search(r"wall time ([0-9.]+)", open(work + "/yade.txt").read()).group(1)))]
import glob
logs = sorted(glob.glob(work + "/lig/log.*.txt"))
if logs:
    rows.append(("LIGGGHTS 3.8, 1 process",
                 min(float(re.findall(r"Loop time of ([0-9.e+-]+) on 1 procs for %d steps" % steps,
                                      open(f).read())[-1]) for f in logs)))
for t in (1, 2):
    rows.append(("granoscope, %d thread%s" % (t, "s" if t > 1 else ""),
                 min(float(re.search(r"steps of \d+ particles in ([0-9.]+) s", open(f).read()).group(1))
                     for f in glob.glob("%s/gs%d.*.txt" % (work, t)))))
print("DEM8 Case 2, rotating drum, 38 000 grains, %d steps of 0.8 us (LIGGGHTS and granoscope: best of %d):"
      % (steps, len(glob.glob(work + "/gs1.*.txt"))))
print("  %-26s %8s %16s %7s" % ("run", "time s", "particle-steps/s", "ratio"))
base = n * steps / rows[0][1]
for name, t in rows:
    print("  %-26s %8.2f %16.3g %6.1fx" % (name, t, n * steps / t, n * steps / t / base))
PY
