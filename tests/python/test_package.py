"""The Python package, imported as a user imports it (PYTHONPATH=build/python), against
analytic answers and the files the library writes. Run by ctest (label python)."""

import json
import math
import pathlib
import shutil
import threading
import time

import numpy as np
import pytest

import clumpforge as cf

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared"


def box(a, b, c):
    """A closed, outward box of sides a, b, c [m], centred at (1, 2, 3) mm."""
    o = np.array([1e-3, 2e-3, 3e-3])
    v = np.array([[x, y, z] for x in (-a / 2, a / 2) for y in (-b / 2, b / 2) for z in (-c / 2, c / 2)]) + o
    # vertex index = 4 ix + 2 iy + iz
    f = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
         [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    return cf.Mesh(v, np.array(f, dtype=np.int32))


def test_the_readme_example_works_as_written(tmp_path):
    mesh = cf.load_mesh(str(ROOT / "meshes/tuber-default.stl"), units="mm")
    repaired = cf.repair(mesh)
    props = cf.mass_properties(repaired.mesh, density=1085.0)
    clump = cf.fill(repaired.mesh, method="lattice", diameter=0.002, density=1085.0)
    assert clump.centres.shape == (len(clump.radii), 3)
    # the study's tuber: ~3.7 g, ~19 mm long
    assert 3.0e-3 < props.mass < 4.5e-3
    assert repaired.after.closed and repaired.after.self_intersecting_pairs == 0
    assert clump.name == "lattice-2mm" and np.allclose(clump.radii, 1e-3)
    assert clump.mass == pytest.approx(props.mass, rel=1e-12)
    np.testing.assert_allclose(clump.principal_moments, props.principal_moments, rtol=1e-12)


def test_mass_properties_of_a_box_are_exact():
    a, b, c = 0.02, 0.01, 0.006
    props = cf.mass_properties(box(a, b, c), density=1000.0)
    m = 1000.0 * a * b * c
    assert props.volume == pytest.approx(a * b * c, rel=1e-12)
    assert props.mass == pytest.approx(m, rel=1e-12)
    np.testing.assert_allclose(props.centroid, [1e-3, 2e-3, 3e-3], atol=1e-15)
    expected = sorted([m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12])
    np.testing.assert_allclose(props.principal_moments, expected, rtol=1e-12)
    assert isinstance(props.principal_axes, np.ndarray) and props.principal_axes.shape == (3, 3)


def test_a_lattice_fill_of_a_box_has_the_lattice_count():
    # a 10 x 10 x 10 mm cube, 2 mm pitch, a node at the centroid: nodes at 0, +-2, +-4 mm
    clump = cf.fill(box(0.01, 0.01, 0.01), method="lattice", diameter=0.002, density=1000.0)
    assert len(clump) == 125
    assert set(np.round(np.abs(clump.centres.ravel()) * 1e3, 9)) == {0.0, 2.0, 4.0}
    # the union of 125 touching 2 mm spheres is 125 * (4/3 pi r^3) of 1e-6 m^3
    assert clump.error.volume_error == pytest.approx(125 * 4 / 3 * math.pi * 1e-9 / 1e-6 - 1, abs=1e-3)


def test_library_errors_are_python_exceptions_with_the_library_message(tmp_path):
    with pytest.raises(cf.NotFoundError) as missing:
        cf.load_mesh(str(tmp_path / "none.stl"))
    assert "none.stl" in str(missing.value) and missing.value.code == "not found"
    assert isinstance(missing.value, FileNotFoundError)
    open_box = box(0.01, 0.01, 0.01)
    open_box = cf.Mesh(open_box.vertices, open_box.faces[:-1])
    with pytest.raises(cf.InvalidMeshError, match="repair"):
        cf.mass_properties(open_box, density=1000.0)
    with pytest.raises(cf.InvalidArgumentError, match="diameter"):
        cf.fill(box(0.01, 0.01, 0.01), diameter=-1.0)
    with pytest.raises(cf.InvalidArgumentError, match="unknown method"):
        cf.fill(box(0.01, 0.01, 0.01), method="voxel")
    with pytest.raises(cf.InvalidArgumentError):
        cf.Mesh(np.zeros((3, 3)), np.array([[0, 1, 7]], dtype=np.int32))


def test_a_library_round_trips_and_exports_write_files(tmp_path):
    clump = cf.fill(box(0.01, 0.008, 0.006), method="adaptive", max_spheres=20, density=1085.0, name="box")
    path = tmp_path / "lib.h5"
    cf.write_library(str(path), [clump])
    back = cf.read_clump(str(path), "box")
    np.testing.assert_array_equal(back.centres, clump.centres)
    np.testing.assert_array_equal(back.radii, clump.radii)
    assert back.mass == clump.mass and back.error.surface_rms == clump.error.surface_rms
    files = cf.export(clump, "liggghts", str(tmp_path / "box.txt"))
    text = pathlib.Path(files[0]).read_text()
    assert f"nspheres {len(clump)}" in text.replace("  ", " ") or str(len(clump)) in text
    pop = cf.export_population([clump, back_renamed(back)], "yade", str(tmp_path / "pop"), fractions=[3, 1])
    assert pop["number_fractions"] == pytest.approx([0.75, 0.25])
    assert (tmp_path / "pop" / "population.py").exists()


def back_renamed(clump):
    return cf.Clump("box2", clump.centres, clump.radii, clump.density, clump.mass, clump.principal_moments,
                    clump.body_volume)


def test_a_drop_rebounds_as_the_cli_says_and_reports_progress():
    clump = cf.read_clump(str(ROOT / "clumps/tuber-default.h5"), "lattice-2mm")
    stages = []
    result = cf.validate(clump, test="drop", surface="Q235", trials=4, seed=7,
                         progress=lambda stage, fraction: stages.append((stage, fraction)))
    assert result.summaries.shape == (4,)
    # a rebound below the release height, above zero; sqrt(h/H) below the table's e = 0.7
    assert np.all((result.summaries > 0) & (result.summaries < 0.2))
    assert all(i.apparent_restitution < 0.7 for i in result.impacts)
    assert stages and all(0.0 <= f <= 1.0 for _, f in stages)
    again = cf.validate(clump, test="drop", surface="Q235", trials=4, seed=7)
    np.testing.assert_array_equal(again.summaries, result.summaries)  # seeds in options: the same bits


def test_long_calls_release_the_gil_and_a_raising_callback_stops_them():
    clump = cf.read_clump(str(ROOT / "clumps/tuber-default.h5"), "lattice-2mm")
    ticks = 0
    done = threading.Event()

    def run():
        # 24 trials: about 0.2 s on an idle machine (6 took 45 ms, too close to the 50 ticks of 1 ms
        # a main thread that runs alongside counts).
        cf.validate(clump, test="roll", surface="soil", trials=24)
        done.set()

    worker = threading.Thread(target=run)
    worker.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    assert ticks > 50  # the main thread ran while the DEM did

    class Stop(Exception):
        pass

    def stop(stage, fraction):
        if fraction > 0.2:
            raise Stop()

    started = time.monotonic()
    with pytest.raises(Stop):
        cf.validate(clump, test="roll", surface="soil", trials=200, progress=stop)
    assert time.monotonic() - started < 30


def test_recordings_read_and_absurd_ones_are_refused(tmp_path):
    recordings = cf.read_recordings(str(ROOT / "clumps/tuber-default-diagnosis/recordings"))
    assert list(recordings) == ["drop-0.2m", "drop-1m", "roll-100mm", "tilt"]
    drop = recordings["drop-1m"]
    assert drop.test == cf.LabTest.drop and drop.release_height == pytest.approx(1.0)
    trial = drop.trials[0]
    assert trial.has_track and trial.t.shape == trial.x.shape == trial.z.shape
    assert trial.release_orientation is None  # like a real lab's
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "recording.json").write_text('{"format": "recording/1", "test": "drop", "surface": "Q235", '
                                        '"release_height_m": 1e9, "trials": []}')
    with pytest.raises(cf.Error, match="recording.json"):
        cf.read_recording(str(bad))
    assert drop.keys_not_read == []
    d = drop.digest()
    assert d["trials"] == d["tracked"] == len(drop.trials) and d["rows"] == sum(t.t.size for t in drop.trials)
    assert d["frame_step_s"] == pytest.approx(1e-3) and d["summary_mean"] == pytest.approx(drop.summaries.mean())
    unread = tmp_path / "unread"
    shutil.copytree(ROOT / "clumps/tuber-default-diagnosis/recordings/drop-1m", unread)
    manifest = json.loads((unread / "recording.json").read_text())
    manifest.setdefault("particle", {}).pop("density_kg_m3", None)
    manifest["particle"]["density"] = 1300  # the lab's own name: kept, not read
    (unread / "recording.json").write_text(json.dumps(manifest))
    misnamed = cf.read_recording(str(unread))
    assert misnamed.particle_density is None
    assert misnamed.keys_not_read == [
        {"section": "particle", "key": "density", "value": "1300", "spec_key": "density_kg_m3"}]


