"""bench/roll_timing.py (run by ctest, label fast): the independent simulator's roll tracks come
down their incline within the recording reader's bound (20 times a frictionless slide's time),
and the same tracks written in milliseconds take 1000 times as long; half way down each is at
negative x, and would be far past the foot were x counted from the release."""

import csv
import pathlib
import re
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "bench" / "roll_timing.py"
LAB_LIKE = ROOT.parent / "shared" / "data" / "lab-like"


def run(*folders):
    out = subprocess.run([sys.executable, str(SCRIPT), *map(str, folders)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return out.stdout


def figures(text):
    counts = re.search(r"roll tracks: (\d+), timed (\d+)", text)
    ratios = re.search(r"least ([\d.]+), median ([\d.]+), 99th percentile ([\d.]+), largest ([\d.]+)", text)
    return int(counts[1]), int(counts[2]), [float(v) for v in ratios.groups()]


def test_lab_likes_rolls_lie_within_the_readers_bound():
    out = run(LAB_LIKE)
    total, timed, (least, median, _, largest) = figures(out)
    assert total == timed == 26 * 3 * 6  # 26 cases, three roll set-ups, six trials
    assert 0.9 < least <= median < largest < 20.0
    starts = re.search(r"start from the foot over the run, (\d+) tracks .*: least ([\d.]+), median ([\d.]+), "
                       r"largest ([\d.]+)", out)
    assert int(starts[1]) == total
    assert 0.25 < float(starts[2]) <= float(starts[3]) <= float(starts[4]) < 1.0
    # Half way down each roll lies inside the reader's bound (x_not_from_the_foot); counted from
    # the release, nearly all lie past it.
    halves = re.search(r"half way down, (\d+) tracks .*: inside the reader's bound by (-?[\d.]+) mm at least, "
                       r"(-?[\d.]+) mm median, (-?[\d.]+) mm at most .*counted from the release, (\d+) of (\d+) past it",
                       out)
    assert int(halves[1]) == int(halves[6]) == total
    assert 0.0 < float(halves[2]) <= float(halves[3]) <= float(halves[4])
    assert int(halves[5]) > 0.85 * total

def test_a_roll_in_milliseconds_takes_a_thousand_times_as_long(tmp_path):
    source = LAB_LIKE / "case-01" / "roll-Q235-35mm"
    copy = tmp_path / "roll-ms"
    shutil.copytree(source, copy)
    for track in copy.glob("*.csv"):
        rows = list(csv.reader(track.open()))
        for row in rows[1:]:
            row[0] = f"{1000 * float(row[0]):.3f}"
        with track.open("w", newline="") as f:
            csv.writer(f, lineterminator="\n").writerows(rows)
    _, _, seconds = figures(run(source))
    _, _, milliseconds = figures(run(copy))
    for s, ms in zip(seconds, milliseconds):
        assert abs(ms / s - 1000.0) < 1.0
    assert milliseconds[0] > 20.0


def test_no_roll_track_is_an_error(tmp_path):
    out = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path)], capture_output=True, text=True)
    assert out.returncode != 0
    assert "no roll track" in out.stderr
