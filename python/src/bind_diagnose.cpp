/// The diagnosis: which physics the model leaves out, from recorded tracks.
#include <fmt/format.h>

#include <cmath>

#include "common.hpp"
#include "diagnose/diagnose.hpp"

namespace clumpforge::python {
namespace {

void bind_enums(py::module_& m) {
  py::enum_<Verdict>(m, "Verdict")
      .value("none", Verdict::None)
      .value("named", Verdict::Named)
      .value("ambiguous", Verdict::Ambiguous)
      .value("unexplained", Verdict::Unexplained)
      .value("undecidable", Verdict::Undecidable);
  py::enum_<Basis> basis(m, "Basis");
  for (Basis b :
       {Basis::Consistent, Basis::SlightMisfit, Basis::FrameByFrame, Basis::Ensemble, Basis::UnexplainedPhases,
        Basis::TooFewTrials, Basis::TooNoisy, Basis::SummariesOnly, Basis::ParticleModel, Basis::UnexplainedOutcomes,
        Basis::UnconvergedParticleModel, Basis::FreeFlights})
    basis.value(std::string(basis_name(b)).c_str(), b);
  py::enum_<UndecidedBecause> because(m, "UndecidedBecause");
  for (UndecidedBecause u : {UndecidedBecause::Nothing, UndecidedBecause::UnknownRelease,
                             UndecidedBecause::PartedTrials, UndecidedBecause::SetUps})
    because.value(std::string(undecided_because_name(u)).c_str(), u);
  py::enum_<FitStart> fit_start(m, "FitStart");
  for (FitStart f : {FitStart::FirstSearch, FitStart::NullKept, FitStart::HeldPoint, FitStart::Profile})
    fit_start.value(std::string(fit_start_name(f)).c_str(), f);
  py::enum_<Phase> phase(m, "Phase");
  for (Phase p : {Phase::Hold, Phase::Flight, Phase::Impact, Phase::Rebound, Phase::SecondFlight, Phase::LaterBounces,
                  Phase::Incline, Phase::Transition, Phase::Flat, Phase::Rest, Phase::Stick, Phase::Slip})
    phase.value(std::string(phase_name(p)).c_str(), p);
  py::enum_<Axis>(m, "Axis").value("x", Axis::X).value("z", Axis::Z);
  m.def(
      "effects",
      [] {
        py::dict out;
        for (const auto& spec : effect_library()) out[py::str(spec.name)] = spec.description;
        return out;
      },
      "The library of candidate effects: {name: description}.");
}

void bind_parts(py::module_& m) {
  py::class_<ParameterValue>(m, "ParameterValue", "A fitted value with its 95 % interval.")
      .def_readonly("name", &ParameterValue::name)
      .def_readonly("value", &ParameterValue::value)
      .def_readonly("low", &ParameterValue::low)
      .def_readonly("high", &ParameterValue::high)
      .def_readonly("curvature_half_width", &ParameterValue::curvature_half_width,
                    "a named effect's 95 % half-width from the chi^2 curvature alone (NaN: not named frame by frame)")
      .def_readonly("by_recording", &ParameterValue::by_recording,
                    "where the trials disagree: each recording's value one step from the fit, (name, value)");
  py::class_<SurfaceParameters>(m, "SurfaceParameters")
      .def_readonly("surface", &SurfaceParameters::surface)
      .def_readonly("interaction", &SurfaceParameters::interaction);
  py::class_<PhaseReport>(m, "PhaseReport", "The misfit of one phase of one recording.")
      .def_readonly("recording", &PhaseReport::recording)
      .def_readonly("phase", &PhaseReport::phase)
      .def_readonly("values", &PhaseReport::values)
      .def_readonly("chi2_per_value", &PhaseReport::chi2_per_value)
      .def_readonly("improved_chi2_per_value", &PhaseReport::improved_chi2_per_value)
      .def_readonly("p_value", &PhaseReport::p_value)
      .def_readonly("significant", &PhaseReport::significant)
      .def_readonly("bias_x_mm", &PhaseReport::bias_x_mm)
      .def_readonly("bias_z_mm", &PhaseReport::bias_z_mm)
      .def_readonly("axis", &PhaseReport::axis)
      .def_readonly("misfit_per_value", &PhaseReport::misfit_per_value)
      .def_readonly("large_misfit_level", &PhaseReport::large_misfit_level)
      .def_readonly("statement", &PhaseReport::statement);
  py::class_<SetUpShare>(m, "SetUpShare", "One surface's recordings of one test, and its share of a chi^2 difference.")
      .def_readonly("surface", &SetUpShare::surface)
      .def_readonly("test", &SetUpShare::test)
      .def_readonly("delta_chi2", &SetUpShare::delta_chi2);
  py::class_<PolishShare>(m, "PolishShare",
                          "One set-up's training chi^2 with each coefficient calibrated on its own test, and "
                          "after the joint polish.")
      .def_readonly("surface", &PolishShare::surface)
      .def_readonly("test", &PolishShare::test)
      .def_readonly("chi2_calibrated", &PolishShare::chi2_calibrated)
      .def_readonly("chi2_polished", &PolishShare::chi2_polished);
  py::class_<HypothesisReport>(m, "HypothesisReport", "One candidate effect as fitted and tested.")
      .def_readonly("name", &HypothesisReport::name)
      .def_readonly("fitted", &HypothesisReport::fitted)
      .def_readonly("values", &HypothesisReport::values)
      .def_readonly("values_used", &HypothesisReport::values_used)
      .def_readonly("delta_chi2", &HypothesisReport::delta_chi2)
      .def_readonly("delta_bic", &HypothesisReport::delta_bic)
      .def_readonly("heldout_delta_chi2", &HypothesisReport::heldout_delta_chi2)
      .def_readonly("all_trials_delta_bic", &HypothesisReport::all_trials_delta_bic)
      .def_readonly("plausible", &HypothesisReport::plausible)
      .def_readonly("improves_heldout", &HypothesisReport::improves_heldout)
      .def_readonly("passes", &HypothesisReport::passes)
      .def_readonly("worsened_phases", &HypothesisReport::worsened_phases)
      .def_readonly("evaluations", &HypothesisReport::evaluations)
      .def_readonly("fit_start", &HypothesisReport::fit_start,
                    "where the fit ended: first_search, or with held starts null_kept, held_point or profile")
      .def_readonly("profile_searched", &HypothesisReport::profile_searched,
                    "whether the held starts searched the first parameter's profile")
      .def_readonly(
          "smallest_detectable", &HypothesisReport::smallest_detectable,
          "with verdict none: the smallest magnitude of its first parameter these recordings would have "
          "revealed: a replay shows it and the recordings reject it (NaN where they do not decide the effect, and "
          "under any other verdict)")
      .def_readonly("detectable_at_any_magnitude", &HypothesisReport::detectable_at_any_magnitude,
                    "with smallest_detectable claimed: the law departs from the null's at any magnitude (a replay at "
                    "a millionth of the strong one shows, and the recordings reject it); smallest_detectable is then "
                    "only the smallest magnitude tried")
      .def_readonly("replay_shown", &HypothesisReport::replay_shown,
                    "with verdict none: the smallest magnitude a replay of the diagnosed clump showed (NaN: none)")
      .def_readonly("strong_delta_chi2", &HypothesisReport::strong_delta_chi2,
                    "with verdict none: chi^2 at the effect's strong magnitude minus the null's (NaN: not probed)")
      .def_readonly("strong_resolution_chi2", &HypothesisReport::strong_resolution_chi2,
                    "the next finer clump's response to the strong magnitude, from the diagnosed clump's")
      .def_readonly("strong_preferred_in", &HypothesisReport::strong_preferred_in,
                    "each set-up's share where the recordings prefer the strong magnitude, largest first")
      .def(
          "preferred_alone",
          [](const HypothesisReport& h) -> std::optional<SetUpShare> {
            const SetUpShare* alone = preferred_alone(h);
            return alone ? std::optional<SetUpShare>(*alone) : std::nullopt;
          },
          "the set-up carrying nine tenths or more of strong_preferred_in, or None");
  py::class_<FitQuality>(m, "FitQuality")
      .def_readonly("train_rms_mm", &FitQuality::train_rms_mm)
      .def_readonly("heldout_rms_mm", &FitQuality::heldout_rms_mm)
      .def_readonly("train_chi2_per_value", &FitQuality::train_chi2_per_value)
      .def_readonly("heldout_chi2_per_value", &FitQuality::heldout_chi2_per_value);
  py::class_<OutcomeHoldout>(m, "OutcomeHoldout",
                             "A name made on the outcomes, checked on the held-out trials' outcomes.")
      .def_readonly("training_trials", &OutcomeHoldout::training_trials)
      .def_readonly("heldout_trials", &OutcomeHoldout::heldout_trials)
      .def_readonly("statistics", &OutcomeHoldout::statistics, "held-out means and spreads compared")
      .def_readonly("chi2_null", &OutcomeHoldout::chi2_null)
      .def_readonly("chi2_named", &OutcomeHoldout::chi2_named)
      .def_readonly("values", &OutcomeHoldout::values, "the effect's parameters from the training trials")
      .def_readonly("rung", &OutcomeHoldout::rung,
                    "the particle-model rung it was made and checked on (0: the diagnosed clump)")
      .def_readonly("seconds", &OutcomeHoldout::seconds, "[s] its wall clock")
      .def_property_readonly("rms_z_null", &OutcomeHoldout::rms_z_null)
      .def_property_readonly("rms_z_named", &OutcomeHoldout::rms_z_named)
      .def_property_readonly("improvement", &OutcomeHoldout::improvement,
                             "the share of the null's held-out RMS z the effect removes");
  py::class_<FlightHoldout>(m, "FlightHoldout",
                            "A name from the free flights, checked on the held-out trials' flights.")
      .def_readonly("training_flights", &FlightHoldout::training_flights)
      .def_readonly("heldout_flights", &FlightHoldout::heldout_flights)
      .def_readonly("offset_m", &FlightHoldout::offset_m, "[m] from the training trials' flights")
      .def_readonly("wobble_m", &FlightHoldout::wobble_m, "[m] the held-out flights' wobble")
      .def_readonly("without_m", &FlightHoldout::without_m, "[m] predicted with the mass centred")
      .def_readonly("with_m", &FlightHoldout::with_m, "[m] predicted with the offset")
      .def_property_readonly("improvement", &FlightHoldout::improvement);
  py::class_<TrackComparison>(m, "TrackComparison", "A recording's first trial against both models (replay time).")
      .def_readonly("recording", &TrackComparison::recording)
      .def_readonly("t", &TrackComparison::t)
      .def_readonly("x", &TrackComparison::x)
      .def_readonly("z", &TrackComparison::z)
      .def_readonly("baseline_t", &TrackComparison::baseline_t)
      .def_readonly("baseline_x", &TrackComparison::baseline_x)
      .def_readonly("baseline_z", &TrackComparison::baseline_z)
      .def_readonly("improved_t", &TrackComparison::improved_t)
      .def_readonly("improved_x", &TrackComparison::improved_x)
      .def_readonly("improved_z", &TrackComparison::improved_z)
      .def_readonly("horizon", &TrackComparison::horizon, "[s] predictable from the release up to here");
  py::class_<PhaseOf>(m, "PhaseOf")
      .def_readonly("recording", &PhaseOf::recording)
      .def_readonly("phase", &PhaseOf::phase)
      .def_readonly("chi2_per_value", &PhaseOf::chi2_per_value)
      .def_readonly("where", &PhaseOf::where);
}

// The particle-model check: the outcomes compared, each finer clump tried and how far it moved them.
void bind_particle_model(py::module_& m) {
  py::enum_<Outcome> outcome(m, "Outcome");
  for (Outcome o : {Outcome::ReboundHeight, Outcome::Drift, Outcome::RollDistance, Outcome::RollTime,
                    Outcome::SlipAngle, Outcome::SlideTime})
    outcome.value(std::string(outcome_name(o)).c_str(), o);
  py::class_<MeanMove>(m, "MeanMove", "One recorded mean's move from a clump to a finer one.")
      .def_readonly("recording", &MeanMove::recording)
      .def_readonly("outcome", &MeanMove::outcome)
      .def_readonly("from_value", &MeanMove::from)
      .def_readonly("to_value", &MeanMove::to)
      .def_readonly("noise", &MeanMove::noise, "the replays' noise and the floor, as a standard error")
      .def_readonly("recorded_se", &MeanMove::se, "the recorded mean's standard error")
      .def("chi2", &MeanMove::chi2)
      .def("matters", &MeanMove::matters, "the move in recorded standard errors");
  py::class_<OutcomeShift>(m, "OutcomeShift",
                           "How a finer clump's replayed outcomes moved from the previous clump's at the same "
                           "coefficients and orientations.")
      .def_property_readonly("means", &OutcomeShift::means, "recorded means both clumps were compared on")
      .def_readonly("chi2", &OutcomeShift::chi2)
      .def_readonly("p", &OutcomeShift::p)
      .def_property_readonly("largest", &OutcomeShift::largest, "the largest move in recorded standard errors")
      .def_property_readonly(
          "largest_move",
          [](const OutcomeShift& s) -> std::optional<MeanMove> {
            if (const MeanMove* m = s.largest_move()) return *m;
            return std::nullopt;
          },
          "the mean that moved most in recorded standard errors (None: no mean compared)")
      .def_readonly("replays", &OutcomeShift::replays)
      .def_readonly("judged", &OutcomeShift::judged,
                    "whether a verdict reads it (false: reported only, on its comparison's own replays)")
      .def_readonly("moves", &OutcomeShift::moves, "each mean compared")
      .def("converged", &OutcomeShift::converged);
  py::class_<ParticleModelRung>(m, "ParticleModelRung", "One clump the particle-model check tried.")
      .def_readonly("name", &ParticleModelRung::name)
      .def_readonly("spheres", &ParticleModelRung::spheres)
      .def_readonly("track_difference_m", &ParticleModelRung::track_difference_m,
                    "[m] replayed tracks against the clump before it (NaN: not compared)")
      .def_readonly("refitted", &ParticleModelRung::refitted)
      .def_readonly("chi2_per_value", &ParticleModelRung::chi2_per_value)
      .def_readonly("worst_phase_chi2_per_value", &ParticleModelRung::worst_phase_chi2_per_value)
      .def_readonly("explains", &ParticleModelRung::explains)
      .def_readonly("outcome_shift", &ParticleModelRung::outcome_shift)
      .def_readonly("seconds", &ParticleModelRung::seconds,
                    "[s] wall clock of its check beyond the release horizon (refit, replays, shifts)")
      .def_readonly("seconds_refit", &ParticleModelRung::seconds_refit,
                    "[s] of its refit alone; 0 when a second comparison at a gate took the first one's again");
  py::class_<ParticleModelCheck>(m, "ParticleModelCheck",
                                 "Whether the particle model, not missing physics, explains a mismatch.")
      .def_readonly("diagnosed", &ParticleModelCheck::diagnosed)
      .def_readonly("spheres", &ParticleModelCheck::spheres)
      .def_readonly("track_tolerance_m", &ParticleModelCheck::track_tolerance_m)
      .def_readonly("rungs", &ParticleModelCheck::rungs)
      .def_readonly("checked", &ParticleModelCheck::checked)
      .def_readonly("resolution_needed", &ParticleModelCheck::resolution_needed);
}

void bind_result(py::module_& m) {
  py::class_<FlightWobble>(m, "FlightWobble",
                           "What the drops' free flights after the first contact say about the tracked point.")
      .def_property_readonly("flights", [](const FlightWobble& f) { return f.flights.size(); })
      .def_readonly("wobble_m", &FlightWobble::wobble_m,
                    "[m] RMS per coordinate about the flights' parabolas beyond the noise (median flight)")
      .def_readonly("noise_m", &FlightWobble::noise_m)
      .def_readonly("allowance_m", &FlightWobble::allowance_m, "[m] the silhouette centroid's wander for this body")
      .def_readonly("judged", &FlightWobble::judged,
                    "enough flights to judge; when False nothing else but flights is measured")
      .def_readonly("detected", &FlightWobble::detected)
      .def_readonly("offset_m", &FlightWobble::offset_m,
                    "[m] the centre of mass's distance from the tracked point (low estimate)")
      .def_readonly("offset_low_m", &FlightWobble::offset_low_m)
      .def_readonly("offset_high_m", &FlightWobble::offset_high_m)
      .def_readonly("smallest_offset_m", &FlightWobble::smallest_offset_m,
                    "[m] the smallest offset these flights would have shown");
  py::class_<RecordingScale>(m, "RecordingScale",
                             "A recording's image scale as its tracks give it: a drop's free flights fall at g "
                             "between bounces, a ball's centre rolls one radius above the incline, so "
                             "in the camera's metres each is the true value times the scale.")
      .def_readonly("recording", &RecordingScale::recording)
      .def_property_readonly(
          "source", [](const RecordingScale& s) { return std::string(to_string(s.measured.source)); },
          "free_flights (measured and expected in m/s^2) or rolling_height (in m)")
      .def_property_readonly(
          "samples", [](const RecordingScale& s) { return s.measured.samples; }, "flights, or frames")
      .def_property_readonly(
          "measured", [](const RecordingScale& s) { return s.measured.measured; }, "as the camera gives it")
      .def_property_readonly(
          "expected", [](const RecordingScale& s) { return s.measured.expected; },
          "in true metres: g, or the ball's radius")
      .def_property_readonly("standard_error", [](const RecordingScale& s) { return s.measured.standard_error; })
      .def_property_readonly("scale", [](const RecordingScale& s) { return s.measured.scale(); })
      .def_property_readonly(
          "off", [](const RecordingScale& s) { return s.measured.off(); },
          "off by more than the tolerance and four standard errors")
      .def_readonly("applied", &RecordingScale::applied, "its lengths were divided by the scale");
  py::class_<PartedRecording>(m, "PartedRecording",
                              "A recording whose trials part where the replays agree for every release.")
      .def_readonly("recording", &PartedRecording::recording)
      .def_readonly("seconds", &PartedRecording::seconds, "[s] after release: fitted up to here");
  py::class_<DiagnoseResult>(m, "DiagnoseResult", "What a diagnosis concludes, and on what basis.")
      .def_readonly("verdict", &DiagnoseResult::verdict)
      .def_readonly("basis", &DiagnoseResult::basis)
      .def_property_readonly("effect",
                             [](const DiagnoseResult& r) -> std::optional<std::string> {
                               if (!r.effect) return std::nullopt;
                               return effect_name(*r.effect);
                             })
      .def_property_readonly("name", &verdict_name, "the verdict as reports write it")
      .def_readonly("statement", &DiagnoseResult::statement)
      .def_readonly("candidates", &DiagnoseResult::candidates)
      .def_readonly("experiment", &DiagnoseResult::experiment)
      .def_readonly("effect_parameters", &DiagnoseResult::effect_parameters)
      .def_readonly("baseline", &DiagnoseResult::baseline)
      .def_readonly("calibrated_per_test", &DiagnoseResult::calibrated_per_test,
                    "the base coefficients each calibrated on its own test's trials, before the joint polish")
      .def_readonly("polish", &DiagnoseResult::polish)
      .def_readonly("improved", &DiagnoseResult::improved)
      .def_readonly("uncalibrated", &DiagnoseResult::uncalibrated)
      .def_readonly("before", &DiagnoseResult::before)
      .def_readonly("after", &DiagnoseResult::after)
      .def_readonly("phases", &DiagnoseResult::phases)
      .def_readonly("hypotheses", &DiagnoseResult::hypotheses)
      .def_readonly("unexplained", &DiagnoseResult::unexplained)
      .def_readonly("outliers", &DiagnoseResult::outliers)
      .def_readonly("tracks", &DiagnoseResult::tracks)
      .def_readonly("notes", &DiagnoseResult::notes)
      .def_readonly("parted", &DiagnoseResult::parted)
      .def_readonly("undecidable", &DiagnoseResult::undecidable)
      .def_readonly("undecided_because", &DiagnoseResult::undecided_because,
                    "why the tracks fitted frame by frame left candidates undecided")
      .def_readonly("particle_model", &DiagnoseResult::particle_model)
      .def_readonly("flights", &DiagnoseResult::flights)
      .def_readonly("image_scale", &DiagnoseResult::image_scale,
                    "each recording's image scale as its tracks give it (RecordingScale)")
      .def_readonly("heldout_outcomes", &DiagnoseResult::heldout_outcomes)
      .def_readonly("heldout_flights", &DiagnoseResult::heldout_flights)
      .def_readonly("evaluations", &DiagnoseResult::evaluations)
      .def_readonly("seconds", &DiagnoseResult::seconds);
}

/// {name: Recording} as the library takes it: the recordings and their names, in the dict's order.
std::pair<std::vector<Recording>, std::vector<std::string>> recordings_of(const py::dict& recordings) {
  std::pair<std::vector<Recording>, std::vector<std::string>> out;
  for (const auto& [name, recording] : recordings) {
    out.second.push_back(py::cast<std::string>(name));
    out.first.push_back(py::cast<Recording>(recording));
  }
  return out;
}

DiagnoseResult run_diagnosis(const Clump& clump, const py::dict& recordings, const std::vector<std::string>& effects,
                             std::optional<MaterialTable> materials, double orientation_prior_deg,
                             double model_accuracy, int ensemble_replays, int max_evaluations, std::uint64_t seed,
                             const std::vector<Clump>& finer_clumps, const std::string& roll_release,
                             const std::string& image_scale, const py::object& progress) {
  const auto [list, names] = recordings_of(recordings);
  if (list.empty()) raise({ErrorCode::InvalidArgument, "no recordings to diagnose"});
  const MaterialTable table = materials ? *materials : default_material_table();
  for (const auto& r : list) unwrap(table.find(r.surface));
  if (max_evaluations < 5 || max_evaluations > 10000)
    raise({ErrorCode::InvalidArgument, "max_evaluations must be between 5 and 10000"});
  DiagnoseOptions options;
  for (const auto& e : effects) options.effects.push_back(unwrap(parse_effect(e)));
  options.orientation_prior_deg = orientation_prior_deg;
  const auto posture = parse_roll_posture(roll_release);
  if (!posture)
    raise({ErrorCode::InvalidArgument, fmt::format("roll_release '{}' is not on-edge or any", roll_release)});
  options.roll_release = *posture;
  const auto scale = parse_image_scale(image_scale);
  if (!scale)
    raise({ErrorCode::InvalidArgument,
           fmt::format("image_scale '{}' is not auto, measured, flights or as-recorded", image_scale)});
  options.image_scale = *scale;
  options.model_accuracy_m = model_accuracy;
  options.ensemble_replays = ensemble_replays;
  options.max_evaluations = max_evaluations;
  options.seed = seed;
  options.finer_clumps = finer_clumps;
  return run_released(progress, [&](const RunContext& c) { return diagnose(clump, table, list, names, options, c); });
}

PathSample path_of(std::vector<double> t, std::vector<double> x, std::vector<double> z) {
  if (t.size() != x.size() || t.size() != z.size())
    raise({ErrorCode::InvalidArgument,
           fmt::format("t, x and z must be as long (they are {}, {} and {})", t.size(), x.size(), z.size())});
  return {std::move(t), std::move(x), std::move(z)};
}

/// The outcomes the diagnosis compares beyond the release horizon, read from one path as it reads
/// a recorded track and a replay (measure_outcomes): a script that reads tracks the same way
/// calls this, not a copy of it.
void bind_outcomes(py::module_& m) {
  m.def(
      "measure_outcomes",
      [](LabTest test, std::vector<double> t, std::vector<double> x, std::vector<double> z, double moved,
         double tilt_rate_deg_per_s, std::optional<double> drift_after_impact) {
        const PathSample path = path_of(std::move(t), std::move(x), std::move(z));
        py::dict out;
        for (const auto& [outcome, value] :
             measure_outcomes(test, path, moved, tilt_rate_deg_per_s, drift_after_impact.value_or(std::nan(""))))
          out[py::cast(outcome)] = value;
        return out;
      },
      py::arg("test"), py::arg("t"), py::arg("x"), py::arg("z"), py::arg("moved") = 1e-3,
      py::arg("tilt_rate_deg_per_s") = 0.0, py::arg("drift_after_impact") = py::none(),
      "The outcomes `clumpforge diagnose` compares beyond the release horizon, read from one path as it "
      "reads a recorded track and a replay: {Outcome: value} (a drop's rebound height above the rest point "
      "and drift [m]; a roll's distance [m] and time to rest [s]; a tilt's slip angle [deg] and slide time "
      "[s]). t [s] since release (a tilt: since the plate started turning), x from the release point and z "
      "the tracked point's height [m]; moved [m] the displacement that counts as motion (the diagnosis uses "
      "max(1 mm, 6 noise sds)); drift_after_impact [s]: a drop's drift read that long after the first impact "
      "instead of at the track's end. Empty for a path of fewer than ten frames.");
  m.def(
      "first_impact_time",
      [](std::vector<double> t, std::vector<double> x, std::vector<double> z, double moved) {
        return first_impact_time(path_of(std::move(t), std::move(x), std::move(z)), moved);
      },
      py::arg("t"), py::arg("x"), py::arg("z"), py::arg("moved") = 1e-3,
      "[s] A drop's first impact as the diagnosis finds it: the lowest point before the path first rises "
      "`moved` [m] above its running minimum; None when it never does.");
}

}  // namespace

void bind_diagnose(py::module_& m) {
  bind_enums(m);
  bind_parts(m);
  bind_particle_model(m);
  bind_result(m);
  bind_outcomes(m);
  m.def("diagnose", &run_diagnosis, py::arg("clump"), py::arg("recordings"),
        py::arg("effects") = std::vector<std::string>{}, py::arg("materials") = py::none(),
        py::arg("orientation_prior_deg") = 15.0, py::arg("model_accuracy") = 3e-4, py::arg("ensemble_replays") = 12,
        py::arg("max_evaluations") = 45, py::arg("seed") = 1, py::arg("finer_clumps") = std::vector<Clump>{},
        py::arg("roll_release") = "on-edge", py::arg("image_scale") = "auto", py::arg("progress") = py::none(),
        "Finds which physics the model leaves out (`clumpforge diagnose`): recordings is {name: Recording} (as "
        "read_recordings returns), effects the candidates (default: every effect of the library), model_accuracy [m] "
        "how closely any clump follows the real particle, finer_clumps finer clumps of the same body (the "
        "resolution raised while replayed tracks change; refitted before a mismatch is blamed on missing physics), "
        "roll_release how the lab set the particle on a roll's incline (on-edge: a flattened particle on its rim; "
        "any), image_scale how a recording whose image scale is off is read (auto: through the scale its tracks give "
        "for a ball (one sphere within 1 % of its scan), as recorded for any other body; measured: through it "
        "always; flights: measured's older name; as-recorded).");
  m.def(
      "measure_image_scale",
      [](const Clump& clump, const py::dict& recordings) {
        const auto [list, names] = recordings_of(recordings);
        return recording_scales(measure_image_scale(clump, list), names, false);
      },
      py::arg("clump"), py::arg("recordings"),
      "Each recording's image scale as `clumpforge diagnose` reads it, without the diagnosis: [RecordingScale] "
      "(a drop's free flights; a ball's rolls, for a ball). recordings is {name: Recording}.");
}

}  // namespace clumpforge::python