def test_diagnose_refuses_a_clump_of_another_density_than_the_recordings_state(tmp_path):
    """A lab-like drop states the particle's density; the same drop stating 1300 kg/m^3 is not a
    recording of the 1085 kg/m^3 tuber clump, and diagnose says so before anything runs."""
    source = SHARED / "data/lab-like/case-13/drop-Q235-0.5"
    stated = cf.read_recording(str(source))
    assert stated.particle_density == pytest.approx(1085.0)
    assert stated.particle_mesh == "../../meshes/sphere.stl" and stated.particle_mesh_units == "mm"
    heavy = tmp_path / "heavy"
    shutil.copytree(source, heavy, copy_function=shutil.copyfile)  # the shared set is read-only
    manifest = json.loads((heavy / "recording.json").read_text())
    manifest["particle"]["density_kg_m3"] = 1300
    (heavy / "recording.json").write_text(json.dumps(manifest))
    clump = cf.read_clump(str(ROOT / "clumps/tuber-default-diagnosis.h5"))
    with pytest.raises(cf.InvalidArgumentError, match="density 1300 kg/m\\^3, and the clump 'adaptive-32' is of 1085"):
        cf.diagnose(clump, {"heavy": cf.read_recording(str(heavy))}, effects=["air_drag"])


def test_a_damaged_byte_in_a_track_is_a_parse_error_not_a_unicode_error(tmp_path):
    # Found by flipping bytes in the bundled recordings: a byte that is not UTF-8, quoted in the
    # error message, came out as UnicodeDecodeError instead of the library's ParseError.
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "recording.json").write_text('{"format": "recording/1", "test": "drop", "surface": "Q235", '
                                        '"setup": {"release_height_m": 0.2}, '
                                        '"trials": [{"id": "1", "track": "t.csv"}]}')
    (bad / "t.csv").write_bytes(b"t_s,x_m,z_m\n0.000,0,0.2\n0.001,0.0\xfc\x1b[2J,0.2\n")
    with pytest.raises(cf.ParseError) as raised:
        cf.read_recording(str(bad))
    message = str(raised.value)
    assert "t.csv:3" in message and "\\xFC\\x1B[2J" in message
    assert "\x1b" not in message


