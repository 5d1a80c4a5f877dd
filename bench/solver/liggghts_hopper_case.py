#!/usr/bin/env python3
"""LIGGGHTS 3.8 input for the shared facet silo (../shared/reference/yade/facets): the same 1000
spheres (packing.csv -> data file: same radii, density, centres, zero velocities), the same STL
read by `fix mesh/surface`, gravity, dt, step count; spheres whose centre falls below z = ZLO
leave the (fixed) domain and are dropped (`thermo_modify lost ignore`), like granoscope's [outlet].

Contact model: `gran model hooke/stiffness tangential history rolling_friction epsd2`, the nearest
LIGGGHTS 3.8 offers to YADE's CohFrictMat law:
  kn = Ec*Rm (Rm = mean radius), kt = nu_c*kn (constant per type pair; YADE/granoscope scale Kn
  with the radii: Ec*2R1R2/(R1+R2) between spheres, Ec*R (merged) or 4/3*Ec*R (yade) against
  the mesh), friction tan(mu), rolling_friction epsd2 with coefficient eta (its own rolling
  stiffness, not beta*Ks*R1*R2), gamman = gammat = 0 with absolute_damping on (no viscous
  damping: YADE's Cundall local damping 0.1 has no LIGGGHTS equivalent, so the grains here are
  less damped). LIGGGHTS' mesh wall (edge/corner flags) is meant to count a sphere at a shared edge once
  (like merged mode).
Usage: liggghts_hopper_case.py PACKING.csv MESH.stl STEPS ZLO DIR   (writes DIR/in.hopper)"""
import math
import os
import sys

packing, stl, steps, zlo, d = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
Ec, nu_c, mu_deg, rho, eta, dt = 2.0e6, 0.3, 18.0, 2550.0, 0.2, 1.43e-5
rows = [l.split(",") for l in open(packing).read().split("\n")[1:] if l.strip()]
rm = sum(float(r[4]) for r in rows) / len(rows)
kn = Ec * rm
os.makedirs(d, exist_ok=True)
with open(os.path.join(d, "packing.data"), "w") as f:
    f.write("LIGGGHTS data file\n\n%d atoms\n1 atom types\n\n" % len(rows))
    f.write("-0.001 0.037 xlo xhi\n-0.001 0.033 ylo yhi\n%.17g 0.08 zlo zhi\n\nAtoms\n\n" % zlo)
    for k, (i, x, y, z, r) in enumerate(rows):
        # atom_style granular: id type diameter density x y z
        f.write("%d 1 %.17g %.17g %s %s %s\n" % (k + 1, 2 * float(r), rho, x, y, z))
model_w = "model hooke/stiffness tangential history rolling_friction epsd2"
keys = "absolute_damping on"
model = model_w + " " + keys
with open(os.path.join(d, "in.hopper"), "w") as f:
    f.write(f"""atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
read_data packing.data
neighbor 0.0005 bin
neigh_modify delay 0
fix m1 all property/global kn peratomtypepair 1 {kn!r}
fix m2 all property/global kt peratomtypepair 1 {nu_c * kn!r}
fix m3 all property/global gamman_abs peratomtypepair 1 0.0
fix m4 all property/global gammat_abs peratomtypepair 1 0.0
fix m5 all property/global coefficientFriction peratomtypepair 1 {math.tan(math.radians(mu_deg))!r}
fix m6 all property/global coefficientRollingFriction peratomtypepair 1 {eta!r}
pair_style gran {model}
pair_coeff * *
timestep {dt!r}
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix cad all mesh/surface file {os.path.abspath(stl)} type 1
fix walls all wall/gran {model_w} mesh n_meshes 1 meshes cad {keys}
fix integr all nve/sphere
thermo_style custom step atoms ke
thermo_modify lost ignore norm no
thermo {steps}
run 1
run {steps}
""")
