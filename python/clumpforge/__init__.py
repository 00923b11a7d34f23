"""clumpforge: multi-sphere clumps from particle scans, their DEM tests, calibration and
diagnosis, from Python.

Lengths are in metres, masses in kg, densities in kg/m^3, angles in degrees where the name
says ``_deg``; arrays are numpy arrays. Every function that runs long releases the GIL and
takes ``progress=callable(stage, fraction)``; raising inside the callback (or Ctrl-C)
stops the work and raises here. Failures raise ``clumpforge.Error`` subclasses carrying the
library's message (the one the command line prints)::

    import clumpforge as cf
    mesh = cf.load_mesh("meshes/tuber-default.stl", units="mm")
    repaired = cf.repair(mesh)
    props = cf.mass_properties(repaired.mesh, density=1085.0)
    clump = cf.fill(repaired.mesh, method="lattice", diameter=0.002, density=1085.0)
"""

from . import errors
from .errors import (
    CancelledError,
    Error,
    InvalidArgumentError,
    InvalidMeshError,
    IoError,
    NotFoundError,
    ParseError,
    RepairFailedError,
)
from ._clumpforge import *  # noqa: F401,F403  (the compiled library)
from ._clumpforge import __version__

__all__ = [name for name in dir() if not name.startswith("_")]
