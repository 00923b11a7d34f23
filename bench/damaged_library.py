#!/usr/bin/env python3
"""What `clumpforge` does with a clump library that has one byte changed, sealed and unsealed.

A library is written with a seal: its first 512 bytes (HDF5's user block) hold the SHA-256 and
length of the HDF5 file after them (docs/clump-library.md). HDF5's addresses count from the
superblock, so the same file less those 512 bytes is the library unsealed, as it was written
before the seal (what `h5unjam` gives). For each position in [--from, --to) of the HDF5 bytes,
one copy of each has that byte changed (XOR --mask), and `clumpforge export COPY --all --format
csv` reads it in a process of its own, timed out after --timeout seconds. Each read is one of:

  refused    a non-zero exit with clumpforge's message
  same       read, and the export is the undamaged library's to the byte (a byte no reader uses)
  other      read, and the export differs: the damage read as another clump
  crashed    the process died on a signal (libhdf5's own calls, before any message)
  hung       still running after the timeout (killed)

  bench/damaged_library.py --clumpforge build/tools/clumpforge \\
      --library clumps/tuber-default-diagnosis.h5 --from 1000 --to 2000 [--json OUT.json]
"""
import argparse
import filecmp
import json
import os
import signal
import subprocess
import sys
import tempfile

SEAL_BYTES = 512
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
OUTCOMES = ("refused", "same", "other", "crashed", "hung")


def hdf5_part(library: bytes) -> tuple[bytes, bytes]:
    """The seal (empty if none) and the HDF5 file after it. Raises ValueError if neither layout."""
    if library.startswith(HDF5_SIGNATURE):
        return b"", library
    if library[SEAL_BYTES:].startswith(HDF5_SIGNATURE):
        return library[:SEAL_BYTES], library[SEAL_BYTES:]
    raise ValueError("not a clump library: no HDF5 signature at byte 0 or 512")


def export(clumpforge: str, library: str, out: str, timeout: float) -> str | int:
    """Runs the export; its exit code, or "crashed" / "hung"."""
    try:
        done = subprocess.run([clumpforge, "export", library, "--all", "--format", "csv", "-o", out],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=timeout,
                              start_new_session=True)
    except subprocess.TimeoutExpired:
        return "hung"
    return "crashed" if done.returncode < 0 else done.returncode


def same_output(a: str, b: str) -> bool:
    """The two exports (a file, or a folder for several clumps) hold the same bytes."""
    if os.path.isfile(a) and os.path.isfile(b):
        return filecmp.cmp(a, b, shallow=False)
    if not (os.path.isdir(a) and os.path.isdir(b)):
        return False
    compared = filecmp.dircmp(a, b)
    if compared.left_only or compared.right_only or compared.funny_files:
        return False
    return all(same_output(os.path.join(a, n), os.path.join(b, n)) for n in compared.common)


def classify(clumpforge: str, copy: str, reference: str, work: str, timeout: float) -> str:
    out = tempfile.mkdtemp(dir=work)
    code = export(clumpforge, copy, os.path.join(out, "export"), timeout)
    if code in ("crashed", "hung"):
        return code
    if code != 0:
        return "refused"
    return "same" if same_output(os.path.join(out, "export"), reference) else "other"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--clumpforge", required=True)
    p.add_argument("--library", required=True, help="a sealed library (written by this clumpforge)")
    p.add_argument("--from", dest="first", type=int, default=1000, help="first HDF5 byte changed")
    p.add_argument("--to", dest="last", type=int, default=2000, help="one past the last HDF5 byte changed")
    p.add_argument("--mask", type=lambda s: int(s, 0), default=0x5A, help="XOR applied to the byte (not 0)")
    p.add_argument("--timeout", type=float, default=10.0, help="seconds before a read counts as hung")
    p.add_argument("--json", help="write the counts and each position's outcome here")
    a = p.parse_args()
    if not 0 < a.mask < 256 or a.timeout <= 0:
        p.error("--mask must be 1..255 and --timeout positive")
    try:
        with open(a.library, "rb") as f:
            seal, body = hdf5_part(f.read())
    except (OSError, ValueError) as e:
        print(f"damaged_library.py: {a.library}: {e}", file=sys.stderr)
        return 1
    if not seal:
        print(f"damaged_library.py: {a.library} has no seal; write it again with this clumpforge", file=sys.stderr)
        return 1
    if not 0 <= a.first < a.last <= len(body):
        p.error(f"--from/--to must lie in [0, {len(body)}] (the library's HDF5 bytes)")
    counts = {kind: {o: 0 for o in OUTCOMES} for kind in ("sealed", "unsealed")}
    where = {kind: {o: [] for o in OUTCOMES if o != "same"} for kind in counts}
    with tempfile.TemporaryDirectory() as work:
        reference = os.path.join(work, "reference")
        copy = os.path.join(work, "copy.h5")
        with open(copy, "wb") as f:
            f.write(seal + body)
        if export(a.clumpforge, copy, reference, a.timeout) != 0:
            print(f"damaged_library.py: clumpforge cannot export {a.library} undamaged", file=sys.stderr)
            return 1
        for i in range(a.first, a.last):
            damaged = bytearray(body)
            damaged[i] ^= a.mask
            for kind, head in (("sealed", seal), ("unsealed", b"")):
                with open(copy, "wb") as f:
                    f.write(head + bytes(damaged))
                outcome = classify(a.clumpforge, copy, reference, work, a.timeout)
                counts[kind][outcome] += 1
                if outcome != "same":
                    where[kind][outcome].append(i)
    n = a.last - a.first
    for kind, c in counts.items():
        print(f"{kind:>8}: {n} copies, HDF5 bytes {a.first}-{a.last - 1} changed one at a time: " +
              ", ".join(f"{o} {c[o]}" for o in OUTCOMES))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"library": a.library, "from": a.first, "to": a.last, "mask": a.mask, "counts": counts,
                       "positions": where}, f, indent=1)
    return 0


if __name__ == "__main__":
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    sys.exit(main())
