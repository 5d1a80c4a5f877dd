#!/usr/bin/env python3
"""Writes the shared YADE clump case (../shared/reference/yade/clumps: 400 clumps, 1200 member
spheres, box walls, top wall moving down) as a granoscope scene: one [[clump_template]] per clump
(its members relative to their sum-of-members centroid, so the placed members land on
packing.csv's centres to round-off), clumps.csv placing each at its centroid with the identity
orientation, mass = "member_sum" (YADE's discretization = 0), walls and parameters from case.json,
output cadences past the end of the run (YADE records nothing either).
The scene needs a loose-sphere packing with at least one sphere: one spectator sphere (r = 0.5 mm)
falls freely 5 cm beside the box and never touches anything.
Usage: make_clump_scene.py REF_DIR STEPS OUT_DIR   (writes OUT_DIR/clumps.toml)"""
import csv
import json
import os
import sys

ref, steps, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
case = json.load(open(os.path.join(ref, "case.json")))
os.makedirs(out, exist_ok=True)
clumps = {}
for r in csv.DictReader(open(os.path.join(ref, "packing.csv"))):
    clumps.setdefault(int(r["clump"]), []).append([float(r[k]) for k in "xyzr"])
m = case["material"]
t = open(os.path.join(out, "clumps.toml"), "w")
t.write(f"""[scene]
name = "clumps"
packing = "spectator.csv"
[material]
young_Pa = {m['young']!r}
stiffness_ratio = {m['stiffness_ratio']!r}
friction_deg = {m['friction_deg']!r}
density_kg_m3 = {m['density']!r}
rolling_stiffness = {m['rolling_stiffness']!r}
rolling_limit = {m['rolling_limit']!r}
rolling_limit_radius = "{m['rolling_limit_radius']}"
[solver]
dt_s = {case['dt']!r}
damping = {case['damping']!r}
gravity_m_s2 = {case['gravity']!r}
steps = {steps}
threads = 1
max_overlap_ratio = 1.0
[output]
every = 100000000
history_every = 100000000
checkpoint_every = 100000000
[clumps]
packing = "clumps.csv"
mass = "member_sum"
""")
for w in case["walls"]:
    t.write(f"""[[walls]]
name = "{w['name']}"
shape = "box"
center_m = {w['center']!r}
half_extents_m = {w['half_extents']!r}
velocity_m_s = {[float(v) for v in w['velocity']]!r}
""")
place = open(os.path.join(out, "clumps.csv"), "w")
place.write("template,x,y,z,qw,qx,qy,qz\n")
for c, mem in sorted(clumps.items()):
    mass = [x[3] ** 3 for x in mem]
    cen = [sum(mk * x[k] for mk, x in zip(mass, mem)) / sum(mass) for k in range(3)]
    rows = ", ".join("[%r, %r, %r, %r]" % (x[0] - cen[0], x[1] - cen[1], x[2] - cen[2], x[3]) for x in mem)
    t.write(f'[[clump_template]]\nname = "c{c}"\nmembers = [{rows}]\n')
    place.write("c%d,%r,%r,%r,1,0,0,0\n" % (c, cen[0], cen[1], cen[2]))
open(os.path.join(out, "spectator.csv"), "w").write("id,x,y,z,r\n0,-0.05,0.012,0.05,0.0005\n")
