#!/usr/bin/env python3
"""Replicates a prepared specimen (the one frame of a lab test's specimen.h5: a dense packing
between six plane walls) side by side into a box of about N spheres (issue 23's benchmark
packing: coordination >= 4, not a lattice). Each copy is shifted by the wall spacing, so copies
meet where their walls were. Writes id,x,y,z,r CSV with the box from 0 to (LX, LY, LZ); prints
"N LX LY LZ TILES". Usage: make_tiled_specimen.py SPECIMEN.h5 N OUT.csv"""
import math
import sys

import h5py
import numpy as np

spec, target, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
f = h5py.File(spec, "r")
x = f["particles/position"][()]
r = f["particles/radius"][()]
a = f["walls/a"][()]  # a point of each plane wall; b its normal
b = f["walls/b"][()]
lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
for p, n in zip(a, b):
    k = int(np.argmax(np.abs(n)))
    if n[k] > 0:
        lo[k] = p[k]
    else:
        hi[k] = p[k]
assert np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)), "six axis-aligned plane walls"
size = hi - lo
# Tiles nx >= ny >= nz with nx <= 2 nz (a compact block), the fewest that reach the target.
need = math.ceil(target / len(r))
best = None
for nz in range(1, need + 1):
    for ny in range(nz, 2 * nz + 1):
        for nx in range(ny, 2 * nz + 1):
            count = nx * ny * nz
            if count < need:
                continue
            key = (count, nx - nz)
            if best is None or key < best[0]:
                best = (key, (nx, ny, nz))
nx, ny, nz = best[1]
with open(out, "w") as o:
    o.write("id,x,y,z,r\n")
    i = 0
    for kz in range(nz):
        for ky in range(ny):
            for kx in range(nx):
                shift = np.array([kx, ky, kz]) * size - lo
                for p, rad in zip(x + shift, r):
                    o.write("%d,%.17g,%.17g,%.17g,%.17g\n" % (i, p[0], p[1], p[2], rad))
                    i += 1
box = np.array([nx, ny, nz]) * size
print(i, "%.17g %.17g %.17g" % tuple(box), "%dx%dx%d" % (nx, ny, nz))
