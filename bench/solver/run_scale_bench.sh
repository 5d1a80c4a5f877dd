#!/usr/bin/env bash
# Issue 23 item 3 (docs/scale.md): speed and memory on the packing researchers run, in one
# script with its baselines. The prepared dense triaxial specimen (data/scenes/triaxial.toml's
# preparation: 1 663 spheres, coordination ~5, not a lattice) replicated side by side to about
# 50 000, 500 000 and 1 000 000 spheres (make_tiled_specimen.py), at rest between six fixed box
# walls, no gravity, the same steps for every code:
#   granoscope 1 process × 1 and 2 threads, 2 processes (mpirun) × 1 thread, and 1 process × 1
#   and 2 threads with the particles in spatial order ([solver] order = "spatial");
#   YADE 2023.02a -j1 and -j2 (yade_scale_case.py: the same law and material);
#   LIGGGHTS 3.8 on 1 and 2 MPI ranks (liggghts_case.py: hooke + rolling friction, same Ec, ρ, dt).
# Prints particle-steps/s with ratios to granoscope 1 × 1, the largest memory (max RSS) per
# sphere, and the cost of output. Every code's time leaves out the first step (the initial
# neighbour search and contacts): YADE and LIGGGHTS time a run after one step; granoscope's
# rate is STEPS·N over the difference of a (1 + STEPS)-step and a 1-step run. Output: the 1 × 1
# run again with a frame with contacts every STEPS/4 steps, giving the time of one frame, and
# from it the fraction of a run that frames every 1 000 steps would take.
#   bench/solver/run_scale_bench.sh [BUILD_DIR]
#   SIZES="50000 500000 1000000" STEPS="400 100 60" BASELINES=1 (0: granoscope only)
#   (20 steps at 10^6 took 4 s against a 1-step run of about 1 s whose time, frames included,
#   varies by tenths: its thread ratios ranged from 1.4 to 1.8; 60 steps give them to +-0.03)
#   REPEAT=1 (rounds of granoscope's runs: the medians are printed, and the thread ratios of each)
# (needs: apt-get install libopenmpi-dev openmpi-bin; --no-install-recommends yade liggghts)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
gs=$build/bin/granoscope
py=/usr/bin/python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ -x "$gs" ] || { echo "build first (scripts/build)"; exit 1; }
mpi="mpirun --allow-run-as-root --oversubscribe --mca btl_vader_single_copy_mechanism none"
read -r -a sizes <<< "${SIZES:-50000 500000 1000000}"
read -r -a stepss <<< "${STEPS:-400 100 60}"
baselines=${BASELINES:-1}
repeat=${REPEAT:-1}

# 1. The prepared specimen: the triaxial scene's preparation, stopped once it is written.
"$gs" simulate "$root/data/scenes/triaxial.toml" --threads 2 -q -o "$work/prep" > /dev/null 2>&1 &
prep=$!
while [ ! -f "$work/prep/specimen.h5" ] && kill -0 "$prep" 2> /dev/null; do sleep 1; done
kill "$prep" 2> /dev/null || true
wait "$prep" 2> /dev/null || true
[ -f "$work/prep/specimen.h5" ] || { echo "the preparation wrote no specimen"; exit 1; }
# The preparation's own time step (dt = auto there): time / step of its last row.
dt=$("$py" -c "import csv,sys; r=list(csv.DictReader(open(sys.argv[1])))[-1]; print(repr(float(r['time_s'])/int(r['step'])))" "$work/prep/preparation.csv")
echo "prepared specimen: $("$py" -c "import h5py,sys; print(len(h5py.File(sys.argv[1])['particles/radius']))" "$work/prep/specimen.h5") spheres; dt = $dt s"

