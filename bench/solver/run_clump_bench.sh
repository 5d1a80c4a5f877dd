#!/usr/bin/env bash
# Rigid-clump speed against YADE 2023.02a (Debian package) on the shared clump case
# (../shared/reference/yade/clumps: 400 clumps of 2 or 4 overlapping spheres, 1200 member spheres,
# 5 box walls and a top box moving down at 0.03 m/s, dt 2.37e-6 s), one thread, the same input
# in the same script. granoscope reads the case as a scene (make_clump_scene.py: one
# [[clump_template]] per clump, mass = "member_sum" = YADE's discretization = 0); YADE builds it
# with appendClumped from packing.csv (yade_clumps_case.py). Both run STEPS steps (default
# 40 000, about 1 mm more wall travel than the reference's 15 000, so that each side runs
# >= 10 s) with no output; particle-steps count the 1200 member spheres on both sides (the
# scene's one spectator sphere, which falls freely beside the box, is not counted).
#   bench/solver/run_clump_bench.sh [BUILD_DIR]     (needs: apt-get install --no-install-recommends yade)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
gs=$build/bin/granoscope
py=/usr/bin/python3
ref=$root/../shared/reference/yade/clumps
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }
[ -f "$ref/packing.csv" ] || { echo "needs ../shared/reference/yade/clumps"; exit 1; }
steps=${STEPS:-40000}
"$py" "$here/make_clump_scene.py" "$ref" "$steps" "$work"
"$gs" simulate "$work/clumps.toml" --threads 1 -q -o "$work/run" > "$work/gs.txt"
yade -n -x -j1 "$here/yade_clumps_case.py" "$ref" "$steps" "$work/yade.json" >/dev/null 2>&1
"$py" - "$work" "$steps" <<'PY'
import json, re, sys
work, steps = sys.argv[1], int(sys.argv[2])
y = json.load(open(work + "/yade.json"))
out = open(work + "/gs.txt").read()
t = float(re.search(r"steps of \d+ particles in ([0-9.]+) s", out).group(1))
c = int(re.search(r"final: (\d+) contacts", out).group(1))
g = 1200 * steps / t
print("clumps, 400 clumps / 1200 member spheres, box, top wall moving, %d steps, one thread:" % steps)
print("  %-28s %8s %16s %7s %9s" % ("run", "time s", "particle-steps/s", "ratio", "contacts"))
print("  %-28s %8.2f %16.3g %7s %9d" % ("YADE 2023.02a -j1", y["seconds"], y["particle_steps_per_s"], "1", y["contacts"]))
print("  %-28s %8.2f %16.3g %6.1fx %9d" % ("granoscope, 1 thread", t, g, g / y["particle_steps_per_s"], c))
PY
