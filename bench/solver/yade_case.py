# YADE 2023.02a timing run of a granoscope bench case. Run: yade -n -x -j1 yade_case.py PACKING.csv CASE STEPS OUT.json
# CASE = oedometer (the shared reference walls, top wall at -0.05 m/s) or box:L (static box of side L m).
# Same contact model as the solver: CohFrictMat, Law2_ScGeom6D_CohFrictPhys_CohesionMoment.
import json, sys, time
packing, case, steps, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
mat = O.materials.append(CohFrictMat(young=3e7, poisson=0.3, frictionAngle=radians(18), density=2550,
                                     alphaKr=0.7, etaRoll=0.4, alphaKtw=0, isCohesive=False,
                                     momentRotationLaw=True))
for line in open(packing).read().split('\n')[1:]:
    if not line.strip(): continue
    i, x, y, z, r = line.split(',')
    O.bodies.append(sphere((float(x), float(y), float(z)), float(r), material=mat))
if case == 'oedometer':
    walls = [((0.0125, 0.0125, -0.002), (0.025, 0.025, 0.002), (0, 0, 0)),
             ((-0.002, 0.0125, 0.05), (0.002, 0.025, 0.1), (0, 0, 0)),
             ((0.027, 0.0125, 0.05), (0.002, 0.025, 0.1), (0, 0, 0)),
             ((0.0125, -0.002, 0.05), (0.025, 0.002, 0.1), (0, 0, 0)),
             ((0.0125, 0.027, 0.05), (0.025, 0.002, 0.1), (0, 0, 0)),
             ((0.0125, 0.0125, 0.0317046381579962), (0.025, 0.025, 0.002), (0, 0, -0.05))]
else:
    L = float(case.split(':')[1]); h = 0.002
    walls = [((L/2, L/2, -h), (L, L, h), (0, 0, 0)), ((-h, L/2, L/2), (h, L, L), (0, 0, 0)),
             ((L + h, L/2, L/2), (h, L, L), (0, 0, 0)), ((L/2, -h, L/2), (L, h, L), (0, 0, 0)),
             ((L/2, L + h, L/2), (L, h, L), (0, 0, 0)), ((L/2, L/2, L + h), (L, L, h), (0, 0, 0))]
for c, e, v in walls:
    b = box(c, e, fixed=True, material=mat)
    b.state.vel = v
    O.bodies.append(b)
O.engines = [ForceResetter(),
             InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom6D()],
                             [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
                             [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)]),
             NewtonIntegrator(damping=0.08, gravity=(0, 0, -9.81))]
O.dt = 1e-6
O.step()
t0 = time.time()
O.run(steps, True)
dt = time.time() - t0
n = sum(1 for b in O.bodies if isinstance(b.shape, Sphere))
json.dump({'spheres': n, 'steps': steps, 'seconds': dt, 'particle_steps_per_s': n * steps / dt}, open(out, 'w'))
