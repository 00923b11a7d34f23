// The diagnosis: its measurement model on known tracks, the concealed-effect generator, and
// a fast blind subset (a control and a strong effect on drop recordings).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/rng.hpp"
#include "diagnose/bodies.hpp"
#include "diagnose/conceal.hpp"
#include "diagnose/diagnose.hpp"
#include "diagnose/tracks.hpp"
#include "fill/fill.hpp"
#include "io/clump_library.hpp"
#include "io/recording_io.hpp"
#include "mesh/load.hpp"
#include "mesh/repair.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {

Clump diagnosis_clump() {
  auto clumps = read_clump_library(test::source_dir() / "clumps" / "tuber-default-diagnosis.h5");
  EXPECT_TRUE(clumps) << clumps.error().message;
  return clumps->front();
}

// A free fall from rest at t0 (in the track's own time), filmed at 1000 fps with noise.
Track falling_track(double t0, double sigma, std::uint64_t seed) {
  Rng rng(seed);
  Track track;
  for (int k = 0; k < 300; ++k) {
    const double t = 10.0 + k * 1e-3;
    const double fall = t > t0 ? 0.5 * 9.81 * (t - t0) * (t - t0) : 0.0;
    track.t.push_back(t);
    track.x.push_back(0.002 + rng.normal(0.0, sigma));
    track.z.push_back(0.5 - fall + rng.normal(0.0, sigma));
  }
  return track;
}

// Recordings of the finer 340-sphere body made with `conceal`, diagnosed against the 32-sphere
// clump with `effect` the only candidate and no replay ensembles (the frame-by-frame figures are
// the ones asserted), and `finer` for the particle-model check.
Result<DiagnoseResult> diagnose_frame_by_frame(const ConcealOptions& conceal, Effect effect,
                                               std::vector<Clump> finer = {}) {
  auto made = make_concealed_recordings(test::generator_tuber(), default_material_table(), conceal);
  if (!made) return std::unexpected(made.error());
  DiagnoseOptions options;
  options.effects = {effect};
  options.ensemble_replays = 0;
  options.finer_clumps = std::move(finer);
  return diagnose(diagnosis_clump(), default_material_table(), made->recordings, made->names, options);
}

// The report of the candidate `name`, or null.
const HypothesisReport* hypothesis_named(const DiagnoseResult& result, std::string_view name) {
  for (const auto& h : result.hypotheses)
    if (h.name == name) return &h;
  return nullptr;
}

}  // namespace

TEST(DiagnoseInputs, ARecordingOfAnotherDensityThanTheClumpIsRefusedBeforeAnyReplay) {
  // A lab-like drop stating 1300 kg/m^3 against the 1085 kg/m^3 tuber clump (as the Python
  // module's diagnose(clump, recordings) would be called): refused, not diagnosed at 1085.
  auto drop = read_recording(test::shared_dir() / "data" / "lab-like" / "case-13" / "drop-Q235-0.5");
  ASSERT_TRUE(drop) << drop.error().message;
  ASSERT_EQ(drop->particle_density, 1085.0);
  const Clump clump = diagnosis_clump();
  DiagnoseOptions options;
  options.effects = {Effect::AirDrag};
  drop->particle_density = 1300.0;
  auto refused = diagnose(clump, default_material_table(), {*drop}, {"drop-Q235-0.5"}, options);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(refused.error().message.find("'drop-Q235-0.5' states the particle's density 1300 kg/m^3"),
            std::string::npos)
      << refused.error().message;
  EXPECT_NE(refused.error().message.find("'adaptive-32' is of 1085 kg/m^3"), std::string::npos)
      << refused.error().message;
  // Within 1 %: one particle, diagnosed (its summaries only, to be quick).
  drop->particle_density = 1090.0;
  for (auto& trial : drop->trials) trial.track.reset();
  auto within = diagnose(clump, default_material_table(), {*drop}, {"drop-Q235-0.5"}, options);
  ASSERT_TRUE(within) << within.error().message;
  EXPECT_TRUE(within->summaries_only);
}

TEST(DiagnoseInputs, ARollSetFarBeyondAnyLabsStartEndsInAVerdictNotANaN) {
  // The bundled 100 mm roll with its start distance 10 m (the reader refuses that since stop
  // 100; a program calling the library need not read one): the outcomes' calibration took a
  // surrogate step that was not finite, and the diagnosis ended "tuber on Q235: rolling friction
  // -nan must be in [0, 10]". The fit now ends where it stands, and the diagnosis gives a verdict.
  auto roll = read_recording(test::source_dir() / "clumps" / "tuber-default-diagnosis" / "recordings" / "roll-100mm");
  ASSERT_TRUE(roll) << roll.error().message;
  roll->start_distance = 10.0;
  auto result = diagnose(diagnosis_clump(), default_material_table(), {*roll}, {"roll-100mm"}, DiagnoseOptions{});
  ASSERT_TRUE(result) << result.error().message;
  for (const auto& base : result->improved) {
    EXPECT_TRUE(std::isfinite(base.interaction.rolling_friction)) << base.surface;
  }
}

TEST(DiagnoseMeasurement, NoiseLevelFromThirdDifferences) {
  // The median absolute third difference recovers sigma within 5 % (600 differences).
  for (double sigma : {2e-5, 1e-4, 5e-4}) {
    const Track track = falling_track(10.05, sigma, 3);
    EXPECT_NEAR(estimate_noise({&track}), sigma, 0.05 * sigma) << sigma;
  }
}

TEST(DiagnoseMeasurement, ReleaseFoundAfterALongPreRoll) {
  // Labs start the camera long before the release: 0.4 s of a held particle, then a free
  // fall from 12.4 s. The first guess lands within 2 ms; a roll's (5/7 g sin 30 deg) too.
  Rng rng(5);
  Track drop, roll, tilt;
  for (int k = 0; k < 800; ++k) {
    const double t = 12.0 + k * 1e-3, tau = std::max(0.0, t - 12.4);
    drop.t.push_back(t);
    drop.x.push_back(rng.normal(0.0, 1e-4));
    drop.z.push_back(0.2 - 0.5 * 9.81 * tau * tau + rng.normal(0.0, 1e-4));
    roll.t.push_back(t);
    const double along = 0.5 * 9.81 * 0.5 * 5.0 / 7.0 * tau * tau;
    roll.x.push_back(-0.03 + along * std::cos(0.5236) + rng.normal(0.0, 1e-4));
    roll.z.push_back(0.03 - along * std::sin(0.5236) + rng.normal(0.0, 1e-4));
  }
  EXPECT_NEAR(guess_shift(drop, LabTest::Drop, 5.0), 12.4, 2e-3);
  EXPECT_NEAR(guess_shift(roll, LabTest::Roll, 5.0, 30.0), 12.4, 2e-3);
  // A tilt filmed from 0.25 s before the plate starts at 3.25 s (2 deg/s): the frames at
  // 0 deg say nothing of when it started.
  for (int k = 0; k < 200; ++k) {
    const double t = 3.0 + k * 0.01;
    tilt.t.push_back(t);
    tilt.x.push_back(0.0);
    tilt.z.push_back(0.009);
    tilt.tilt.push_back(std::max(0.0, 2.0 * (t - 3.25)));
  }
  EXPECT_NEAR(guess_shift(tilt, LabTest::Tilt, 2.0), 3.25, 1e-6);
}

TEST(DiagnoseMeasurement, AlignmentFindsTheTimeOriginAndHorizontalOrigin) {
  // A replay of the same fall (released at replay time 0, x = 0) against a track released at
  // 10.0731 s and 2 mm to the side: the shift within 20 microseconds, the offset within 20 um.
  std::vector<ReplaySample> replay;
  for (int k = 0; k <= 5000; ++k) {
    ReplaySample s;
    s.t = k * 1e-4;
    s.z = 0.5 - 0.5 * 9.81 * s.t * s.t;
    replay.push_back(s);
  }
  const Track track = falling_track(10.0731, 1e-4, 5);
  const double guess = guess_shift(track, LabTest::Drop, 5.0);
  EXPECT_NEAR(guess, 10.0731, 0.003);
  const Alignment a = align(track, replay, 1e-4, OriginFit{}, guess, 0.02, 5e-4);
  EXPECT_NEAR(a.shift, 10.0731, 2e-5);
  EXPECT_NEAR(a.x_offset, 0.002, 2e-5);
  EXPECT_NEAR(a.chi_squared / a.values, 1.0, 0.15);
}

