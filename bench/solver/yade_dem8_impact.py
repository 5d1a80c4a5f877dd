# DEM8 Case 3 (penetration) in YADE 2023.02a, as the benchmark's own YADE script
# (/usr/share/doc/yade/examples/DEM2020Benchmark/Case3_PenetrationTest.py) sets it up: steel
# facets (Ig2_Facet_Sphere_ScGeom(hertzian=True)), the bed of material M1, the steel ball,
# Ip2_FrictMat_FrictMat_MindlinPhys with the benchmark's restitutions (M1-M1 0.5, M1-steel 0.4,
# steel-steel 0.4) and Law2_ScGeom_MindlinPhys_Mindlin, no global damping, dt = 0.5 us. The ball
# starts at (0, 0, Z0) with velocity (0, 0, -V0) (the shipped script reads a ball row that the
# shared bed file does not have, so the ball is placed here), and the run records its height.
#   yade -j1 -n -x bench/solver/yade_dem8_impact.py PARTICLES.txt WALLS.txt N Z0 V0 T_END OUT.csv
import math, os, sys, tempfile, time
from yade import *
from yade import ymport

parts, walls, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
z0, v0, t_end, out = float(sys.argv[4]), float(sys.argv[5]), float(sys.argv[6]), sys.argv[7]
steel = O.materials.append(FrictMat(young=210e9, poisson=0.2, density=7200,
                                    frictionAngle=math.atan(0.2), label='Steel'))
m1 = O.materials.append(FrictMat(young=1.0e9, poisson=0.2, density=2500,
                                 frictionAngle=math.atan(0.3), label='M1'))
tmp = tempfile.mkdtemp()
wf = os.path.join(tmp, "walls.txt")
with open(walls) as a, open(wf, "w") as b:  # textFacets wants the header commented out
    b.write("#" + a.read().replace("\r", ""))
O.bodies.append(ymport.textFacets(wf, material=steel))
rows = []
with open(parts) as f:
    f.readline()
    for line in f:
        c = line.split()
        if len(c) != 4:
            continue
        rows.append([float(v) for v in c])
        if len(rows) == n:
            break
for r, x, y, z in rows:
    O.bodies.append(sphere((x, y, z), r, material=m1))
ball = O.bodies.append(sphere((0, 0, z0), 0.01, material=steel))
O.bodies[ball].state.vel = (0, 0, -v0)
O.dt = 5e-7
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()], verletDist=-0.1),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom(hertzian=True)],
                    [Ip2_FrictMat_FrictMat_MindlinPhys(
                        en=MatchMaker(matches=((1, 1, 0.5), (0, 1, 0.4), (0, 0, 0.4))))],
                    [Law2_ScGeom_MindlinPhys_Mindlin()]),
    NewtonIntegrator(damping=0, gravity=(0, 0, -9.81)),
]
f = open(out, "w")
f.write("step,time_s,z_m,vz_m_s\n")


def record():
    s = O.bodies[ball].state
    f.write("%d,%.17g,%.17g,%.17g\n" % (O.iter, O.time, s.pos[2], s.vel[2]))
    f.flush()


record()
O.engines = O.engines + [PyRunner(iterPeriod=100, command="record()")]
t0 = time.time()
O.run(int(round(t_end / O.dt)), True)
record()  # the end (the recorder runs before each hundredth step, so it last saw step N - 100)
print("steps", O.iter, "particles", len(rows) + 1, "wall time", time.time() - t0)
