#!/usr/bin/env python3
"""LIGGGHTS 3.8 input for DEM8 Case 1 (silo discharge, M1; docs/dem8.md): the spheres of a CSV
(id,x,y,z,r: a frame of a granoscope run of data/scenes/dem8_silo_laptop.toml) at rest, type 1
(M1), the benchmark's steel silo (written as an STL from its walls .txt, read by
`fix mesh/surface`, type 2; `curvature_tolerant yes`: the small-orifice mesh has a triangle
whose smallest angle, 0.26 deg, fails LIGGGHTS' mesh check), dt = 1.5 us, gravity. A sphere whose centre leaves the fixed domain,
whose bottom is the orifice plane, is lost (thermo_modify lost ignore), as the benchmark's
script erases those below it.

Contact model: `gran model hertz tangential history` with the benchmark's Young's moduli,
Poisson ratios, restitutions and friction coefficients per type pair (LIGGGHTS derives its
viscous damping from the restitution with its own formula, not YADE's Thornton fit; a speed row).
Usage: liggghts_dem8_silo.py PACKING.csv WALLS.txt ORIFICE_Z STEPS EVERY DIR  (writes DIR/in.silo)"""
import csv
import os
import sys

from liggghts_dem8_common import hertz_input, write_stl

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
write_stl(walls, os.path.join(d, "walls.stl"), "silo")
with open(os.path.join(d, "in.silo"), "w") as f:
    f.write(f"""{hertz_input("silo.data", 0.0004, 1.5e-6, 1.0e9, 0.5, 0.3, "curvature_tolerant yes")}thermo_style custom step atoms ke
thermo_modify lost ignore norm no
thermo {every}
run 1
run {steps}
""")
