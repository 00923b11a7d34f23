#!/usr/bin/env python3
"""Read the camera's image scale of every recording in a set, as `clumpforge diagnose` reads it.

A camera's lengths pass through its image scale; `diagnose` measures it on each recording where
the tracks show it without any coefficient (report.json `image_scale`; docs/diagnose.md, "The
image scale"): a drop's free flights after the first contact fall at g, and a ball's centre rolls
one radius above the incline. This runs that measurement alone (clumpforge.measure_image_scale,
no diagnosis) on every recording folder under SET (a folder of recordings, or a folder of cases
of recordings such as ../shared/data/lab-like), with the clump `diagnose --mesh` takes of the
mesh each manifest names (the first adaptive fill of 1, 2, 4, ... spheres whose surface lies
within 0.1 mm RMS of it), and prints one line per reading and a summary per source:

  bench/image_scale_survey.py ../shared/data/lab-like --meshes ../shared/data/lab-like/meshes [--json OUT.json]

A manifest's mesh is opened only inside its recording's folder or a --meshes folder the user
names, never elsewhere because a recording names it. Recordings that name no mesh (the
generated sets of bench_diagnose) are read with --mesh MESH [--units mm] [--density 1085], or
with a stored clump, --clump LIBRARY.h5:NAME (the bench diagnoses the generated tuber sets with
clumps/tuber-default-ladder.h5:adaptive-64); either, given, serves every recording.

A reading is off when it departs from 1 by more than its tolerance (0.1 % for flights, 0.3 % for
a ball's height) and four standard errors. Nothing is written but OUT.json (temporary file, then
rename).
"""
import argparse
import json
import os
import pathlib
import sys
import tempfile

from built_module import library  # the clumpforge module, PYTHONPATH or the build tree


class Refusal(Exception):
    """Bad input: the message names the file and what is wrong."""


def recording_folders(root: pathlib.Path) -> dict:
    """{folder holding recordings: [recording folder names]}, in name order."""
    groups = {}
    for manifest in sorted(root.rglob("recording.json")):
        groups.setdefault(manifest.parent.parent, []).append(manifest.parent.name)
    return groups


def inside(path: pathlib.Path, folder: pathlib.Path) -> bool:
    return path == folder or folder in path.parents


def stated_particle(folder: pathlib.Path, names: list, args) -> tuple:
    """(mesh path, units, density) of the group: --mesh's when given, else the one the manifests
    state; all must state the same, and each mesh must lie in its recording's folder or in
    --meshes."""
    if args.mesh:
        return str(args.mesh), args.units, args.density
    meshes = args.meshes
    stated = set()
    for name in names:
        manifest = folder / name / "recording.json"
        try:
            particle = json.loads(manifest.read_text()).get("particle", {})
        except (OSError, ValueError) as e:
            raise Refusal(f"{manifest}: {e}") from None
        if "mesh" not in particle:
            raise Refusal(f"{manifest}: names no particle mesh (particle.mesh); give one with --mesh")
        mesh = (folder / name / particle["mesh"]).resolve()
        if not (inside(mesh, (folder / name).resolve()) or (meshes and inside(mesh, meshes.resolve()))):
            raise Refusal(f"{manifest}: its mesh '{particle['mesh']}' lies outside its folder"
                          f"{' and ' + str(meshes) if meshes else ''}; name the folder that holds it with --meshes")
        stated.add((str(mesh), particle.get("mesh_units", "mm"), float(particle.get("density_kg_m3", 1085.0))))
    if len(stated) != 1:
        raise Refusal(f"{folder}: its recordings state {len(stated)} particles; survey one particle per folder")
    return stated.pop()


def stored_clump(cf, spec: str):
    """The clump LIBRARY.h5:NAME names."""
    library, _, name = spec.rpartition(":")
    if not library or not name:
        raise Refusal(f"--clump {spec}: not LIBRARY.h5:NAME")
    if not pathlib.Path(library).is_file():
        raise Refusal(f"--clump {spec}: {library} is not a file")
    for clump in cf.read_library(library):
        if clump.name == name:
            return clump
    raise Refusal(f"--clump {spec}: {library} holds no clump '{name}'")


