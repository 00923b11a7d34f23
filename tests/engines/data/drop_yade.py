# Drop one exported clump onto a plane in YADE (clumpforge export test).
# Usage: yade -n -x drop_yade.py EXPORTED_SCRIPT.py
import sys
exec(open(sys.argv[1]).read())
mat = O.materials.append(FrictMat(young=5e6, poisson=0.4, density=1085, frictionAngle=0.5))
O.bodies.append(utils.wall(0, axis=2, sense=1, material=mat))
clump_id = add_clump(material=mat, position=Vector3(0, 0, 0.03))
state = O.bodies[clump_id].state
print('CF_MEMBERS', len(O.bodies[clump_id].shape.members))
print('CF_MASS', state.mass)
print('CF_INERTIA', state.inertia[0], state.inertia[1], state.inertia[2])
print('CF_Z0', state.pos[2])
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                             [Law2_ScGeom_FrictPhys_CundallStrack()]),
             NewtonIntegrator(gravity=(0, 0, -9.81), damping=0.3)]
O.dt = 0.5 * PWaveTimeStep()
O.run(int(1.0 / O.dt), True)  # rocking on its flat face ends by 0.75 s
print('CF_Z1', state.pos[2])
print('CF_SPEED', state.vel.norm())