TEST(DiagnoseMeasurement, TwoClumpsWhoseReplaysDifferOnlyByWhatTheAlignmentAbsorbsAreOneModel) {
  // The resolution stage's measure (step 0). A tilt's slide starting 2 ms later (a finer clump
  // rests on other points) is what every fit's time shift absorbs: within 0.005 mm, though
  // with only the mean removed the two differ by more than the 0.158 mm that took the generated
  // cases to 128 spheres before b88cdad. A slide 5 % faster is no shift: more than 0.5 mm.
  // Frames beyond the horizon do not count.
  const auto slide = [](double start, double acceleration) {
    std::vector<ReplaySample> replay;
    for (int k = 0; k <= 1000; ++k) {
      ReplaySample s;
      s.t = k * 1e-3;
      const double moving = std::max(0.0, s.t - start);
      s.x = 0.5 * acceleration * moving * moving;
      s.z = 0.01;
      replay.push_back(s);
    }
    return replay;
  };
  const auto coarse = slide(0.4, 1.0), later = slide(0.402, 1.0), faster = slide(0.4, 1.05);
  const double inf = std::numeric_limits<double>::infinity();
  double mean = 0.0, square = 0.0;
  for (std::size_t k = 0; k < coarse.size(); ++k) {
    const double d = coarse[k].x - later[k].x;
    mean += d / static_cast<double>(coarse.size());
    square += d * d / static_cast<double>(coarse.size());
  }
  ASSERT_GT(std::sqrt(square - mean * mean), 0.158e-3);
  EXPECT_LT(replay_difference(coarse, later, inf, 3e-3), 0.005e-3);
  EXPECT_GT(replay_difference(coarse, faster, inf, 3e-3), 0.5e-3);
  EXPECT_LT(replay_difference(coarse, faster, 0.39, 3e-3), 1e-9);
}

TEST(ConcealedRecordings, HideTheEffectInTheSummariesAndReadBack) {
  const Clump clump = diagnosis_clump();
  ConcealOptions options;
  options.effect = Effect::AirDrag;
  options.values = {1.5};
  options.trials = 4;
  options.drop_heights = {0.2, 1.0};
  options.roll_starts = {};
  options.tilt = false;
  auto made = make_concealed_recordings(clump, default_material_table(), options);
  ASSERT_TRUE(made) << made.error().message;
  ASSERT_EQ(made->recordings.size(), 2u);
  ASSERT_EQ(made->summaries.size(), 1u);  // the study's set-up: the 0.2 m drop
  // The summary mean of the study's set-up matches the effect-free baseline's within 2 %.
  EXPECT_NEAR(made->summaries[0].effect_mean, made->summaries[0].baseline_mean,
              0.02 * made->summaries[0].baseline_mean);
  test::ScratchDir dir("conceal");
  ASSERT_TRUE(write_recording(dir / "drop", made->recordings[1]));
  auto back = read_recording(dir / "drop");
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->trials.size(), 4u);
  ASSERT_TRUE(back->trials[0].track);
  // Like a lab's, the trials carry no release orientation unless asked to.
  EXPECT_FALSE(back->trials[0].release_orientation.has_value());
  options.orientation = OrientationRecord::Noisy;
  auto noisy = make_concealed_recordings(clump, default_material_table(), options);
  ASSERT_TRUE(noisy) << noisy.error().message;
  ASSERT_TRUE(noisy->recordings[1].trials[0].release_orientation);
  options.orientation = OrientationRecord::Exact;
  auto exact = make_concealed_recordings(clump, default_material_table(), options);
  ASSERT_TRUE(exact) << exact.error().message;
  ASSERT_TRUE(exact->recordings[1].trials[0].release_orientation);
  // noisy:15 records an orientation off the true one by a Gaussian angle of rms 15 deg.
  const double off = noisy->recordings[1].trials[0].release_orientation->angularDistance(
      *exact->recordings[1].trials[0].release_orientation);
  EXPECT_GT(off, 1e-6);
  EXPECT_LT(off, 4.0 * 15.0 * 3.141592653589793 / 180.0);
  EXPECT_NE(answer_json(options, *made).find("\"effect\": \"air_drag\""), std::string::npos);
}

// The decision on the numbers of a blind benchmark case (strong elastic-plastic restitution
// hidden): its training fit stopped 3119 below the viscoelastic one, but refitted on every
// trial it is 23921 ahead. The ranking on every trial names it; a training margin alone
// would have named the wrong one.
namespace {
HypothesisReport hypothesis(std::string name, double delta_bic, bool passes, double all_trials_delta_bic = NAN) {
  HypothesisReport h;
  h.name = std::move(name);
  h.delta_bic = delta_bic;
  h.passes = passes;
  h.all_trials_delta_bic = all_trials_delta_bic;
  return h;
}
}  // namespace

TEST(DiagnoseDecision, PassingCandidatesCompeteOnEveryTrial) {
  std::vector<HypothesisReport> hs = {hypothesis("air_drag", 53.7, false),
                                      hypothesis("viscoelastic_restitution", 38836.6, true, 15721054.9),
                                      hypothesis("elastic_plastic_restitution", 35717.3, true, 15744975.9),
                                      hypothesis("plastic_substrate", 1936.8, false)};
  Decision d = decide(hs, 10.0);
  ASSERT_TRUE(d.named());
  EXPECT_EQ(hs[*d.best].name, "elastic_plastic_restitution");
  EXPECT_EQ(hs[*d.runner_up].name, "viscoelastic_restitution");
  EXPECT_EQ(hs[*d.training_next].name, "viscoelastic_restitution");

  // Within the margin on every trial: ambiguous, best first.
  hs[1].all_trials_delta_bic = 15744970.0;
  d = decide(hs, 10.0);
  EXPECT_FALSE(d.named());
  ASSERT_TRUE(d.best);
  EXPECT_EQ(hs[*d.best].name, "elastic_plastic_restitution");
  ASSERT_EQ(d.close.size(), 1u);
  EXPECT_EQ(hs[d.close[0]].name, "viscoelastic_restitution");

  // A failed candidate within the margin of the best training delta-BIC is an alternative.
  hs[1].all_trials_delta_bic = 15721054.9;
  hs[3].delta_bic = 38830.0;
  d = decide(hs, 10.0);
  EXPECT_FALSE(d.named());
  ASSERT_EQ(d.close.size(), 1u);
  EXPECT_EQ(hs[d.close[0]].name, "plastic_substrate");

  // The training-best candidate fails a check: nothing is named, even with others passing.
  hs[3].delta_bic = 40000.0;
  d = decide(hs, 10.0);
  EXPECT_FALSE(d.best);
  EXPECT_FALSE(d.named());

  EXPECT_FALSE(decide({}, 10.0).best);
}

