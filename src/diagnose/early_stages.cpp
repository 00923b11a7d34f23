/// The stages up to the located misfit: inputs checked, tracks loaded, the release state, the
/// clump's resolution, the baseline fit, the phases located.

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <numbers>
#include <numeric>
#include <ranges>

#include "core/rng.hpp"
#include "diagnose/stages.hpp"
#include "numerics/least_squares.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge::diagnosis {

// Whether rolls without a recorded orientation are replayed from the rim (see RollPosture).
bool on_edge_rolls(const Clump& clump, const DiagnoseOptions& options) {
  return options.roll_release == RollPosture::OnEdge && has_edge(clump.principal_moments);
}

/// The release state, a nuisance: every trial replays an orientation its prior allows (the
/// recorded one when the lab wrote one down, else a draw from the prior: uniform, or a roll
/// on its rim) and is
/// fitted frame by frame only up to its release horizon, where replays from every
/// orientation the prior allows still agree to half the noise level (their tracked points'
/// displacements; the origins are fitted). Beyond it no single replay can stand for the
/// trial. Returns a note per recording.
Result<std::vector<std::string>> settle_release_state(Context& c, const Model& model, const DiagnoseOptions& options) {
  const auto& recs = *c.ev.recordings;
  const bool on_edge = on_edge_rolls(*c.ev.clump, options);
  std::vector<std::string> notes;
  for (std::size_t r = 0; r < recs.size(); ++r) {
    const Recording& rec = recs[r];
    // One prior shared by the trials without a recorded orientation, one per trial with one.
    std::vector<std::pair<OrientationPrior, std::vector<std::size_t>>> groups;
    for (std::size_t i = 0; i < c.ev.trials.size(); ++i) {
      TrackedTrial& tt = c.ev.trials[i];
      if (tt.recording != r) continue;
      tt.origins = OriginFit{true, rec.test != LabTest::Tilt};
      OrientationPrior prior;
      prior.spread = options.orientation_prior_deg * std::numbers::pi / 180.0;
      prior.recorded = rec.trials[tt.trial].release_orientation;
      prior.on_edge = on_edge;
      if (!prior.recorded && !groups.empty() && !groups.front().first.recorded) {
        groups.front().second.push_back(i);
      } else if (!prior.recorded) {
        groups.insert(groups.begin(), {prior, {i}});
      } else {
        groups.push_back({prior, {i}});
      }
    }
    if (groups.empty()) continue;
    if (auto ok = check_cancelled(c.ev); !ok) return std::unexpected(ok.error());
    const LabOptions lab = lab_options_for(c.ev, model, rec);
    auto world = make_lab_world(*c.ev.clump, *c.ev.table, rec, lab);
    if (!world) return std::unexpected(world.error());
    std::vector<double> horizons;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const auto& [prior, members] = groups[g];
      const auto candidates =
          draw_release_orientations(rec.test, prior, options.release_orientations, options.seed, 7000 + 1000 * r + g);
      ReplayOptions replay;
      replay.sample_interval = c.ev.sample_interval;
      for (std::size_t i : members) replay.duration = std::max(replay.duration, c.ev.trials[i].duration);
      std::vector<std::vector<ReplaySample>> replays(candidates.size());
      tbb::parallel_for(std::size_t{0}, candidates.size(),
                        [&](std::size_t k) { replays[k] = replay_trial(*world, rec, candidates[k], lab, replay); });
      c.evaluations += static_cast<int>(candidates.size());
      const double horizon = release_horizon(replays, 0.5 * c.ev.sigma[r]);
      for (std::size_t i : members) {
        c.ev.trials[i].orientation = candidates.front();
        c.ev.trials[i].alternatives.assign(candidates.begin() + 1,
                                           candidates.begin() + std::min(candidates.size(), kAlternativeReleases + 1));
        c.ev.trials[i].release_horizon = horizon;
      }
      horizons.push_back(horizon);
    }
    const bool recorded =
        std::any_of(groups.begin(), groups.end(), [](const auto& g) { return g.first.recorded.has_value(); });
    notes.push_back(fmt::format(
        "{}: release orientation {}; replays from {} orientations it allows agree until {} after release", c.names[r],
        recorded ? fmt::format("recorded (a prior of +-{:g} deg)", options.orientation_prior_deg)
        : rec.test == LabTest::Roll && on_edge ? std::string("unknown (on its rim at a uniform turn)")
                                               : std::string("unknown (uniform prior)"),
        options.release_orientations,
        fmt::join(horizons | std::views::transform([](double h) {
                    return std::isfinite(h) ? fmt::format("{:.3f} s", h) : std::string("the end");
                  }),
                  ", ")));
  }
  return notes;
}

