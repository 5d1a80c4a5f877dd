# Makes the YADE importer fixtures. Run from tests/data/yade with Debian's YADE 2023.02a:
#   yade -n -x -j1 make_fixture.py
# 40 spheres settle in a box under gravity; then the spheres are written by VTKRecorder (XML .vtu)
# and by VTKExporter (legacy ASCII .vtk) together with the interactions (legacy .vtk).
from yade import pack, export
import random
random.seed(7)
O.materials.append(FrictMat(young=1e7, poisson=0.3, frictionAngle=0.5, density=2600, label='m'))
O.bodies.append(geom.facetBox((0.02, 0.02, 0.02), (0.02, 0.02, 0.02), wallMask=31))
sp = pack.SpherePack()
sp.makeCloud((0.002, 0.002, 0.002), (0.038, 0.038, 0.05), rMean=0.004, rRelFuzz=0.3, num=40, seed=3)
sp.toSimulation(material='m')
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom()],
                    [Ip2_FrictMat_FrictMat_FrictPhys()], [Law2_ScGeom_FrictPhys_CundallStrack()]),
    NewtonIntegrator(damping=0.4, gravity=(0, 0, -9.81)),
    VTKRecorder(fileName='yade_', recorders=['spheres', 'velocity', 'id', 'clumpId', 'materialId'], iterPeriod=1000000, label='rec'),
]
O.dt = 0.5 * PWaveTimeStep()
O.run(20000, True)
rec.iterPeriod = 1
O.step()
ex = export.VTKExporter('yade_export')
ex.exportSpheres(what=dict(id='b.id', linVel='b.state.vel', angVel='b.state.angVel'))
ex.exportInteractions(what=dict(id1='i.id1', id2='i.id2', forceN='i.phys.normalForce', forceT='i.phys.shearForce',
                                  normal='i.geom.normal', contactPoint='i.geom.contactPoint',
                                  penetrationDepth='i.geom.penetrationDepth'))
n_sph = sum(1 for b in O.bodies if isinstance(b.shape, Sphere))
n_ss = sum(1 for i in O.interactions if i.isReal and isinstance(O.bodies[i.id1].shape, Sphere)
           and isinstance(O.bodies[i.id2].shape, Sphere))
with open('expected.txt', 'w') as f:
    f.write('spheres %d\nsphere_sphere_interactions %d\nreal_interactions %d\niter %d\n'
            % (n_sph, n_ss, sum(1 for i in O.interactions if i.isReal), O.iter))
print(open('expected.txt').read())