// The fast blind subset: recordings made by the generator from a finer clump of the same
// scan (340 spheres against the diagnosis's 32, 100 steps per contact against its 50), with
// no release orientation recorded, diagnosed by the library against a fixed candidate list
// (the same for every case); the answer is only compared afterwards.
TEST(DiagnoseBlind, ControlGivesNoneAndStrongDragIsNamed) {
  const Clump clump = diagnosis_clump();
  const Clump finer = test::generator_tuber();
  const MaterialTable table = default_material_table();
  DiagnoseOptions options;
  options.effects = {Effect::AirDrag, Effect::ViscoelasticRestitution, Effect::StaticKineticFriction};
  options.max_evaluations = 30;
  for (bool with_drag : {false, true}) {
    SCOPED_TRACE(with_drag);
    const ConcealOptions conceal = with_drag ? test::one_metre_drops(Effect::AirDrag, {1.5}) : test::one_metre_drops();
    ASSERT_EQ(conceal.orientation, OrientationRecord::None);
    auto made = make_concealed_recordings(finer, table, conceal);
    ASSERT_TRUE(made) << made.error().message;
    auto result = diagnose(clump, table, made->recordings, made->names, options);
    ASSERT_TRUE(result) << result.error().message;
    // The first flights' misfit against the camera noise, as the report gives it (what decides
    // whether candidates are fitted): the control's at the noise (about 1), the drag's above its
    // level of 2.
    double flight_misfit = 0.0;
    for (const PhaseReport& p : result->phases) {
      if (p.phase != Phase::Flight) continue;
      EXPECT_EQ(p.large_misfit_level, 2.0);
      ASSERT_TRUE(std::isfinite(p.misfit_per_value)) << p.recording;
      flight_misfit = std::max(flight_misfit, p.misfit_per_value);
    }
    if (with_drag)
      EXPECT_GE(flight_misfit, 2.0);
    else
      EXPECT_NEAR(flight_misfit, 1.0, 0.5);
    // The baseline's polish: each set-up's chi^2 before and after, once each; the polish never
    // makes the whole worse (Levenberg-Marquardt from the per-test calibration keeps its start
    // unless it gains).
    ASSERT_EQ(result->calibrated_per_test.size(), result->baseline.size());
    ASSERT_FALSE(result->polish.empty());
    double calibrated = 0.0, polished = 0.0;
    for (std::size_t k = 0; k < result->polish.size(); ++k) {
      const PolishShare& p = result->polish[k];
      EXPECT_EQ(p.test, LabTest::Drop) << p.surface;
      for (std::size_t m = 0; m < k; ++m) EXPECT_NE(result->polish[m].surface, p.surface);
      calibrated += p.chi2_calibrated;
      polished += p.chi2_polished;
    }
    EXPECT_LE(polished, calibrated * (1.0 + 1e-9));
    if (!with_drag) {
      EXPECT_EQ(result->verdict, Verdict::None) << result->statement;
      EXPECT_NEAR(result->before.train_rms_mm, 0.1, 0.02);  // the camera's noise, nothing else
      // What a `none` says would have shown must include what the same set-up names (C_d 1.5).
      const auto drag = std::find_if(result->hypotheses.begin(), result->hypotheses.end(),
                                     [](const HypothesisReport& h) { return h.name == "air_drag"; });
      ASSERT_NE(drag, result->hypotheses.end());
      EXPECT_LT(drag->smallest_detectable, 1.5);
      EXPECT_GT(drag->smallest_detectable, 0.0);
      // Decided absent only where the recordings reject the strong magnitude (C_d 1.5 in these
      // flights: by far more than the margin), not on a first-order signal alone; a restitution
      // law the fitted e absorbs is left undecided, not ruled out.
      EXPECT_GT(drag->strong_delta_chi2, 100.0);
      const auto& undecided = result->undecidable;
      EXPECT_EQ(std::count(undecided.begin(), undecided.end(), "air_drag"), 0) << result->statement;
      EXPECT_EQ(std::count(undecided.begin(), undecided.end(), "viscoelastic_restitution"), 1) << result->statement;
    } else {
      ASSERT_EQ(result->verdict, Verdict::Named) << result->statement;
      ASSERT_EQ(result->effect, Effect::AirDrag);
      // Strong drag is found by the first search; no held start is needed.
      const auto drag = std::ranges::find(result->hypotheses, std::string("air_drag"), &HypothesisReport::name);
      ASSERT_NE(drag, result->hypotheses.end());
      EXPECT_EQ(drag->fit_start, FitStart::FirstSearch);
      EXPECT_FALSE(drag->profile_searched);
      ASSERT_EQ(result->effect_parameters.size(), 1u);
      EXPECT_NEAR(result->effect_parameters[0].value, 1.5, 0.3);
      EXPECT_LT(result->after.heldout_rms_mm, 0.5 * result->before.heldout_rms_mm);
      // A named effect's smallest detectable magnitude is not probed: NaN (null in report.json),
      // not 0, which would read as "any drag at all would have shown".
      for (const HypothesisReport& h : result->hypotheses)
        EXPECT_TRUE(std::isnan(h.smallest_detectable)) << h.name << " " << h.smallest_detectable;
    }
  }
}

// Filmed at 240 fps with 0.5 mm noise (the benchmark's small set, made from the finer
// 340-sphere body), air drag shows in the drops' first flights by about the camera noise: held
// to three times hypot(noise, model accuracy) as every other phase (until the commit after
// be4bed9), realistic drag (C_d 0.45) was `none`, though its fit gained delta-BIC 560 and the
// held-out trials 541; a first flight from rest is held to the camera noise
// (kLargeFlightMisfit), since no particle model's inaccuracy enters before the first contact.
// Realistic drag is named there with its C_d; no drag is named in the control; and a `none`
// must still not claim that an effect it missed would have shown: drag at C_d 0.1 is `none`,
// with no smallest detectable drag at or below 0.1 (at b88cdad the delta-BIC alone said 0.078).
TEST(DiagnoseBlind, TheSmallestDetectableEffectHoldsToTheLargeMisfitANameNeeds) {
  for (const double cd : {0.0, 0.1, 0.45}) {
    // The benchmark's small set (drops from 0.2 and 1 m, a 100 mm roll, a tilt; 4 trials), its
    // air_drag-realistic case's seed.
    ConcealOptions conceal = cd > 0.0 ? test::one_metre_drops(Effect::AirDrag, {cd}) : test::one_metre_drops();
    conceal.drop_heights = {0.2, 1.0};
    conceal.roll_starts = {0.10};
    conceal.tilt = true;
    conceal.seed = 1001;
    conceal.frame_rate_hz = 240.0;
    conceal.noise_m = 5e-4;
    auto result = diagnose_frame_by_frame(conceal, Effect::AirDrag);
    ASSERT_TRUE(result) << result.error().message;
    const HypothesisReport* drag = hypothesis_named(*result, "air_drag");
    ASSERT_NE(drag, nullptr);
    if (cd >= 0.45) {
      ASSERT_EQ(result->verdict, Verdict::Named) << result->statement;
      ASSERT_EQ(result->effect, Effect::AirDrag);
      ASSERT_EQ(result->effect_parameters.size(), 1u);
      // Its 95 % interval holds the hidden C_d (0.444 [0.407, 0.481] at the commit after be4bed9).
      EXPECT_LE(result->effect_parameters[0].low, cd) << result->statement;
      EXPECT_GE(result->effect_parameters[0].high, cd) << result->statement;
      EXPECT_GT(drag->heldout_delta_chi2, 0.0);
      continue;
    }
    ASSERT_EQ(result->verdict, Verdict::None) << cd << ": " << result->statement;
    EXPECT_FALSE(drag->passes) << cd;
    if (cd > 0.0) {
      // No replay below the hidden drag showed, and no limit at or below it is claimed (NaN: none).
      EXPECT_GT(drag->replay_shown, cd) << result->statement;
      EXPECT_FALSE(drag->smallest_detectable <= cd) << result->statement;
    }
  }
}

// A `none` must not call absent an effect it cannot judge. A strong centre-of-mass offset
// (2.5 mm and 1.2 mm along the body's 1st and 3rd axes) in a 100 mm roll and a tilt of the
// finer 340-sphere body (a drop's fitted window ends at its first contact, where an offset
// has not acted yet). Unnamed frame by frame; at 1268dbb the report called it decided on the
// diagnosed clump's first-order signal, and one replay of the strong offset at one release
// misfits these recordings by delta-chi^2 about 3600 (the tilt's): the release is a nuisance,
// and at other releases the trials allow, the strong offset is not rejected.
TEST(DiagnoseBlind, AStrongEffectWhosePathHangsOnTheReleaseIsNotCalledAbsent) {
  ConcealOptions conceal = test::one_metre_drops(Effect::ComOffset, {2.5e-3, 1.2e-3});
  conceal.drop_heights = {};
  conceal.roll_starts = {0.10};
  conceal.tilt = true;
  // The finer clump the command line checks its particle model with (the ladder's next rung).
  auto ladder = read_clump_library(test::source_dir() / "clumps" / "tuber-default-ladder.h5");
  ASSERT_TRUE(ladder) << ladder.error().message;
  auto next = select_clump(*ladder, "adaptive-64", "tuber-default-ladder.h5");
  ASSERT_TRUE(next) << next.error().message;
  auto result = diagnose_frame_by_frame(conceal, Effect::ComOffset, {*next});
  ASSERT_TRUE(result) << result.error().message;
  if (result->verdict == Verdict::Named) {
    EXPECT_EQ(result->effect, Effect::ComOffset) << result->statement;
    return;
  }
  ASSERT_EQ(result->verdict, Verdict::None) << result->statement;
  const auto& undecided = result->undecidable;
  EXPECT_EQ(std::count(undecided.begin(), undecided.end(), "com_offset"), 1) << result->statement;
  const HypothesisReport* offset = hypothesis_named(*result, "com_offset");
  ASSERT_NE(offset, nullptr);
  // A replay of the offset shows at its strong magnitude (the first-order guess of a smaller one is
  // replayed before it is claimed, and here none smaller showed); undecided, it claims no limit.
  EXPECT_LE(offset->replay_shown, 2.5e-3) << result->statement;
  EXPECT_TRUE(std::isnan(offset->smallest_detectable)) << offset->smallest_detectable;
  // Over the releases tried it is not rejected by the margin (the figure is kept in the test's
  // XML output, --gtest_output=xml).
  RecordProperty("strong_delta_chi2", std::to_string(offset->strong_delta_chi2));
  EXPECT_LT(offset->strong_delta_chi2, 10.0 + 2.0 * std::log(offset->values_used)) << offset->strong_delta_chi2;
}

