#!/usr/bin/env python3
"""How a tuber's outcomes after the first contact change with the clump's resolution.

Generates the same trials (seed, coefficients, release orientations) with each clump given,
by `clumpforge-conceal` (no effect, orientation none), and prints per recording the mean and
sd over the trials of the distance from the first tracked point to the rest point (the
median of the last ten frames: a drop's drift, a roll's path), of the summary the
recording states (a drop's rebound height, a roll's distance on the flat) and of a drop's
rebound read from its track three ways (rebound_readings: as the diagnosis reads it, above
the first impact's low point, and from the falling and rising parabolas), with each clump's
move from the one before in standard errors of a recorded mean of 8 trials. The diagnosis's step 0
chooses the resolution inside the fitted windows; this shows how far the outcomes beyond them
are from converged (docs/diagnose.md, Limits).

  bench/outcomes_by_resolution.py --conceal build/tools/clumpforge-conceal \
      clumps/tuber-default-ladder.h5:adaptive-32 clumps/tuber-default-ladder.h5:adaptive-128 \
      clumps/tuber-default.h5:adaptive-340
"""
import argparse
import csv
import json
import math
import pathlib
import statistics
import subprocess
import sys
import tempfile

from built_module import library  # the clumpforge module, PYTHONPATH or the build tree


def track_rows(track: pathlib.Path) -> tuple:
    """A track's frames with finite coordinates: (t, x, z) lists."""
    t, x, z = [], [], []
    with track.open() as f:
        for r in csv.DictReader(f):
            try:
                row = float(r["t_s"]), float(r["x_m"]), float(r["z_m"])
            except (KeyError, ValueError):
                continue
            if all(math.isfinite(v) for v in row):
                for column, v in zip((t, x, z), row):
                    column.append(v)
    return t, x, z


def rest_distance(x: list) -> float:
    """How far a track's x ends (the median of its last ten frames) from where it began."""
    if len(x) < 10:
        return math.nan
    return abs(statistics.median(x[-10:]) - x[0])


G = 9.81


def free_fall_fit(t: list, z: list) -> tuple:
    """(a, b) of z + g t^2 / 2 = a + b t, least squares: a free flight's parabola with g known."""
    y = [zi + 0.5 * G * ti * ti for ti, zi in zip(t, z)]
    n, st, sy = len(t), sum(t), sum(y)
    stt, sty = sum(ti * ti for ti in t), sum(ti * yi for ti, yi in zip(t, y))
    b = (n * sty - st * sy) / (n * stt - st * st)
    return (sy - b * st) / n, b


def parabolas_rise(t: list, z: list, impact: int, apex: int) -> float:
    """The rise from the first impact to the apex of the flight after it, from the falling and
    rising parabolas (g known) and where they meet: g (t_apex - t_meet)^2 / 2, free of where the
    frames fall about the contact. NaN when either flight has under five frames clear of the
    contact, or the parabolas meet more than two frames away from it (a rock or a roll on the
    plate, not a flight)."""
    if impact + 2 >= len(z):
        return math.nan
    dt = (t[-1] - t[0]) / max(1, len(t) - 1)
    falling = [k for k in range(impact - 2) if z[k] < z[0] - 2e-3]
    end = apex
    while end + 1 < len(z) and z[end + 1] > z[impact + 2]:
        end += 1
    rising = list(range(impact + 2, end + 1))
    if len(falling) < 5 or len(rising) < 5:
        return math.nan
    af, bf = free_fall_fit([t[k] for k in falling], [z[k] for k in falling])
    ar, br = free_fall_fit([t[k] for k in rising], [z[k] for k in rising])
    if bf == br:
        return math.nan
    meet = (ar - af) / (bf - br)
    if not t[falling[-1]] - 2 * dt <= meet <= t[rising[0]] + 2 * dt:
        return math.nan
    return 0.5 * G * (br / G - meet) ** 2


