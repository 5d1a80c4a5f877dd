#!/usr/bin/env bash
# Mesh-wall speed against LIGGGHTS 3.8 (Debian package): the shared facet silo
# (../shared/reference/yade/facets: 1000 spheres, a flat-bottomed 48-facet silo with a saw-tooth
# wall and a 20 x 18 mm orifice) discharging for 20 000 steps of dt = 1.43e-5 s. Same packing
# (LIGGGHTS reads it as a data file: same radii, density 2550, centres, zero velocities), the
# same STL (granoscope [[mesh]], LIGGGHTS fix mesh/surface), same gravity, dt and step count;
# spheres whose centre drops below z = -0.01 m are removed on both sides (granoscope [outlet],
# LIGGGHTS: the bottom of its fixed domain, thermo_modify lost ignore). One thread / one process.
#   bench/solver/run_hopper_bench.sh [BUILD_DIR]   (needs: apt-get install --no-install-recommends liggghts)
#   REPEAT=N (default 1): N rounds, each running the three in turn (LIGGGHTS, yade mode, merged
#   mode), each round's times and ratios printed and then the median ratio: on a shared VM one
#   run's ratio moves by 20-40 % between minutes (bench/README.md), the median of interleaved
#   rounds much less.
#
# Rates are "live particle-steps/s": the particles present, summed over the steps (from the
# counts every 500 steps), divided by the wall time of the stepping loop, so the spheres already
# discharged do not count; "nominal" = 1000 x steps / time is printed too.
#
# Physics differences (speed benchmark, not a validation):
# - Contact law. granoscope: YADE's CohFrictMat law (Kn = Ec*2R1R2/(R1+R2), Ks = 0.3 Kn, tan 18 deg
#   friction, rolling stiffness beta*Ks*R1R2 capped at eta*min(R)*|Fn|), Ec = 2 MPa, Cundall local
#   damping 0.1, no viscous damping; "yade" mode: one contact per triangle with Kn = 4/3 Ec R,
#   "merged" mode: one per flat region, plane-wall Kn = Ec R. LIGGGHTS: `hooke/stiffness tangential
#   history rolling_friction epsd2` (the Hooke model with kn/kt given explicitly; plain `hooke`
#   derives kn from Young's modulus, restitution and a characteristic velocity instead): one
#   kn = Ec*Rmean = 3 N/mm for every pair and the mesh (no radius scaling; radii 1.0-2.0 mm),
#   kt = 0.3 kn, the same tan 18 deg, epsd2 rolling friction with coefficient 0.2 (its own
#   rolling stiffness), gamman = gammat = 0 (absolute_damping on) and no local damping, which
#   LIGGGHTS does not have: its grains are less damped and discharge somewhat faster.
# - LIGGGHTS' mesh wall (edge/corner flags) is meant to count a sphere at a shared edge once
#   (like merged mode); granoscope's yade mode does not (YADE's facets).
# - LIGGGHTS integrates with velocity Verlet (nve/sphere), granoscope with YADE's leapfrog.
# - Neighbour skin 0.5 mm on both sides (granoscope: half the smallest radius, YADE's default).
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
repeat=${REPEAT:-1}
every=500
zlo=-0.01

"$py" "$here/liggghts_hopper_case.py" "$ref/packing.csv" "$ref/mesh.stl" "$steps" "$zlo" "$work/lig"
sed -i "s/^thermo $steps\$/thermo $every/" "$work/lig/in.hopper"
for contact in yade merged; do
  facet_silo_scene "$work/hopper_$contact.toml" "$ref" "$contact" "$steps" "$every" "$zlo"
done
for r in $(seq 1 "$repeat"); do
  (cd "$work/lig" && liggghts -in in.hopper > "log_$r.txt" 2>&1)
  for contact in yade merged; do
    "$gs" simulate "$work/hopper_$contact.toml" --threads 1 -q -o "$work/run_${contact}_$r" \
      > "$work/gs_${contact}_$r.txt"
  done
done

"$py" - "$work" "$steps" "$every" "$repeat" <<'PY'
import csv, re, statistics, sys
work, steps, every, repeat = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
def live(counts):  # {step: particles present after it} -> particle-steps over steps 1..steps
    s = sorted(counts)
    return sum((counts[a] + counts[b]) / 2 * (b - a) for a, b in zip(s, s[1:]))
def liggghts(r):
    log = open("%s/lig/log_%d.txt" % (work, r)).read()
    t = float(re.findall(r"Loop time of ([0-9.e+-]+) on 1 procs for %d steps" % steps, log)[-1])
    runs = log.split("run %d" % steps)[-1]
    c = {int(m.group(1)) - 1: int(m.group(2))
         for m in re.finditer(r"^\s+(\d+)\s+(\d+)\s+\S+\s*$", runs, re.M)}
    c = {k: v for k, v in c.items() if 0 <= k <= steps}
    return t, live(c), 1000 - c[steps]
def granoscope(mode, r):
    out = open("%s/gs_%s_%d.txt" % (work, mode, r)).read()
    t = float(re.search(r"steps of \d+ particles in ([0-9.]+) s", out).group(1))
    h = list(csv.DictReader(open("%s/run_%s_%d/history.csv" % (work, mode, r))))
    cg = {0: 1000}
    cg.update({int(row["step"]): 1000 - int(float(row["removed"])) for row in h})
    return t, live(cg), 1000 - cg[steps]
names = ["LIGGGHTS 3.8, 1 process", "granoscope, yade mode, 1 thread",
         "granoscope, merged mode, 1 thread"]
ratios = {n: [] for n in names}
print("facet silo (hopper), 1000 spheres, 48-facet STL, %d steps, outlet z < -0.01 m:" % steps)
for r in range(1, repeat + 1):
    rows = [liggghts(r), granoscope("yade", r), granoscope("merged", r)]
    if repeat > 1:
        print("round %d of %d:" % (r, repeat))
    print("  %-32s %8s %14s %7s %14s %11s" % ("run", "time s", "live p-steps/s", "ratio",
                                              "nominal p-s/s", "discharged"))
    base = rows[0][1] / rows[0][0]
    for name, (t, ps, out) in zip(names, rows):
        ratios[name].append(ps / t / base)
        print("  %-32s %8.2f %14.3g %6.1fx %14.3g %11d" % (name, t, ps / t, ps / t / base,
                                                            1000 * steps / t, out))
if repeat > 1:
    print("median of %d interleaved rounds (each against the round's LIGGGHTS run):" % repeat)
    for name in names[1:]:
        print("  %-32s %6.2fx   (rounds %s)" % (name, statistics.median(ratios[name]),
                                               ", ".join("%.2f" % x for x in ratios[name])))
PY
