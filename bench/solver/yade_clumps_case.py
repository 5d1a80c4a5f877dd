# YADE 2023.02a timing run of the shared clump case (../shared/reference/yade/clumps: 400 clumps of
# 2 or 4 overlapping spheres, 1200 members, 5 box walls and a top box moving down at 0.03 m/s).
# Run: yade -n -x -j1 yade_clumps_case.py REF_DIR STEPS OUT.json
# Built as the reference README says (appendClumped of packing.csv's members, discretization = 0,
# the same engines and parameters); no recorders. Rate = member spheres x steps / s.
import csv, json, sys, time
ref, steps, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
case = json.load(open(ref + '/case.json'))
m = case['material']
mat = O.materials.append(CohFrictMat(young=m['young'], poisson=m['stiffness_ratio'], frictionAngle=radians(m['friction_deg']),
                                     density=m['density'], alphaKr=m['rolling_stiffness'], etaRoll=m['rolling_limit'],
                                     alphaKtw=0, etaTwist=-1, isCohesive=False, momentRotationLaw=True))
for w in case['walls']:
    b = utils.box(center=w['center'], extents=w['half_extents'], fixed=True, material=mat)
    b.state.vel = Vector3(*w['velocity'])
    O.bodies.append(b)
clumps = {}
for r in csv.DictReader(open(ref + '/packing.csv')):
    clumps.setdefault(int(r['clump']), []).append(((float(r['x']), float(r['y']), float(r['z'])), float(r['r'])))
members = 0
for c in sorted(clumps):
    O.bodies.appendClumped([utils.sphere(x, r, material=mat) for x, r in clumps[c]], discretization=0)
    members += len(clumps[c])
O.engines = [ForceResetter(),
             InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom6D()],
                             [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
                             [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)]),
             NewtonIntegrator(damping=case['damping'], gravity=case['gravity'])]
O.dt = case['dt']
O.step()
t0 = time.time()
O.run(steps, True)
dt = time.time() - t0
contacts = sum(1 for i in O.interactions if i.isReal)
json.dump({'steps': steps, 'seconds': dt, 'members': members, 'contacts': contacts,
           'particle_steps_per_s': members * steps / dt}, open(out, 'w'))
