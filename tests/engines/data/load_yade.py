# Load one exported clump in YADE and report what YADE holds (clumpforge export test).
# Usage: yade -n -x load_yade.py EXPORTED_SCRIPT.py X Y Z
# Prints the clump's mass, position, inertia in its own frame, that frame's axes in the
# world, and every member's world position and radius after one step without gravity.
import sys
exec(open(sys.argv[1]).read())
mat = O.materials.append(FrictMat(young=5e6, poisson=0.4, density=1085, frictionAngle=0.5))
position = Vector3(float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]))
clump_id = add_clump(material=mat, position=position)
O.engines = [ForceResetter(), NewtonIntegrator(gravity=(0, 0, 0), damping=0.0)]
O.dt = 1e-6
O.run(1, True)
state = O.bodies[clump_id].state
rotation = state.ori.toRotationMatrix()
print('CF_MASS %.17g' % state.mass)
print('CF_POS %.17g %.17g %.17g' % (state.pos[0], state.pos[1], state.pos[2]))
print('CF_INERTIA %.17g %.17g %.17g' % (state.inertia[0], state.inertia[1], state.inertia[2]))
print('CF_AXES ' + ' '.join('%.17g' % rotation[i, j] for j in range(3) for i in range(3)))
for member_id in sorted(O.bodies[clump_id].shape.members.keys()):
    b = O.bodies[member_id]
    print('CF_MEMBER %.17g %.17g %.17g %.17g' % (b.state.pos[0], b.state.pos[1], b.state.pos[2], b.shape.radius))
