#!/usr/bin/env bash
# DEM8 Case 1 (silo discharge, M1): the discharge rate of granoscope against LIGGGHTS 3.8 (one of
# the benchmark's eight codes) from the same settled packing, a cross-code check of the rate
# (docs/dem8.md). Not a speed benchmark: both run side by side, one core each.
#
# RUN_DIR is a run of data/scenes/dem8_silo_laptop.toml (or a scene like it) stopped when the
# filling has settled (`steps = 1` after the filling: its last frame is the packing at rest on the
# lid). Both codes start from that frame at rest with the orifice open (the lid gone, contact
# histories empty, velocities zero: the same start for both) and run STEPS steps (default 180 000
# = 0.27 s at dt 1.5 us), counting the particles every 500 steps; a sphere whose centre drops
# below the orifice plane is removed on both sides. Then the rate of each is fitted as
# dem8_silo_rate.py does (least squares through the count from SKIP s on, default 0.05 s), with
# the rates over successive 25 ms.
# granoscope: the scene's Hertz-Mindlin law (YADE's, Thornton's damping fit), one contact per
# sphere and flat region (`merged`, the shipped scenes' mode). LIGGGHTS: liggghts_dem8_silo.py
# (`gran model hertz tangential history`, Tsuji's damping from the same restitutions, the silo as
# an STL mesh, the same Verlet skin).
#   bench/solver/run_dem8_silo_rate_check.sh RUN_DIR [BUILD_DIR]   (needs liggghts, ../shared/dem8)
# ORIFICE=small: the small-orifice silo (RUN_DIR a run of dem8_silo_small_laptop.toml).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
run=${1:?usage: run_dem8_silo_rate_check.sh RUN_DIR [BUILD_DIR]}
build=${2:-$root/build}
gs=$build/bin/granoscope
py=/usr/bin/python3
d8=$(cd "$root/../shared/dem8" 2>/dev/null && pwd) || { echo "needs ../shared/dem8"; exit 1; }
command -v liggghts > /dev/null || { echo "needs liggghts (apt-get install --no-install-recommends liggghts)"; exit 1; }
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }
work=${WORK:-$(mktemp -d)}
[ -n "${WORK:-}" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work"
steps=${STEPS:-180000}
skip=${SKIP:-0.05}
every=500
. "$here/dem8_silo_orifice.sh"
traj=$run/trajectory.h5
[ -f "$traj" ] || { echo "$traj: no finished run (stop it after the filling: steps = 1)"; exit 1; }
"$gs" convert "$traj" "$work/frame.csv" --frame -1 > /dev/null 2>&1
n=$("$py" "$here/dem8_silo_frame_scene.py" "$root/data/scenes/$scene.toml" "$work" "$d8" "$steps" \
  --threads 1 --history-every "$every")
echo "$n spheres from $work/frame.csv"
"$py" "$here/liggghts_dem8_silo.py" "$work/packing.csv" "$walls" "$z_orifice" "$steps" "$every" \
  "$work/lig"
if [ -z "${REPORT_ONLY:-}" ]; then  # (REPORT_ONLY=1 with WORK=DIR: the report of runs made)
  (cd "$work/lig" && liggghts -in in.silo > log.txt 2>&1) &
  lig=$!
  (cd "$work" && "$gs" simulate silo.toml --threads 1 -q -o gs > gs.txt 2>&1) &
  ours=$!
  wait $lig || { echo "LIGGGHTS failed: $work/lig/log.txt"; exit 1; }
  wait $ours || { echo "granoscope failed: $work/gs.txt"; exit 1; }
fi
"$py" - "$work" "$steps" "$every" "$skip" "$here" <<'PY'
import csv, re, sys
work, steps, every, skip = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
sys.path.insert(0, sys.argv[5])
from dem8_silo_rate import fit_rate  # (the fit dem8_silo_rate.py reports)
dt = 1.5e-6
n = sum(1 for _ in csv.DictReader(open(work + "/packing.csv")))
# LIGGGHTS: `run 1`, then `run STEPS` printing the count at the steps that are multiples of
# `every` since the start (and at its first and last step, 1 and STEPS + 1: left out)
log = open(work + "/lig/log.txt").read().split("run %d" % steps)[-1]
lig = {0: 0}
lig.update({int(m.group(1)): n - int(m.group(2))
            for m in re.finditer(r"^\s+(\d+)\s+(\d+)\s+\S+\s*$", log, re.M)
            if int(m.group(1)) % every == 0 and int(m.group(1)) <= steps})
ours = {0: 0}
ours.update({int(r["step"]): round(float(r["removed"]))
             for r in csv.DictReader(open(work + "/gs/history.csv"))})
def fit(c):
    ks = [k for k in sorted(c) if k * dt >= skip - 1e-12]
    xs = [k * dt for k in ks]
    return fit_rate(xs, [c[k] for k in ks]) + (xs[0], xs[-1])
print("DEM8 Case 1 discharge from the same settled packing, %d spheres, %d steps of 1.5 us:" % (n, steps))
print("  t (s)   above the orifice: granoscope  LIGGGHTS 3.8")
marks = {round(j * 0.1 / dt / every) * every for j in range(int(steps * dt / 0.1) + 1)} | {steps}
for k in sorted(marks & set(ours) & set(lig)):
    print("  %6.4f  %28d  %12d" % (k * dt, n - ours[k], n - lig[k]))
print("  rate over successive 25 ms (particles/s), granoscope / LIGGGHTS:")
w = round(0.025 / dt / every) * every
for k in range(0, steps - w + 1, w):
    if k in ours and k + w in ours and k in lig and k + w in lig:
        print("  %5.3f-%5.3f s  %8.0f  %8.0f" % (k * dt, (k + w) * dt, (ours[k + w] - ours[k]) / (w * dt),
                                              (lig[k + w] - lig[k]) / (w * dt)))
for name, c in (("granoscope", ours), ("LIGGGHTS 3.8", lig)):
    s, r2, dev, a, b = fit(c)
    print("  %-13s rate %8.1f particles/s over %.3f..%.3f s (R^2 %.6f, max |N - fit| %.1f), "
          "%+.1f %% against the benchmark's 23.2 k/s" % (name, s, a, b, r2, dev, 100 * (s / 23200 - 1)))
PY
