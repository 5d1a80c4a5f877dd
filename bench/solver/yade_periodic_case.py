# YADE 2023.02a timing run of a shared periodic case (../shared/reference/yade/periodic: 1000
# spheres sheared at constant volume; or periodic2d: 600 spheres in the plane, blockedDOFs
# 'zXY', constant-area biaxial strain). Run: yade -n -x -j1 yade_periodic_case.py REF_DIR STEPS OUT.json
# Built as the reference README says (O.cell.hSize and O.cell.velGrad from case.json, the same
# engines and parameters); no recorders. Rate = spheres x steps / s over the steps after the first.
import csv, json, sys, time
ref, steps, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
case = json.load(open(ref + '/case.json'))
O.periodic = True
h = case['hsize']
O.cell.hSize = Matrix3(*[h[i][j] for i in range(3) for j in range(3)])
m = case['material']
mat = O.materials.append(CohFrictMat(young=m['young'], poisson=m['stiffness_ratio'], frictionAngle=radians(m['friction_deg']),
                                     density=m['density'], alphaKr=m['rolling_stiffness'], etaRoll=m['rolling_limit'],
                                     alphaKtw=0, etaTwist=-1, isCohesive=False, momentRotationLaw=True))
n = 0
for r in csv.DictReader(open(ref + '/packing.csv')):
    b = utils.sphere((float(r['x']), float(r['y']), float(r['z'])), float(r['r']), material=mat)
    if 'blocked_dofs' in case: b.state.blockedDOFs = case['blocked_dofs']
    O.bodies.append(b)
    n += 1
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(avoidGranularRatcheting=True)],
                             [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
                             [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)]),
             NewtonIntegrator(damping=case['damping'], gravity=(0, 0, 0))]
O.dt = case['dt']
L = case['vel_grad']
O.cell.velGrad = Matrix3(*[L[i][j] for i in range(3) for j in range(3)])
O.step()
t0 = time.time()
O.run(steps, True)
dt = time.time() - t0
s = utils.getStress()
json.dump({'steps': steps, 'seconds': dt, 'spheres': n, 'contacts': sum(1 for i in O.interactions if i.isReal),
           'sxz': s[0, 2], 'sxx': s[0, 0], 'particle_steps_per_s': n * steps / dt}, open(out, 'w'))
