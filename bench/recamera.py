#!/usr/bin/env python3
"""Film a set of recordings again with a coarser camera: fewer frames, more noise.

The diagnosis benchmark's independent set (../shared/data/lab-like) was filmed at one camera
setting per test; labs film at others (240-250 fps with 0.5 mm noise is common beside 1000 fps
with 0.1 mm). This copies a set of recordings (a folder holding recording folders, at any
depth, each with its recording.json) and re-films every track: it keeps the frames of a lower
frame rate that divides the recorded one (by the frames' times, so a dropped frame stays
dropped) and adds Gaussian noise to x_m and z_m so that the total noise per axis is the one
asked (the added part is sqrt(asked^2 - recorded^2), the recorded one from each manifest's
camera.position_noise_m). Each manifest's camera keys are rewritten to match; the length
summaries (rebound_height_m, roll_distance_m) get the same added noise, as a lab measuring
them from its films would; everything else is copied as it is (ANSWERS.json, meshes, extra
keys). The output is written to a temporary folder beside it and renamed at the end.

With --scale S the camera's image scale is off by S as well (calibrated off the particle's
plane): every x_m and z_m, and every length summary, is multiplied by S before the noise is
added, as such a camera reads them.

  bench/recamera.py ../shared/data/lab-like OUT --fps drop=250 --noise 5e-4 --seed 1
  bench/recamera.py SET OUT --noise 1e-4 --scale 1.01
  build/bench/bench_diagnose --recordings-set OUT -o OUT-diagnosed

A test's frame rate is kept when --fps does not name it; --noise applies to every test.
"""
import argparse
import csv
import json
import math
import os
import pathlib
import random
import shutil
import sys
import tempfile

TESTS = ("drop", "roll", "tilt")
LENGTH_SUMMARIES = ("rebound_height_m", "roll_distance_m")


class Refusal(Exception):
    """Bad input: the message names the file and what is wrong."""


def parse_fps(text):
    rates = {}
    for item in filter(None, (text or "").split(",")):
        test, _, value = item.partition("=")
        if test not in TESTS:
            raise Refusal(f"--fps: unknown test '{test}' (drop, roll or tilt)")
        try:
            rate = float(value)
        except ValueError:
            raise Refusal(f"--fps: '{value}' is not a frame rate") from None
        if not (0.0 < rate <= 1e6):
            raise Refusal(f"--fps: {test} frame rate {value} outside (0, 1e6] Hz")
        rates[test] = rate
    return rates


def decimation(recorded, wanted, where):
    """How many recorded frames make one of the new camera's (an integer, or a refusal)."""
    step = recorded / wanted
    if step < 1.0 - 1e-9 or abs(step - round(step)) > 1e-6:
        raise Refusal(f"{where}: {wanted:g} fps does not divide the recorded {recorded:g} fps")
    return int(round(step))


def inside(folder, name, where):
    """The track `name` resolved inside `folder` (never a path leaving it)."""
    path = (folder / name).resolve()
    if folder.resolve() not in path.parents:
        raise Refusal(f"{where}: track '{name}' leaves its recording's folder")
    return path


def refilm_track(path, shown, step, rate, added, rng, scale=1.0):
    """The track's rows at the new frame rate, x_m and z_m times `scale` with `added` noise
    (metres); `shown` is the path messages name (the user's file, not its copy)."""
    try:
        with path.open(newline="") as f:
            rows = list(csv.reader(f))
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise Refusal(f"{shown}: cannot read the track ({e.__class__.__name__}: {getattr(e, 'strerror', None) or e})") from None
    if not rows or "t_s" not in rows[0]:
        raise Refusal(f"{shown}: no t_s column in the header")
    header = rows[0]
    t_col = header.index("t_s")
    noisy = [header.index(c) for c in ("x_m", "z_m") if c in header]
    out, first = [header], None
    for line, row in enumerate(rows[1:], start=2):
        try:
            t = float(row[t_col])
        except (IndexError, ValueError):
            raise Refusal(f"{shown}:{line}: t_s '{row[t_col] if t_col < len(row) else ''}' is not a number") from None
        first = t if first is None else first
        if round((t - first) * rate) % step:
            continue
        row = list(row)
        for c in noisy:
            if c < len(row) and row[c].strip():
                try:
                    row[c] = f"{float(row[c]) * scale + rng.gauss(0.0, added):.6f}"
                except ValueError:
                    raise Refusal(f"{shown}:{line}: {header[c]} '{row[c]}' is not a number") from None
        out.append(row)
    return out


