"""bench/damaged_library.py with the real clumpforge (run by ctest, label fast): every changed
byte of a sealed library refused before libhdf5 reads it, the same bytes unsealed sorted into
what libhdf5 and clumpforge make of them, and the script's refusals."""

import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "bench" / "damaged_library.py"
LIBRARY = ROOT / "clumps" / "tuber-default-diagnosis.h5"
CLUMPFORGE = os.environ["CLUMPFORGE"]


def run(*args):
    return subprocess.run([sys.executable, str(SCRIPT), "--clumpforge", CLUMPFORGE, *map(str, args)],
                          capture_output=True, text=True)


def test_every_changed_byte_of_a_sealed_library_is_refused(tmp_path):
    # Bytes 0-95 of the HDF5 file: the superblock and the root group's symbol table entry,
    # where an unsealed file's damage is read by libhdf5 before anything else.
    done = run("--library", LIBRARY, "--from", 0, "--to", 96, "--json", tmp_path / "out.json")
    assert done.returncode == 0, done.stderr
    counts = json.loads((tmp_path / "out.json").read_text())["counts"]
    assert counts["sealed"] == {"refused": 96, "same": 0, "other": 0, "crashed": 0, "hung": 0}
    assert sum(counts["unsealed"].values()) == 96
    # Unsealed, some of these bytes are not checked by anyone: read as if undamaged, or as another clump.
    assert counts["unsealed"]["refused"] < 96
    assert "sealed: 96 copies" in done.stdout


def test_no_changed_byte_of_an_unsealed_library_crashes_clumpforge(tmp_path):
    # HDF5 bytes 1040-1049 hold eight that crashed libhdf5 unsealed, and with it clumpforge
    # (SIGSEGV, before stop 100); an unsealed library is now read first in a process of its own.
    done = run("--library", LIBRARY, "--from", 1040, "--to", 1050, "--json", tmp_path / "out.json")
    assert done.returncode == 0, done.stderr
    counts = json.loads((tmp_path / "out.json").read_text())["counts"]
    assert counts["unsealed"]["crashed"] == 0 and counts["unsealed"]["hung"] == 0
    assert counts["unsealed"]["refused"] >= 8
    assert counts["sealed"]["refused"] == 10


def test_a_library_without_a_seal_or_with_absurd_options_is_refused(tmp_path):
    unsealed = tmp_path / "unsealed.h5"
    unsealed.write_bytes(LIBRARY.read_bytes()[512:])
    done = run("--library", unsealed, "--from", 0, "--to", 4)
    assert done.returncode == 1 and "has no seal" in done.stderr
    text = tmp_path / "text.h5"
    text.write_text("not hdf5")
    done = run("--library", text)
    assert done.returncode == 1 and "no HDF5 signature" in done.stderr
    assert run("--library", LIBRARY, "--mask", 0).returncode == 2
    assert run("--library", LIBRARY, "--from", 10, "--to", 10 ** 9).returncode == 2