def test_diagnose_takes_finer_clumps_of_the_same_body_only():
    """The particle-model check needs clumps of one body: a finer clump of another is refused by
    name before anything runs; the result carries the check (None without finer clumps)."""
    recordings = cf.read_recordings(str(ROOT / "clumps/tuber-default-diagnosis/recordings"))
    small = cf.fill(box(0.01, 0.01, 0.01), method="lattice", diameter=0.002, density=1085.0)
    big = cf.fill(box(0.02, 0.02, 0.02), method="lattice", diameter=0.002, density=1085.0)
    with pytest.raises(cf.InvalidArgumentError, match="not a model of the body"):
        cf.diagnose(small, recordings, finer_clumps=[big])
    with pytest.raises(cf.InvalidArgumentError, match="roll_release 'flat'"):
        cf.diagnose(small, recordings, roll_release="flat")
    with pytest.raises(cf.InvalidArgumentError, match="image_scale 'pixels'"):
        cf.diagnose(small, recordings, image_scale="pixels")
    assert {"recording", "source", "samples", "measured", "expected", "standard_error", "scale", "off", "applied"} <= set(
        dir(cf.RecordingScale)
    )
    assert "image_scale" in dir(cf.DiagnoseResult)
    assert "particle_model" in dir(cf.DiagnoseResult)
    assert cf.Basis.particle_model != cf.Basis.unexplained_outcomes
    # Beyond the release horizon a mismatch on a clump not converged there is undecidable.
    assert cf.Basis.unconverged_particle_model != cf.Basis.unexplained_outcomes
    assert {"means", "chi2", "p", "largest", "largest_move", "replays", "judged", "converged", "moves"} <= set(
        dir(cf.OutcomeShift)
    )
    assert {"recording", "outcome", "from_value", "to_value", "noise", "recorded_se", "chi2", "matters"} <= set(
        dir(cf.MeanMove)
    )
    assert "outcome_shift" in dir(cf.ParticleModelRung)
    assert "seconds" in dir(cf.ParticleModelRung) and "seconds_refit" in dir(cf.ParticleModelRung)
    # The drops' free flights: what they say about the tracked point, and the basis they name on.
    assert "flights" in dir(cf.DiagnoseResult)
    assert {"judged", "wobble_m", "allowance_m", "detected", "offset_m", "smallest_offset_m"} <= set(dir(cf.FlightWobble))
    assert cf.Basis.free_flights != cf.Basis.ensemble
    # A name made beyond the release horizon, checked on the held-out trials where it was made.
    assert {"heldout_outcomes", "heldout_flights"} <= set(dir(cf.DiagnoseResult))
    assert {"training_trials", "heldout_trials", "rms_z_null", "rms_z_named", "improvement", "values", "rung"} <= set(
        dir(cf.OutcomeHoldout)
    )
    assert {"training_flights", "heldout_flights", "offset_m", "wobble_m", "without_m", "with_m"} <= set(
        dir(cf.FlightHoldout)
    )