// The smallest detectable effect a `none` reports is one a replay showed, not the strong
// magnitude's signal scaled down as if the response were linear. A realistic drop of kinetic
// friction below static (0.1) on the tilt of the finer 340-sphere body, unnamed: the figure
// reported must not lie far below it. Tolerance: a factor of 2, since the figure is the
// diagnosed 32-sphere clump's response with the coefficients' absorption taken to first order,
// not the recorded body's with the coefficients refitted (replay-checked 0.078). The first-order
// figure claimed 0.0043, 23 times too little; the generated 8-trial set's static-kinetic cases
// at 6ac3aa3 claimed 0.0009 and 0.0006 with 0.1 and 0.25 hidden, and lab-like case-21, a sphere
// with adhesion of about 0.08 J/m^2 left unnamed, 0.0096 (0.079 replay-checked).
// A limit is claimed only for an effect the recordings decide (they reject its strong
// magnitude); here they reject the strong 0.25. Until f01998e the replay's figure, 0.078, was
// claimed with 0.1 hidden: the 32-sphere clump responds more than the 340-sphere body. Since
// the commit after it the claim must pass the strong magnitude's whole check itself
// (checked_limit): the recordings do not reject 0.078, nor the two magnitudes tried above it,
// and the strong 0.25 is claimed. No limit at or below the hidden 0.1 may be claimed.
TEST(DiagnoseBlind, TheSmallestDetectableEffectIsOneAReplayShowed) {
  ConcealOptions conceal = test::one_metre_drops(Effect::StaticKineticFriction, {0.1});
  conceal.drop_heights = {};
  conceal.tilt = true;
  auto result = diagnose_frame_by_frame(conceal, Effect::StaticKineticFriction);
  ASSERT_TRUE(result) << result.error().message;
  if (result->verdict == Verdict::Named) {
    EXPECT_EQ(result->effect, Effect::StaticKineticFriction) << result->statement;
    return;
  }
  ASSERT_EQ(result->verdict, Verdict::None) << result->statement;
  const HypothesisReport* drop = hypothesis_named(*result, "static_kinetic_friction");
  ASSERT_NE(drop, nullptr);
  RecordProperty("replay_shown", std::to_string(drop->replay_shown));
  RecordProperty("smallest_detectable", std::to_string(drop->smallest_detectable));
  EXPECT_GT(drop->replay_shown, 0.5 * 0.1) << result->statement;
  const bool undecided =
      std::count(result->undecidable.begin(), result->undecidable.end(), "static_kinetic_friction") == 1;
  EXPECT_EQ(std::isfinite(drop->smallest_detectable), !undecided) << result->statement;
  EXPECT_FALSE(drop->smallest_detectable <= 0.1) << result->statement;
  EXPECT_FALSE(drop->smallest_detectable < drop->replay_shown) << result->statement;
}

// A `none` must not call absent an effect whose strong magnitude the null's coefficients could
// absorb had they been calibrated again with it. A strong adhesion (0.4 J/m^2) hidden in the six
// recordings of clumpforge-conceal (4 trials) of the finer 340-sphere body: on the tilt it presses
// the body onto the plate, and the baseline's static friction takes it up (0.58, the concealed
// one 0.27). With the strong adhesion added at that friction the diagnosed clump does not slide
// at all, so the chi^2 is flat there and a refit from it does not move; at 7aeaa84 the recordings
// rejected the strong adhesion by 8887 and 0.135 J/m^2 was claimed as the smallest detectable.
// With the friction calibrated again over its whole range, they fit it better than the null.
TEST(DiagnoseBlind, AnEffectTheCoefficientsAbsorbFarFromTheNullIsNotCalledAbsent) {
  ConcealOptions conceal = test::one_metre_drops(Effect::Adhesion, {0.4});
  // clumpforge-conceal's six recordings: on the tilt alone (4 or 8 trials) the first-order signal
  // does not show, and the check is not reached.
  conceal.drop_heights = {0.2, 0.5, 1.0};
  conceal.roll_starts = {0.035, 0.10};
  conceal.tilt = true;
  conceal.seed = 1014;
  auto result = diagnose_frame_by_frame(conceal, Effect::Adhesion);
  ASSERT_TRUE(result) << result.error().message;
  if (result->verdict == Verdict::Named) {
    EXPECT_EQ(result->effect, Effect::Adhesion) << result->statement;
    return;
  }
  ASSERT_EQ(result->verdict, Verdict::None) << result->statement;
  const HypothesisReport* adhesion = hypothesis_named(*result, "adhesion");
  ASSERT_NE(adhesion, nullptr);
  RecordProperty("strong_delta_chi2", std::to_string(adhesion->strong_delta_chi2));
  EXPECT_EQ(std::count(result->undecidable.begin(), result->undecidable.end(), "adhesion"), 1) << result->statement;
  EXPECT_FALSE(adhesion->smallest_detectable <= 0.4) << result->statement;
  const double needed = 10.0 + std::log(adhesion->values_used);
  EXPECT_LT(adhesion->strong_delta_chi2, needed) << result->statement;
  // Where the recordings prefer it (-55 at 4d1d961, by the margin of about 19): the tilt carries
  // it, where adhesion trades with the static friction (the report asks for the experiment that
  // would tell them apart). A control of the generated nine-set-up set prefers a strong adhesion on
  // its tilt too (docs/diagnose.md), so it is not named.
  if (adhesion->strong_delta_chi2 <= -needed) {
    const SetUpShare* alone = preferred_alone(*adhesion);
    ASSERT_NE(alone, nullptr) << result->statement;
    EXPECT_EQ(alone->test, LabTest::Tilt);
    EXPECT_GE(alone->delta_chi2, needed);
  }
}

TEST(DiagnoseBlind, AnEffectOutsideTheCandidatesIsUnexplainedNotNamed) {
  // Strong drag hidden, but only viscous rolling offered: no candidate may be named, and the
  // generic smooth discrepancy must point at the drops' flights (cross-validated).
  const Clump clump = diagnosis_clump();
  const MaterialTable table = default_material_table();
  DiagnoseOptions options;
  options.effects = {Effect::ViscousRolling};
  options.max_evaluations = 30;
  auto made = make_concealed_recordings(clump, table, test::one_metre_drops(Effect::AirDrag, {1.5}));
  ASSERT_TRUE(made) << made.error().message;
  auto result = diagnose(clump, table, made->recordings, made->names, options);
  ASSERT_TRUE(result) << result.error().message;
  ASSERT_EQ(result->verdict, Verdict::Unexplained) << result->statement;
  EXPECT_TRUE(result->effect_parameters.empty());
  EXPECT_EQ(result->basis, Basis::UnexplainedPhases);
  bool flight = false;
  for (const auto& u : result->unexplained)
    flight = flight || (u.phase == Phase::Flight && u.recording == made->names[0]);
  EXPECT_TRUE(flight) << result->statement;
}

TEST(DiagnoseBlind, OneTrialsMisfitIsAnOutlierNotAMismatch) {
  // A control whose first (training) 1 m drop drifts sideways from its release on, 20 mm/s,
  // as a draught or a tumble no model reproduces would: one trial alone misfits its fall
  // (always within the release horizon) far beyond the noise while the other trials fit.
  // That is an outlier, not a mismatch the trials share: `none`, with the outlier said.
  const Clump clump = diagnosis_clump();
  const MaterialTable table = default_material_table();
  ConcealOptions conceal = test::one_metre_drops();
  auto made = make_concealed_recordings(clump, table, conceal);
  ASSERT_TRUE(made) << made.error().message;
  Track& track = *made->recordings[0].trials[0].track;
  // The release: where the fall (z 0.5 mm lower 10 frames on) begins, after the hold.
  auto falling = [&](std::size_t k) {
    return std::isfinite(track.z[k]) && std::isfinite(track.z[k + 10]) && track.z[k + 10] < track.z[k] - 5e-4;
  };
  std::size_t release = 0;
  while (release + 10 < track.size() && !falling(release)) ++release;
  ASSERT_LT(release + 10, track.size());
  for (std::size_t k = release; k < track.size(); ++k) track.x[k] += 0.02 * (track.t[k] - track.t[release]);
  DiagnoseOptions options;
  options.effects = {Effect::AirDrag, Effect::ViscoelasticRestitution};
  options.max_evaluations = 30;
  auto result = diagnose(clump, table, made->recordings, made->names, options);
  ASSERT_TRUE(result) << result.error().message;
  EXPECT_EQ(result->verdict, Verdict::None) << result->statement;
  // The outlier is said, as the first recording's phases where one trial alone misfits.
  ASSERT_FALSE(result->outliers.empty()) << result->statement;
  EXPECT_EQ(result->outliers.front().recording, made->names[0]);
}

