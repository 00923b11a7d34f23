"""bench/outcomes_by_resolution.py --match with the real clumpforge-conceal (run by ctest, label
fast; CLUMPFORGE_CONCEAL names the binary): the finer clump is run at the restitution that gives
it the first clump's mean 0.2 m rebound, a higher one under whole wall mass (a finer clump's
touching spheres damp more, docs/diagnose.md); without --match each clump keeps the restitution
given; a clump not named LIBRARY.h5:NAME is refused."""

import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "bench" / "outcomes_by_resolution.py"
LADDER = ROOT / "clumps" / "tuber-default-ladder.h5"


def run(*args):
    conceal = os.environ.get("CLUMPFORGE_CONCEAL", str(ROOT / "build" / "tools" / "clumpforge-conceal"))
    return subprocess.run([sys.executable, str(SCRIPT), "--conceal", conceal, "--trials", "2", *args],
                          capture_output=True, text=True)


def test_match_gives_the_finer_clump_the_first_clumps_rebound():
    done = run("--match", "drop-0.2m", "--json", f"{LADDER}:adaptive-32", f"{LADDER}:adaptive-64")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    e = report["restitution"]
    assert e["adaptive-32"] == 0.634823744
    # whole wall mass: the 64-sphere clump needs a higher restitution for the same rebound
    assert e["adaptive-64"] > e["adaptive-32"] + 0.02
    rebound = report["outcomes"]["drop-0.2m rebound height"]
    # 8 halvings of [0.3, 0.999] leave e within 0.0027; near e = 0.7 the mean rebound changes by
    # about 0.25 mm per 0.001 of e (23.5 -> 38 mm from 0.635 to 0.699), so within 1.5 mm
    assert abs(rebound["adaptive-64"]["mean_mm"] - rebound["adaptive-32"]["mean_mm"]) < 1.5


def test_without_match_every_clump_keeps_the_restitution_given_and_a_bad_spec_is_refused():
    done = run("--json", f"{LADDER}:adaptive-32")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert "restitution" not in report and "drop-1m rebound height" in report
    refused = run(f"{LADDER}")
    assert refused.returncode == 2 and "is not LIBRARY.h5:NAME" in refused.stderr
