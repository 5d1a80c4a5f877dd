#!/usr/bin/env bash
# Solver speed against YADE 2023.02a and LIGGGHTS 3.8 (Debian packages), same cases, same machine,
# same script. Prints particle-steps/s and ratios, and granoscope's memory per particle.
#   bench/solver/run_solver_bench.sh [BUILD_DIR]     (needs: apt-get install --no-install-recommends yade liggghts)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
gs=$build/bin/granoscope
py=/usr/bin/python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ref=$root/../shared/reference/yade/oedometer
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }

rate() { "$py" -c "import json,sys; print(json.load(open(sys.argv[1]))['particle_steps_per_s'])" "$1"; }
ours() {  # scene steps threads -> particle-steps/s and max RSS (kB)
  /usr/bin/time -f "%M" -o "$work/rss" "$gs" simulate "$1" --steps "$2" --threads "$3" -q -o "$work/run" \
    | sed -n 's/.*(\([0-9.e+]*\) particle-steps\/s.*/\1/p'
}

echo "== oedometer: 883 spheres, top wall moving (the shared YADE reference case)"
# The engine alone, as YADE runs it below (no recorders): the scene with its output cadences
# pushed past the end of the run. Then the scene as shipped (frames every 1000 steps, history
# every 100, checkpoints every 5000) to show what the output costs.
sed -e "s|^packing = .*|packing = \"$ref/packing.csv\"|" -e 's/^every = .*/every = 1000000/' \
  -e 's/^history_every = .*/history_every = 1000000/' -e 's/^checkpoint_every = .*/checkpoint_every = 1000000/' \
  "$root/data/scenes/oedometer_yade.toml" > "$work/oedometer_engine.toml"
o1=$(ours "$work/oedometer_engine.toml" 20000 1); rss1=$(cat "$work/rss")
o2=$(ours "$work/oedometer_engine.toml" 20000 2)
oo=$(ours "$root/data/scenes/oedometer_yade.toml" 20000 1)
yade_steps=${YADE_STEPS:-5000}
yade -n -x -j1 "$here/yade_case.py" "$ref/packing.csv" oedometer "$yade_steps" "$work/yade.json" >/dev/null 2>&1
y=$(rate "$work/yade.json")

echo "== LIGGGHTS: the same 883-sphere packing at rest between static walls"
"$py" "$here/liggghts_case.py" "$ref/packing.csv" 0.025 0.025 0.0297046381579962 20000 "$work/lig" >/dev/null
start=$(date +%s.%N); (cd "$work/lig" && liggghts -in in.bench >/dev/null 2>&1); end=$(date +%s.%N)
l=$("$py" -c "print(883*20000/($end-$start))")
cat > "$work/rest.toml" <<TOML
[scene]
name = "rest"
packing = "$ref/packing.csv"
[material]
young_Pa = 3.0e7
stiffness_ratio = 0.3
friction_deg = 18.0
density_kg_m3 = 2550.0
rolling_stiffness = 0.7
rolling_limit = 0.4
[solver]
dt_s = 1.0e-6
damping = 0.08
gravity_m_s2 = [0.0, 0.0, -9.81]
steps = 20000
max_overlap_ratio = 0.5
[output]
every = 100000
history_every = 1000
checkpoint_every = 100000
[[walls]]
shape = "plane"
point_m = [0, 0, 0]
normal = [0, 0, 1]
[[walls]]
shape = "plane"
point_m = [0, 0, 0]
normal = [1, 0, 0]
[[walls]]
shape = "plane"
point_m = [0.025, 0, 0]
normal = [-1, 0, 0]
[[walls]]
shape = "plane"
point_m = [0, 0, 0]
normal = [0, 1, 0]
[[walls]]
shape = "plane"
point_m = [0, 0.025, 0]
normal = [0, -1, 0]
[[walls]]
shape = "plane"
point_m = [0, 0, 0.0297046381579962]
normal = [0, 0, -1]
TOML
r1=$(ours "$work/rest.toml" 20000 1)

echo "== dense box: ${BOX_N:=55000} spheres"
L=$("$py" "$here/make_box_packing.py" "$BOX_N" "$work/box.csv")
sed -e "s|$ref/packing.csv|$work/box.csv|" -e "s|0.025|$L|g" -e "s|0.0297046381579962|$L|" -e 's/name = "rest"/name = "box"/' \
  "$work/rest.toml" > "$work/box.toml"
b1=$(ours "$work/box.toml" 500 1); rssb=$(cat "$work/rss")
b2=$(ours "$work/box.toml" 500 2)
yade -n -x -j1 "$here/yade_case.py" "$work/box.csv" "box:$L" 100 "$work/yadebox.json" >/dev/null 2>&1
yb=$(rate "$work/yadebox.json")

"$py" - "$o1" "$o2" "$y" "$r1" "$l" "$b1" "$b2" "$yb" "$rss1" "$rssb" "$BOX_N" "$oo" <<'PY'
import sys
o1, o2, y, r1, l, b1, b2, yb, rss1, rssb, n, oo = map(float, sys.argv[1:])
print()
print("%-44s %14s %10s" % ("case", "particle-steps/s", "ratio"))
print("%-44s %14.3g %10s" % ("oedometer, YADE 2023.02a -j1", y, "1"))
print("%-44s %14.3g %9.1fx" % ("oedometer, granoscope 1 thread", o1, o1 / y))
print("%-44s %14.3g %9.1fx" % ("oedometer, granoscope 2 threads", o2, o2 / y))
print("%-44s %14.3g %9.1fx" % ("oedometer, granoscope 1 thread, with output", oo, oo / y))
print("%-44s %14.3g %10s" % ("at rest, LIGGGHTS 3.8 (1 process)", l, "1"))
print("%-44s %14.3g %9.1fx" % ("at rest, granoscope 1 thread", r1, r1 / l))
print("%-44s %14.3g %10s" % ("dense box %d, YADE -j1" % n, yb, "1"))
print("%-44s %14.3g %9.1fx" % ("dense box, granoscope 1 thread", b1, b1 / yb))
print("%-44s %14.3g %9.1fx" % ("dense box, granoscope 2 threads", b2, b2 / yb))
print("memory per particle (granoscope, max RSS / N): %.2f kB (883 spheres), %.2f kB (%d spheres)" % (rss1 / 883, rssb / n, n))
PY