def rebound_readings(t: list, x: list, z: list, moved: float = 1e-3) -> dict:
    """A drop's rebound [m] read three ways: the highest point after the first impact above the rest
    point (the median of the last ten frames), read by the diagnosis's own measure_outcomes (its
    `moved` is max(1 mm, 6 noise sds): 1 mm at the cameras compared here); above the impact's lowest
    frame (at most v_down v_up / (v_down + v_up) / fps above a brief contact, by the frames' phase);
    from the parabolas (parabolas_rise). 0 for every reading when the path never rises `moved`."""
    names = ("above the rest point", "above the impact's low point", "from the parabolas")
    if len(z) < 10:
        return dict.fromkeys(names, math.nan)
    cf = library()
    impact_time = cf.first_impact_time(t, x, z, moved)
    if impact_time is None:
        return dict.fromkeys(names, 0.0)
    impact = t.index(impact_time)
    apex = max(range(impact, len(z)), key=lambda k: z[k])
    above_rest = cf.measure_outcomes(cf.LabTest.drop, t, x, z, moved)[cf.Outcome.rebound_height]
    return dict(zip(names, (above_rest, z[apex] - z[impact], parabolas_rise(t, z, impact, apex))))


# Each recording's summary as the recording states it (recording-format.md), in mm.
SUMMARY = {"drop-0.2m": ("rebound height", "rebound_height_m"), "drop-1m": ("rebound height", "rebound_height_m"),
           "roll-100mm": ("roll distance", "roll_distance_m")}


def summaries(folder: pathlib.Path, key: str) -> list:
    recording = json.loads((folder / "recording.json").read_text())
    return [t.get("summary", {}).get(key, math.nan) for t in recording["trials"]]


def finite(values: list) -> list:
    return [v for v in values if math.isfinite(v)]


def add(results: dict, row: str, name: str, values_m: list) -> None:
    values = finite(values_m)
    results.setdefault(row, {})[name] = {
        "mean_mm": 1e3 * statistics.mean(values) if values else math.nan,
        "sd_mm": 1e3 * statistics.stdev(values) if len(values) > 1 else math.nan,
        "trials": len(values),
    }


def move_in_se(a: dict, b: dict, trials: int = 8) -> float:
    """b's mean from a's in standard errors of a recorded mean of `trials` trials (the spreads pooled)."""
    se = math.sqrt((a["sd_mm"] ** 2 + b["sd_mm"] ** 2) / 2.0 / trials)
    return (b["mean_mm"] - a["mean_mm"]) / se if se > 0 else math.nan


