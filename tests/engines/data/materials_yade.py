# Load exported materials in YADE and drop one sphere of the particle material onto a wall of
# each surface (clumpforge materials export test). Usage: yade -n -x materials_yade.py materials.py
# Prints, per surface, the apparent restitution sqrt(apex / drop) of the first rebound.
import sys
from math import sqrt
exec(open(sys.argv[1]).read())
for surface in ('Q235', 'soil'):
    O.reset()
    exec(open(sys.argv[1]).read())
    radius, height = 0.005, 0.1
    ball = O.bodies.append(utils.sphere((0, 0, height + radius), radius, material=CF_MATERIALS['tuber']))
    O.bodies.append(utils.wall(0, axis=2, sense=1, material=CF_MATERIALS[surface]))
    O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()], [CF_IP2], [CF_LAW2]),
                 NewtonIntegrator(gravity=(0, 0, -9.81), damping=0)]
    O.dt = 1e-5  # about 75 steps per Hertz contact of this sphere
    apex, touched = 0.0, False
    while O.time < 1.0:
        O.step()  # synchronous: O.run(n, True) polls with sleeps
        gap = O.bodies[ball].state.pos[2] - radius
        touched = touched or gap < 0
        if touched and gap > 0:
            apex = max(apex, gap)
            if O.bodies[ball].state.vel[2] < 0:
                break
    print('CF_RESTITUTION %s %.6f' % (surface, sqrt(apex / height)))
