# clumpforge 0.1.0 clump 'adaptive-55' (adaptive method, 55 spheres); source mesh sha256 5db4afcccbb2a7c789b14ac39696b4eac1c93a0be396907af4818598252d7e63; frame: principal axes, centre of mass at the origin; SI units
# Builds the clump in YADE with the body's centre of mass, principal axes, mass and inertia. In a YADE script:
#   exec(open('adaptive-55.yade.py').read()); clump_id = add_clump(material=my_material, position=Vector3(0, 0, 0.1))
# `position` is where the body's centre of mass goes; the clump keeps the file's orientation.
# YADE places a clump at its members' volume centroid (overlaps counted twice) with axes along their
# principal axes. The members are therefore clumped with the weighting radii below, whose volumes put
# that centroid on the body's centre of mass and those axes on the body's principal axes (computed by
# clumpforge: centroid within 1e-9 m, axes within 1e-6 deg), and then given their true radii and
# masses; the clump's mass and inertia are set to the body's.
import os
from math import pi
from yade import utils
from yade.minieigenHP import Vector3, Matrix3
CF_SPHERES_FILE = os.path.join(os.path.dirname(os.path.abspath(globals().get('__file__', 'adaptive-55.yade.py'))), 'adaptive-55.yade.txt')
CF_MASS = 0.0037143881418471576  # kg
CF_INERTIA = Matrix3(1.0981826897242915e-07, 0, 0,
                     0, 1.4064971395594661e-07, 0,
                     0, 0, 1.8135121057762288e-07)  # kg m^2, file frame, about the centre of mass
CF_DENSITY = 1085  # kg/m^3
CF_WEIGHTING_RADII = [
    0.0068204784519908255, 0.0060566618274444112, 0.006093502873495779, 0.0050677710143515542,
    0.0059155165062550917, 0.0054988192380004287, 0.005145362232678574, 0.0052453108216562972,
    0.0047979062553984179, 0.0058326417250226768, 0.0051156655050561845, 0.0049921815489939389,
    0.0062049959303127188, 0.0069620436929193853, 0.005433011961438596, 0.0049018162489740192,
    0.0047937881281183321, 0.0045145927540471281, 0.0059197360847200843, 0.0067301690909116934,
    0.0053989782596311807, 0.0038908398788163106, 0.0047599294773912103, 0.0050446151218016995,
    0.0062769739680033059, 0.0062947886322669965, 0.005791827765777309, 0.0063582791605081134,
    0.0068123805799795685, 0.004346057989555163, 0.0037383700092394174, 0.0040503189918863307,
    0.0040181932434401246, 0.004701169096400384, 0.0034460863600952584, 0.0061163268932702556,
    0.004280850592971213, 0.0055573200468614732, 0.0048364577447406933, 0.005432997936917333,
    0.0048340847805633186, 0.0052597640062223725, 0.0042754054123834402, 0.0066346008460434445,
    0.0069793412548724773, 0.0049908642474536793, 0.0035765071496211493, 0.0064082866199538461,
    0.0038593745732702473, 0.006972485095177723, 0.0054803113152011029, 0.0060568804363455376,
    0.0036243092837073957, 0.0053133585048278555, 0.0041800103493052866,
]  # m, one per sphere in file order

def add_clump(material=None, position=Vector3(0, 0, 0), spheres_file=None):
    kw = {} if material is None else {'material': material}
    path = spheres_file or CF_SPHERES_FILE
    if not os.path.exists(path):
        path = os.path.join(os.getcwd(), 'adaptive-55.yade.txt')
    rows = [line.split() for line in open(path) if line.strip() and not line.startswith('#')]
    if len(rows) != len(CF_WEIGHTING_RADII):
        raise ValueError('%s has %d spheres, this script expects %d' % (path, len(rows), len(CF_WEIGHTING_RADII)))
    centres = [Vector3(float(r[0]), float(r[1]), float(r[2])) for r in rows]
    members = [utils.sphere(position + x, w, **kw) for x, w in zip(centres, CF_WEIGHTING_RADII)]
    clump_id, member_ids = O.bodies.appendClumped(members)
    for member_id, row in zip(member_ids, rows):
        member = O.bodies[member_id]
        radius = float(row[3])
        member.shape.radius = radius
        member.state.mass = member.material.density * 4.0 / 3.0 * pi * radius ** 3
        member.state.inertia = Vector3(1, 1, 1) * 0.4 * member.state.mass * radius ** 2
    state = O.bodies[clump_id].state
    rotation = state.ori.toRotationMatrix()
    local = rotation.transpose() * CF_INERTIA * rotation
    state.mass = CF_MASS
    state.inertia = Vector3(local[0, 0], local[1, 1], local[2, 2])
    return clump_id