def refilm_recording(manifest, shown, fps, noise, rng, scale=1.0):
    """Re-films one recording's tracks in place; `shown` maps a copied path to the user's."""
    where = str(shown(manifest))
    try:
        recording = json.loads(manifest.read_text())
    except (OSError, ValueError) as e:
        raise Refusal(f"{where}: {e}") from None
    if not isinstance(recording, dict):
        raise Refusal(f"{where}: not a JSON object")
    trials = recording.get("trials", [])
    if not isinstance(trials, list) or not all(isinstance(t, dict) for t in trials):
        raise Refusal(f"{where}: trials must be a list of objects")
    if any(not isinstance(t.get("summary", {}), dict) for t in trials):
        raise Refusal(f"{where}: a trial's summary must be an object")
    test = recording.get("test")
    camera = recording.get("camera") or {}
    rate = camera.get("frame_rate_hz")
    if test not in TESTS or not isinstance(rate, (int, float)) or not rate > 0:
        raise Refusal(f"{where}: needs a test (drop, roll, tilt) and camera.frame_rate_hz")
    wanted = fps.get(test, rate)
    step = decimation(float(rate), float(wanted), where)
    recorded_noise = float(camera.get("position_noise_m") or 0.0)
    if noise < recorded_noise:
        raise Refusal(f"{where}: --noise {noise:g} m is below the recorded {recorded_noise:g} m")
    added = math.sqrt(noise * noise - recorded_noise * recorded_noise)
    folder = manifest.parent
    done = set()
    for trial in trials:
        if "track" in trial:
            path = inside(folder, str(trial["track"]), where)
            if path in done:
                continue
            done.add(path)
            rows = refilm_track(path, shown(path), step, float(rate), added, rng, scale)
            with path.open("w", newline="") as f:
                csv.writer(f, lineterminator="\n").writerows(rows)
        for key, value in (trial.get("summary") or {}).items():
            if key in LENGTH_SUMMARIES and isinstance(value, (int, float)):
                trial["summary"][key] = round(max(0.0, value * scale + rng.gauss(0.0, added)), 5)
    camera["frame_rate_hz"] = int(wanted) if float(wanted).is_integer() else float(wanted)
    camera["position_noise_m"] = noise
    recording["camera"] = camera
    manifest.write_text(json.dumps(recording, indent=1) + "\n")


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("recordings", type=pathlib.Path, help="a folder of recordings (any depth)")
    parser.add_argument("output", type=pathlib.Path, help="the new set's folder (must not exist)")
    parser.add_argument("--fps", default="", help="new frame rates per test, e.g. drop=250,roll=125")
    parser.add_argument("--noise", type=float, required=True, help="total camera noise per axis [m]")
    parser.add_argument("--seed", type=int, default=1, help="seed of the added noise")
    parser.add_argument("--scale", type=float, default=1.0,
                        help="the camera's image scale: lengths multiplied by it (default 1)")
    args = parser.parse_args(argv)
    try:
        fps = parse_fps(args.fps)
        if not (0.0 <= args.noise <= 0.01):
            raise Refusal(f"--noise {args.noise:g} m outside [0, 0.01] m")
        if not (0.5 <= args.scale <= 2.0):
            raise Refusal(f"--scale {args.scale:g} outside [0.5, 2]")
        source = args.recordings.resolve()
        if not source.is_dir():
            raise Refusal(f"{args.recordings}: not a folder")
        target = args.output.resolve()
        if target.exists():
            raise Refusal(f"{args.output}: exists (choose a new folder)")
        if source == target or source in target.parents:
            raise Refusal(f"{args.output}: inside the recordings it re-films")
        target.parent.mkdir(parents=True, exist_ok=True)
        work = pathlib.Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
        try:
            copy = work / "set"
            shutil.copytree(source, copy, symlinks=True)
            rng = random.Random(args.seed)
            manifests = sorted(copy.rglob("recording.json"))
            if not manifests:
                raise Refusal(f"{args.recordings}: no recording.json in it")
            for manifest in manifests:
                refilm_recording(manifest, lambda p: source / p.relative_to(copy), fps, args.noise, rng, args.scale)
            settings = {"source": str(source), "fps": fps, "noise_m": args.noise, "seed": args.seed,
                        "scale": args.scale, "recordings": len(manifests)}
            (copy / "RECAMERA.json").write_text(json.dumps(settings, indent=1) + "\n")
            os.rename(copy, target)
        finally:
            shutil.rmtree(work, ignore_errors=True)
    except Refusal as e:
        print(f"recamera: {e}", file=sys.stderr)
        return 1
    print(f"{len(manifests)} recordings filmed again into {args.output} "
          f"({', '.join(f'{t} {r:g} fps' for t, r in fps.items()) or 'frame rates kept'}; noise {args.noise:g} m"
          f"{f'; image scale {args.scale:g}' if args.scale != 1.0 else ''})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