/// Stage 0: options a diagnosis cannot run with.
Result<void> check_options(const DiagnoseOptions& options) {
  if (!(options.model_accuracy_m >= 0.0 && options.model_accuracy_m <= 0.01)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("the particle model's accuracy must lie in [0, 10] mm, not {:g} mm",
                            1e3 * options.model_accuracy_m));
  }
  if (!(options.impact_accuracy >= 0.0 && options.impact_accuracy <= 0.2)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("the accuracy of a replayed impact's outgoing speed must lie in [0, 20] %, not {} %",
                            100.0 * options.impact_accuracy));
  }
  if (options.ensemble_replays != 0 && (options.ensemble_replays < 4 || options.ensemble_replays > 1000)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("replays per recording for the ensemble comparison must be 0 (skip) or 4 to 1000, not {}",
                            options.ensemble_replays));
  }
  if (options.ensemble_replays_at_gate != 0 &&
      (options.ensemble_replays_at_gate < 4 || options.ensemble_replays_at_gate > 1000)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("replays per recording at a gate must be 0 (never) or 4 to 1000, not {}",
                            options.ensemble_replays_at_gate));
  }
  if (options.release_orientations < 2 || options.release_orientations > 1000) {
    return fail(
        ErrorCode::InvalidArgument,
        fmt::format("release orientations drawn per prior must be 2 to 1000, not {}", options.release_orientations));
  }
  if (!(options.orientation_prior_deg > 0.0 && options.orientation_prior_deg <= 180.0)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("the recorded orientation's uncertainty must lie in (0, 180] deg, not {}",
                            options.orientation_prior_deg));
  }
  return {};
}

