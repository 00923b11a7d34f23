# Insert a mixture of exported clumps in YADE (clumpforge population export test).
# Usage: yade -n -x mixture_yade.py POPULATION.py N
# Prints, per inserted clump, its template, mass, principal moments, the distance of its
# centre of mass from the position asked for, and its member count, after one step.
import sys
exec(open(sys.argv[1]).read())
count = int(sys.argv[2])
mat = O.materials.append(FrictMat(young=5e6, poisson=0.4, density=1085, frictionAngle=0.5))
positions = [Vector3(0.03 * (k % 4), 0.03 * (k // 4), 0.05) for k in range(count)]
placed = add_mixture(positions, material=mat, seed=3)
O.engines = [ForceResetter(), NewtonIntegrator(gravity=(0, 0, 0), damping=0.0)]
O.dt = 1e-6
O.run(1, True)
for (clump_id, template), asked in zip(placed, positions):
    s = O.bodies[clump_id].state
    print('CF_BODY %s %.17g %.17g %.17g %.17g %.17g %d' % (template, s.mass, s.inertia[0], s.inertia[1], s.inertia[2],
                                                         (s.pos - asked).norm(), len(O.bodies[clump_id].shape.members)))