def survey(cf, root: pathlib.Path, args) -> list:
    clumps, rows = {}, []
    given = stored_clump(cf, args.clump) if args.clump else None
    for folder, names in recording_folders(root).items():
        if given is None:
            key = stated_particle(folder, names, args)
            if key not in clumps:
                mesh, units, density = key
                clumps[key] = cf.fill(cf.load_mesh(mesh, units=units), method="adaptive", surface_target=1e-4,
                                      density=density)
        clump = given or clumps[key]
        recordings = {name: cf.read_recording(str(folder / name)) for name in names}
        for r in cf.measure_image_scale(clump, recordings):
            rows.append({"set": str(folder.relative_to(root)) if folder != root else ".", "recording": r.recording,
                         "spheres": len(clump.radii), "from": r.source, "samples": r.samples, "scale": r.scale,
                         "standard_error": r.standard_error / r.expected, "off": r.off})
    return rows


def summary(rows: list) -> list:
    lines = []
    for source in ("free_flights", "rolling_height"):
        picked = [r for r in rows if r["from"] == source]
        if not picked:
            continue
        worst = max(picked, key=lambda r: abs(r["scale"] - 1.0))
        lines.append(f"{source}: {len(picked)} readings, {sum(r['off'] for r in picked)} off; scale "
                     f"{min(r['scale'] for r in picked):.4f}-{max(r['scale'] for r in picked):.4f}, farthest "
                     f"{worst['set']}/{worst['recording']} {worst['scale']:.4f} +- {worst['standard_error']:.4f}")
    return lines


def write_atomically(path: pathlib.Path, text: str) -> None:
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    with os.fdopen(handle, "w") as out:
        out.write(text)
    os.replace(temporary, path)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("set", type=pathlib.Path, help="a folder of recordings, or of cases of recordings")
    parser.add_argument("--meshes", type=pathlib.Path, help="a folder whose meshes the manifests may name")
    parser.add_argument("--mesh", type=pathlib.Path, help="the particle's mesh for every recording")
    parser.add_argument("--clump", help="LIBRARY.h5:NAME, a stored clump for every recording")
    parser.add_argument("--units", default="mm", help="--mesh's length unit (default mm)")
    parser.add_argument("--density", type=float, default=1085.0, help="with --mesh [kg/m^3] (default 1085)")
    parser.add_argument("--json", type=pathlib.Path, help="also write every reading and the summary here")
    args = parser.parse_args(argv)
    try:
        if not args.set.is_dir():
            raise Refusal(f"{args.set}: not a folder")
        cf = library()
        try:
            if args.mesh and args.clump:
                raise Refusal("--mesh and --clump: give one")
            if args.mesh and not args.mesh.is_file():
                raise Refusal(f"--mesh {args.mesh}: not a file")
            if not 1.0 <= args.density <= 25000.0:
                raise Refusal(f"--density {args.density:g} outside [1, 25000] kg/m^3")
            rows = survey(cf, args.set, args)
        except cf.Error as e:
            raise Refusal(str(e)) from None
        if not rows:
            raise Refusal(f"{args.set}: no recording shows its image scale (no tracked drops, nor a ball's rolls)")
    except Refusal as e:
        print(f"image_scale_survey: {e}", file=sys.stderr)
        return 2
    for r in rows:
        print(f"{r['set']:<12} {r['recording']:<16} {r['from']:<15} {r['samples']:>5} "
              f"{r['scale']:.5f} +- {r['standard_error']:.5f}{'  off' if r['off'] else ''}")
    lines = summary(rows)
    print("\n".join(lines))
    if args.json:
        write_atomically(args.json, json.dumps({"readings": rows, "summary": lines}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