/// Stage 1, load and noise: each recording's noise level from its own tracks (weighed with
/// the model's accuracy), and the trials with enough frames, every other one held out.
/// Returns the camera noise per recording.
std::vector<double> load_tracks(Context& c, DiagnoseResult& result, const std::vector<Recording>& recordings,
                                const std::vector<std::string>& names, const DiagnoseOptions& options) {
  // Noise level per recording, from its own tracks.
  std::vector<double> camera_noise;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    std::vector<const Track*> tracks;
    for (const auto& t : recordings[r].trials) {
      if (t.track) tracks.push_back(&*t.track);
    }
    double sigma = estimate_noise(tracks);
    if (recordings[r].position_noise_m) {
      result.notes.push_back(fmt::format("{}: the lab states {:.3g} mm of noise; the tracks show {:.3g} mm (used)",
                                         names[r], *recordings[r].position_noise_m * 1000.0, sigma * 1000.0));
      if (!std::isfinite(sigma)) sigma = *recordings[r].position_noise_m;
    }
    // Residuals are weighed against the camera noise and the particle model's own accuracy
    // together: no clump reproduces a real particle to a tenth of a millimetre, and a
    // misfit within that accuracy is not evidence of missing physics.
    camera_noise.push_back(sigma);
    c.ev.sigma.push_back(std::hypot(sigma, options.model_accuracy_m));
    if (!tracks.empty()) result.noise_m.emplace_back(names[r], sigma);
  }
  // The trials that can be used.
  std::vector<std::string> too_short, cut_short;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    const Recording& rec = recordings[r];
    int used = 0;
    for (std::size_t i = 0; i < rec.trials.size(); ++i) {
      const auto& track = rec.trials[i].track;
      if (!track) continue;
      int frames = 0;
      for (std::size_t k = 0; k < track->size(); ++k)
        frames += std::isfinite(track->x[k]) && std::isfinite(track->z[k]);
      if (frames < 30 || !std::isfinite(c.ev.sigma[r])) {
        too_short.push_back(fmt::format("{} trial {} ({} usable frames)", names[r], rec.trials[i].id, frames));
        continue;
      }
      TrackedTrial tt;
      tt.recording = r;
      tt.trial = i;
      tt.training = used % 2 == 0;
      const double rate = rec.tilt_rate_deg_per_s.value_or(options.lab.tilt_rate_deg_per_s);
      tt.shift_guess = guess_shift(*track, rec.test, rate, rec.incline_deg);
      const double last = track->t.back() - tt.shift_guess;
      const double longest = rec.test == LabTest::Tilt ? kTiltEndDeg / rate : options.lab.max_time;
      tt.duration = std::clamp(last + 0.05, 0.05, longest);
      if (last + 0.05 > longest)
        cut_short.push_back(fmt::format("{} trial {} (tracked to {:.3g} s after release, replayed to {:.3g} s)",
                                        names[r], rec.trials[i].id, last, longest));
      if (rec.test == LabTest::Tilt) tt.record_from = std::max(0.0, track->t.front() - tt.shift_guess - 0.05);
      (tt.training ? c.training : c.heldout).push_back(c.ev.trials.size());
      c.all.push_back(c.ev.trials.size());
      c.ev.trials.push_back(tt);
      ++used;
    }
  }
  result.tracked_trials = static_cast<int>(c.ev.trials.size());
  result.training_trials = static_cast<int>(c.training.size());
  if (!too_short.empty())
    result.notes.push_back(fmt::format("left out (too short or no noise estimate): {}", fmt::join(too_short, ", ")));
  if (!cut_short.empty())
    result.notes.push_back(
        fmt::format("frames after the longest replay are not compared: {}", fmt::join(cut_short, ", ")));
  c.camera_noise = camera_noise;
  return camera_noise;
}

/// The starting model: the materials table's coefficients per surface of the recordings.
Result<Model> starting_model(Context& c, const MaterialTable& table, const std::vector<Recording>& recordings,
                             const DiagnoseOptions& options) {
  // Base coefficients: the materials table's, per surface.
  Model baseline;
  for (const auto& rec : recordings) {
    if (std::any_of(baseline.base.begin(), baseline.base.end(),
                    [&](const auto& b) { return b.surface == rec.surface; }))
      continue;
    auto pair = table.interaction(options.lab.particle_material, rec.surface);
    if (!pair) return std::unexpected(pair.error());
    baseline.base.push_back({rec.surface, *pair});
    c.table_values.push_back({rec.surface, *pair});
  }
  return baseline;
}

/// Stages 2 and 3, release state and horizons: the release orientations the prior allows, how
/// long each trial stays predictable, the first time origins.
Result<void> release_stage(Context& c, DiagnoseResult& result, const Model& baseline, const DiagnoseOptions& options) {
  const RunContext& run = *c.run;
  run.report("release state", 0.02);
  auto release_notes = settle_release_state(c, baseline, options);
  if (!release_notes) return std::unexpected(release_notes.error());
  result.notes.insert(result.notes.end(), release_notes->begin(), release_notes->end());
  if (auto ok = initialise_shifts(c.ev, baseline); !ok) return std::unexpected(ok.error());
  if (auto ok = set_horizons(c, baseline, options.horizon_perturbation); !ok) return std::unexpected(ok.error());
  return {};
}

