#!/usr/bin/env bash
# Periodic-cell speed against YADE 2023.02a (Debian package) on the shared periodic cases
# (../shared/reference/yade/periodic: 1000 spheres, simple shear at constant volume;
# periodic2d: 600 spheres in the plane, constant-area biaxial strain), one thread, the same
# input in the same script. granoscope reads each case as a scene ([cell] with the case's
# hSize and velGrad); YADE builds it as the README says (yade_periodic_case.py). Both run STEPS
# steps (default 5000) after a first one, with no output; the final contact count and stress
# are printed beside the times as a check that it is the same run.
#   bench/solver/run_periodic_bench.sh [BUILD_DIR]   (needs: apt-get install --no-install-recommends yade)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
gs=$build/bin/granoscope
py=/usr/bin/python3
work=${KEEP:-$(mktemp -d)}
[ -n "${KEEP:-}" ] || trap 'rm -rf "$work"' EXIT
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }
steps=${STEPS:-5000}
for c in periodic periodic2d; do
  ref=$root/../shared/reference/yade/$c
  [ -f "$ref/packing.csv" ] || { echo "needs ../shared/reference/yade/$c"; exit 1; }
  "$py" - "$ref" "$steps" "$work/$c.toml" <<'PY'
import json, sys
ref, steps, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
c = json.load(open(ref + "/case.json"))
m = c["material"]
mat = lambda x: "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in x) + "]"
two_d = 'two_d = "spheres_in_plane"\n' if c.get("blocked_dofs") == "zXY" else ""
open(out, "w").write(f"""[scene]
name = "{c['kind']}"
packing = "{ref}/packing.csv"
[material]
young_Pa = {m['young']!r}
stiffness_ratio = {m['stiffness_ratio']!r}
friction_deg = {m['friction_deg']!r}
density_kg_m3 = {m['density']!r}
rolling_stiffness = {m['rolling_stiffness']!r}
rolling_limit = {m['rolling_limit']!r}
[solver]
dt_s = {c['dt']!r}
damping = {c['damping']!r}
steps = {steps + 1}
threads = 1
max_overlap_ratio = 0.5
[output]
every = 100000000
history_every = 100000000
checkpoint_every = 100000000
[cell]
hsize_m = {mat(c['hsize'])}
velocity_gradient_1_s = {mat(c['vel_grad'])}
{two_d}""")
PY
  "$gs" simulate "$work/$c.toml" --threads 1 -q -o "$work/run_$c" > "$work/gs_$c.txt"
  yade -n -x -j1 "$here/yade_periodic_case.py" "$ref" "$steps" "$work/yade_$c.json" >/dev/null 2>&1
done
"$py" - "$work" "$steps" <<'PY'
import csv, json, re, sys
work, steps = sys.argv[1], int(sys.argv[2])
print("periodic cells, %d steps (+1), one thread (stress: sigma_xz in 3D, sigma_xx in 2D):" % steps)
print("  %-40s %8s %16s %7s %9s %12s" % ("run", "time s", "particle-steps/s", "ratio", "contacts", "stress Pa"))
for c, what, ij in (("periodic", "1000 spheres, simple shear", "xz"), ("periodic2d", "600 spheres in plane, biaxial", "xx")):
    y = json.load(open("%s/yade_%s.json" % (work, c)))
    out = open("%s/gs_%s.txt" % (work, c)).read()
    t = float(re.search(r"steps of \d+ particles in ([0-9.]+) s", out).group(1))
    cont = int(re.search(r"final: (\d+) contacts", out).group(1))
    h = list(csv.DictReader(open("%s/run_%s/history.csv" % (work, c))))[-1]
    rate = y["spheres"] * (steps + 1) / t
    print("  %-40s %8.2f %16.3g %7s %9d %12.5g" % ("YADE 2023.02a -j1, " + what, y["seconds"], y["particle_steps_per_s"], "1", y["contacts"], y["s" + ij]))
    print("  %-40s %8.2f %16.3g %6.1fx %9d %12.5g" % ("granoscope, 1 thread", t, rate, rate / y["particle_steps_per_s"], cont, float(h["cell_stress_" + ij + "_Pa"])))
PY