TEST(DiagnoseBlind, TooShortOrTooNoisyIsUndecidable) {
  const Clump clump = diagnosis_clump();
  const MaterialTable table = default_material_table();
  ConcealOptions conceal;
  conceal.trials = 2;
  conceal.drop_heights = {0.2};
  conceal.roll_starts = {};
  conceal.tilt = false;
  conceal.noise_m = 3e-3;  // 3 mm: a blurred, hand-clicked track
  auto noisy = make_concealed_recordings(clump, table, conceal);
  ASSERT_TRUE(noisy) << noisy.error().message;
  auto result = diagnose(clump, table, noisy->recordings, noisy->names, {});
  ASSERT_TRUE(result) << result.error().message;
  EXPECT_EQ(result->verdict, Verdict::Undecidable);
  EXPECT_EQ(result->basis, Basis::TooNoisy) << result->statement;
  // Tracks of 20 frames each.
  conceal.noise_m = 1e-4;
  auto made = make_concealed_recordings(clump, table, conceal);
  ASSERT_TRUE(made);
  for (auto& trial : made->recordings[0].trials) {
    Track& t = *trial.track;
    t.t.resize(20);
    t.x.resize(20);
    t.z.resize(20);
  }
  result = diagnose(clump, table, made->recordings, made->names, {});
  ASSERT_TRUE(result) << result.error().message;
  EXPECT_EQ(result->verdict, Verdict::Undecidable);
  EXPECT_EQ(result->basis, Basis::TooFewTrials) << result->statement;
}

TEST(DiagnoseBlind, FramesBeyondTheLongestReplayAreSaidNotCompared) {
  // A camera left running: a frame 20 s after the drop's last. A throw is replayed for 6 s at
  // most, so those frames are not compared, and the report says so (it said nothing).
  const Clump clump = diagnosis_clump();
  const MaterialTable table = default_material_table();
  ConcealOptions conceal;
  conceal.trials = 1;  // one usable trial: undecidable at once, after the trials are read
  conceal.drop_heights = {0.2};
  conceal.roll_starts = {};
  conceal.tilt = false;
  auto made = make_concealed_recordings(clump, table, conceal);
  ASSERT_TRUE(made) << made.error().message;
  Track& t = *made->recordings[0].trials[0].track;
  t.t.push_back(t.t.back() + 20.0);
  t.x.push_back(t.x.back());
  t.z.push_back(t.z.back());
  auto result = diagnose(clump, table, made->recordings, made->names, {});
  ASSERT_TRUE(result) << result.error().message;
  EXPECT_EQ(result->basis, Basis::TooFewTrials) << result->statement;
  const auto said = std::ranges::find_if(result->notes, [](const std::string& n) {
    return n.starts_with("frames after the longest replay are not compared") && n.find("replayed to 6 s") != n.npos;
  });
  EXPECT_NE(said, result->notes.end());
}

TEST(DiagnoseParticleModel, AControlMadeFromAFinerBodyIsTheClumpsNotMissingPhysics) {
  // Recordings of bundled tuber 01 made from its 394-sphere clump, diagnosed with a 4-sphere
  // fill of its scan: the tumbling tuber's rebounds and rolls beyond the release horizon
  // differ from the coarse clump's replays far beyond their scatter, and no effect explains
  // that. Alone, the coarse clump must say `unexplained` (not name an effect); given a finer
  // clump of the same scan (the library's 66 spheres, not the generator's), it must find the
  // mismatch is the particle model's: `none`, and the resolution needed.
  auto loaded = load_mesh(test::source_dir() / "meshes" / "tuber-01.stl", {.unit = LengthUnit::Millimetre});
  ASSERT_TRUE(loaded) << loaded.error().message;
  auto repaired = repair_mesh(std::move(loaded->soup));  // the bundled scans are damaged, as scans are
  ASSERT_TRUE(repaired) << repaired.error().message;
  SdfOptions sdf;
  sdf.feature_size = 1e-3;
  auto body = prepare_body(repaired->soup, 1085.0, sdf);
  ASSERT_TRUE(body) << body.error().message;
  FillOptions fill;
  fill.method = FillMethod::Adaptive;
  fill.max_spheres = 4;
  auto coarse = fill_body(*body, fill);
  ASSERT_TRUE(coarse) << coarse.error().message;
  auto library = read_clump_library(test::source_dir() / "clumps" / "tuber-01.h5");
  ASSERT_TRUE(library) << library.error().message;
  auto generator = select_clump(*library, "adaptive-394", "tuber-01.h5");
  auto finer = select_clump(*library, "adaptive-66", "tuber-01.h5");
  ASSERT_TRUE(generator && finer);
  const MaterialTable table = default_material_table();
  ConcealOptions conceal;
  conceal.trials = 6;
  conceal.drop_heights = {0.5, 1.0};
  conceal.roll_starts = {0.035};
  conceal.tilt = false;
  conceal.seed = 5;
  auto made = make_concealed_recordings(*generator, table, conceal);
  ASSERT_TRUE(made) << made.error().message;
  DiagnoseOptions options;
  options.effects = {Effect::AirDrag, Effect::ViscousRolling};
  options.max_evaluations = 30;
  auto alone = diagnose(coarse->clump, table, made->recordings, made->names, options);
  ASSERT_TRUE(alone) << alone.error().message;
  EXPECT_EQ(alone->verdict, Verdict::Unexplained) << alone->statement;
  EXPECT_FALSE(alone->particle_model.has_value());
  options.finer_clumps = {*finer};
  auto checked = diagnose(coarse->clump, table, made->recordings, made->names, options);
  ASSERT_TRUE(checked) << checked.error().message;
  EXPECT_EQ(checked->verdict, Verdict::None) << checked->statement;
  EXPECT_EQ(checked->basis, Basis::ParticleModel) << checked->statement;
  ASSERT_TRUE(checked->particle_model.has_value());
  EXPECT_TRUE(checked->particle_model->checked);
  EXPECT_EQ(checked->particle_model->resolution_needed, 66);
}

// The generated benchmark's control-09 (faf32db): the default tuber's --small set, 4 trials,
// made from its adaptive-340 with the control's coefficients; its rolls made, and replayed, from
// any orientation (`--roll-release any`).
struct Control09 {
  Clump coarse;  ///< the 4 mm lattice of the same scan: 55 equal spheres
  std::vector<Clump> ladder;
  MaterialTable table;
  ConcealResult made;
};
std::optional<Control09> control_09(const std::vector<std::string>& rungs) {
  auto generators = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  auto ladder = read_clump_library(test::source_dir() / "clumps" / "tuber-default-ladder.h5");
  if (!generators || !ladder) return std::nullopt;
  auto generator = select_clump(*generators, "adaptive-340", "tuber-default.h5");
  auto coarse = select_clump(*generators, "lattice-4mm", "tuber-default.h5");
  if (!generator || !coarse) return std::nullopt;
  Control09 set{*coarse, {}, default_material_table(), {}};
  for (const auto& name : rungs) {
    auto rung = select_clump(*ladder, name, "tuber-default-ladder.h5");
    if (!rung) return std::nullopt;
    set.ladder.push_back(*rung);
  }
  ConcealOptions conceal;
  conceal.trials = 4;
  conceal.drop_heights = {0.2, 1.0};
  conceal.roll_starts = {0.10};
  conceal.seed = 1508;
  conceal.roll_release = RollPosture::Any;
  Interaction base = *set.table.interaction("tuber", "Q235");
  base.restitution = 0.686568574;
  base.static_friction = 0.349312327;
  base.rolling_friction = 0.018711772;
  conceal.base = base;
  auto made = make_concealed_recordings(*generator, set.table, conceal);
  EXPECT_TRUE(made) << made.error().message;
  if (!made) return std::nullopt;
  set.made = std::move(*made);
  return set;
}

// Control-09 diagnosed with the 4 mm lattice, its rolls replayed from any orientation, given
// `finer` clumps of the same scan.
Result<DiagnoseResult> diagnose_control_09(const Control09& set, std::vector<Clump> finer) {
  DiagnoseOptions options;
  options.roll_release = RollPosture::Any;
  options.finer_clumps = std::move(finer);
  return diagnose(set.coarse, set.table, set.made.recordings, set.made.names, options);
}

TEST(DiagnoseParticleModel, BeyondTheHorizonACoarseClumpIsCheckedBeforeAnEffectIsNamed) {
  // Control-09 diagnosed with a clump built otherwise and coarser in its contacts (the 4 mm
  // lattice): frame by frame nothing misfits, and beyond the release horizon no coefficient
  // calibrated on the outcomes makes its replays bounce and roll like the recordings:
  // `unexplained`. Given a finer fill of the same scan (tuber-default-ladder.h5's adaptive-64,
  // not the generator's 340) the mismatch must be found to be the particle model's: `none`, 64
  // spheres needed. (Until the calibration's regression surrogate, the ladder's adaptive-32 stood
  // here; its calibrated null now reproduces these outcomes, as the finer body's should.)
  auto set = control_09({"adaptive-64"});
  ASSERT_TRUE(set);
  auto alone = diagnose_control_09(*set, {});
  ASSERT_TRUE(alone) << alone.error().message;
  EXPECT_EQ(alone->verdict, Verdict::Unexplained) << alone->statement;
  EXPECT_EQ(alone->basis, Basis::UnexplainedOutcomes) << alone->statement;
  auto checked = diagnose_control_09(*set, set->ladder);
  ASSERT_TRUE(checked) << checked.error().message;
  EXPECT_EQ(checked->verdict, Verdict::None) << checked->statement;
  EXPECT_EQ(checked->basis, Basis::ParticleModel) << checked->statement;
  ASSERT_TRUE(checked->particle_model.has_value());
  EXPECT_EQ(checked->particle_model->resolution_needed, 64);
}