/// The recorded trials' own horizons. A recording whose replays agree for every release
/// orientation (a sphere) is fitted through its whole tracks, one replay for every trial; if
/// its recorded trials, put in the replay frame by the baseline's alignments, part from each
/// other beyond the noise (recorded_horizon: by max(1 mm, 5 camera noise levels) for 20
/// frames running), the body's path hangs on something unrecorded, and from there on no
/// single replay can stand for them. Their release horizon becomes that time: they are fitted
/// up to it, and compared beyond it as a sample (the ensembles), where their test's
/// coefficient is calibrated again (Context::parted). A tilt's trials part at onsets that
/// differ. Returns whether any changed, with a note per such recording.
Result<bool> recorded_horizons(Context& c, DiagnoseResult& result, const Model& baseline) {
  constexpr int kSustained = 20;
  const auto& recs = *c.ev.recordings;
  // The recordings whose replays agree for every release, and their trials.
  std::vector<std::vector<std::size_t>> members(recs.size());
  std::vector<bool> regular(recs.size(), true);
  for (std::size_t i = 0; i < c.ev.trials.size(); ++i) {
    const TrackedTrial& tt = c.ev.trials[i];
    members[tt.recording].push_back(i);
    regular[tt.recording] = regular[tt.recording] && !std::isfinite(tt.release_horizon);
  }
  std::vector<std::size_t> which;
  for (std::size_t r = 0; r < recs.size(); ++r) {
    if (regular[r] && members[r].size() >= 2) which.insert(which.end(), members[r].begin(), members[r].end());
  }
  if (which.empty()) return false;
  auto scores = score(c, baseline, which, false);  // one evaluation of all of them, for the alignments
  if (!scores) return std::unexpected(scores.error());
  std::vector<const Alignment*> alignment(c.ev.trials.size(), nullptr);
  for (std::size_t k = 0; k < which.size(); ++k) alignment[which[k]] = &(*scores)[k].alignment;
  bool changed = false;
  for (std::size_t r = 0; r < recs.size(); ++r) {
    if (!regular[r] || members[r].size() < 2) continue;
    std::vector<Track> tracks;
    double frame = 0.0;
    for (std::size_t i : members[r]) {
      const Track& recorded = *recs[r].trials[c.ev.trials[i].trial].track;
      frame = std::max(frame, frame_interval(recorded));
      // From the release on; lost frames left out (the horizon interpolates across them).
      const Track moved = in_replay_frame(recorded, *alignment[i]);
      Track kept;
      for (std::size_t f = 0; f < moved.size(); ++f) {
        if (moved.t[f] < 0.0 || !std::isfinite(moved.x[f]) || !std::isfinite(moved.z[f])) continue;
        kept.t.push_back(moved.t[f]);
        kept.x.push_back(moved.x[f]);
        kept.z.push_back(moved.z[f]);
      }
      tracks.push_back(std::move(kept));
    }
    const double noise = r < c.camera_noise.size() ? c.camera_noise[r] : c.ev.sigma[r];
    const double tolerance = std::max(1e-3, 5.0 * noise);
    const double parted = recorded_horizon(tracks, frame, tolerance, kSustained);
    if (!std::isfinite(parted)) continue;
    for (std::size_t i : members[r]) c.ev.trials[i].release_horizon = parted;
    c.parted.insert({recs[r].surface, coefficient_for(recs[r].test)});
    result.parted.push_back({c.names[r], parted});
    changed = true;
    result.notes.push_back(fmt::format(
        "{}: replays from every release orientation agree, but the recorded trials part from each other {:.3f} s "
        "after release (by more than {:.2g} mm): the path hangs on something unrecorded; fitted up to there, "
        "compared beyond it as a sample",
        c.names[r], parted, 1e3 * tolerance));
  }
  return changed;
}

