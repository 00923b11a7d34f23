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


def filmed_drop(phase: float, noise: float, rng) -> tuple:
    """A drop from 0.2 m filmed at 1000 fps (the first frame `phase` ms into the fall): a free fall
    to a contact at centroid height 5 mm, a rebound at 0.5 m/s (rise 12.74 mm), a second contact
    at the same height, and a rest at 4 mm (the body toppled onto a flatter face)."""
    sys.path.insert(0, str(ROOT / "bench"))
    from outcomes_by_resolution import G
    fall = (2 * 0.195 / G) ** 0.5
    flight = 2 * 0.5 / G

    def z_at(s):
        if s < fall:
            return 0.2 - 0.5 * G * s * s
        if s < fall + flight:
            u = s - fall
            return 0.005 + 0.5 * u - 0.5 * G * u * u
        return 0.004
    t = [phase * 1e-3 + k * 1e-3 for k in range(400)]
    return t, [z_at(s) + rng.gauss(0.0, noise) for s in t]


def test_the_parabolas_read_the_rebound_wherever_the_frames_fall_about_the_contact():
    import random
    sys.path.insert(0, str(ROOT / "bench"))
    from outcomes_by_resolution import rebound_readings
    rng = random.Random(5)
    rise = 0.5 ** 2 / (2 * 9.81)
    # the lowest frame about an instant contact: min(v_down s, v_up (1 - s)) / fps above it, the
    # frames' phase s: at most v_down v_up / (v_down + v_up) / fps, 0.40 mm here
    v_down = (2 * 9.81 * 0.195) ** 0.5
    worst = v_down * 0.5 / (v_down + 0.5) * 1e-3
    for noise, within in ((0.0, 2e-5), (1e-4, 2e-4)):
        low_errors = []
        for k in range(20):
            t, z = filmed_drop(k / 20.0, noise, rng)
            r = rebound_readings(t, [0.0] * len(t), z)
            # the parabolas: exact without noise; with 0.1 mm on about 100 frames per flight, 0.2 mm
            assert abs(r["from the parabolas"] - rise) < within, (noise, k, r)
            # the rest point is 1 mm below the contact: that reading is 1 mm high (the highest of
            # the noisy frames a few tenths higher still; the apex frame g dt^2 / 8 below the apex;
            # the rest height the diagnosis's median of ten noisy frames, the upper of the middle
            # two: within two noise sds of the rest)
            assert -2 * noise - 2e-6 <= r["above the rest point"] - (rise + 1e-3) < 5 * noise + 1e-6, (noise, k, r)
            low_errors.append(r["above the impact's low point"] - rise)
        if noise == 0.0:
            assert all(-worst - 1e-9 <= e <= 1e-9 for e in low_errors), low_errors
            assert max(low_errors) - min(low_errors) > 0.6 * worst, low_errors
