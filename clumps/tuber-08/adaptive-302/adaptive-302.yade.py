# clumpforge 0.1.0 clump 'adaptive-302' (adaptive method, 302 spheres); source mesh sha256 093d8ce657526ed32ea4c9c82f8696cb0d3cb3b043835b13ffd1022e7d7b067b; frame: principal axes, centre of mass at the origin; SI units
# Builds the clump in YADE with the body's true mass and inertia. Use inside a YADE script:
#   exec(open('adaptive-302.yade.py').read()); clump_id = add_clump(material=my_material, position=Vector3(0, 0, 0.1))
# ymport.textClumps sums the spheres' volumes (overlaps counted twice), so the mass and inertia it
# computes are replaced here. YADE keeps a diagonal inertia in the clump's own frame, which it
# chooses from the spheres; the body's tensor is expressed in that frame and its diagonal is used.
import os
from yade import ymport
from yade.minieigenHP import Vector3, Matrix3, Quaternion
CF_SPHERES_FILE = os.path.join(os.path.dirname(os.path.abspath(globals().get('__file__', 'adaptive-302.yade.py'))), 'adaptive-302.yade.txt')
CF_MASS = 0.0026692939976871262  # kg
CF_PRINCIPAL_MOMENTS = Vector3(6.9775016289187576e-08, 7.3071520767278469e-08, 1.0170810210228337e-07)  # kg m^2, about the principal axes x, y, z
CF_DENSITY = 1085  # kg/m^3

def add_clump(material=None, position=Vector3(0, 0, 0), spheres_file=None):
    kw = {} if material is None else {'material': material}
    path = spheres_file or CF_SPHERES_FILE
    if not os.path.exists(path):
        path = os.path.join(os.getcwd(), 'adaptive-302.yade.txt')
    clump_id = ymport.textClumps(path, shift=position, **kw)[0][0]
    state = O.bodies[clump_id].state
    rotation = state.ori.toRotationMatrix()
    body = Matrix3(CF_PRINCIPAL_MOMENTS[0], 0, 0, 0, CF_PRINCIPAL_MOMENTS[1], 0, 0, 0, CF_PRINCIPAL_MOMENTS[2])
    local = rotation.transpose() * body * rotation
    state.mass = CF_MASS
    state.inertia = Vector3(local[0, 0], local[1, 1], local[2, 2])
    return clump_id
