#!/usr/bin/env python3
"""Writes a LIGGGHTS 3.8 data file and input script for a packing at rest in a box of static
walls: hooke + tangential history + rolling_friction epsd2, the same Ec/νc/μ/η parameters, dt
1e-6, gravity. Usage: liggghts_case.py PACKING.csv LX LY LZ STEPS DIR [YOUNG DENSITY DT GRAVITY]
(the optional four: Ec in Pa, density in kg/m³, time step in s, gravity in m/s², 0 for none;
defaults 3e7, 2550, 1e-6, 9.81)."""
import os
import sys

packing, lx, ly, lz, steps, d = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]), sys.argv[6]
young, density, dt, gravity = (float(v) for v in (sys.argv[7:11] if len(sys.argv) > 10 else (3e7, 2550, 1e-6, 9.81)))
rows = [l.split(",") for l in open(packing).read().split("\n")[1:] if l.strip()]
os.makedirs(d, exist_ok=True)
with open(os.path.join(d, "packing.data"), "w") as f:
    f.write("LIGGGHTS data file\n\n%d atoms\n1 atom types\n\n" % len(rows))
    f.write("0 %.17g xlo xhi\n0 %.17g ylo yhi\n0 %.17g zlo zhi\n\nAtoms\n\n" % (lx, ly, lz))
    for k, (i, x, y, z, r) in enumerate(rows):
        # atom_style granular: id type diameter density x y z
        f.write("%d 1 %.17g %.17g %s %s %s\n" % (k + 1, 2 * float(r), density, x, y, z))
with open(os.path.join(d, "in.bench"), "w") as f:
    f.write("""atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
read_data packing.data
neighbor 0.0003 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype %.17g
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.9
fix m4 all property/global coefficientFriction peratomtypepair 1 0.3249
fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.4
fix m6 all property/global characteristicVelocity scalar 0.1
pair_style gran model hooke tangential history rolling_friction epsd2
pair_coeff * *
timestep %.17g
%sfix w1 all wall/gran model hooke tangential history rolling_friction epsd2 primitive type 1 zplane 0.0
fix w2 all wall/gran model hooke tangential history rolling_friction epsd2 primitive type 1 xplane 0.0
fix w3 all wall/gran model hooke tangential history rolling_friction epsd2 primitive type 1 xplane %.17g
fix w4 all wall/gran model hooke tangential history rolling_friction epsd2 primitive type 1 yplane 0.0
fix w5 all wall/gran model hooke tangential history rolling_friction epsd2 primitive type 1 yplane %.17g
fix w6 all wall/gran model hooke tangential history rolling_friction epsd2 primitive type 1 zplane %.17g
fix integr all nve/sphere
thermo 100000
run 1
run %d
""" % (young, dt, "fix gravi all gravity %.17g vector 0.0 0.0 -1.0\n" % gravity if gravity else "",
       lx, ly, lz, steps))