namespace {

/// Each set-up's training chi^2 under `calibrated` (the coefficients each on its own test) and
/// `polished` (the joint polish from there).
Result<std::vector<PolishShare>> polish_shares(Context& c, const Model& calibrated, const Model& polished) {
  const auto& recs = *c.ev.recordings;
  auto before = score(c, calibrated, c.training, false);
  if (!before) return std::unexpected(before.error());
  auto after = score(c, polished, c.training, false);
  if (!after) return std::unexpected(after.error());
  std::vector<PolishShare> out;
  for (std::size_t k = 0; k < c.training.size(); ++k) {
    const Recording& r = recs[c.ev.trials[c.training[k]].recording];
    auto it =
        std::ranges::find_if(out, [&](const PolishShare& p) { return p.surface == r.surface && p.test == r.test; });
    if (it == out.end()) it = out.insert(out.end(), PolishShare{r.surface, r.test, 0.0, 0.0});
    it->chi2_calibrated += (*before)[k].alignment.chi_squared;
    it->chi2_polished += (*after)[k].alignment.chi_squared;
  }
  return out;
}

}  // namespace

/// Stage 4, baseline: e, mu_s and mu_r per surface on the training trials (each on its own
/// test over a wide grid, then together), the horizons set again under it; the coefficients
/// the fitted windows do not pin are said to be uncalibrated.
Result<Model> baseline_stage(Context& c, DiagnoseResult& result, Model baseline, const DiagnoseOptions& options) {
  const RunContext& run = *c.run;
  const auto& names = c.names;
  const auto& recordings = *c.ev.recordings;
  run.report("baseline", 0.05);
  auto fitted = fit_baseline(c, baseline, false, c.training);
  if (!fitted) return std::unexpected(fitted.error());
  baseline = *fitted;
  c.ev.shift.clear();
  if (auto ok = initialise_shifts(c.ev, baseline); !ok) return std::unexpected(ok.error());
  auto parted = recorded_horizons(c, result, baseline);
  if (!parted) return std::unexpected(parted.error());
  if (auto ok = set_horizons(c, baseline, options.horizon_perturbation); !ok) return std::unexpected(ok.error());
  if (*parted) {
    // The first fit ran through frames no single replay stands for: again, up to the horizons.
    auto again = fit_baseline(c, baseline, false, c.training);
    if (!again) return std::unexpected(again.error());
    baseline = *again;
    if (auto ok = set_horizons(c, baseline, options.horizon_perturbation); !ok) return std::unexpected(ok.error());
  }
  // Again: each coefficient now fitted with the others near their values (fit_coefficients'
  // two steps, each kept for the report).
  auto calibrated = calibrate_each_test(c, baseline, c.training, false, Pinning::Decide);
  if (!calibrated) return std::unexpected(calibrated.error());
  auto polished = refit(c, *calibrated, nullptr, c.training, options.max_evaluations);
  if (!polished) return std::unexpected(polished.error());
  auto shares = polish_shares(c, *calibrated, polished->model);
  if (!shares) return std::unexpected(shares.error());
  result.calibrated_per_test = calibrated->base;
  result.polish = std::move(*shares);
  baseline = polished->model;
  result.baseline = baseline.base;
  for (const auto& [surface, coefficient] : c.unpinned) {
    const auto it =
        std::find_if(baseline.base.begin(), baseline.base.end(), [&](const auto& b) { return b.surface == surface; });
    result.notes.push_back(
        fmt::format("{} on {} is not pinned by the fitted parts of the tracks (its chi^2 moves by less than {:g} over "
                    "its range): the materials table's {:.4g} is kept, uncalibrated",
                    coefficient_name(coefficient), surface, kUnpinned, coefficient_of(it->interaction, coefficient)));
    result.uncalibrated.push_back(fmt::format("{}:{}", surface, coefficient_name(coefficient)));
  }
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    std::vector<std::string> horizons;
    for (const auto& tt : c.ev.trials) {
      if (tt.recording == r)
        horizons.push_back(std::isfinite(tt.horizon) ? fmt::format("{:.3f}", tt.horizon) : std::string("end"));
    }
    if (!horizons.empty())
      result.notes.push_back(
          fmt::format("{}: fitted up to {} s after release (per trial)", names[r], fmt::join(horizons, ", ")));
  }
  return baseline;
}

