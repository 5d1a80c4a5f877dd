# YADE 2023.02a timing run of the shared facet silo (../shared/reference/yade/facets: 1000 spheres,
# 48 facets, discharge through the orifice). Run: yade -n -x -j1 yade_facets_case.py REF_DIR STEPS OUT.json
# Same engines and parameters as the reference run (README there); no recorders.
import csv, json, sys, time
ref, steps, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
mat = O.materials.append(CohFrictMat(young=2e6, poisson=0.3, frictionAngle=radians(18), density=2550,
                                     alphaKr=0.5, etaRoll=0.2, alphaKtw=0, etaTwist=-1,
                                     isCohesive=False, momentRotationLaw=True))
for r in csv.DictReader(open(ref + '/packing.csv')):
    O.bodies.append(sphere((float(r['x']), float(r['y']), float(r['z'])), float(r['r']), material=mat))
for r in csv.DictReader(open(ref + '/mesh.csv')):
    v = [Vector3(*[float(r['v%d%s' % (k, c)]) for c in 'xyz']) for k in range(3)]
    O.bodies.append(facet(v, material=mat))
O.engines = [ForceResetter(),
             InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Facet_Sphere_ScGeom6D()],
                             [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
                             [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)]),
             NewtonIntegrator(damping=0.1, gravity=(0, 0, -9.81))]
O.dt = 1.43e-05
O.step()
t0 = time.time()
O.run(steps, True)
dt = time.time() - t0
json.dump({'steps': steps, 'seconds': dt, 'particle_steps_per_s': 1000 * steps / dt}, open(out, 'w'))
