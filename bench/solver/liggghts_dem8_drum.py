#!/usr/bin/env python3
"""LIGGGHTS 3.8 input for DEM8 Case 2 (rotating drum; docs/dem8.md): the benchmark's bed (30 000
M1 grains of r = 1 mm as type 1, 8 000 M2 grains of r = 2 mm as type 2), the 1 200-triangle
steel drum (type 3; written as an STL from the benchmark's walls.txt, `fix mesh/surface`) turning
at 2 rad/s about +y through the origin (`fix move/mesh ... rotate`), dt = 0.8 us, gravity, the
benchmark's restitution and friction per type pair, `gran model hertz tangential history`
(LIGGGHTS derives its viscous damping from the restitution with its own formula: a speed row).
Usage: liggghts_dem8_drum.py PartCoordinates.txt WALLS.txt SKIN_M STEPS DIR  (writes DIR/in.drum)"""
import math
import os
import sys

from liggghts_dem8_common import hertz_input_types, write_stl

parts, walls, skin, steps, d = sys.argv[1:6]
steps = int(steps)
os.makedirs(d, exist_ok=True)
rows = []
with open(parts) as f:
    f.readline()
    for line in f:
        c = line.split()
        if len(c) == 4:
            rows.append([float(v) for v in c])
with open(os.path.join(d, "drum.data"), "w") as f:
    f.write("LIGGGHTS data file\n\n%d atoms\n3 atom types\n\n" % len(rows))
    f.write("-0.11 0.11 xlo xhi\n-0.04 0.04 ylo yhi\n-0.11 0.11 zlo zhi\n\nAtoms\n\n")
    for k, (r, x, y, z) in enumerate(rows):  # id type diameter density x y z
        t, rho = (2, 2000) if r > 0.0015 else (1, 2500)
        f.write("%d %d %.17g %d %.17g %.17g %.17g\n" % (k + 1, t, 2 * r, rho, x, y, z))
write_stl(walls, os.path.join(d, "walls.stl"), "drum")
with open(os.path.join(d, "in.drum"), "w") as f:
    f.write(f"""{hertz_input_types("drum.data", skin, 8.0e-7, [1.0e9, 0.5e9, 2.1e11],
                                  [[0.5, 0.45, 0.4], [0.45, 0.4, 0.4], [0.4, 0.4, 0.4]],
                                  [[0.3, 0.2, 0.2], [0.2, 0.4, 0.2], [0.2, 0.2, 0.2]])}fix turn all move/mesh mesh cad rotate origin 0. 0. 0. axis 0. 1. 0. period {2 * math.pi / 2.0!r}
fix integr all nve/sphere
thermo_style custom step atoms ke
thermo_modify lost ignore norm no
thermo {steps}
run 1
run {steps}
""")
