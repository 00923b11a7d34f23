"""bench/rim_faces.py against analytic rims (run by ctest, label fast): a ring of N equal
spheres on a circle of radius R rolls over N faces of length 2 R sin(pi/N) each; a single
sphere over none; a library that is not there, and too few directions, are refused by name."""

import math
import pathlib
import subprocess
import sys

import h5py
import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "bench" / "rim_faces.py"
sys.path.insert(0, str(ROOT / "bench"))
import rim_faces  # noqa: E402


def ring(n, radius, sphere, axis=2):
    angle = 2 * math.pi * np.arange(n) / n
    plane = [i for i in range(3) if i != axis]
    centres = np.zeros((n, 3))
    centres[:, plane[0]], centres[:, plane[1]] = radius * np.cos(angle), radius * np.sin(angle)
    return centres, np.full(n, sphere)


def test_a_ring_of_equal_spheres_rolls_over_chords():
    for n in (6, 18, 70):
        centres, radii = ring(n, 8e-3, 1.5e-3)
        faces = rim_faces.rim_faces(centres, radii, 2, 72000)
        assert len(faces) == n
        # tolerance: the 72000 directions resolve a switch to 1e-4 rad; the face is a chord at it
        np.testing.assert_allclose(faces, 2 * 8e-3 * math.sin(math.pi / n), rtol=1e-6)


def test_a_ring_normal_to_another_axis_and_a_single_sphere():
    centres, radii = ring(12, 5e-3, 1e-3, axis=0)
    faces = rim_faces.rim_faces(centres, radii, 0, 36000)
    np.testing.assert_allclose(faces, 2 * 5e-3 * math.sin(math.pi / 12), rtol=1e-6)
    # the rim normal to a ring's own plane meets two spheres only, at the ring's far ends
    assert len(rim_faces.rim_faces(centres, radii, 2, 36000)) == 2
    assert len(rim_faces.rim_faces(np.zeros((1, 3)), np.array([1e-3]), 2, 3600)) == 0


def test_the_table_names_each_clump_and_a_missing_library_or_clump_is_refused(tmp_path):
    centres, radii = ring(18, 8e-3, 1.5e-3)
    library = tmp_path / "ring.h5"
    with h5py.File(library, "w") as f:
        g = f.create_group("clumps/ring-18")
        g["spheres"] = np.column_stack([centres, radii])
        g["principal_moments_kg_m2"] = np.array([1.0, 1.0, 2.0])  # the ring's axis: z
    done = subprocess.run([sys.executable, str(SCRIPT), f"{library}:ring-18"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    row = done.stdout.splitlines()[2].split("|")
    assert row[1].strip() == "ring-18" and row[3].strip() == "18"
    assert float(row[4]) == round(18 * 2 * 8.0 * math.sin(math.pi / 18), 1)
    missing = subprocess.run([sys.executable, str(SCRIPT), f"{tmp_path / 'none.h5'}:ring"], capture_output=True,
                             text=True)
    assert missing.returncode == 1 and "none.h5" in missing.stderr
    no_clump = subprocess.run([sys.executable, str(SCRIPT), f"{library}:ring-7"], capture_output=True, text=True)
    assert no_clump.returncode == 1 and "ring-7" in no_clump.stderr
    no_library = subprocess.run([sys.executable, str(SCRIPT), "ring-18"], capture_output=True, text=True)
    assert no_library.returncode == 1 and "give LIBRARY.h5:NAME" in no_library.stderr


def test_too_few_directions_are_refused():
    done = subprocess.run([sys.executable, str(SCRIPT), "--samples", "10", "x.h5:a"], capture_output=True, text=True)
    assert done.returncode == 2 and "--samples 360 or more" in done.stderr and done.stdout == ""
