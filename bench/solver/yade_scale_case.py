# YADE 2023.02a timing run of issue 23's benchmark packing (bench/solver/run_scale_bench.sh).
# Run: yade -n -x -jN yade_scale_case.py PACKING.csv LX LY LZ STEPS DT OUT.json
# The packing at rest between six fixed box walls around [0, L], no gravity; the granoscope
# scene's material and law: CohFrictMat (Ec 3e8, νc 0.3, μ 18°, ρ 2600, β 0.7, η 0.4),
# Law2_ScGeom6D_CohFrictPhys_CohesionMoment, damping 0.08.
import json, resource, sys, time
packing, lx, ly, lz, steps, dt, out = (sys.argv[1], float(sys.argv[2]), float(sys.argv[3]),
                                       float(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6]), sys.argv[7])
mat = O.materials.append(CohFrictMat(young=3e8, poisson=0.3, frictionAngle=radians(18), density=2600,
                                     alphaKr=0.7, etaRoll=0.4, alphaKtw=0, isCohesive=False,
                                     momentRotationLaw=True))
t_load = time.time()
spheres = []
with open(packing) as f:
    next(f)
    for line in f:
        i, x, y, z, r = line.split(',')
        spheres.append(sphere((float(x), float(y), float(z)), float(r), material=mat))
O.bodies.append(spheres)
h = 0.002
for c, e in (((lx/2, ly/2, -h), (lx, ly, h)), ((lx/2, ly/2, lz + h), (lx, ly, h)),
             ((-h, ly/2, lz/2), (h, ly, lz)), ((lx + h, ly/2, lz/2), (h, ly, lz)),
             ((lx/2, -h, lz/2), (lx, h, lz)), ((lx/2, ly + h, lz/2), (lx, h, lz))):
    O.bodies.append(box(c, e, fixed=True, material=mat))
O.engines = [ForceResetter(),
             InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom6D()],
                             [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
                             [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)]),
             NewtonIntegrator(damping=0.08, gravity=(0, 0, 0))]
O.dt = dt
O.step()  # (the first step: the collider's initial sort and the contacts' creation)
setup = time.time() - t_load
t0 = time.time()
O.run(steps, True)
secs = time.time() - t0
n = len(spheres)
json.dump({'spheres': n, 'steps': steps, 'seconds': secs, 'setup_seconds': setup,
           'particle_steps_per_s': n * steps / secs,
           'max_rss_kB': resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
           'contacts': sum(1 for i in O.interactions if i.isReal)}, open(out, 'w'))
