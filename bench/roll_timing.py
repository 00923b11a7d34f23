#!/usr/bin/env python3
"""How long roll tracks take to come down their incline, against a frictionless slide's time,
and how far from the foot they start, against the incline's run.

The recording reader refuses a roll that starts in the slope's upper half and whose tracked point
comes from a fifth to four fifths of the start distance down the slope in more than 20 times a
frictionless slide's time, sqrt(2 / (g sin(incline))) (sqrt(0.8 d) - sqrt(0.2 d)), or in less
than 0.4 of it (src/io/recording_io.cpp, wrong_roll_timing): a track whose t_s is in
milliseconds takes about 1000 times it, and one whose incline_deg is in radians about 0.16. This
reads every roll recording under the folders given (any depth, each a recording.json with its
tracks), times each track as the reader does (from the median of its first five tracked x
positions; tracks that start further down or do not pass both marks are counted apart) and
prints how many, and the
ratios' least, median, 99th percentile and largest, with the slowest tracks. It also prints how
far from the foot (x_m is 0 there) each track that starts on the slope and reaches the foot
starts, over the incline's run: the reader refuses one under 0.25 that is 5 cm or more short of
the run (a start distance in millimetres). And where each track that comes down 0.8 of the
incline's rise or more has come half its way down, against the reader's bound there: a quarter
of the incline's run plus 1.5 times the track's resting height (the median of its last five
heights) times sin(incline). It prints how far inside the bound the tracks lie as read (the
reader refuses one past it: x_m not counted from the foot; x_not_from_the_foot), and how many
lie past it were their x counted from where the particle was released.

  bench/roll_timing.py ../shared/data/lab-like OUT-of-bench_diagnose ...
"""
import argparse
import csv
import json
import math
import os
import statistics

G = 9.80665  # dem's kStandardGravity


def track_xz(path):
    """The tracked (t, x, z) of a track file, rows with a lost cell left out."""
    with open(path, newline="", encoding="utf-8-sig") as f:
        rows = csv.DictReader(f)
        out = []
        for row in rows:
            try:
                out.append((float(row["t_s"]), float(row["x_m"]), float(row["z_m"])))
            except (TypeError, ValueError):
                continue
        return out


def ratio(points, incline_deg, start_distance):
    """The track's time from a fifth to four fifths of the way down, over a slide's; None if not passed
    or not from the slope's upper half (the reader judges no other)."""
    if len(points) < 10:
        return None
    angle = math.radians(incline_deg)
    run = start_distance * math.cos(angle)
    start = statistics.median(x for _, x in points[:5])
    if -start < 0.5 * run:
        return None
    first = next((t for t, x in points if x >= start + 0.2 * run), None)
    last = next((t for t, x in points if x >= start + 0.8 * run), None)
    if first is None or last is None:
        return None
    slide = math.sqrt(2.0 / (G * math.sin(angle))) * (math.sqrt(0.8 * start_distance) - math.sqrt(0.2 * start_distance))
    return (last - first) / slide


def start_fraction(points, incline_deg, start_distance):
    """How far from the foot the track starts, over the run; None if it does not start on the slope
    and reach the foot."""
    if len(points) < 10:
        return None
    first = statistics.median(x for _, x in points[:5])
    if first >= 0.0 or max(x for _, x in points) <= 0.0:
        return None
    return -first / (start_distance * math.cos(math.radians(incline_deg)))


def half_way_x(points, incline_deg, start_distance):
    """How far past the reader's bound the track is half way down, in metres, as read and counted
    from its start (negative: inside it); None if the incline rises less than 5 mm or the track comes
    down less than 0.8 of that."""
    if len(points) < 10:
        return None
    angle = math.radians(incline_deg)
    run, rise = start_distance * math.cos(angle), start_distance * math.sin(angle)
    z0 = statistics.median(z for _, _, z in points[:5])
    x0 = statistics.median(x for _, x, _ in points[:5])
    resting = statistics.median(z for _, _, z in points[-5:])
    descent = z0 - min(z for _, _, z in points)
    if rise < 5e-3 or descent < 0.8 * rise:
        return None
    x = next(x for _, x, z in points if z <= z0 - 0.5 * descent)
    bound = 0.25 * run + 1.5 * max(resting, 0.0) * math.sin(angle)
    return x - bound, x - x0 - bound


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--slowest", type=int, default=5, help="how many of the slowest tracks to list")
    args = parser.parse_args()
    timed, unpassed, unread, starts, halves = [], 0, 0, [], []
    for folder in args.folders:
        for root, _, files in os.walk(folder):
            if "recording.json" not in files:
                continue
            try:
                with open(os.path.join(root, "recording.json"), encoding="utf-8") as f:
                    manifest = json.load(f)
                if manifest.get("test") != "roll":
                    continue
                setup = manifest["setup"]
                float(setup["incline_deg"]), float(setup["start_distance_m"])
            except (OSError, ValueError, RecursionError, KeyError, TypeError, AttributeError):
                unread += 1  # a damaged manifest (the fuzz cases of a hostile-input test)
                continue
            for trial in manifest.get("trials", []):
                if "track" not in trial:
                    continue
                path = os.path.join(root, trial["track"])
                try:
                    points = track_xz(path)
                except (OSError, ValueError, KeyError, csv.Error):
                    unread += 1
                    continue
                xt = [(t, x) for t, x, _ in points]
                r = ratio(xt, setup["incline_deg"], setup["start_distance_m"])
                half = half_way_x(points, setup["incline_deg"], setup["start_distance_m"])
                if half is not None:
                    halves.append(half)
                start = start_fraction(xt, setup["incline_deg"], setup["start_distance_m"])
                if start is not None:
                    starts.append(start)
                if r is None:
                    unpassed += 1
                else:
                    timed.append((r, path))
    if not timed:
        raise SystemExit("no roll track passes both marks under " + ", ".join(args.folders))
    values = sorted(r for r, _ in timed)
    p99 = values[min(len(values) - 1, int(math.ceil(0.99 * len(values))) - 1)]
    print(f"roll tracks: {len(timed) + unpassed}, timed {len(timed)}, not from the slope's upper half or not past "
          f"four fifths {unpassed}"
          f" (manifests or tracks not read: {unread})")
    print(f"time over a frictionless slide's: least {values[0]:.3f}, median {statistics.median(values):.3f}, "
          f"99th percentile {p99:.3f}, largest {values[-1]:.3f} (the reader refuses below 0.4 and beyond 20)")
    if starts:
        print(f"start from the foot over the run, {len(starts)} tracks from the slope to the flat: least "
              f"{min(starts):.3f}, median {statistics.median(starts):.3f}, largest {max(starts):.3f} (the reader "
              f"refuses under 0.25 when 5 cm short)")
    if halves:
        inside = sorted(-h for h, _ in halves)
        past = sum(1 for _, h in halves if h > 0.0)
        print(f"half way down, {len(halves)} tracks down 0.8 of the rise or more: inside the reader's bound by "
              f"{1e3 * inside[0]:.2f} mm at least, {1e3 * statistics.median(inside):.2f} mm median, "
              f"{1e3 * inside[-1]:.2f} mm at most (the reader refuses a track past it); counted from the release, "
              f"{past} of {len(halves)} past it")
    for r, path in sorted(timed, reverse=True)[: args.slowest]:
        print(f"  {r:8.3f}  {path}")


if __name__ == "__main__":
    main()
