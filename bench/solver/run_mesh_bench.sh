#!/usr/bin/env bash
# Mesh-wall speed against YADE 2023.02a (Debian package) on the shared facet silo: 1000 spheres
# draining through the orifice of a 48-facet silo with a saw-tooth wall, 20 000 steps, one thread,
# same input (our scene reads the reference's packing and its STL), in the same script.
#   bench/solver/run_mesh_bench.sh [BUILD_DIR]     (needs: apt-get install --no-install-recommends yade)
set -euo pipefail
. "$(dirname "$0")/facet_silo_scene.sh"
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
gs=$build/bin/granoscope
py=/usr/bin/python3
ref=$root/../shared/reference/yade/facets
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }
[ -f "$ref/mesh.stl" ] || { echo "needs ../shared/reference/yade/facets"; exit 1; }
steps=${STEPS:-20000}
for contact in yade merged; do
  facet_silo_scene "$work/silo_$contact.toml" "$ref" "$contact" "$steps" 100000000
done
ours() { "$gs" simulate "$1" --threads 1 -q -o "$work/run" | sed -n 's/.*(\([0-9.e+]*\) particle-steps\/s.*/\1/p'; }
g_yade=$(ours "$work/silo_yade.toml")
g_merged=$(ours "$work/silo_merged.toml")
yade -n -x -j1 "$here/yade_facets_case.py" "$ref" "$steps" "$work/yade.json" >/dev/null 2>&1
y=$("$py" -c "import json,sys; print(json.load(open(sys.argv[1]))['particle_steps_per_s'])" "$work/yade.json")
"$py" - "$y" "$g_yade" "$g_merged" <<'PY'
import sys
y, a, b = map(float, sys.argv[1:])
print("facet silo, 1000 spheres, 48 facets, one thread (particle-steps/s):")
print(f"  YADE 2023.02a -j1        {y:.3g}")
print(f"  granoscope, yade mode    {a:.3g}   ratio {a / y:.1f}x")
print(f"  granoscope, merged mode  {b:.3g}   ratio {b / y:.1f}x")
PY
