#include "diagnose/model.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace clumpforge {
bool can_dent(const MaterialTable& table, const LabOptions& lab, std::string_view surface) {
  const auto particle = table.find(lab.particle_material);
  const auto wall = table.find(surface);
  if (!particle || !wall) return true;
  return (*wall)->youngs_modulus <= kDentStiffnessRatio * (*particle)->youngs_modulus;
}

LabOptions lab_options_for(const Evaluator& ev, const Model& model, const Recording& recording) {
  LabOptions options = ev.lab;
  for (const auto& base : model.base) {
    if (base.surface == recording.surface) options.interaction = base.interaction;
  }
  if (model.effect && (*model.effect != Effect::PlasticSubstrate || can_dent(*ev.table, options, recording.surface)))
    apply_effect(*model.effect, model.values, options);
  if (recording.tilt_rate_deg_per_s) options.tilt_rate_deg_per_s = *recording.tilt_rate_deg_per_s;
  if (recording.test == LabTest::Drop)
    options.steps_per_contact = std::max(options.steps_per_contact, ev.drop_steps_per_contact);
  return options;
}

double first_phase_end_time(const std::vector<ReplaySample>& replay, LabTest test) {
  if (test == LabTest::Tilt) return std::numeric_limits<double>::infinity();  // the plate angle column fixes the origin
  for (const auto& s : replay) {
    if (s.t <= 0.0) continue;
    if (test == LabTest::Drop && s.contacts > 0) return s.t - 0.001;
    if (test == LabTest::Roll && s.wall == 1) return s.t - 0.005;
  }
  return std::numeric_limits<double>::infinity();
}

