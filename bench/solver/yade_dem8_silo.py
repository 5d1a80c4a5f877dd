# DEM8 Case 1 (silo discharge) in YADE 2023.02a, as the benchmark's own YADE script
# (/usr/share/doc/yade/examples/DEM2020Benchmark/Case1_SiloFlow.py) sets it up: the steel silo
# as facets (Ig2_Facet_Sphere_ScGeom(hertzian=True)), spheres of M1 (or M2),
# Ip2_FrictMat_FrictMat_MindlinPhys with the benchmark's friction angles and restitutions by
# MatchMaker, Law2_ScGeom_MindlinPhys_Mindlin, no global damping, verletDist 0.1 r, dt 1.5 us
# (M2: 2 us), the spheres below the orifice erased every 500 steps. The benchmark's settled
# packing is not available: the spheres come from a CSV (id,x,y,z,r: a granoscope frame), at rest.
#   yade -j1 -n -x bench/solver/yade_dem8_silo.py PACKING.csv WALLS.txt ORIFICE_Z M1|M2 STEPS
import csv, math, os, sys, tempfile, time
from yade import *
from yade import ymport

packing, walls, z_orifice, material, steps = (sys.argv[1], sys.argv[2], float(sys.argv[3]),
                                              sys.argv[4], int(sys.argv[5]))
steel = O.materials.append(FrictMat(young=210e9, poisson=0.2, density=7200, label='Steel'))
if material == 'M1':
    O.materials.append(FrictMat(young=1.0e9, poisson=0.2, density=2500, label='M1'))
    e_gg, f_gg, e_gs, f_gs, dt = 0.5, 0.3, 0.4, 0.2, 1.5e-6
else:
    O.materials.append(FrictMat(young=0.5e9, poisson=0.2, density=2000, label='M2'))
    e_gg, f_gg, e_gs, f_gs, dt = 0.4, 0.4, 0.4, 0.2, 2e-6
tmp = tempfile.mkdtemp()
wf = os.path.join(tmp, "walls.txt")
with open(walls) as a, open(wf, "w") as b:  # textFacets wants the header commented out
    b.write("#" + a.read().replace("\r", ""))
O.bodies.append(ymport.textFacets(wf, material=steel))
n = 0
for row in csv.DictReader(open(packing)):
    O.bodies.append(sphere((float(row['x']), float(row['y']), float(row['z'])), float(row['r']),
                           material=material))
    n += 1
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()], label="collider"),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom(hertzian=True)],
                    [Ip2_FrictMat_FrictMat_MindlinPhys(
                        frictAngle=MatchMaker(matches=((1, 1, math.atan(f_gg)),
                                                       (0, 1, math.atan(f_gs)))),
                        en=MatchMaker(matches=((1, 1, e_gg), (0, 1, e_gs))))],
                    [Law2_ScGeom_MindlinPhys_Mindlin(preventGranularRatcheting=False)]),
    NewtonIntegrator(damping=0, gravity=[0, 0, -9.810]),
]
collider.verletDist = 0.1 * O.bodies[-1].shape.radius
O.dynDt = False
O.dt = dt
erased = 0
t0 = time.time()
while O.iter < steps:
    O.run(min(500, steps - O.iter), True)
    gone = [b.id for b in O.bodies if isinstance(b.shape, Sphere) and b.state.pos[2] < z_orifice]
    for i in gone:
        O.bodies.erase(i)
    erased += len(gone)
print("steps", O.iter, "particles", n, "erased", erased, "wall time", time.time() - t0)
