#!/usr/bin/env python3
"""The faces a clump's rim rolls over, by its resolution.

A flattened particle rolls on its rim: the curve of the body in the plane normal to its axis
of largest moment (the flat's normal), through the centre of mass. A clump's rim is a chain of
spheres. Rolling on a flat, the contact runs over sphere i, then the body pivots about that
contact until the next sphere j lands: the rim rolls like a polygon with rounded corners, with
a face of length L between the two contact points at each change of sphere. The landing is an
impact whose normal speed is about omega * L, and the contact's damping takes a share of its
energy, so the energy lost per revolution goes with the sum of L^2 over the faces (the body's
own curvature loses nothing). Geometry only: no DEM is run, and a particle that wobbles off its
rim meets other faces (docs/diagnose.md, "Why the rolls do not converge").

For each clump: its spheres, the spheres of its rim (contacts around one revolution), the sum
of the faces' lengths, the sum of their squares and the longest face.

  bench/rim_faces.py clumps/tuber-default-ladder.h5:adaptive-32 \\
      clumps/tuber-default-ladder.h5:adaptive-256 clumps/tuber-default.h5:adaptive-340
"""
import argparse
import sys

import numpy as np

from clump_spec import read_clump


def rim_faces(centres: np.ndarray, radii: np.ndarray, axis: int, samples: int) -> np.ndarray:
    """The faces' lengths [m] around the rim normal to `axis` (a principal axis of the clump's frame)."""
    plane = [i for i in range(3) if i != axis]
    angle = np.linspace(0.0, 2.0 * np.pi, samples, endpoint=False)
    down = np.zeros((samples, 3))  # the flat's direction from the centre, round the rim
    down[:, plane[0]], down[:, plane[1]] = np.cos(angle), np.sin(angle)
    along = np.zeros((samples, 3))  # the flat's direction of rolling there
    along[:, plane[0]], along[:, plane[1]] = -np.sin(angle), np.cos(angle)
    touching = np.argmax(down @ centres.T + radii, axis=1)  # the sphere on the flat
    changes = np.nonzero(touching != np.roll(touching, -1))[0]
    nxt = touching[(changes + 1) % samples]
    return np.abs(np.einsum("ij,ij->i", centres[nxt] - centres[touching[changes]], along[changes]))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("clumps", nargs="+", help="LIBRARY.h5:NAME")
    p.add_argument("--samples", type=int, default=72000, help="directions round the rim")
    a = p.parse_args()
    if a.samples < 360:
        print("rim_faces: --samples 360 or more, please", file=sys.stderr)
        return 2
    print("| clump | spheres | rim spheres | sum of faces (mm) | sum of faces^2 (mm^2) | longest face (mm) |")
    print("|---|---:|---:|---:|---:|---:|")
    for spec in a.clumps:
        try:
            name, spheres, moments = read_clump(spec, "spheres", "principal_moments_kg_m2")
        except ValueError as e:
            print(f"rim_faces: {e}", file=sys.stderr)
            return 1
        faces = rim_faces(spheres[:, :3], spheres[:, 3], int(np.argmax(moments)), a.samples)
        print(f"| {name} | {len(spheres)} | {len(faces)} | {1e3 * faces.sum():.1f} | {1e6 * (faces**2).sum():.1f} | "
              f"{1e3 * faces.max():.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
