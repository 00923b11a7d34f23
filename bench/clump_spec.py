"""Reading one clump of a library named on a command line as LIBRARY.h5:NAME (the bench scripts')."""
import h5py
import numpy as np


def read_clump(spec: str, *fields: str) -> tuple:
    """The clump's name and each of `fields` (datasets of its group, e.g. "spheres": x, y, z, r
    per row in the clump's frame). Raises ValueError naming the spec and what is wrong."""
    library, _, name = spec.rpartition(":")
    if not library or not name:
        raise ValueError(f"{spec}: give LIBRARY.h5:NAME")
    try:
        with h5py.File(library, "r") as f:
            group = f["clumps"][name]
            return (name, *(np.asarray(group[field][()]) for field in fields))
    except (OSError, KeyError) as e:
        raise ValueError(f"{spec}: {e}") from e
