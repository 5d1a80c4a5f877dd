#!/usr/bin/env bash
# threads = "auto" (picked by timing the steps, solver/scenes/thread_tuner.hpp) against fixed
# counts, on a machine alone and with a second run beside it (docs/scale.md, "Picked by timing").
# For each shipped laptop scene: one run alone and two of the same at once, with `--threads 2`,
# `--threads 1` and the scene's own "auto"; the seconds of each run's stepping loops (summed over
# a sweep's points) and, per count, the two-at-once time over the alone time.
#   bench/solver/run_auto_threads_bench.sh [BUILD_DIR]
#   STEPS=N (default 30000: each run, or each sweep point, stops at step N)
#   SCENES="a b" (default: interface_shear interface_shear_sinusoid triaxial direct_shear
#   kuhn_biaxial, the scenes of data/scenes/ below 5 000 particles)
# About 12 minutes on a 2-core machine. Run it with nothing else on the cores.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
gs=$build/bin/granoscope
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }
steps=${STEPS:-30000}
scenes=${SCENES:-"interface_shear interface_shear_sinusoid triaxial direct_shear kuhn_biaxial"}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# the seconds of a run's stepping loops: the sum of its summary lines' "in T s"
seconds() { awk '/particle-steps\/s/ {for (i = 1; i <= NF; i++) if ($i == "in") s += $(i + 1)}
                 END {printf "%.2f", s}' "$1"; }
run() {  # run NAME SCENE [ARGS...]: one simulate, its summary lines in $work/NAME.txt
  local name=$1 scene=$2
  shift 2
  (cd "$root" && "$gs" simulate "data/scenes/$scene.toml" --steps "$steps" -q "$@" \
    -o "$work/$name" > "$work/$name.txt" 2>&1)
}

printf "%-26s %-10s %9s %19s %8s\n" "scene ($steps steps)" "threads" "alone s" "two at once s" "ratio"
for scene in $scenes; do
  for mode in 2 1 auto; do
    args=()
    [ "$mode" = auto ] || args=(--threads "$mode")
    run "${scene}_${mode}_alone" "$scene" "${args[@]}"
    run "${scene}_${mode}_a" "$scene" "${args[@]}" &
    run "${scene}_${mode}_b" "$scene" "${args[@]}" &
    wait
    alone=$(seconds "$work/${scene}_${mode}_alone.txt")
    a=$(seconds "$work/${scene}_${mode}_a.txt")
    b=$(seconds "$work/${scene}_${mode}_b.txt")
    ratio=$(awk -v a="$a" -v b="$b" -v s="$alone" 'BEGIN {printf "%.1fx", (a + b) / 2 / s}')
    printf "%-26s %-10s %9s %9s / %7s %8s\n" "$scene" "$mode" "$alone" "$a" "$b" "$ratio"
  done
done