/// Stage 5, locate: the baseline's residuals per recording and phase, and the phases beyond
/// the noise.
Result<Located> locate_stage(Context& c, DiagnoseResult& result, const Model& baseline) {
  Located out;
  auto base_scores = score(c, baseline, c.all, true);
  if (!base_scores) return std::unexpected(base_scores.error());
  out.base_chi2.assign(c.ev.trials.size(), 0.0);
  for (std::size_t k = 0; k < c.all.size(); ++k) out.base_chi2[c.all[k]] = (*base_scores)[k].alignment.chi_squared;
  const Groups all_groups = phase_groups(c, c.all, *base_scores);
  result.phases = locate(c, all_groups);
  // The training trials' groups, and the flagged ones, for the signature check.
  std::vector<TrialScore> train_scores;
  for (std::size_t k = 0; k < c.all.size(); ++k) {
    if (c.ev.trials[c.all[k]].training) train_scores.push_back((*base_scores)[k]);
  }
  out.base_train_groups = phase_groups(c, c.training, train_scores);
  for (PhaseReport& p : result.phases) {
    const auto key = std::find_if(out.base_train_groups.begin(), out.base_train_groups.end(), [&](const auto& kg) {
      return kg.first.phase == p.phase && c.names[kg.first.recording] == p.recording;
    });
    p.large_misfit_level = large_misfit_level(p.phase);
    if (key != out.base_train_groups.end() && key->second.values > 0)
      p.misfit_per_value = misfit_per_value(c, key->first, key->second);
  }
  for (const auto& [key, g] : all_groups) {
    if (key.phase == Phase::Hold || g.values < 10) continue;
    if (beyond_noise(g.chi2, g.values, all_groups.size())) out.flagged.push_back(key);
  }
  out.base_scores = std::move(*base_scores);
  return out;
}

/// Stage 0, the particle model's resolution by convergence of the replayed tracks: the
/// training trials replayed at the starting coefficients with the clump and with the next finer
/// one; while they differ by more than half the smallest weight (hypot(noise, model accuracy))
/// within the fitted windows, the finer clump is taken. The release stage runs with the clump
/// kept (its horizons are the fitted windows). The finer clumps not taken are left in c.finer.
Result<void> resolution_stage(Context& c, DiagnoseResult& result, const Model& start, const DiagnoseOptions& options) {
  ParticleModelCheck check;
  double tolerance = kNever;
  for (std::size_t r = 0; r < c.ev.sigma.size(); ++r) {
    if (std::isfinite(c.ev.sigma[r]) && c.camera_noise.size() > r && std::isfinite(c.camera_noise[r]))
      tolerance = std::min(tolerance, 0.5 * c.ev.sigma[r]);
  }
  check.track_tolerance_m = tolerance;
  const auto rung_of = [](const Clump& clump) {
    ParticleModelRung rung;
    rung.name = clump.name;
    rung.spheres = static_cast<int>(clump.spheres.size());
    return rung;
  };
  check.rungs.push_back(rung_of(*c.ev.clump));
  for (const Clump& finer : options.finer_clumps) check.rungs.push_back(rung_of(finer));
  DiagnoseResult release;
  if (auto ok = release_stage(c, release, start, options); !ok) return std::unexpected(ok.error());
  std::size_t k = 0;
  while (k < options.finer_clumps.size()) {
    auto coarse = score(c, start, c.training, true);
    if (!coarse) return std::unexpected(coarse.error());
    auto fine = [&] {
      const ClumpSwap swap(c, &options.finer_clumps[k]);
      return score(c, start, c.training, true);
    }();
    if (!fine) return std::unexpected(fine.error());
    double sum = 0.0;
    for (std::size_t i = 0; i < c.training.size(); ++i) {
      const double d = replay_difference((*coarse)[i].replay, (*fine)[i].replay, c.ev.trials[c.training[i]].horizon,
                                         c.ev.shift_window);
      sum += d * d;
    }
    const double difference = std::sqrt(sum / std::max<std::size_t>(1, c.training.size()));
    check.rungs[k + 1].track_difference_m = difference;
    if (difference <= tolerance) break;
    c.ev.clump = &options.finer_clumps[k++];  // kept: its release state and horizons replace the coarser one's
    release = {};
    if (auto ok = release_stage(c, release, start, options); !ok) return std::unexpected(ok.error());
  }
  result.notes.insert(result.notes.end(), release.notes.begin(), release.notes.end());
  for (std::size_t j = k; j < options.finer_clumps.size(); ++j) c.finer.push_back(&options.finer_clumps[j]);
  check.rungs.erase(check.rungs.begin(), check.rungs.begin() + static_cast<std::ptrdiff_t>(k));
  check.diagnosed = c.ev.clump->name;
  check.spheres = static_cast<int>(c.ev.clump->spheres.size());
  if (check.rungs.size() > 1) {
    result.notes.push_back(fmt::format(
        "particle model: {} ({} spheres); the training trials' replayed tracks move by {} with the next finer clump "
        "({}), against {:.3f} mm for convergence",
        check.diagnosed, check.spheres,
        std::isfinite(check.rungs[1].track_difference_m)
            ? fmt::format("{:.3f} mm", check.rungs[1].track_difference_m * 1e3)
            : std::string("?"),
        check.rungs[1].name, tolerance * 1e3));
  }
  result.particle_model = std::move(check);
  return {};
}