def test_diagnose_from_python_names_the_bundled_air_drag_and_reports_each_candidate():
    """The bundled recordings (air drag concealed, no release orientations) diagnosed from Python
    as from the CLI: air drag named frame by frame, adhesion fitted and failing; each candidate's
    report carries the absence-check fields report.json writes (NaN or empty where not probed)."""
    recordings = cf.read_recordings(str(ROOT / "clumps/tuber-default-diagnosis/recordings"))
    clump = cf.read_clump(str(ROOT / "clumps/tuber-default-diagnosis.h5"))
    result = cf.diagnose(clump, recordings, effects=["air_drag", "adhesion"])
    assert result.verdict == cf.Verdict.named and result.effect == "air_drag"
    assert result.basis == cf.Basis.frame_by_frame
    by_name = {h.name: h for h in result.hypotheses}
    assert by_name["air_drag"].passes and not by_name["adhesion"].passes
    # delta-BIC margin 10 (DiagnoseOptions::min_delta_bic)
    assert by_name["air_drag"].delta_bic > 10 > by_name["adhesion"].delta_bic
    # Named from the frames: its held-out trials are the tracks' (after < before), and no check
    # of a name on the outcomes or the flights ran.
    assert result.after.heldout_rms_mm < result.before.heldout_rms_mm
    assert result.heldout_outcomes is None and result.heldout_flights is None
    for h in result.hypotheses:
        assert h.values_used > 0 and isinstance(h.worsened_phases, list)
        # The absence check runs only under verdict none: nothing probed, nothing preferred.
        assert math.isnan(h.strong_delta_chi2) and math.isnan(h.strong_resolution_chi2)
        assert h.strong_preferred_in == [] and h.preferred_alone() is None
    assert {"surface", "test", "delta_chi2"} <= set(dir(cf.SetUpShare))
    # Strong enough to be found by the first search: no held start was needed.
    assert by_name["air_drag"].fit_start == cf.FitStart.first_search
    assert not by_name["air_drag"].profile_searched
    # The baseline's polish, per set-up: what each test's chi^2 was with the coefficients each
    # calibrated on its own test, and after; the polish never makes the whole worse.
    assert len(result.calibrated_per_test) == len(result.baseline)
    assert result.polish and all(isinstance(p.test, cf.LabTest) for p in result.polish)
    assert sum(p.chi2_polished for p in result.polish) <= sum(p.chi2_calibrated for p in result.polish) * (1 + 1e-9)
    # The drag shows in the drops' first flights: their misfit against the camera noise reaches
    # the level (2) at which candidates are fitted frame by frame.
    flights = [p for p in result.phases if p.phase == cf.Phase.flight]
    assert flights and all(p.large_misfit_level == 2.0 for p in flights)
    assert max(p.misfit_per_value for p in flights) >= 2.0