secs() { sed -n 's/.* particles in \([0-9.e+]*\) s .*/\1/p' "$1"; }
scene() {  # csv lx ly lz steps every out.toml
  "$py" - "$@" "$dt" <<'PY'
import sys
csv, lx, ly, lz, steps, every, out, dt = sys.argv[1:9]
lx, ly, lz, h = float(lx), float(ly), float(lz), 0.002
text = f'''[scene]
name = "scale"
packing = "{csv}"
[material]
young_Pa = 3.0e8
stiffness_ratio = 0.3
friction_deg = 18.0
density_kg_m3 = 2600.0
rolling_stiffness = 0.7
rolling_limit = 0.4
[solver]
dt_s = {dt}
damping = 0.08
gravity_m_s2 = [0.0, 0.0, 0.0]
steps = {steps}
max_overlap_ratio = 0.5
[output]
every = {every}
history_every = 100000000
checkpoint_every = 100000000
'''
for c, e in (((lx/2, ly/2, -h), (lx, ly, h)), ((lx/2, ly/2, lz + h), (lx, ly, h)),
             ((-h, ly/2, lz/2), (h, ly, lz)), ((lx + h, ly/2, lz/2), (h, ly, lz)),
             ((lx/2, -h, lz/2), (lx, h, lz)), ((lx/2, ly + h, lz/2), (lx, h, lz))):
    text += '[[walls]]\nshape = "box"\ncenter_m = [%r, %r, %r]\nhalf_extents_m = [%r, %r, %r]\n' % (c + e)
open(out, "w").write(text)
PY
}

