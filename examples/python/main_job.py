#!/usr/bin/env python3
"""The main job in Python: repair a scan, its mass properties, lattice and adaptive clumps
with their error reports, exports, and the study's drop test in the built-in DEM, with a
matplotlib figure of the rebound heights against the clump's sphere count.

    PYTHONPATH=build/python python3 examples/python/main_job.py [SCAN] [-o OUT]
"""

import argparse
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import clumpforge as cf  # noqa: E402


def main():
    root = pathlib.Path(__file__).resolve().parents[2]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scan", nargs="?", default=str(root / "meshes/tuber-default.stl"))
    parser.add_argument("--units", default="mm")
    parser.add_argument("--density", type=float, default=1085.0, help="kg/m^3 (default: the study's tuber)")
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("-o", "--output", default="out/python")
    args = parser.parse_args()
    out = pathlib.Path(args.output)
    out.mkdir(parents=True, exist_ok=True)

    def progress(stage, fraction):
        print(f"\r  {stage}: {100 * fraction:3.0f} %", end="", file=sys.stderr, flush=True)

    mesh = cf.load_mesh(args.scan, units=args.units)
    repaired = cf.repair(mesh)
    props = cf.mass_properties(repaired.mesh, density=args.density)
    print(f"{args.scan}: {len(mesh.faces)} faces -> {repaired.after.faces} after repair; "
          f"volume {props.volume * 1e9:.1f} mm^3, mass {props.mass * 1e3:.3f} g, "
          f"principal moments {np.array2string(props.principal_moments * 1e9, precision=3)} g mm^2")

    clumps = [cf.fill(repaired.mesh, method="lattice", diameter=d, density=args.density, progress=progress)
              for d in (0.004, 0.002, 0.001)]
    clumps += [cf.fill(repaired.mesh, method="adaptive", max_spheres=n, density=args.density, progress=progress)
               for n in (32, 128)]
    print(file=sys.stderr)
    print(f"{'clump':>14} {'spheres':>8} {'volume err':>11} {'surface RMS':>12} {'axes':>8}")
    for c in clumps:
        e = c.error
        print(f"{c.name:>14} {len(c):8d} {100 * e.volume_error:10.2f}% {e.surface_rms * 1e3:9.3f} mm "
              f"{e.axis_error_deg:7.3f}°")
    cf.write_library(str(out / "clumps.h5"), clumps)
    (out / "exports").mkdir(exist_ok=True)
    for fmt, suffix in (("liggghts", "multisphere"), ("yade", "yade.txt"), ("csv", "csv")):
        files = cf.export(clumps[1], fmt, str(out / "exports" / f"{clumps[1].name}.{suffix}"))
        print(f"exported {clumps[1].name} for {fmt}: {', '.join(pathlib.Path(f).name for f in files)}")

    rebounds = {}
    for c in clumps:
        run = cf.validate(c, test="drop", surface="Q235", trials=args.trials, progress=progress)
        rebounds[c.name] = run.summaries * 1e3
    print(file=sys.stderr)

    fig, ax = plt.subplots(figsize=(6.4, 4.0), layout="constrained")
    counts = [len(c) for c in clumps]
    means = [rebounds[c.name].mean() for c in clumps]
    errors = [1.96 * rebounds[c.name].std(ddof=1) / np.sqrt(len(rebounds[c.name])) for c in clumps]
    for c, n in zip(clumps, counts):
        ax.plot(np.full(args.trials, n), rebounds[c.name], "o", color="0.75", ms=3, zorder=1)
    ax.errorbar(counts, means, yerr=errors, fmt="s", color="C0", capsize=3, zorder=2,
                label="mean and 95 % interval")
    for c, n, m in zip(clumps, counts, means):
        ax.annotate(c.name, (n, m), textcoords="offset points", xytext=(6, 4), fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("spheres in the clump")
    ax.set_ylabel("first rebound height on Q235 [mm]")
    ax.set_title("Drop from 0.2 m: rebound against clump resolution")
    ax.legend(loc="best", frameon=False)
    for suffix in ("png", "svg"):
        fig.savefig(out / f"rebound-vs-spheres.{suffix}", dpi=150)
    print(f"wrote {out / 'clumps.h5'}, {out / 'exports'}/, {out / 'rebound-vs-spheres.png'} and .svg")


if __name__ == "__main__":
    main()