def outcomes(a, library: str, name: str, restitution: float, out: pathlib.Path) -> dict:
    """One clump's outcomes (row -> values in m) at `restitution`; raises RuntimeError on a refusal."""
    cmd = [a.conceal, library, "--clump", name, "--effect", "none", "--seed", str(a.seed), "--surface", a.surface,
           "--restitution", str(restitution), "--static-friction", str(a.static_friction), "--rolling-friction",
           str(a.rolling_friction), "--small", "--trials", str(a.trials), "--wall-mass", a.wall_mass,
           "--steps-per-contact", str(a.steps_per_contact), "-o", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(done.stderr.strip())
    rows = {}
    for rec in ("drop-0.2m", "drop-1m", "roll-100mm"):
        tracks = [track_rows(track) for track in sorted((out / rec).glob("trial-*.csv"))]
        rows[f"{rec} rest distance"] = [rest_distance(x) for _, x, _ in tracks]
        rows[f"{rec} {SUMMARY[rec][0]}"] = summaries(out / rec, SUMMARY[rec][1])
        if rec.startswith("drop"):
            for t, x, z in tracks:
                for reading, value in rebound_readings(t, x, z).items():
                    rows.setdefault(f"{rec} rebound {reading}", []).append(value)
    return rows


def finite_mean(values: list) -> float:
    values = finite(values)
    return statistics.mean(values) if values else math.nan


def matched(a, library: str, name: str, target: float, tmp: pathlib.Path) -> tuple:
    """The restitution (bisected in [0.3, 0.999], 8 halvings) at which this clump's mean `a.match`
    meets `target` [m] (it rises with e), and the outcomes there."""
    row = f"{a.match} {SUMMARY[a.match][0]}"
    low, high, best = 0.3, 0.999, None
    for step in range(8):
        e = 0.5 * (low + high)
        rows = outcomes(a, library, name, e, tmp / f"{name}-{step}")
        gap = finite_mean(rows[row]) - target
        if best is None or abs(gap) < abs(best[2]):
            best = (e, rows, gap)
        low, high = (e, high) if gap < 0 else (low, e)
    return best[0], best[1]


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("clumps", nargs="+", help="LIBRARY.h5:NAME, coarsest first")
    p.add_argument("--conceal", default="build/tools/clumpforge-conceal")
    p.add_argument("--trials", type=int, default=16)
    p.add_argument("--seed", type=int, default=77)
    p.add_argument("--surface", default="Q235")
    p.add_argument("--restitution", type=float, default=0.634823744)
    p.add_argument("--static-friction", type=float, default=0.405234611)
    p.add_argument("--rolling-friction", type=float, default=0.0252642907)
    p.add_argument("--wall-mass", choices=["whole", "shared"], default="whole",
                   help="the mass in each sphere's wall-contact damping (clumpforge-conceal --wall-mass)")
    p.add_argument("--steps-per-contact", type=int, default=100,
                   help="time steps per contact (clumpforge-conceal's; 100, the generator's, by default; the "
                        "diagnosis replays with 50)")
    p.add_argument("--match", choices=["drop-0.2m", "drop-1m", "roll-100mm"],
                   help="each clump after the first at the restitution (bisected) that gives this recording's mean "
                        "summary the first clump's, as a calibration on it would: how the other outcomes then move")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    a = p.parse_args()
    results, restitutions = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        target = None
        for spec in a.clumps:
            library, _, name = spec.rpartition(":")
            if not library or not name:
                print(f"outcomes_by_resolution: '{spec}' is not LIBRARY.h5:NAME", file=sys.stderr)
                return 2
            try:
                if a.match and target is not None:
                    restitutions[name], rows = matched(a, library, name, target, pathlib.Path(tmp))
                else:
                    restitutions[name] = a.restitution
                    rows = outcomes(a, library, name, a.restitution, pathlib.Path(tmp) / name)
                    if a.match:
                        target = finite_mean(rows[f"{a.match} {SUMMARY[a.match][0]}"])
            except RuntimeError as e:
                print(f"outcomes_by_resolution: {spec}: {e}", file=sys.stderr)
                return 1
            for row, values in rows.items():
                add(results, row, name, values)
    if a.json:
        print(json.dumps({"restitution": restitutions, "outcomes": results} if a.match else results, indent=2))
        return 0
    names = [s.rpartition(":")[2] for s in a.clumps]
    print("| recording, outcome (mm) | " + " | ".join(names) + " |")
    print("|---|" + "---:|" * len(names))
    if a.match:
        print("| restitution | " + " | ".join(f"{restitutions[n]:.4f}" for n in names) + " |")
    def cell(v: dict) -> str:
        fewer = f" [{v['trials']} trials]" if v["trials"] != a.trials else ""
        return f"{v['mean_mm']:.1f} +- {v['sd_mm']:.1f}{fewer}"

    for rec, by in results.items():
        cells = [cell(by[names[0]])]
        for before, here in zip(names, names[1:]):
            cells.append(f"{cell(by[here])} ({move_in_se(by[before], by[here]):+.1f})")
        print(f"| {rec} | " + " | ".join(cells) + " |")
    print("(in brackets: the move from the clump before, in standard errors of a recorded mean of 8 trials; in square "
          "brackets: the trials a reading was had from, where fewer than all)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
