# YADE 2023.02a reference for the Hertz-Mindlin law (Ip2_FrictMat_FrictMat_MindlinPhys with a
# coefficient of restitution + Law2_ScGeom_MindlinPhys_Mindlin, the law the DEM8 benchmark
# prescribes): 240 spheres (r 1.0-1.4 mm, seeded) in 16 columns with gaps, falling under gravity
# into a 12 x 12 mm box of five box walls, no global damping. Writes packing.csv (id,x,y,z,r),
# and state_STEP.csv (id,x,y,z,vx,vy,vz,wx,wy,wz) after the steps asked for.
#   yade -x -n bench/solver/yade_hertz_case.py OUT_DIR [STEPS ...]
import math, os, random, sys
from yade import *

out = sys.argv[1]
marks = [int(a) for a in sys.argv[2:]] or [2500, 5000]
os.makedirs(out, exist_ok=True)
E, nu, rho, mu, en = 5e7, 0.3, 2600.0, 0.4, 0.6
mat = O.materials.append(FrictMat(young=E, poisson=nu, density=rho, frictionAngle=math.atan(mu)))
L = 0.012
walls = [((L / 2, L / 2, -0.001), (L, L, 0.001)),
         ((-0.001, L / 2, 0.02), (0.001, L, 0.04)), ((L + 0.001, L / 2, 0.02), (0.001, L, 0.04)),
         ((L / 2, -0.001, 0.02), (L, 0.001, 0.04)), ((L / 2, L + 0.001, 0.02), (L, 0.001, 0.04))]
for c, h in walls:
    O.bodies.append(box(center=c, extents=h, fixed=True, material=mat))
random.seed(7)
rows = []
for iz in range(15):  # 4 x 4 columns, 2.95 mm apart, layers 3.1 mm apart: no initial contact
    for iy in range(4):
        for ix in range(4):
            r = 0.001 + 0.0004 * random.random()
            x = 0.00146 + ix * 0.00295 + 0.00005 * random.random() + (0.00015 if iz % 2 else 0)
            y = 0.00146 + iy * 0.00295 + 0.00005 * random.random()
            z = 0.0016 + iz * 0.0031 + 0.0001 * random.random()
            rows.append((x, y, z, r))
ids = []
with open(os.path.join(out, "packing.csv"), "w") as f:
    f.write("id,x,y,z,r\n")
    for i, (x, y, z, r) in enumerate(rows):
        b = O.bodies.append(sphere((x, y, z), r, material=mat))
        ids.append(b)
        f.write("%d,%.17g,%.17g,%.17g,%.17g\n" % (i, x, y, z, r))
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
                    [Ip2_FrictMat_FrictMat_MindlinPhys(en=en, es=en)],
                    [Law2_ScGeom_MindlinPhys_Mindlin()]),
    NewtonIntegrator(damping=0.0, gravity=(0, 0, -9.81)),
]
G = E / (2 * (1 + nu))
rayleigh = math.pi * 0.001 * math.sqrt(rho / G) / (0.1631 * nu + 0.8766)
O.dt = 0.2 * rayleigh
print("dt", repr(O.dt))
done = 0
for m in sorted(marks):
    O.run(m - done, True)
    done = m
    with open(os.path.join(out, "state_%d.csv" % m), "w") as f:
        f.write("id,x,y,z,vx,vy,vz,wx,wy,wz\n")
        for i, b in enumerate(ids):
            s = O.bodies[b].state
            f.write("%d,%s\n" % (i, ",".join("%.17g" % v for v in
                                             (*s.pos, *s.vel, *s.angVel))))
    print("step", m, "contacts", sum(1 for i in O.interactions if i.isReal))
with open(os.path.join(out, "dt.txt"), "w") as f:
    f.write("%.17g\n" % O.dt)
print("lgr", O.engines[2].lawDispatcher.functors[0].preventGranularRatcheting)
