#!/usr/bin/env python3
"""Writes a dense box packing (compressed cubic lattice: spacing 2 mm, radii uniform in
[0.95, 1.05] mm, so about half the neighbours overlap by up to 7 % of a radius) as id,x,y,z,r CSV. Usage: make_box_packing.py N OUT.csv -> prints the box size (m)."""
import math
import random
import sys

n = int(sys.argv[1])
side = math.ceil(n ** (1 / 3))
a = 2.0e-3  # lattice spacing
random.seed(1)
with open(sys.argv[2], "w") as f:
    f.write("id,x,y,z,r\n")
    for i in range(n):
        x, y, z = i % side, (i // side) % side, i // (side * side)
        r = 1e-3 * (0.95 + 0.1 * random.random())
        j = [random.uniform(-1e-5, 1e-5) for _ in range(3)]
        f.write("%d,%.17g,%.17g,%.17g,%.17g\n" % (i, 1.1e-3 + x * a + j[0], 1.1e-3 + y * a + j[1], 1.1e-3 + z * a + j[2], r))
print((side - 1) * a + 2.2e-3)