TEST(DiagnoseParticleModel, AClumpThatAgreesExplainsOnlyOnceTheNextReplaysTheSameOutcomes) {
  // Control-09 again, the 4 mm lattice given two finer fills (64 and 128 spheres). A clump whose
  // null agrees with the recorded outcomes explains the mismatch only when the next clump, at its
  // coefficients, replays the same outcomes: on the generated 8-trial set at 0167403, ten of
  // eighteen effect cases ended `none` with a 64-sphere clump whose outcomes then moved by 2.5-3.6
  // recorded standard errors from 64 to 128 spheres. So the 128-sphere clump is always replayed,
  // the clump named as needed has a converged successor (or is the finest), and a control is
  // never blamed on an effect.
  auto set = control_09({"adaptive-64", "adaptive-128"});
  ASSERT_TRUE(set);
  auto checked = diagnose_control_09(*set, set->ladder);
  ASSERT_TRUE(checked) << checked.error().message;
  EXPECT_NE(checked->verdict, Verdict::Named) << checked->statement;
  EXPECT_NE(checked->verdict, Verdict::Ambiguous) << checked->statement;
  ASSERT_TRUE(checked->particle_model.has_value());
  const auto& rungs = checked->particle_model->rungs;
  ASSERT_EQ(rungs.size(), 3u);
  ASSERT_TRUE(rungs[2].refitted) << checked->statement;
  ASSERT_TRUE(rungs[2].outcome_shift.has_value()) << checked->statement;
  if (checked->basis == Basis::ParticleModel) {
    ASSERT_TRUE(checked->particle_model->resolution_needed.has_value());
    if (*checked->particle_model->resolution_needed == 64) {
      EXPECT_TRUE(rungs[1].explains);
      EXPECT_TRUE(rungs[2].outcome_shift->converged()) << checked->statement;
    } else {
      EXPECT_EQ(*checked->particle_model->resolution_needed, 128) << checked->statement;
      EXPECT_TRUE(rungs[2].explains);
    }
  }
  // A clump whose agreement the next one did not keep is not said to explain.
  if (!rungs[2].outcome_shift->converged()) {
    EXPECT_FALSE(rungs[1].explains);
  }
}

namespace {

// Whether two diagnoses said the same, to the bit: the verdict and all it rests on (the notes
// carry every calibrated coefficient and chi^2 as printed), the replays compared, each chi^2
// beyond the release horizon and each rung's.
void expect_same_diagnosis(const DiagnoseResult& a, const DiagnoseResult& b) {
  EXPECT_EQ(a.verdict, b.verdict);
  EXPECT_EQ(a.basis, b.basis);
  EXPECT_EQ(a.statement, b.statement);
  EXPECT_EQ(a.notes, b.notes);
  EXPECT_EQ(a.evaluations, b.evaluations);
  ASSERT_EQ(a.ensemble.has_value(), b.ensemble.has_value());
  if (a.ensemble) {
    EXPECT_EQ(a.ensemble->null_chi2, b.ensemble->null_chi2);
    ASSERT_EQ(a.ensemble->hypotheses.size(), b.ensemble->hypotheses.size());
    for (std::size_t k = 0; k < a.ensemble->hypotheses.size(); ++k)
      EXPECT_EQ(a.ensemble->hypotheses[k].chi2, b.ensemble->hypotheses[k].chi2) << k;
  }
  ASSERT_EQ(a.particle_model.has_value(), b.particle_model.has_value());
  if (!a.particle_model) return;
  ASSERT_EQ(a.particle_model->rungs.size(), b.particle_model->rungs.size());
  for (std::size_t k = 0; k < a.particle_model->rungs.size(); ++k) {
    const ParticleModelRung &x = a.particle_model->rungs[k], &y = b.particle_model->rungs[k];
    EXPECT_TRUE(x.chi2_per_value == y.chi2_per_value || (std::isnan(x.chi2_per_value) && std::isnan(y.chi2_per_value)))
        << k;
    ASSERT_EQ(x.outcome_shift.has_value(), y.outcome_shift.has_value()) << k;
    if (x.outcome_shift) {
      EXPECT_EQ(x.outcome_shift->chi2, y.outcome_shift->chi2) << k;
    }
  }
}

}  // namespace

TEST(DiagnoseParticleModel, AReplayReadBackChangesNothing) {
  // A replay asked for again (the same clump, model, recording and release orientation) is read
  // back, not run again (ReplayMemo): the last rung's move is measured on 48 replays from the
  // previous clump's calibrated coefficients, whose first 12 are that clump's calibrated null.
  // Control-09 with the 64- and 128-sphere fills, with and without reading back: the same
  // diagnosis to the bit, and replays read back only with it. About five minutes: labelled
  // `slow` (EnsembleReplayMemo checks the memo itself in the default suite).
  auto set = control_09({"adaptive-64", "adaptive-128"});
  ASSERT_TRUE(set);
  DiagnoseOptions options;
  options.roll_release = RollPosture::Any;
  options.finer_clumps = set->ladder;
  auto read_back = diagnose(set->coarse, set->table, set->made.recordings, set->made.names, options);
  options.reuse_replays = false;
  auto run_all = diagnose(set->coarse, set->table, set->made.recordings, set->made.names, options);
  ASSERT_TRUE(read_back && run_all);
  EXPECT_GT(read_back->replays_reused, 0);
  EXPECT_EQ(run_all->replays_reused, 0);
  expect_same_diagnosis(*read_back, *run_all);
}

// Tuber drops on soil from `heights`, `trials` each, made from the finer adaptive-340 of the
// default scan with `base` (the table's soil coefficients when unset), no release orientation.
Result<ConcealResult> soil_drops_from_the_finer_body(int trials, const std::vector<double>& heights, std::uint64_t seed,
                                                     std::optional<Interaction> base = {}) {
  auto generators = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  if (!generators) return std::unexpected(generators.error());
  auto generator = select_clump(std::move(*generators), "adaptive-340", "tuber-default.h5");
  if (!generator) return std::unexpected(generator.error());
  ConcealOptions conceal;
  conceal.surface = "soil";
  conceal.trials = trials;
  conceal.drop_heights = heights;
  conceal.roll_starts = {};
  conceal.tilt = false;
  conceal.seed = seed;
  conceal.base = std::move(base);
  return make_concealed_recordings(*generator, default_material_table(), conceal);
}

TEST(DiagnoseEnsemble, ARestitutionFarFromTheTablesIsCalibratedOnTheOutcomes) {
  // Tuber drops on soil from 0.2 and 0.5 m, six trials each, made from the finer adaptive-340
  // with a soil restitution of 0.92 against the table's 0.44, no release orientation. Frame by
  // frame the fits end at the first contact, so the restitution is calibrated on the outcomes
  // only, from the table's value, where the replays' mean rebounds are a fifth of the recorded
  // ones. A tuber's mean rebound grows about as a power of e, and 12 chaotic replays move it by
  // its scatter for a step of 0.05: the calibration must still bring every recorded mean within
  // two standard errors of the replays' (|z| < 2), and the verdict be `none`. The clump's e is not
  // the finer body's (a 32-sphere clump rebounds otherwise), so no value is asserted, only that
  // it left the table's by more than 0.2. One free coefficient and no rolls: the earlier
  // calibration passed this too; its failure needed rolls pulling against the drops (see
  // DiagnoseCli.AnotherSimulatorsTuberControlIsConsistentWithTheDiagnosedClumpAlone).
  const MaterialTable table = default_material_table();
  Interaction base = *table.interaction("tuber", "soil");
  const double table_e = base.restitution;
  base.restitution = 0.92;
  auto made = soil_drops_from_the_finer_body(6, {0.2, 0.5}, 2611, base);
  ASSERT_TRUE(made) << made.error().message;
  DiagnoseOptions options;
  options.effects = {Effect::AirDrag, Effect::ViscoelasticRestitution};
  auto result = diagnose(diagnosis_clump(), table, made->recordings, made->names, options);
  ASSERT_TRUE(result) << result.error().message;
  EXPECT_EQ(result->verdict, Verdict::None) << result->statement;
  ASSERT_TRUE(result->ensemble.has_value()) << result->statement;
  const auto& here = result->ensemble->calibrated_here;
  EXPECT_NE(std::find(here.begin(), here.end(), "soil:restitution"), here.end());
  const auto soil = std::find_if(result->ensemble->calibrated.begin(), result->ensemble->calibrated.end(),
                                 [](const SurfaceParameters& s) { return s.surface == "soil"; });
  ASSERT_NE(soil, result->ensemble->calibrated.end());
  EXPECT_GT(soil->interaction.restitution, table_e + 0.2);
  int means = 0;
  for (const auto& c : result->ensemble->null_comparisons) {
    if (c.statistic != Statistic::Mean) continue;
    ++means;
    EXPECT_LT(std::abs(c.z), 2.0) << outcome_name(c.outcome) << " of recording " << c.recording;
  }
  EXPECT_EQ(means, 4);  // rebound height and drift of each drop
}

