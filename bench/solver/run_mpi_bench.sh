#!/usr/bin/env bash
# Strong scaling on this machine (issue 23, docs/scale.md): the same scene on 1 process with 1
# and 2 threads and on 2 processes (mpirun, 1 thread each), particle-steps/s and ratios against
# 1 process / 1 thread in the same script, and the halo traffic per step. Cases: the shared
# YADE oedometer (883 spheres, 20 000 steps) and the dense box (BOX_N spheres, default 55 000,
# 500 steps; bench/solver/make_box_packing.py), both with output cadences past the end.
#   bench/solver/run_mpi_bench.sh [BUILD_DIR]     (needs: apt-get install libopenmpi-dev openmpi-bin)
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
command -v mpirun >/dev/null || { echo "needs mpirun (apt-get install openmpi-bin)"; exit 1; }
mpi="mpirun --allow-run-as-root --oversubscribe --mca btl_vader_single_copy_mechanism none"

sed -e "s|^packing = .*|packing = \"$ref/packing.csv\"|" -e 's/^every = .*/every = 1000000/' \
  -e 's/^history_every = .*/history_every = 1000000/' -e 's/^checkpoint_every = .*/checkpoint_every = 1000000/' \
  "$root/data/scenes/oedometer_yade.toml" > "$work/oedometer.toml"
n=${BOX_N:-55000}
L=$("$py" "$here/make_box_packing.py" "$n" "$work/box.csv")
sed -e "s|^packing = .*|packing = \"$work/box.csv\"|" -e 's/^name = .*/name = "box"/' \
  -e 's/^max_overlap_ratio = .*/max_overlap_ratio = 0.5/' "$work/oedometer.toml" > "$work/box.toml"
# The box: six planes around the lattice (the oedometer's boxes replaced).
"$py" - "$work/box.toml" "$L" <<'PY'
import sys
path, L = sys.argv[1], float(sys.argv[2])
text = open(path).read().split("[[walls]]")[0]
planes = [((0, 0, 0), (0, 0, 1)), ((0, 0, 0), (1, 0, 0)), ((L, 0, 0), (-1, 0, 0)),
          ((0, 0, 0), (0, 1, 0)), ((0, L, 0), (0, -1, 0)), ((0, 0, L), (0, 0, -1))]
for p, nrm in planes:
    text += '[[walls]]\nshape = "plane"\npoint_m = [%r, %r, %r]\nnormal = [%r, %r, %r]\n' % (p + nrm)
open(path, "w").write(text)
PY

rate() { sed -n 's/.*(\([0-9.e+]*\) particle-steps\/s.*/\1/p' "$1"; }
halo() { sed -n 's/.*processes: \([0-9.e+]*\) MB in halo.*/\1/p' "$1"; }
run_case() {  # name scene steps particles
  local name=$1 scene=$2 steps=$3 np=$4
  "$gs" simulate "$scene" --steps "$steps" --threads 1 -q -o "$work/r11" > "$work/t11"
  "$gs" simulate "$scene" --steps "$steps" --threads 2 -q -o "$work/r12" > "$work/t12"
  $mpi -np 2 "$gs" simulate "$scene" --steps "$steps" --threads 1 -q -o "$work/r21" > "$work/t21"
  "$py" - "$name" "$steps" "$np" "$(rate "$work/t11")" "$(rate "$work/t12")" "$(rate "$work/t21")" \
    "$(halo "$work/t21")" <<'PY'
import sys
name, steps, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
r11, r12, r21, halo = (float(x) for x in sys.argv[4:8])
print("%s, %d steps:" % (name, steps))
print("  %-36s %16s %7s" % ("run", "particle-steps/s", "ratio"))
for label, r in (("1 process, 1 thread", r11), ("1 process, 2 threads", r12),
                 ("2 processes (mpirun), 1 thread each", r21)):
    print("  %-36s %16.3g %6.2fx" % (label, r, r / r11))
print("  halo exchange: %.3g kB per step per process (%.1f bytes per particle per step)"
      % (halo * 1e3 / steps / 2, halo * 1e6 / steps / n))
PY
}
run_case "oedometer, 883 spheres" "$work/oedometer.toml" 20000 883
run_case "dense box, $n spheres" "$work/box.toml" 500 "$n"