def test_materials_export_names_its_conventions():
    text = cf.export_materials(cf.default_materials(), "liggghts", conventions="liggghts")
    assert "coefficientRestitution" in text and "Tsuji" in text
    assert "lever arm R = the element sphere's radius" in text
    assert cf.default_materials().interaction("tuber", "Q235").restitution > 0
    table = json.loads(cf.default_materials().to_json())
    assert [m["name"] for m in table["materials"]] == ["tuber", "Q235", "soil"]


def test_ctrl_c_stops_a_long_call_within_a_second():
    import os
    import signal

    clump = cf.read_clump(str(ROOT / "clumps/tuber-default.h5"), "lattice-2mm")
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        cf.validate(clump, test="roll", surface="soil", trials=400)
    elapsed = time.monotonic() - started
    timer.join()
    assert elapsed < 1.5


def test_an_export_whose_companion_would_overwrite_it_is_refused(tmp_path):
    clump = cf.read_clump(str(ROOT / "clumps/tuber-default.h5"), "lattice-2mm")
    with pytest.raises(cf.InvalidArgumentError, match="both the primary file and its companion"):
        cf.export(clump, "yade", str(tmp_path / "c.py"))
    assert list(tmp_path.iterdir()) == []


def test_figures_draw_a_diagnosis_folder_with_lost_frames(tmp_path):
    """The figures module on a folder like diagnose writes: a lost frame (null) and a release
    horizon; PNG and SVG come out whole, nothing temporary stays, and a bad folder is refused."""
    import json
    import subprocess
    import sys

    from clumpforge import figures

    t = np.linspace(0.0, 0.45, 200)
    z = 1.0 - 0.5 * 9.81 * t**2
    recorded = list(z + 1e-4 * np.sin(40 * t))
    recorded[17] = None
    track = {"recording": "drop-1m", "t": list(t), "x": [0.0] * t.size, "z": recorded, "horizon": 0.3,
             "baseline_t": list(t), "baseline_x": [0.0] * t.size, "baseline_z": list(z + 1e-3 * t),
             "improved_t": list(t), "improved_x": [0.0] * t.size, "improved_z": list(z)}
    report = {"verdict": "air_drag", "noise_m": {"drop-1m": 1e-4},
              "phases": [{"recording": "drop-1m", "phase": "flight", "chi2_per_value": 4.0,
                          "improved_chi2_per_value": 1.1, "significant": True}]}
    (tmp_path / "report.json").write_text(json.dumps(report))
    (tmp_path / "tracks.json").write_text(json.dumps([track]))
    written = figures.draw("diagnosis", tmp_path)
    names = sorted(pathlib.Path(p).name for p in written)
    assert names == ["residuals-by-phase.png", "residuals-by-phase.svg", "track-drop-1m.png", "track-drop-1m.svg"]
    assert (tmp_path / "track-drop-1m.png").read_bytes()[1:4] == b"PNG"
    assert not list(tmp_path.glob("*.tmp.*"))
    bad = subprocess.run([sys.executable, "-m", "clumpforge.figures", "study", str(tmp_path)], capture_output=True,
                         text=True)
    assert bad.returncode == 1 and "study.json" in bad.stderr