/// Four-square tilts on steel, made from the finer adaptive-340 (no release orientation), with a
/// kinetic friction `drop` below the static one (none: a control).
Result<ConcealResult> four_square_tilts_from_the_finer_body(int trials, std::optional<double> drop,
                                                            std::uint64_t seed) {
  auto generators = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  if (!generators) return std::unexpected(generators.error());
  auto generator = select_clump(std::move(*generators), "adaptive-340", "tuber-default.h5");
  if (!generator) return std::unexpected(generator.error());
  ConcealOptions conceal;
  conceal.trials = trials;
  conceal.drop_heights = {};
  conceal.roll_starts = {};
  conceal.seed = seed;
  if (drop) {
    conceal.effect = Effect::StaticKineticFriction;
    conceal.values = {*drop};
  }
  return make_concealed_recordings(*generator, default_material_table(), conceal);
}

/// A friction drop of 0.25 named on six tilts, checked on the three it was not calibrated on: the
/// drop predicts them better than the null (more than 30 % of the held-out RMS z), and its value
/// from the three training trials is within 0.1 of the concealed.
void expect_the_drop_predicts_the_heldout_tilts(const OutcomeHoldout& held) {
  EXPECT_EQ(held.training_trials, 3);
  EXPECT_EQ(held.heldout_trials, 3);
  EXPECT_GT(held.statistics, 0);
  EXPECT_GT(held.improvement(), 0.3) << held.rms_z_null() << " -> " << held.rms_z_named();
  ASSERT_EQ(held.values.size(), 1u);
  EXPECT_NEAR(held.values[0], 0.25, 0.1);
}

TEST(DiagnoseEnsemble, AKineticFrictionBelowTheStaticOneIsNamedFromFourSquareTiltsAndAControlIsNot) {
  // Six four-square tilts each, from the finer adaptive-340, no release orientation. Frame by
  // frame the fits stop where the trials part, at the first sliding onset (the body's onset
  // changes with its heading), so the slide after it is seen only as a sample: the slide time
  // from 1 to 4 mm along the plate. With the library's strong drop (0.25) the friction drop is
  // named there; the control, with the same candidates, is `none`. Adhesion, which acts on a tilt
  // too, is the rival asked about.
  const MaterialTable table = default_material_table();
  DiagnoseOptions options;
  options.effects = {Effect::StaticKineticFriction, Effect::Adhesion};
  for (const std::optional<double> drop : {std::optional<double>(0.25), std::optional<double>()}) {
    auto made = four_square_tilts_from_the_finer_body(6, drop, 2613);
    ASSERT_TRUE(made) << made.error().message;
    auto result = diagnose(diagnosis_clump(), table, made->recordings, made->names, options);
    ASSERT_TRUE(result) << result.error().message;
    ASSERT_TRUE(result->ensemble.has_value()) << result->statement;
    if (drop) {
      EXPECT_EQ(result->verdict, Verdict::Named) << result->statement;
      EXPECT_EQ(result->effect, Effect::StaticKineticFriction) << result->statement;
      EXPECT_EQ(result->basis, Basis::Ensemble) << result->statement;
      // The name checked on the trials it was not calibrated on: the null and the drop calibrated
      // again on the three training trials' slip angles and slide times, both compared with the
      // three held out. The drop predicts them better, and its value from half the trials is
      // within 0.1 of the 0.25 concealed.
      ASSERT_TRUE(result->heldout_outcomes.has_value()) << result->statement;
      const OutcomeHoldout& held = *result->heldout_outcomes;
      expect_the_drop_predicts_the_heldout_tilts(held);
    } else {
      EXPECT_EQ(result->verdict, Verdict::None) << result->statement;
      EXPECT_FALSE(result->heldout_outcomes.has_value());
    }
    const auto& compared = result->ensemble->null_comparisons;
    EXPECT_TRUE(std::any_of(compared.begin(), compared.end(),
                            [](const OutcomeComparison& c) { return c.outcome == Outcome::SlideTime; }));
  }
}

TEST(DiagnoseEnsemble, ANameMadeWithAFinerClumpIsCheckedOnTheHeldOutTrialsWithThatClump) {
  // The same strong friction drop in six four-square tilts of the finer adaptive-340, diagnosed
  // with the coarse adaptive-55 and the ladder's 128 and 256 spheres as finer clumps. No clump
  // leaves the outcomes consistent, the ladder converges from 128 to 256 spheres, and the drop is
  // named on adaptive-256's comparison (judge_on_converged_clump). The held-out check is made as
  // the name was, with adaptive-256 and its refitted coefficients: before, a name on a finer rung
  // had none.
  auto library = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  ASSERT_TRUE(library) << library.error().message;
  auto coarse = select_clump(*library, "adaptive-55", "tuber-default.h5");
  ASSERT_TRUE(coarse) << coarse.error().message;
  auto ladder = read_clump_library(test::source_dir() / "clumps" / "tuber-default-ladder.h5");
  ASSERT_TRUE(ladder) << ladder.error().message;
  DiagnoseOptions options;
  options.effects = {Effect::StaticKineticFriction, Effect::Adhesion};
  for (const char* name : {"adaptive-128", "adaptive-256"}) {
    auto finer = select_clump(*ladder, name, "tuber-default-ladder.h5");
    ASSERT_TRUE(finer) << finer.error().message;
    options.finer_clumps.push_back(*finer);
  }
  auto made = four_square_tilts_from_the_finer_body(6, 0.25, 2613);
  ASSERT_TRUE(made) << made.error().message;
  auto result = diagnose(*coarse, default_material_table(), made->recordings, made->names, options);
  ASSERT_TRUE(result) << result.error().message;
  ASSERT_EQ(result->verdict, Verdict::Named) << result->statement;
  EXPECT_EQ(result->effect, Effect::StaticKineticFriction) << result->statement;
  EXPECT_EQ(result->basis, Basis::Ensemble) << result->statement;
  ASSERT_TRUE(result->particle_model.has_value());
  ASSERT_TRUE(result->heldout_outcomes.has_value()) << result->statement;
  const OutcomeHoldout& held = *result->heldout_outcomes;
  ASSERT_GT(held.rung, 0u) << "named with the diagnosed clump: this test no longer reaches a finer rung";
  ASSERT_LT(held.rung, result->particle_model->rungs.size());
  EXPECT_EQ(result->particle_model->rungs[held.rung].name, "adaptive-256");
  // Measured 98.0 % (RMS z 15.11 -> 0.30 over 4 means and spreads), the drop 0.215 from the three
  // training trials: in the test's properties (--gtest_output=json:FILE).
  RecordProperty("heldout_rms_z_null", std::to_string(held.rms_z_null()));
  RecordProperty("heldout_rms_z_named", std::to_string(held.rms_z_named()));
  RecordProperty("heldout_drop", held.values.empty() ? "none" : std::to_string(held.values[0]));
  expect_the_drop_predicts_the_heldout_tilts(held);
}

TEST(DiagnoseEnsemble, ARecordingWithMoreTrialsThanReplaysIsReplayedOncePerTrial) {
  // Fourteen tuber drops from 0.2 m on soil, made from the finer adaptive-340, no release
  // orientation, diagnosed with the default 12 replays per recording. The recorded sample's mean
  // has a standard error of s/sqrt(14); 12 replays would leave the comparison's at
  // s sqrt(1/14 + 1/12), the replays' share the larger. Each recording is replayed once per trial
  // when it has more trials than replays: every comparison's ensemble sample holds the 14.
  auto made = soil_drops_from_the_finer_body(14, {0.2}, 2612);
  ASSERT_TRUE(made) << made.error().message;
  const MaterialTable table = default_material_table();
  DiagnoseOptions options;
  options.effects = {Effect::AirDrag};
  ASSERT_EQ(options.ensemble_replays, 12);
  options.ensemble_replays_at_gate = 0;  // the 12 replays' rule, not the second comparison's
  auto result = diagnose(diagnosis_clump(), table, made->recordings, made->names, options);
  ASSERT_TRUE(result) << result.error().message;
  ASSERT_TRUE(result->ensemble.has_value()) << result->statement;
  ASSERT_FALSE(result->ensemble->null_comparisons.empty());
  for (const auto& c : result->ensemble->null_comparisons) {
    EXPECT_EQ(c.recorded_n, 14) << outcome_name(c.outcome);
    EXPECT_EQ(c.ensemble_n, 14) << outcome_name(c.outcome);
  }
}

