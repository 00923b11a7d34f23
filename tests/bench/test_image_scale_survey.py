"""bench/image_scale_survey.py with the built Python module (run by ctest, label fast): the
lab-like sphere's recordings read at the true scale and through a camera 1 % long, a mesh
outside the recording's folder opened only when the user names its folder, and nothing written
on a refusal."""

import json
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "bench" / "image_scale_survey.py"
RECAMERA = ROOT / "bench" / "recamera.py"
LAB_LIKE = ROOT.parent / "shared" / "data" / "lab-like"


def survey(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True)


def test_a_sphere_cases_recordings_read_at_the_true_scale_and_through_one_off(tmp_path):
    run = survey(LAB_LIKE / "case-02", "--meshes", LAB_LIKE / "meshes", "--json", tmp_path / "true.json")
    assert run.returncode == 0, run.stderr
    readings = json.loads((tmp_path / "true.json").read_text())["readings"]
    assert sorted(r["from"] for r in readings).count("rolling_height") == 3
    assert sum(r["from"] == "free_flights" for r in readings) == 5
    assert not any(r["off"] for r in readings)
    assert all(abs(r["scale"] - 1.0) < 1e-3 for r in readings)
    assert "rolling_height: 3 readings, 0 off" in run.stdout

    copy = tmp_path / "long"
    subprocess.run([sys.executable, str(RECAMERA), str(LAB_LIKE / "case-02"), str(copy), "--noise", "1e-4",
                    "--scale", "1.01"], check=True, capture_output=True)
    shutil.copytree(LAB_LIKE / "meshes", tmp_path / "meshes")
    run = survey(copy, "--meshes", tmp_path / "meshes", "--json", tmp_path / "long.json")
    assert run.returncode == 0, run.stderr
    readings = json.loads((tmp_path / "long.json").read_text())["readings"]
    assert len(readings) == 8
    for r in readings:
        assert r["off"], r
        assert abs(r["scale"] - 1.01) < 2e-3, r


def test_a_mesh_outside_the_recordings_folder_is_not_opened_unless_its_folder_is_named(tmp_path):
    run = survey(LAB_LIKE / "case-02", "--json", tmp_path / "out.json")
    assert run.returncode == 2
    assert "recording.json: its mesh '../../meshes/sphere.stl' lies outside its folder" in run.stderr
    assert "--meshes" in run.stderr
    assert not (tmp_path / "out.json").exists()
    assert list(tmp_path.iterdir()) == []


def test_a_folder_without_recordings_is_refused(tmp_path):
    run = survey(tmp_path / "absent")
    assert run.returncode == 2 and "not a folder" in run.stderr
    (tmp_path / "empty").mkdir()
    run = survey(tmp_path / "empty")
    assert run.returncode == 2 and "no recording shows its image scale" in run.stderr


def test_absurd_options_are_refused(tmp_path):
    run = survey(LAB_LIKE / "case-02", "--mesh", tmp_path / "none.stl")
    assert run.returncode == 2 and "--mesh" in run.stderr and "not a file" in run.stderr
    run = survey(LAB_LIKE / "case-02", "--mesh", LAB_LIKE / "meshes" / "sphere.stl", "--density", "1e9")
    assert run.returncode == 2 and "outside [1, 25000]" in run.stderr
    run = survey(LAB_LIKE / "case-02", "--clump", ROOT / "clumps" / "tuber-default-ladder.h5:adaptive-7")
    assert run.returncode == 2 and "holds no clump 'adaptive-7'" in run.stderr


def test_a_stored_clump_serves_every_recording(tmp_path):
    """With a tuber's clump the sphere's rolls give no scale (a tumbling body's centre rises and
    falls), its drops still do."""
    run = survey(LAB_LIKE / "case-02", "--clump", ROOT / "clumps" / "tuber-default-ladder.h5:adaptive-64")
    assert run.returncode == 0, run.stderr
    assert "free_flights: 5 readings" in run.stdout and "rolling_height" not in run.stdout
