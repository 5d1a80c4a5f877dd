#!/usr/bin/env python3
"""LIGGGHTS 3.8 input for DEM8 Case 1 (silo discharge, M1; docs/dem8.md): the spheres of a CSV
(id,x,y,z,r: a frame of a granoscope run of data/scenes/dem8_silo_laptop.toml) at rest, type 1
(M1), the benchmark's steel silo (written as an STL from its walls .txt, read by
`fix mesh/surface`, type 2), dt = 1.5 us, gravity. A sphere whose centre leaves the fixed domain,
whose bottom is the orifice plane, is lost (thermo_modify lost ignore), as the benchmark's
script erases those below it.

Contact model: `gran model hertz tangential history` with the benchmark's Young's moduli,
Poisson ratios, restitutions and friction coefficients per type pair (LIGGGHTS derives its
viscous damping from the restitution with its own formula, not YADE's Thornton fit; a speed row).
Usage: liggghts_dem8_silo.py PACKING.csv WALLS.txt ORIFICE_Z STEPS EVERY DIR  (writes DIR/in.silo)"""
import csv
import os
import sys

packing, walls, z_orifice, steps, every, d = sys.argv[1:7]
z_orifice, steps, every = float(z_orifice), int(steps), int(every)
os.makedirs(d, exist_ok=True)
rows = [(float(r["x"]), float(r["y"]), float(r["z"]), float(r["r"]))
        for r in csv.DictReader(open(packing))]
with open(os.path.join(d, "silo.data"), "w") as f:
    f.write("LIGGGHTS data file\n\n%d atoms\n2 atom types\n\n" % len(rows))
    f.write("-0.11 0.11 xlo xhi\n-0.11 0.11 ylo yhi\n%.17g 0.33 zlo zhi\n\nAtoms\n\n" % z_orifice)
    for k, (x, y, z, r) in enumerate(rows):  # id type diameter density x y z
        f.write("%d 1 %.17g 2500 %.17g %.17g %.17g\n" % (k + 1, 2 * r, x, y, z))
with open(walls) as a, open(os.path.join(d, "walls.stl"), "w") as b:
    a.readline()
    b.write("solid silo\n")
    for line in a:
        c = line.split()
        if len(c) != 9:
            continue
        b.write(" facet normal 0 0 0\n  outer loop\n")
        for k in range(3):
            b.write("   vertex %s %s %s\n" % tuple(c[3 * k:3 * k + 3]))
        b.write("  endloop\n endfacet\n")
    b.write("endsolid silo\n")
model = "model hertz tangential history"
with open(os.path.join(d, "in.silo"), "w") as f:
    f.write(f"""atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
hard_particles yes
read_data silo.data
neighbor 0.001 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 1.0e9 2.1e11
fix m2 all property/global poissonsRatio peratomtype 0.2 0.2
fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.4 0.4 0.4
fix m4 all property/global coefficientFriction peratomtypepair 2 0.3 0.2 0.2 0.2
pair_style gran {model}
pair_coeff * *
timestep 1.5e-6
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix cad all mesh/surface file walls.stl type 2
fix walls all wall/gran {model} mesh n_meshes 1 meshes cad
fix integr all nve/sphere
thermo_style custom step atoms ke
thermo_modify lost ignore norm no
thermo {every}
run 1
run {steps}
""")