TEST(DiagnoseEnsemble, TheOutcomesAreTheSameWhateverTheThreadCount) {
  // The ensemble runs every recording's replays in one parallel loop (291b7e0): each replay is
  // its own, so one thread and two must give the same comparisons to the bit, and so the
  // same report. Tuber drops from 0.2 and 0.5 m on soil, from the finer adaptive-340.
  auto made = soil_drops_from_the_finer_body(6, {0.2, 0.5}, 2613);
  ASSERT_TRUE(made) << made.error().message;
  const MaterialTable table = default_material_table();
  DiagnoseOptions options;
  options.effects = {Effect::AirDrag};
  std::vector<DiagnoseResult> results;
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    auto result = diagnose(diagnosis_clump(), table, made->recordings, made->names, options);
    ASSERT_TRUE(result) << result.error().message;
    ASSERT_TRUE(result->ensemble.has_value()) << result->statement;
    results.push_back(std::move(*result));
  }
  const auto& one = results[0].ensemble->null_comparisons;
  const auto& two = results[1].ensemble->null_comparisons;
  ASSERT_EQ(one.size(), two.size());
  ASSERT_GE(one.size(), 4u);  // rebound height and drift, mean and spread, of both recordings
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].ensemble_mean, two[i].ensemble_mean) << outcome_name(one[i].outcome);
    EXPECT_EQ(one[i].ensemble_sd, two[i].ensemble_sd) << outcome_name(one[i].outcome);
  }
  EXPECT_EQ(results[0].verdict, results[1].verdict);
  EXPECT_EQ(results[0].statement, results[1].statement);
}

// The independent simulator's exact sphere (r 9.35 mm, 1085 kg/m^3) as a one-sphere clump.
Clump lab_like_sphere() {
  constexpr double r = 9.35e-3, density = 1085.0;
  Clump sphere;
  sphere.name = "sphere";
  sphere.spheres = {Sphere{Eigen::Vector3d::Zero(), r}};
  sphere.density = density;
  sphere.body_volume = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  sphere.mass = density * sphere.body_volume;
  sphere.principal_moments = Eigen::Vector3d::Constant(0.4 * sphere.mass * r * r);
  sphere.inertia = sphere.principal_moments.asDiagonal();
  sphere.method = FillMethod::Adaptive;
  return sphere;
}

// Four steel set-ups of one case of ../shared/data/lab-like (recordings made by a simulator that
// shares no code with this project; no release orientations).
std::pair<std::vector<Recording>, std::vector<std::string>> lab_like_steel(const std::string& case_id,
                                                                           const std::vector<std::string>& setups = {
                                                                               "drop-Q235-0.5", "drop-Q235-1.0",
                                                                               "roll-Q235-35mm", "roll-Q235-70mm"}) {
  std::vector<Recording> recordings;
  std::vector<std::string> names;
  for (const std::string& setup : setups) {
    auto r = read_recording(test::shared_dir() / "data" / "lab-like" / case_id / setup / "recording.json");
    EXPECT_TRUE(r) << r.error().message;
    if (!r) continue;
    recordings.push_back(std::move(*r));
    names.push_back(setup);
  }
  return {std::move(recordings), std::move(names)};
}

TEST(DiagnoseRecordedHorizon, ASphereWhoseTrialsPartIsComparedAsASample) {
  // Case-10: a sphere whose centre of mass lies 1 mm from its centre. Its replays agree for
  // every release, yet its six trials of each set-up part (rolls of 0.07 to 0.45 m from one
  // start): each recording is fitted only up to the parting, and beyond it the trials as a
  // sample (means and spreads of the outcomes) name the offset; its rolls alone show it so. Its
  // drops alone name it frame by frame, and their free flights show it too: between bounces the
  // spun sphere's tracked point circles its centre of mass. Case-13, a plain sphere with other
  // coefficients, parts nowhere and is `none`.
  const MaterialTable table = default_material_table();
  DiagnoseOptions options;
  options.effects = {Effect::AirDrag, Effect::ViscousRolling, Effect::ComOffset};
  const Clump sphere = lab_like_sphere();
  {
    const auto [recordings, names] = lab_like_steel("case-10", {"roll-Q235-35mm", "roll-Q235-70mm"});
    ASSERT_EQ(recordings.size(), 2u);
    auto result = diagnose(sphere, table, recordings, names, options);
    ASSERT_TRUE(result) << result.error().message;
    ASSERT_EQ(result->parted.size(), 2u) << result->statement;
    for (const auto& p : result->parted) {
      EXPECT_GT(p.seconds, 0.1) << p.recording;  // not before the incline
      EXPECT_LT(p.seconds, 1.0) << p.recording;
    }
    EXPECT_FALSE(result->flights.has_value());  // no drops
    EXPECT_EQ(result->verdict, Verdict::Named) << result->statement;
    EXPECT_EQ(result->effect, Effect::ComOffset) << result->statement;
    EXPECT_EQ(result->basis, Basis::Ensemble) << result->statement;
  }
  {
    const auto [recordings, names] = lab_like_steel("case-10", {"drop-Q235-0.5", "drop-Q235-1.0"});
    auto result = diagnose(sphere, table, recordings, names, options);
    ASSERT_TRUE(result) << result.error().message;
    EXPECT_EQ(result->verdict, Verdict::Named) << result->statement;  // frame by frame, up to the parting
    EXPECT_EQ(result->effect, Effect::ComOffset) << result->statement;
    ASSERT_TRUE(result->flights.has_value());
    EXPECT_EQ(result->flights->allowance_m, 0.0);  // a sphere's silhouette centroid is its centre
    EXPECT_TRUE(result->flights->detected);
    EXPECT_GT(result->flights->offset_m, 0.2e-3);  // a low estimate of the 1 mm
    EXPECT_LT(result->flights->offset_m, 1.1e-3);
  }
  {
    const auto [recordings, names] = lab_like_steel("case-13");
    ASSERT_EQ(recordings.size(), 4u);
    auto result = diagnose(sphere, table, recordings, names, options);
    ASSERT_TRUE(result) << result.error().message;
    EXPECT_TRUE(result->parted.empty()) << result->parted.front().recording;
    EXPECT_EQ(result->verdict, Verdict::None) << result->statement;
  }
}

TEST(DiagnoseParticleModel, AFinerClumpOfAnotherBodyIsRefused) {
  const Clump clump = diagnosis_clump();
  Clump other = clump;
  other.name = "a-heavier-body";
  other.mass *= 1.5;
  Recording rec;
  rec.test = LabTest::Drop;
  rec.surface = "Q235";
  Trial trial;
  trial.track = falling_track(10.05, 1e-4, 3);
  rec.trials = {trial, trial};
  DiagnoseOptions options;
  options.finer_clumps = {other};
  auto result = diagnose(clump, default_material_table(), {rec}, {"drop"}, options);
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(result.error().message.find("a-heavier-body"), std::string::npos) << result.error().message;
}

TEST(DiagnoseOptions, AbsurdImpactAccuracyOrEnsembleSizeIsRefusedByName) {
  const Clump clump = diagnosis_clump();
  const MaterialTable table = default_material_table();
  Recording rec;
  rec.test = LabTest::Drop;
  rec.surface = "Q235";
  const std::vector<Recording> recordings{rec};
  const std::vector<std::string> names{"drop"};
  DiagnoseOptions options;
  options.impact_accuracy = 0.5;  // 50 %: no replay is that far off
  auto result = diagnose(clump, table, recordings, names, options);
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(result.error().message.find("impact"), std::string::npos) << result.error().message;
  options = {};
  options.ensemble_replays = 2;  // too few to have a spread
  result = diagnose(clump, table, recordings, names, options);
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(result.error().message.find("ensemble"), std::string::npos) << result.error().message;
  for (const int at_gate : {2, 1001}) {  // a second draw too small to have a spread, or absurd
    options = {};
    options.ensemble_replays_at_gate = at_gate;
    result = diagnose(clump, table, recordings, names, options);
    ASSERT_FALSE(result);
    EXPECT_EQ(result.error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(result.error().message.find("at a gate"), std::string::npos) << result.error().message;
  }
}

}  // namespace clumpforge
