# clumpforge 0.1.0 clump 'adaptive-288' (adaptive method, 288 spheres); source mesh sha256 5727352b2f77d1da5017969b591a383a18c4ab93ed7b055c9a7280d3b4a5e0c8; frame: principal axes, centre of mass at the origin; SI units
# Builds the clump in YADE with the body's true mass and inertia. Use inside a YADE script:
#   exec(open('adaptive-288.yade.py').read()); clump_id = add_clump(material=my_material, position=Vector3(0, 0, 0.1))
# ymport.textClumps sums the spheres' volumes (overlaps counted twice), so the mass and inertia it
# computes are replaced here. YADE keeps a diagonal inertia in the clump's own frame, which it
# chooses from the spheres; the body's tensor is expressed in that frame and its diagonal is used.
import os
from yade import ymport
from yade.minieigenHP import Vector3, Matrix3, Quaternion
CF_SPHERES_FILE = os.path.join(os.path.dirname(os.path.abspath(globals().get('__file__', 'adaptive-288.yade.py'))), 'adaptive-288.yade.txt')
CF_MASS = 0.0025149572549102981  # kg
CF_PRINCIPAL_MOMENTS = Vector3(5.6778613674559279e-08, 7.4925445919748599e-08, 9.7427916641956639e-08)  # kg m^2, about the principal axes x, y, z
CF_DENSITY = 1085  # kg/m^3

def add_clump(material=None, position=Vector3(0, 0, 0), spheres_file=None):
    kw = {} if material is None else {'material': material}
    path = spheres_file or CF_SPHERES_FILE
    if not os.path.exists(path):
        path = os.path.join(os.getcwd(), 'adaptive-288.yade.txt')
    clump_id = ymport.textClumps(path, shift=position, **kw)[0][0]
    state = O.bodies[clump_id].state
    rotation = state.ori.toRotationMatrix()
    body = Matrix3(CF_PRINCIPAL_MOMENTS[0], 0, 0, 0, CF_PRINCIPAL_MOMENTS[1], 0, 0, 0, CF_PRINCIPAL_MOMENTS[2])
    local = rotation.transpose() * body * rotation
    state.mass = CF_MASS
    state.inertia = Vector3(local[0, 0], local[1, 1], local[2, 2])
    return clump_id
