"""bench/recamera.py: a set of recordings filmed again with a coarser camera (run by ctest,
label fast): the frames kept, the noise added, the manifests rewritten, and each refusal
leaving nothing behind."""

import csv
import json
import math
import pathlib
import statistics
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "bench" / "recamera.py"


def make_set(root, track_name="trial-01.csv"):
    """One drop recording at 1000 fps, 0.1 mm noise: 2000 frames of a still particle with
    frame 7 dropped and one empty x cell, and an answers file beside it."""
    rec = root / "case-01" / "drop-Q235-0.2"
    rec.mkdir(parents=True)
    rows = [["t_s", "x_m", "z_m"]]
    for k in range(2000):
        if k == 7:
            continue
        x = "" if k == 12 else f"{0.001 * math.sin(k / 50):.6f}"
        rows.append([f"{0.25 + k / 1000:.3f}", x, f"{0.2 + 1e-4 * math.cos(k / 30):.6f}"])
    with (rec / "trial-01.csv").open("w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)
    manifest = {
        "format": "recording/1",
        "test": "drop",
        "surface": "Q235",
        "setup": {"release_height_m": 0.2},
        "camera": {"frame_rate_hz": 1000, "position_noise_m": 0.0001},
        "notes": "kept",
        "trials": [{"id": "01", "track": track_name, "summary": {"rebound_height_m": 0.05}, "extra": 3}],
    }
    (rec / "recording.json").write_text(json.dumps(manifest))
    (root / "ANSWERS.json").write_text('{"cases": {}}')
    return rec


def run(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True)


def read_track(path):
    with path.open(newline="") as f:
        return list(csv.reader(f))


def test_a_drop_filmed_again_at_250_fps_with_half_a_millimetre(tmp_path):
    source = tmp_path / "set"
    original = read_track(make_set(source) / "trial-01.csv")
    out = tmp_path / "out"
    r = run(source, out, "--fps", "drop=250", "--noise", "5e-4", "--seed", "3")
    assert r.returncode == 0, r.stderr
    rec = out / "case-01" / "drop-Q235-0.2"
    rows = read_track(rec / "trial-01.csv")
    assert rows[0] == ["t_s", "x_m", "z_m"]
    by_time = {row[0]: row for row in original[1:]}
    kept = [row[0] for row in rows[1:]]
    # Every fourth frame of the recorded clock, from the first frame's time on.
    assert kept == [t for t in by_time if round((float(t) - 0.25) * 1000) % 4 == 0]
    assert "0.254" in kept and "0.255" not in kept and "0.258" in kept
    assert len(kept) == 500
    # The empty cell stays empty; the other cells carry the added noise, sqrt(0.5^2 - 0.1^2) mm.
    assert [row[1] for row in rows[1:] if row[0] == "0.262"] == [""]
    added = [float(row[c]) - float(by_time[row[0]][c]) for row in rows[1:] for c in (1, 2) if row[c]]
    expected = math.sqrt(0.5e-3**2 - 0.1e-3**2)
    assert abs(statistics.pstdev(added) / expected - 1.0) < 0.08  # 999 draws: 2.2 % standard error
    assert abs(statistics.mean(added)) < 4 * expected / math.sqrt(len(added))
    manifest = json.loads((rec / "recording.json").read_text())
    assert manifest["camera"] == {"frame_rate_hz": 250, "position_noise_m": 5e-4}
    assert manifest["notes"] == "kept" and manifest["trials"][0]["extra"] == 3
    assert manifest["trials"][0]["summary"]["rebound_height_m"] != 0.05
    assert abs(manifest["trials"][0]["summary"]["rebound_height_m"] - 0.05) < 5 * expected
    assert (out / "ANSWERS.json").read_text() == '{"cases": {}}'
    assert json.loads((out / "RECAMERA.json").read_text())["fps"] == {"drop": 250.0}
    # The same seed films the same set; another seed another.
    again = tmp_path / "again"
    assert run(source, again, "--fps", "drop=250", "--noise", "5e-4", "--seed", "3").returncode == 0
    assert read_track(again / "case-01" / "drop-Q235-0.2" / "trial-01.csv") == rows
    other = tmp_path / "other"
    assert run(source, other, "--fps", "drop=250", "--noise", "5e-4", "--seed", "4").returncode == 0
    assert read_track(other / "case-01" / "drop-Q235-0.2" / "trial-01.csv") != rows


def test_an_image_scale_off_multiplies_every_length(tmp_path):
    source = tmp_path / "set"
    original = read_track(make_set(source) / "trial-01.csv")
    out = tmp_path / "out"
    r = run(source, out, "--noise", "1e-4", "--scale", "1.01")
    assert r.returncode == 0, r.stderr
    rec = out / "case-01" / "drop-Q235-0.2"
    rows = read_track(rec / "trial-01.csv")
    assert [row[0] for row in rows] == [row[0] for row in original]  # every frame kept, no noise added
    for new, old in zip(rows[1:], original[1:]):
        for c in (1, 2):
            assert (new[c] == "") == (old[c] == "")
            if old[c]:
                assert abs(float(new[c]) - 1.01 * float(old[c])) < 1e-6
    manifest = json.loads((rec / "recording.json").read_text())
    assert abs(manifest["trials"][0]["summary"]["rebound_height_m"] - 0.0505) < 1e-9
    assert json.loads((out / "RECAMERA.json").read_text())["scale"] == 1.01
    refused(tmp_path, source, tmp_path / "bad", "--noise", "1e-4", "--scale", "0", message="--scale 0 outside [0.5, 2]")


def test_a_frame_rate_not_named_is_kept(tmp_path):
    source = tmp_path / "set"
    make_set(source)
    out = tmp_path / "out"
    assert run(source, out, "--fps", "roll=125", "--noise", "2e-4").returncode == 0
    assert len(read_track(out / "case-01" / "drop-Q235-0.2" / "trial-01.csv")) == 2000  # header + 1999 frames


def refused(tmp_path, source, out, *options, message):
    r = run(source, out, *options)
    assert r.returncode == 1, r.stdout
    assert message in r.stderr, r.stderr
    assert "Traceback" not in r.stderr
    assert not out.exists()
    assert not [p for p in out.parent.iterdir() if p.name.startswith(f".{out.name}.")]


def test_bad_options_and_recordings_are_refused_and_nothing_is_written(tmp_path):
    source = tmp_path / "set"
    make_set(source)
    out = tmp_path / "out"
    manifest = source / "case-01" / "drop-Q235-0.2" / "recording.json"
    refused(tmp_path, source, out, "--fps", "drop=300", "--noise", "5e-4",
            message=f"{manifest}: 300 fps does not divide the recorded 1000 fps")
    refused(tmp_path, source, out, "--fps", "drop=2000", "--noise", "5e-4", message="does not divide")
    refused(tmp_path, source, out, "--noise", "5e-5", message=f"{manifest}: --noise 5e-05 m is below the recorded")
    refused(tmp_path, source, out, "--noise", "1", message="--noise 1 m outside [0, 0.01] m")
    refused(tmp_path, source, out, "--fps", "spin=10", "--noise", "5e-4", message="--fps: unknown test 'spin'")
    refused(tmp_path, source, out, "--fps", "drop=-5", "--noise", "5e-4", message="outside (0, 1e6] Hz")
    refused(tmp_path, source, source / "inner", "--noise", "5e-4", message="inside the recordings it re-films")
    out.mkdir()
    r = run(source, out, "--noise", "5e-4")
    assert r.returncode == 1 and "exists" in r.stderr
    out.rmdir()
    leaving = tmp_path / "leaving"
    make_set(leaving, track_name="../../../secret.csv")
    (tmp_path / "secret.csv").write_text("t_s,x_m,z_m\n0,0,0\n")
    refused(tmp_path, leaving, out, "--noise", "5e-4", message="track '../../../secret.csv' leaves its recording's folder")
    assert (tmp_path / "secret.csv").read_text() == "t_s,x_m,z_m\n0,0,0\n"
    missing = tmp_path / "missing"
    make_set(missing, track_name="trial-09.csv")
    refused(tmp_path, missing, out, "--noise", "5e-4",
            message=f"{missing / 'case-01' / 'drop-Q235-0.2' / 'trial-09.csv'}: cannot read the track")
    for name, bad, what in (("listed", '{"trials": {"a": 1}}', "trials must be a list of objects"),
                            ("summary", '{"trials": [{"id": "1", "summary": [1]}]}', "a trial's summary must be an object"),
                            ("array", "[1, 2]", "not a JSON object")):
        rec = make_set(tmp_path / name)
        (rec / "recording.json").write_text(bad)
        refused(tmp_path, tmp_path / name, out, "--noise", "5e-4", message=f"{rec / 'recording.json'}: {what}")
    broken = tmp_path / "broken"
    rec = make_set(broken)
    (rec / "recording.json").write_text("{ not json")
    refused(tmp_path, broken, out, "--noise", "5e-4",
            message=f"{broken / 'case-01' / 'drop-Q235-0.2' / 'recording.json'}: Expecting property name")
