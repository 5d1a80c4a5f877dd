# DEM8 Case 2 (rotating drum) in YADE 2023.02a, as the benchmark's own YADE script
# (/usr/share/doc/yade/examples/DEM2020Benchmark/Case2_rotating_drum_openmp.py) sets it up:
# steel facets (Ig2_Facet_Sphere_ScGeom(hertzian=True)) turning at 2 rad/s about +y through the
# origin (RotationEngine), the bed of M1 (r = 1 mm) and M2 (r = 2 mm) grains, the script's
# restitution and friction per material pair (MatchMaker), Law2_ScGeom_MindlinPhys_Mindlin (the
# script's preventGranularRatcheting=False is left out: 2023.02a ignores it and warns), no global damping, dt = 0.8 us, its Verlet distance 1e-4 m. The
# script reads the grains from two files per material; the shared bed has them in one file with
# the radius, split here by radius. Runs STEPS steps after one warm-up step, prints the wall time.
#   yade -j1 -n -x bench/solver/yade_dem8_drum.py PartCoordinates.txt walls.txt STEPS
import math, os, sys, tempfile, time
from yade import *
from yade import ymport

parts, walls, steps = sys.argv[1], sys.argv[2], int(sys.argv[3])
steel = O.materials.append(FrictMat(young=210e9, poisson=0.2, density=7200, label='Steel'))
m1 = O.materials.append(FrictMat(young=1.0e9, poisson=0.2, density=2500, label='M1'))
m2 = O.materials.append(FrictMat(young=0.5e9, poisson=0.2, density=2000, label='M2'))
tmp = tempfile.mkdtemp()
wf = os.path.join(tmp, "walls.txt")
with open(walls) as a, open(wf, "w") as b:  # textFacets wants the header commented out
    b.write("#" + a.read().replace("\r", ""))
facets = ymport.textFacets(wf, material=steel)
spheres = []
with open(parts) as f:
    f.readline()
    for line in f:
        c = line.split()
        if len(c) != 4:
            continue
        r, x, y, z = (float(v) for v in c)
        spheres.append(sphere((x, y, z), r, material=m2 if r > 0.0015 else m1))
fr = MatchMaker(matches=((m1, m1, math.atan(0.3)), (steel, m1, math.atan(0.2)),
                         (steel, m2, math.atan(0.2)), (m1, m2, math.atan(0.2)),
                         (m2, m2, math.atan(0.4))))
en = MatchMaker(matches=((m1, m1, 0.5), (steel, m1, 0.4), (steel, m2, 0.4), (m1, m2, 0.45),
                         (m2, m2, 0.4)))
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()], label="collider"),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom(hertzian=True)],
                    [Ip2_FrictMat_FrictMat_MindlinPhys(frictAngle=fr, en=en)],
                    [Law2_ScGeom_MindlinPhys_Mindlin()]),
    NewtonIntegrator(damping=0, gravity=(0, 0, -9.81)),
    RotationEngine(rotateAroundZero=True, zeroPoint=(0, 0, 0), rotationAxis=(0, 1, 0),
                   angularVelocity=2, ids=range(len(facets))),
]
O.bodies.append(facets)
O.bodies.append(spheres)
collider.verletDist = 1e-4  # (the script's: 10 % of the smallest radius)
O.dt = 8e-7
O.run(1, True)
t0 = time.time()
O.run(steps, True)
print("steps", steps, "particles", len(spheres), "wall time", time.time() - t0)
