#!/usr/bin/env python3
"""LIGGGHTS 3.8 input for DEM8 Case 3 (penetration; docs/dem8.md), the laptop variant of
data/scenes/dem8_impact_laptop.toml: the benchmark's 25 000 M1 grains (type 1) and the steel
ball (type 2, r = 10 mm, at (0, 0, Z0) moving down at V0), the 56-triangle steel box (written as an
STL from the benchmark's walls.txt, read by `fix mesh/surface`, type 2), dt = 0.5 us, gravity.

Contact model: `gran model hertz tangential history` with the benchmark's Young's moduli, Poisson
ratios, restitutions and friction coefficients per type pair (LIGGGHTS derives its viscous
damping from the restitution with its own formula, not YADE's Thornton fit; for a speed row).
The ball's height is printed with the thermo output (v_bz).
Usage: liggghts_dem8_impact.py PARTICLES.txt WALLS.txt N Z0 V0 STEPS EVERY DIR  (writes DIR/in.impact)"""
import os
import sys

from liggghts_dem8_common import hertz_input, write_stl

parts, walls, n, z0, v0, steps, every, d = sys.argv[1:9]
n, z0, v0, steps, every = int(n), float(z0), float(v0), int(steps), int(every)
os.makedirs(d, exist_ok=True)
rows = []
with open(parts) as f:
    f.readline()
    for line in f:
        c = line.split()
        if len(c) == 4:
            rows.append([float(v) for v in c])
        if len(rows) == n:
            break
with open(os.path.join(d, "bed.data"), "w") as f:
    f.write("LIGGGHTS data file\n\n%d atoms\n2 atom types\n\n" % (n + 1))
    f.write("-0.06 0.06 xlo xhi\n-0.04 0.04 ylo yhi\n-0.1 0.12 zlo zhi\n\nAtoms\n\n")
    for k, (r, x, y, z) in enumerate(rows):  # id type diameter density x y z
        f.write("%d 1 %.17g 2500 %.17g %.17g %.17g\n" % (k + 1, 2 * r, x, y, z))
    f.write("%d 2 0.02 7200 0 0 %.17g\n" % (n + 1, z0))
write_stl(walls, os.path.join(d, "walls.stl"), "box")
with open(os.path.join(d, "in.impact"), "w") as f:
    f.write(f"""{hertz_input("bed.data", 0.0005, 5.0e-7, 1.0e9, 0.5, 0.3)}set atom {n + 1} vx 0.0 vy 0.0 vz {-v0!r}
variable bz equal z[{n + 1}]
thermo_style custom step atoms ke v_bz
thermo_modify lost ignore norm no
thermo {every}
run 1
run {steps}
""")