double replay_summary(const std::vector<ReplaySample>& replay, LabTest test) {
  if (replay.empty()) return std::numeric_limits<double>::quiet_NaN();
  switch (test) {
    case LabTest::Drop: {
      bool touched = false, left = false;
      double apex = 0.0;
      for (const auto& s : replay) {
        if (!touched) {
          touched = s.contacts > 0;
          continue;
        }
        if (s.contacts == 0) left = true;
        if (left && s.contacts > 0) break;
        if (left) apex = std::max(apex, s.lowest);
      }
      return apex;
    }
    case LabTest::Roll:
      return std::max(0.0, replay.back().x);
    case LabTest::Tilt: {
      const double start = replay.front().along_plate;
      for (const auto& s : replay) {
        if (std::abs(s.along_plate - start) > 1e-3) return s.tilt_deg;
      }
      return 90.0;
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

Result<void> check_cancelled(const Evaluator& evaluator) {
  if (evaluator.cancelled && evaluator.cancelled()) return fail(ErrorCode::Cancelled, "diagnosis cancelled");
  return {};
}

Result<std::vector<TrialScore>> evaluate(const Evaluator& ev, const Model& model, const std::vector<std::size_t>& which,
                                         bool keep_replays, Residuals residuals_kept) {
  if (auto ok = check_cancelled(ev); !ok) return std::unexpected(ok.error());
  const auto& recordings = *ev.recordings;
  // One lab world per recording that is needed.
  std::vector<std::optional<LabWorld>> worlds(recordings.size());
  std::vector<LabOptions> options(recordings.size());
  for (std::size_t i : which) {
    const std::size_t r = ev.trials[i].recording;
    if (worlds[r]) continue;
    options[r] = lab_options_for(ev, model, recordings[r]);
    auto made = make_lab_world(*ev.clump, *ev.table, recordings[r], options[r]);
    if (!made) return std::unexpected(made.error());
    worlds[r] = std::move(*made);
  }
  std::vector<TrialScore> scores(which.size());
  tbb::parallel_for(std::size_t{0}, which.size(), [&](std::size_t k) {
    const TrackedTrial& tt = ev.trials[which[k]];
    const Recording& recording = recordings[tt.recording];
    ReplayOptions replay;
    // Up to the horizon, and no later than the frames scored need (the cutoff, in the track's
    // time, less the time shift, which the alignment below moves by at most its window): the
    // first stage of a fit scores only the early window, and a sphere's horizon is the end.
    const double window = recording.test == LabTest::Tilt ? ev.shift_window : 5.0 * ev.shift_window;
    double until = std::min(tt.duration, tt.horizon + 0.02);
    if (ev.shift.size() == ev.trials.size() && std::isfinite(tt.cutoff))
      until = std::min(until, tt.cutoff - ev.shift[which[k]] + window + 0.02);
    replay.duration = ev.full_duration ? tt.duration : std::max(until, 0.02);
    replay.sample_interval = ev.sample_interval;
    replay.record_from = tt.record_from;
    auto samples = replay_trial(*worlds[tt.recording], recording, tt.orientation, options[tt.recording], replay);
    const Track& track = *recording.trials[tt.trial].track;
    const Weights sigma = weights_for(samples, ev.sigma[tt.recording], ev.impact_accuracy);
    TrialScore& score = scores[k];
    // The time origin is chosen on the first phase (free fall, the incline), where the
    // release alone decides the motion; a later misfit then shows where it is.
    const double first_phase_end = first_phase_end_time(samples, recording.test);
    if (ev.shift.size() == ev.trials.size()) {
      // Wide enough for a model that falls or rolls milliseconds later than the first one
      // (strong drag); the first phase's chi^2 is a single bowl in the shift.
      score.alignment = align(track, samples, sigma, tt.origins, ev.shift[which[k]], window, window, tt.cutoff,
                              ev.shift[which[k]] + first_phase_end);
    } else {
      score.alignment =
          align(track, samples, sigma, tt.origins, tt.shift_guess, ev.shift_range[which[k]], 5e-4, tt.cutoff,
                tt.shift_guess + first_phase_end + (recording.test == LabTest::Drop ? 0.0 : ev.shift_range[which[k]]));
    }
    score.summary = replay_summary(samples, recording.test);
    if (residuals_kept != Residuals::None) {
      // The same cells every time (frames up to the cutoff, non-empty cells), in order, each
      // with its phase as phase_groups files it when asked.
      const bool cells = residuals_kept == Residuals::ValuesAndCells;
      const PhaseMarks marks = cells ? phase_marks(samples, recording.test) : PhaseMarks{};
      for (const auto& f : residuals(track, samples, sigma, score.alignment)) {
        if (f.t + score.alignment.shift > tt.cutoff) break;
        const Phase phase = cells ? phase_at(marks, recording.test, f.t) : Phase::Hold;
        for (const auto& [r, axis] : {std::pair{f.rx, Axis::X}, std::pair{f.rz, Axis::Z}}) {
          if (!std::isfinite(r)) continue;
          score.residuals.push_back(r);
          if (cells) score.cells.emplace_back(phase, axis);
        }
      }
    }
    if (keep_replays) score.replay = std::move(samples);
  });
  return scores;
}

double total_chi_squared(const std::vector<TrialScore>& scores) {
  double sum = 0.0;
  for (const auto& s : scores) sum += s.alignment.chi_squared;
  return sum;
}

int total_values(const std::vector<TrialScore>& scores) {
  int sum = 0;
  for (const auto& s : scores) sum += s.alignment.values;
  return sum;
}

void set_shift_ranges(Evaluator& ev) {
  if (ev.shift_range.size() == ev.trials.size()) return;
  ev.shift_range.assign(ev.trials.size(), 0.0);
  for (std::size_t i = 0; i < ev.trials.size(); ++i) {
    const LabTest test = (*ev.recordings)[ev.trials[i].recording].test;
    ev.shift_range[i] = test == LabTest::Roll ? 0.1 : 0.02;  // a roll may creep before it rolls
  }
}

Result<void> initialise_shifts(Evaluator& ev, const Model& model) {
  ev.shift.clear();
  set_shift_ranges(ev);
  std::vector<std::size_t> all(ev.trials.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  auto scores = evaluate(ev, model, all, false);
  if (!scores) return std::unexpected(scores.error());
  ev.shift.resize(ev.trials.size());
  for (std::size_t i = 0; i < all.size(); ++i) ev.shift[i] = (*scores)[i].alignment.shift;
  return {};
}

}  // namespace clumpforge