for k in "${!sizes[@]}"; do
  target=${sizes[$k]}
  steps=${stepss[$k]:-${stepss[-1]}}
  read -r n lx ly lz tiles <<< "$("$py" "$here/make_tiled_specimen.py" "$work/prep/specimen.h5" "$target" "$work/p.csv")"
  scene "$work/p.csv" "$lx" "$ly" "$lz" $((steps + 1)) 1000000000 "$work/s.toml"
  scene "$work/p.csv" "$lx" "$ly" "$lz" $((steps + 1)) $((steps / 4)) "$work/o.toml"
  # The same scene with the particles renumbered along a Morton curve ([solver] order).
  sed 's/^max_overlap_ratio = 0.5$/&\norder = "spatial"/' "$work/s.toml" > "$work/s_spatial.toml"
  echo
  echo "== $n spheres ($tiles copies), box $lx x $ly x $lz m, $steps steps"
  # (each rate from a 1-step and a (1 + STEPS)-step run: the first step left out)
  ours() {  # label threads launcher... (the scene: $scene_toml)
    local label=$1 threads=$2
    shift 2
    "$@" "$gs" simulate "$scene_toml" --threads "$threads" --steps 1 -q -o "$work/r" > "$work/$label.1"
    "$@" "$gs" simulate "$scene_toml" --threads "$threads" -q -o "$work/r" > "$work/$label.n"
    "$py" -c "import sys; print($n*$steps/(float(sys.argv[2])-float(sys.argv[1])))" \
      "$(secs "$work/$label.1")" "$(secs "$work/$label.n")"
  }
  # REPEAT rounds, each running every configuration once (interleaved, so that a slow spell
  # of the machine touches all of them); each rate is the median of its rounds, and the
  # two-thread ratios are given per round too.
  r11s=() r12s=() r21s=() s11s=() s12s=() t11s=()
  for _ in $(seq "$repeat"); do
    scene_toml=$work/s.toml
    r11s+=("$(ours t11 1 /usr/bin/time -f %M -o "$work/m11")")
    t11s+=("$(secs "$work/t11.n")")
    r12s+=("$(ours t12 2)")
    r21s+=("$(ours t21 1 $mpi -np 2 sh -c "/usr/bin/time -f %M -o $work/m21.\$OMPI_COMM_WORLD_RANK \"\$0\" \"\$@\"")")
    scene_toml=$work/s_spatial.toml
    s11s+=("$(ours u11 1)")
    s12s+=("$(ours u12 2)")
  done
  # (a rate is left out when its STEPS took no longer than the 1-step run: too few steps for
  # this machine's noise; nan when every round's was)
  median() { printf '%s\n' "$@" | awk '$1 + 0 > 0' | sort -g | awk '{v[NR] = $1} END {print NR == 0 ? "nan" : (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
  r11=$(median "${r11s[@]}") r12=$(median "${r12s[@]}") r21=$(median "${r21s[@]}")
  s11=$(median "${s11s[@]}") s12=$(median "${s12s[@]}")
  rounds=""
  for j in "${!r11s[@]}"; do
    rounds+=$("$py" -c "import sys; a = [float(x) for x in sys.argv[1:]]; print(' %.2f/%.2f' % (a[1] / a[0], a[3] / a[2]))" \
      "${r11s[$j]}" "${r12s[$j]}" "${s11s[$j]}" "${s12s[$j]}")
  done
  "$gs" simulate "$work/o.toml" --threads 1 -q -o "$work/ro" > "$work/to"
  out_mb=$(du -sm "$work/ro" | cut -f1)
  y1=0 y2=0 ym=0 l1=0 l2=0 lm=0
  if [ "$baselines" = 1 ]; then
    yade -n -x -j1 "$here/yade_scale_case.py" "$work/p.csv" "$lx" "$ly" "$lz" "$steps" "$dt" "$work/y1.json" > /dev/null 2>&1
    yade -n -x -j2 "$here/yade_scale_case.py" "$work/p.csv" "$lx" "$ly" "$lz" "$steps" "$dt" "$work/y2.json" > /dev/null 2>&1
    y1=$("$py" -c "import json,sys; print(json.load(open(sys.argv[1]))['particle_steps_per_s'])" "$work/y1.json")
    y2=$("$py" -c "import json,sys; print(json.load(open(sys.argv[1]))['particle_steps_per_s'])" "$work/y2.json")
    ym=$("$py" -c "import json,sys; print(json.load(open(sys.argv[1]))['max_rss_kB'])" "$work/y1.json")
    "$py" "$here/liggghts_case.py" "$work/p.csv" "$lx" "$ly" "$lz" "$steps" "$work/lig" 3e8 2600 "$dt" 0 > /dev/null
    (cd "$work/lig" && /usr/bin/time -f %M -o "$work/ml" liggghts -in in.bench > log1.txt 2>&1)
    (cd "$work/lig" && $mpi -np 2 liggghts -in in.bench > log2.txt 2>&1)
    loop() { awk '/^Loop time of/ {t=$4} END {print t}' "$1"; }  # the last run's (the STEPS)
    l1=$("$py" -c "print($n*$steps/$(loop "$work/lig/log1.txt"))")
    l2=$("$py" -c "print($n*$steps/$(loop "$work/lig/log2.txt"))")
    lm=$(cat "$work/ml")
  fi
  "$py" - "$n" "$steps" "$r11" "$r12" "$r21" \
    "$(cat "$work/m11")" "$(cat "$work/m21.0")" "$(cat "$work/m21.1")" "$(median "${t11s[@]}")" "$(secs "$work/to")" \
    "$out_mb" "$y1" "$y2" "$ym" "$l1" "$l2" "$lm" "$s11" "$s12" "$repeat" "$rounds" <<'PY'
import sys
n, steps = int(sys.argv[1]), int(sys.argv[2])
r11, r12, r21 = (float(x) for x in sys.argv[3:6])
m11, m21a, m21b = (float(x) for x in sys.argv[6:9])
t11, to, out_mb = float(sys.argv[9]), float(sys.argv[10]), float(sys.argv[11])
y1, y2, ym, l1, l2, lm = (float(x) for x in sys.argv[12:18])
s11, s12 = float(sys.argv[18]), float(sys.argv[19])
repeat, rounds = int(sys.argv[20]), sys.argv[21]
print("  %-40s %16s %8s %14s" % ("run", "particle-steps/s", "ratio", "kB per sphere"))
rows = [("granoscope, 1 process x 1 thread", r11, m11), ("granoscope, 1 process x 2 threads", r12, None),
        ("granoscope, 2 processes x 1 thread", r21, max(m21a, m21b)),
        ("granoscope, spatial order, 1 x 1", s11, None),
        ("granoscope, spatial order, 1 x 2", s12, None)]
if y1:
    rows += [("YADE -j1", y1, ym), ("YADE -j2", y2, None), ("LIGGGHTS, 1 rank", l1, lm),
             ("LIGGGHTS, 2 ranks (mpirun)", l2, None)]
for label, r, m in rows:
    print("  %-40s %16.3g %7.2fx %14s" % (label, r, r / r11, "%.2f" % (m / n) if m else ""))
print("  (memory: the largest resident set of the process, or of either process, over the run)")
print("  (granoscope: the median of %d interleaved rounds)" % repeat)
print("  two threads / one thread: file order %.2fx, spatial order %.2fx (medians);"
      " per round, file/spatial:%s" % (r12 / r11, s12 / s11, rounds))
# The frames run: 4 more frames than the plain run (every STEPS/4 and the last; step 0's is
# written before the timer starts in both).
frame = (to - t11) / 4
step = n / r11
print("  output: a frame with contacts takes %.3g s (%.3g MB; %.3g steps' time); frames every"
      " 1 000 steps would take %.1f %% of a run" % (frame, out_mb / 6, frame / step,
                                                    100 * frame / (frame + 1000 * step)))
PY
done
