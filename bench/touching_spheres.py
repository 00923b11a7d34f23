#!/usr/bin/env python3
"""How many of a clump's spheres can touch a plate at once, by its resolution.

For release orientations drawn uniformly (a dropped particle meets the plate as it was
released), counts the spheres whose lowest point lies within DEPTH of the clump's lowest
point: the spheres that an impact compressing the contact by DEPTH can bring into contact.
Each sphere's contact is damped with the whole clump's mass (the LIGGGHTS/EDEM convention,
src/dem/step.cpp), so N of them touching together damp like one contact with sqrt(N) times
the damping ratio (docs/diagnose.md, "Why the ladder does not converge"). Geometry only: no
DEM is run, and the overlap an impact reaches is shared among the spheres that touch.

  bench/touching_spheres.py clumps/tuber-default-ladder.h5:adaptive-32 \
      clumps/tuber-default-ladder.h5:adaptive-256 clumps/tuber-default.h5:adaptive-340
"""
import argparse
import sys

import numpy as np

from clump_spec import read_clump


def rotation(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("clumps", nargs="+", help="LIBRARY.h5:NAME")
    p.add_argument("--orientations", type=int, default=2000)
    p.add_argument("--depths-mm", default="0.5,1,2", help="contact depths [mm], comma-separated")
    p.add_argument("--seed", type=int, default=1)
    a = p.parse_args()
    depths = [float(d) * 1e-3 for d in a.depths_mm.split(",")]
    if a.orientations < 1 or not depths or any(not d > 0 for d in depths):
        print("touching_spheres: orientations >= 1 and positive depths, please", file=sys.stderr)
        return 2
    quaternions = np.random.default_rng(a.seed).normal(size=(a.orientations, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1)[:, None]
    print("| clump | spheres | " + " | ".join(f"within {d * 1e3:g} mm: median (mean)" for d in depths) + " |")
    print("|---|---:|" + "---:|" * len(depths))
    for spec in a.clumps:
        try:
            name, spheres = read_clump(spec, "spheres")
        except ValueError as e:
            print(f"touching_spheres: {e}", file=sys.stderr)
            return 1
        centres, radii = spheres[:, :3], spheres[:, 3]
        counts = np.empty((len(depths), len(quaternions)))
        for i, q in enumerate(quaternions):
            lowest = (centres @ rotation(q).T)[:, 2] - radii
            for k, d in enumerate(depths):
                counts[k, i] = np.count_nonzero(lowest <= lowest.min() + d)
        cells = " | ".join(f"{np.median(c):g} ({c.mean():.1f})" for c in counts)
        print(f"| {name} | {len(radii)} | {cells} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
