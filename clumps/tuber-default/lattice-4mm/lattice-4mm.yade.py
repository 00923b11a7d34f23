# clumpforge 0.1.0 clump 'lattice-4mm' (lattice method, 55 spheres); source mesh sha256 5db4afcccbb2a7c789b14ac39696b4eac1c93a0be396907af4818598252d7e63; frame: principal axes, centre of mass at the origin; SI units
# Builds the clump in YADE with the body's centre of mass, principal axes, mass and inertia. In a YADE script:
#   exec(open('lattice-4mm.yade.py').read()); clump_id = add_clump(material=my_material, position=Vector3(0, 0, 0.1))
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
CF_SPHERES_FILE = os.path.join(os.path.dirname(os.path.abspath(globals().get('__file__', 'lattice-4mm.yade.py'))), 'lattice-4mm.yade.txt')
CF_MASS = 0.0037143881418471576  # kg
CF_INERTIA = Matrix3(1.0981826897242915e-07, 0, 0,
                     0, 1.4064971395594661e-07, 0,
                     0, 0, 1.8135121057762288e-07)  # kg m^2, file frame, about the centre of mass
CF_DENSITY = 1085  # kg/m^3
CF_WEIGHTING_RADII = [
    0.0018772558200809977, 0.0019933494997406713, 0.0019736073603944062, 0.0019534621518903826,
    0.001932892648564138, 0.0019118757777898375, 0.002061370986611329, 0.0020429279743429504,
    0.0020241458131786453, 0.0020050084678775236, 0.0019854986546080067, 0.0021251771882407284,
    0.0021078387281973886, 0.0020902102346169872, 0.002072279265387928, 0.0020540325017643379,
    0.0019715337262202893, 0.0019513454585907033, 0.0019307305888949301, 0.0020149821845849023,
    0.0019956678450252585, 0.0019759722355762338, 0.0019558759641777525, 0.0019353580108124745,
    0.0020381043695203958, 0.0020192319490232153, 0.0020000000000000005, 0.0019803908940908372,
    0.0019603855779089826, 0.0019399634096781751, 0.0020607134913280469, 0.0020422585482498183,
    0.0020234638998828489, 0.0020043134682743999, 0.0019847899222389526, 0.0020647772838861657,
    0.0020463958952711948, 0.0020276782226695241, 0.0020201995080922999, 0.0020361600895783503,
    0.0020172511019028736, 0.0019979808163960418, 0.0019783314636262488, 0.0019582838331918787,
    0.0020142940516692008, 0.0019949663209437173, 0.0019752566492380985, 0.0019551455890124891,
    0.0019346120582612752, 0.0019919426877437417, 0.0019721722320132544, 0.0019519972378412409,
    0.0019313963536585321, 0.0019103463656068053, 0.0019281699051874603,
]  # m, one per sphere in file order

def add_clump(material=None, position=Vector3(0, 0, 0), spheres_file=None):
    kw = {} if material is None else {'material': material}
    path = spheres_file or CF_SPHERES_FILE
    if not os.path.exists(path):
        path = os.path.join(os.getcwd(), 'lattice-4mm.yade.txt')
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
