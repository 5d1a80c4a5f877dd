#!/usr/bin/env bash
# What a finely toothed mesh wall costs (issue 14: "a silo wall of 8 000 micro-teeth must cost
# about what its contacts cost, not spheres × facets"). A bed of 5476 spheres (d = 1.5 mm, four
# layers) settles on a 6 × 6 cm floor that is (a) a plane, (b) seed 004's smooth saw-tooth
# (R_n = 0.01: h_g = 15 µm, s_g = 60 µm, 1000 teeth, 6000 triangles), (c) the same with 10 000
# teeth across two floors' worth of length folded into strips (60 000 triangles), all merged mode,
# one thread. Two runs of each: 2000 steps, before the bed reaches the floor (what the mesh alone
# costs), and 20 000 steps, the bottom layer resting on the teeth (what its contacts cost).
# Prints particle-steps/s and the cost against the plane.
#   bench/solver/run_teeth_bench.sh [BUILD_DIR]   (KEEP=1 keeps the work folder)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
gs=$build/bin/granoscope
py=/usr/bin/python3
work=$(mktemp -d)
trap '[ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }
steps=${STEPS:-2000}
settled=${SETTLED_STEPS:-20000}
"$py" - "$work/packing.csv" <<'PY'
import sys
r, pitch, n = 0.00075, 0.0016, 37
with open(sys.argv[1], "w") as f:
    f.write("id,x,y,z,r\n")
    k = 0
    for l in range(4):
        for i in range(n):
            for j in range(n):
                f.write(f"{k},{0.0012 + i * pitch},{0.0012 + j * pitch},{r + 0.0001 + l * pitch},{r}\n")
                k += 1
PY
"$gs" surface sawtooth --length 0.06 --width 0.06 --height 1.5e-5 --spacing 6e-5 \
  --group floor -o "$work/teeth_6k.stl" 2>/dev/null
# 60 000 triangles: ten strips of 0.6 cm, each 1000 teeth of 6 µm pitch.
"$py" - "$work" "$gs" <<'PY'
import subprocess, sys
work, gs = sys.argv[1], sys.argv[2]
parts = []
for s in range(10):
    out = f"{work}/strip{s}.stl"
    subprocess.run([gs, "surface", "sawtooth", "--length", "0.006", "--width", "0.06",
                    "--height", "1.5e-6", "--spacing", "6e-6", "--origin", f"{0.006 * s},0,0",
                    "--group", "floor", "-o", out], check=True, capture_output=True)
    body = open(out).read().splitlines()
    parts += body[1:-1]
open(f"{work}/teeth_60k.stl", "w").write("solid floor\n" + "\n".join(parts) + "\nendsolid floor\n")
PY
scene() {  # $1 name, $2 floor TOML, $3 steps
  cat > "$work/$1.toml" <<TOML
[scene]
name = "$1"
packing = "packing.csv"
[material]
young_Pa = 1.0e7
stiffness_ratio = 0.3
friction_deg = 30.0
density_kg_m3 = 2650.0
[solver]
dt_s = 2.0e-6
damping = 0.2
gravity_m_s2 = [0.0, 0.0, -9.81]
steps = $3
[output]
every = 100000000
history_every = 100000000
checkpoint_every = 100000000
$2
TOML
}
walls='[[walls]]
shape = "plane"
point_m = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
[[walls]]
shape = "plane"
point_m = [0.06, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
[[walls]]
shape = "plane"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
[[walls]]
shape = "plane"
point_m = [0.0, 0.06, 0.0]
normal = [0.0, -1.0, 0.0]'
for run in "$steps" "$settled"; do
  scene "plane_$run" "$walls
[[walls]]
shape = \"plane\"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]" "$run"
  scene "teeth6k_$run" "$walls
[[mesh]]
file = \"teeth_6k.stl\"" "$run"
  scene "teeth60k_$run" "$walls
[[mesh]]
file = \"teeth_60k.stl\"" "$run"
done
# Per run: particle-steps/s, and the contacts at the end (sphere-sphere and sphere-wall, from the
# final line), so that the cost can be set against what the contacts themselves cost.
rate() {
  "$gs" simulate "$work/$1.toml" --threads 1 -q -o "$work/out_$1" |
    sed -n 's/.*(\([0-9.e+]*\) particle-steps\/s.*/\1/p; s/^final: \([0-9]*\) contacts.*/\1/p' | paste -sd' '
}
for run in "$steps" "$settled"; do
  a=$(rate "plane_$run"); b=$(rate "teeth6k_$run"); c=$(rate "teeth60k_$run")
  "$py" - "$run" $a $b $c <<'PY'
import sys
steps = int(sys.argv[1])
a, na, b, nb, c, nc = map(float, sys.argv[2:])
n = 5476
print("5476 spheres settling on a 6 x 6 cm floor, %d steps, one thread:" % steps)
print("  %-38s %12s %9s %10s %22s" % ("floor", "p-steps/s", "contacts", "cost", "cost per (sphere+contact)"))
for name, r, k in (("plane", a, na), ("saw-tooth, 1000 teeth, 6000 triangles", b, nb),
                   ("saw-tooth, 10000 teeth, 60000 tri.", c, nc)):
    print("  %-38s %12.3g %9d %9.2fx %21.2fx" % (name, r, k, a / r, (a / r) * (n + na) / (n + k)))
PY
done