def test_the_diagnosis_reads_a_drop_and_a_roll_as_it_reads_their_tracks():
    """measure_outcomes on analytic paths at 1000 fps: a drop from 0.2 m onto a contact at 5 mm,
    a rebound at 0.5 m/s (rise v^2 / 2g), rest at 4 mm and 30 mm along; a roll that comes to rest
    120 mm along at 0.3 s."""
    g = 9.81
    s = np.arange(600) * 1e-3
    fall = (2 * 0.195 / g) ** 0.5
    flight = 2 * 0.5 / g
    u = s - fall
    z = np.where(s < fall, 0.2 - 0.5 * g * s**2, np.where(u < flight, 0.005 + 0.5 * u - 0.5 * g * u**2, 0.004))
    x = np.clip(0.1 * u, 0.0, 0.03)
    t, x, z = s.tolist(), x.tolist(), z.tolist()
    out = cf.measure_outcomes(cf.LabTest.drop, t, x, z, moved=1e-3)
    assert set(out) == {cf.Outcome.rebound_height, cf.Outcome.drift}
    rise = 0.5**2 / (2 * g)
    # the rest point 1 mm below the contact; the apex frame at most g dt^2 / 8 below the apex
    assert out[cf.Outcome.rebound_height] == pytest.approx(rise + 1e-3, abs=2e-6)
    assert out[cf.Outcome.drift] == pytest.approx(0.03, abs=1e-12)
    impact = cf.first_impact_time(t, x, z, moved=1e-3)
    assert impact == pytest.approx(fall, abs=1e-3)
    # read 50 ms after the first impact, the drift is where the path was then
    later = cf.measure_outcomes(cf.LabTest.drop, t, x, z, moved=1e-3, drift_after_impact=0.05)
    assert later[cf.Outcome.drift] == pytest.approx(0.1 * 0.0455, abs=1.5e-3)
    roll = cf.measure_outcomes(cf.LabTest.roll, t, [min(0.12, 0.4 * s) for s in t], [0.01] * len(t), moved=1e-3)
    assert roll[cf.Outcome.roll_distance] == pytest.approx(0.12, abs=1e-12)
    # the last frame farther than 1 mm from the rest point: 0.4 s (t) - 1 mm / 0.4 m/s
    assert roll[cf.Outcome.roll_time] == pytest.approx(0.3 - 2.5e-3, abs=1.5e-3)
    assert cf.first_impact_time(t, x, [0.2 - 1e-4 * k for k in range(600)], moved=1e-3) is None
    assert cf.measure_outcomes(cf.LabTest.drop, t[:9], x[:9], z[:9]) == {}
    with pytest.raises(cf.InvalidArgumentError, match="must be as long"):
        cf.measure_outcomes(cf.LabTest.drop, t, x[:-1], z)


def test_the_bench_diagnoses_the_fill_diagnose_takes_on_the_default_scan():
    # bench_diagnose's default clump (adaptive-64 of the ladder library) is the one diagnose --mesh
    # takes on this scan: the first adaptive fill whose surface lies within a third of
    # --model-accuracy (0.3 mm, diagnose's default) of the mesh. The 32-sphere fill lies just outside.
    clumps = {c.name: c for c in cf.read_library(str(ROOT / "clumps/tuber-default-ladder.h5"))}
    limit = 0.3e-3 / 3
    assert clumps["adaptive-32"].error.surface_rms > limit
    assert clumps["adaptive-64"].error.surface_rms <= limit


def test_the_image_scale_is_measured_without_a_diagnosis():
    """measure_image_scale reads each recording's image scale as diagnose does: a drop's free
    flights for any body, a ball's rolls for a one-sphere clump (the scan's fill of the lab-like
    ball), a tilt none. At the true scale none is off."""
    ball = cf.fill(cf.load_mesh(str(SHARED / "data/lab-like/meshes/sphere.stl"), units="mm"), method="adaptive",
                   surface_target=1e-4)
    assert len(ball.radii) == 1
    readings = cf.measure_image_scale(ball, cf.read_recordings(str(SHARED / "data/lab-like/case-02")))
    sources = [r.source for r in readings]
    assert sources.count("free_flights") == 5 and sources.count("rolling_height") == 3
    assert not any(r.recording.startswith("tilt") for r in readings)
    for r in readings:
        assert not r.off and not r.applied, r.recording
        assert abs(r.scale - 1.0) < 2e-3, (r.recording, r.scale)
        assert r.samples > 5