/// Refuses what no diagnosis can run on: no recordings, names not one per recording, absurd
/// options, a finer clump of another body (it would "explain" any mismatch).
Result<void> check_inputs(const Clump& clump, const std::vector<Recording>& recordings,
                          const std::vector<std::string>& names, const DiagnoseOptions& options) {
  if (recordings.empty()) return fail(ErrorCode::InvalidArgument, "no recordings to diagnose");
  if (names.size() != recordings.size()) return fail(ErrorCode::InvalidArgument, "one name per recording is needed");
  if (auto ok = check_options(options); !ok) return std::unexpected(ok.error());
  if (auto ok = check_stated_density(recordings, clump.density, fmt::format("the clump '{}'", clump.name), names); !ok)
    return ok;
  for (const Clump& finer : options.finer_clumps) {
    if (finer.spheres.empty() || !(std::abs(finer.mass - clump.mass) <= 0.05 * clump.mass)) {
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("the finer clump '{}' ({} spheres, {:.4g} g) is not a model of the body of '{}' "
                              "({:.4g} g): the particle-model check needs clumps of one body",
                              finer.name, finer.spheres.size(), finer.mass * 1e3, clump.name, clump.mass * 1e3));
    }
  }
  return {};
}

/// Why nothing can be decided from these tracks (too few usable trials, too noisy), if so.
std::optional<std::pair<Basis, std::string>> undecidable_tracks(const Context& c,
                                                                const std::vector<double>& camera_noise) {
  double worst_sigma = 0.0;
  for (double s : camera_noise) {
    if (std::isfinite(s)) worst_sigma = std::max(worst_sigma, s);
  }
  if (c.ev.trials.size() < 2 || c.training.empty() || c.heldout.empty()) {
    return std::pair{Basis::TooFewTrials, fmt::format("only {} usable tracked trial(s): at least two (one to fit, "
                                                      "one held out), each with 30 or more frames where both "
                                                      "x_m and z_m were tracked, are needed to decide anything",
                                                      c.ev.trials.size())};
  }
  if (worst_sigma > 1e-3) {
    return std::pair{
        Basis::TooNoisy,
        fmt::format(
            "the tracks are too noisy to decide anything: {:.2f} mm of camera noise, where the effects in the "
            "library move the tracked point by 0.1 to a few mm; track with sub-pixel centroids (0.02 to 0.1 mm)",
            worst_sigma * 1000.0)};
  }
  return std::nullopt;
}

}  // namespace clumpforge::diagnosis
