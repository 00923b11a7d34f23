// The diagnosis as one call (`clumpforge diagnose` and bench_diagnose): recordings, particle
// model, diagnose(), and the report.
#include "diagnose_job.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ranges>

#include "cli_common.hpp"
#include "fill/fill.hpp"
#include "io/clump_library.hpp"
#include "io/materials_io.hpp"
#include "io/recording_io.hpp"

namespace clumpforge::cli {
namespace {

namespace fs = std::filesystem;

// Where the particle's density came from.
enum class DensityFrom { CommandLine, Recordings, Library, Default };

std::string_view density_from_name(DensityFrom from) {
  switch (from) {
    case DensityFrom::CommandLine:
      return "command_line";
    case DensityFrom::Recordings:
      return "recordings";
    case DensityFrom::Library:
      return "library";
    case DensityFrom::Default:
      return "default";
  }
  return "default";
}

// The particle diagnosed: a mesh with its unit and density, or a library's clump (mesh empty).
struct ParticleChoice {
  std::string mesh;
  bool mesh_from_recordings = false;
  std::string units = "mm";
  double density = kStudyDensity;
  DensityFrom density_from = DensityFrom::Default;
};

// The mesh: the one given, or the one the recordings name inside a recording's folder (nothing
// outside it is opened because a recording names it: the refusal says to give it as --mesh).
Result<ParticleChoice> mesh_choice(const DiagnoseJob& job, const StatedParticle& stated) {
  ParticleChoice c;
  if (!job.mesh.empty()) {
    c.mesh = job.mesh;
  } else if (stated.mesh) {
    auto inside = stated.mesh_inside();
    if (!inside)
      return fail(inside.error().code,
                  fmt::format("{}; clumpforge opens nothing outside a recording's folder because the recording names "
                              "it: give the mesh as --mesh '{}'{}",
                              inside.error().message, stated.mesh_as_named()->string(),
                              stated.mesh_units ? fmt::format(" --units {}", *stated.mesh_units) : std::string()));
    c.mesh = inside->string();
    c.mesh_from_recordings = true;
  } else {
    return fail(ErrorCode::InvalidArgument,
                "give exactly one of --mesh and --library: the recordings name no particle mesh (particle.mesh)");
  }
  std::error_code ec;
  const bool stated_mesh = c.mesh_from_recordings ||
                           (stated.mesh && fs::absolute(job.mesh, ec).lexically_normal() == stated.mesh_as_named());
  if (job.units && stated_mesh && stated.mesh_units && *job.units != *stated.mesh_units)
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{} states the particle mesh's units as {}, --units gives {}: leave --units out to use "
                            "the recording's",
                            stated.mesh_in.string(), *stated.mesh_units, *job.units));
  c.units = job.units ? *job.units : (stated_mesh && stated.mesh_units ? *stated.mesh_units : "mm");
  return c;
}

// The particle: its mesh (mesh_choice) or a library, and its density, from the command line, the
// recordings or the default; a density given and stated must agree (a library's clump: in
// library_models).
Result<ParticleChoice> particle_choice(const DiagnoseJob& job, const StatedParticle& stated) {
  if (job.density) {
    if (auto ok = check_density_option(*job.density); !ok) return std::unexpected(ok.error());
  }
  if (job.units) {  // checked whether or not a mesh is read: --library took --units furlong without a word
    if (auto unit = parse_length_unit(*job.units); !unit) return std::unexpected(unit.error());
  }
  if (job.density && stated.density && !same_density(*job.density, *stated.density))
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{} states the particle's density {:g} kg/m^3, --density gives {:g}: one particle, one "
                            "density (leave --density out to use the recording's)",
                            stated.density_in.string(), *stated.density, *job.density));
  ParticleChoice c;
  if (job.library.empty()) {
    auto mesh = mesh_choice(job, stated);
    if (!mesh) return std::unexpected(mesh.error());
    c = std::move(*mesh);
  }
  c.density = job.density ? *job.density : stated.density.value_or(kStudyDensity);
  c.density_from = job.density      ? DensityFrom::CommandLine
                   : stated.density ? DensityFrom::Recordings
                                    : DensityFrom::Default;
  return c;
}

// A number, or null when it is not finite (JSON has no infinity or NaN).
nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// Where the recordings prefer a candidate's strong magnitude: each set-up's share.
nlohmann::json preferred_json(const std::vector<SetUpShare>& shares) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& s : shares)
    out.push_back({{"surface", s.surface}, {"test", std::string(to_string(s.test))}, {"delta_chi2", s.delta_chi2}});
  return out;
}

// How a rung's replayed outcomes moved from the previous clump's (null when not compared).
nlohmann::json outcome_shift_json(const std::optional<OutcomeShift>& shift, const std::vector<std::string>& names) {
  if (!shift) return nlohmann::json();
  const auto move_json = [&](const MeanMove& m) {
    return nlohmann::json{
        {"recording", m.recording < names.size() ? nlohmann::json(names[m.recording]) : nlohmann::json()},
        {"outcome", std::string(outcome_name(m.outcome))},
        {"from", finite_or_null(m.from)},
        {"to", finite_or_null(m.to)},
        {"noise", finite_or_null(m.noise)},
        {"recorded_se", finite_or_null(m.se)}};
  };
  nlohmann::json moves = nlohmann::json::array();
  for (const MeanMove& m : shift->moves) moves.push_back(move_json(m));
  nlohmann::json out{{"means", shift->means()},
                     {"chi2", finite_or_null(shift->chi2)},
                     {"p", finite_or_null(shift->p)},
                     {"largest_se", finite_or_null(shift->largest())},
                     {"recording", nullptr},
                     {"outcome", nullptr},
                     {"from", nullptr},
                     {"to", nullptr},
                     {"replays", shift->replays},
                     {"judged", shift->judged},
                     {"converged", shift->judged ? nlohmann::json(shift->converged()) : nlohmann::json()},
                     {"moves", moves}};
  // The move that matters most, as its entry in `moves` (null when no mean was compared).
  if (const MeanMove* most = shift->largest_move()) {
    const nlohmann::json j = move_json(*most);
    for (const char* key : {"recording", "outcome", "from", "to"}) out[key] = j[key];
  }
  return out;
}

nlohmann::json coefficients_json(const std::vector<SurfaceParameters>& base) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& b : base) {
    out[b.surface] = {{"restitution", b.interaction.restitution},
                      {"static_friction", b.interaction.static_friction},
                      {"rolling_friction", b.interaction.rolling_friction}};
  }
  return out;
}

nlohmann::json quality_json(const FitQuality& q) {
  nlohmann::json summary = nlohmann::json::object();
  for (const auto& [name, v] : q.summary_error) summary[name] = v;
  return {{"train_rms_mm", q.train_rms_mm},
          {"heldout_rms_mm", q.heldout_rms_mm},
          {"train_chi2_per_value", q.train_chi2_per_value},
          {"heldout_chi2_per_value", q.heldout_chi2_per_value},
          {"summary_error_mm_or_deg", summary}};
}

// The particle model and the finer clumps of the same body the diagnosis may take or check
// against (DiagnoseOptions::finer_clumps).
struct ParticleModels {
  Clump clump;
  std::vector<std::pair<int, double>> ladder;  ///< spheres, surface RMS [m] of each resolution tried
  std::vector<Clump> finer;
};

// From a library: the clump named, and the library's clumps with more spheres (fewest first).
// Its clump's density must agree with the one the recordings state or --density gives.
Result<ParticleModels> library_models(const DiagnoseJob& job, ParticleChoice& choice, const StatedParticle& stated) {
  auto clumps = read_clump_library(job.library);
  if (!clumps) return std::unexpected(clumps.error());
  std::vector<Clump> others = *clumps;
  auto chosen = select_clump(std::move(*clumps), job.clump_name, job.library);
  if (!chosen) return std::unexpected(chosen.error());
  const auto differs = [&](double d) { return chosen->density > 0.0 && !same_density(chosen->density, d); };
  if (choice.density_from != DensityFrom::Default && differs(choice.density))
    return fail(ErrorCode::InvalidArgument,
                fmt::format("'{}': clump '{}' was made at the density {:g} kg/m^3, and {} {:g} kg/m^3: fill the "
                            "mesh at that density, or diagnose it with --mesh",
                            job.library, chosen->name, chosen->density,
                            choice.density_from == DensityFrom::CommandLine
                                ? std::string("--density gives")
                                : fmt::format("{} states", stated.density_in.string()),
                            choice.density));
  if (chosen->density > 0.0) {
    choice.density = chosen->density;
    choice.density_from = DensityFrom::Library;
  }
  ParticleModels out{.clump = std::move(*chosen), .ladder = {}, .finer = {}};
  std::erase_if(others, [&](const Clump& c) { return c.spheres.size() <= out.clump.spheres.size(); });
  std::ranges::sort(others, {}, [](const Clump& c) { return c.spheres.size(); });
  for (auto& c : others) {
    if (static_cast<int>(out.finer.size()) < job.finer_clumps) out.finer.push_back(std::move(c));
  }
  return out;
}

// The mesh filled adaptively (with --spheres, or to the surface accuracy by convergence, the
// resolutions tried in `ladder`); finer fills with twice, four times ... as many spheres, kept
// when they lie closer to the mesh.
Result<ParticleModels> particle_models(const DiagnoseJob& job, ParticleChoice& choice, const StatedParticle& stated,
                                       const RunContext& context) {
  if (!job.library.empty()) return library_models(job, choice, stated);
  ParticleModels out;
  SdfOptions sdf;
  sdf.feature_size = 1e-3;
  auto body = load_closed_body(choice.mesh, choice.units, choice.density, sdf, context);
  if (!body) return std::unexpected(body.error());
  FillOptions fill;
  fill.method = FillMethod::Adaptive;
  fill.max_spheres = job.spheres;
  auto filled = job.spheres > 0 ? fill_body(body->body, fill, context)
                                : fill_to_surface_accuracy(body->body, fill, job.options.model_accuracy_m / 3.0,
                                                           kMaxAutoSpheres, &out.ladder, context);
  if (!filled) return fail(filled.error().code, fmt::format("'{}': {}", choice.mesh, filled.error().message));
  out.clump = std::move(filled->clump);
  double surface = out.clump.error.surface_rms;
  int spheres = static_cast<int>(out.clump.spheres.size());
  for (int k = 0; k < job.finer_clumps && 2 * spheres <= kMaxFinerSpheres; ++k) {
    fill.max_spheres = 2 * spheres;
    auto finer = fill_body(body->body, fill, context);
    if (!finer) return fail(finer.error().code, fmt::format("'{}': {}", choice.mesh, finer.error().message));
    spheres = fill.max_spheres;
    // A fill no closer to the mesh (a sphere's mesh is one sphere; more add corners) is no finer.
    if (!(finer->clump.error.surface_rms < surface)) break;
    surface = finer->clump.error.surface_rms;
    out.finer.push_back(std::move(finer->clump));
  }
  return out;
}
/// report.json's particle_model: the clump ladder climbed and what each finer rung explained.
nlohmann::json particle_model_json(const DiagnoseResult& r) {
  if (!r.particle_model) return nlohmann::json();
  const auto& m = *r.particle_model;
  nlohmann::json rungs = nlohmann::json::array();
  for (const auto& rung : m.rungs) {
    rungs.push_back({{"clump", rung.name},
                     {"spheres", rung.spheres},
                     {"track_difference_mm", finite_or_null(rung.track_difference_m * 1e3)},
                     {"refitted", rung.refitted},
                     {"chi2_per_value", rung.refitted ? finite_or_null(rung.chi2_per_value) : nlohmann::json()},
                     {"worst_phase_chi2_per_value",
                      rung.refitted ? finite_or_null(rung.worst_phase_chi2_per_value) : nlohmann::json()},
                     {"explains", rung.explains},
                     {"outcome_shift", outcome_shift_json(rung.outcome_shift, r.ensemble ? r.ensemble->recordings
                                                                                         : std::vector<std::string>{})},
                     {"seconds", rung.seconds},
                     {"seconds_refit", rung.seconds_refit}});
  }
  return {{"diagnosed", m.diagnosed},
          {"spheres", m.spheres},
          {"track_tolerance_mm", finite_or_null(m.track_tolerance_m * 1e3)},
          {"checked", m.checked},
          {"chi2_per_value", m.checked ? finite_or_null(m.chi2_per_value) : nlohmann::json()},
          {"worst_phase_chi2_per_value", m.checked ? finite_or_null(m.worst_phase_chi2_per_value) : nlohmann::json()},
          {"resolution_needed_spheres", m.resolution_needed ? nlohmann::json(*m.resolution_needed) : nlohmann::json()},
          {"rungs", rungs}};
}

/// report.json's flights: the free flights' wobble and the centre-of-mass offset they show.
nlohmann::json flights_json(const FlightWobble& f) {
  // Too few flights to judge: only their number and the allowance; the measures are null.
  const auto measured = [&f](double metres) { return f.judged ? nlohmann::json(metres * 1e3) : nlohmann::json(); };
  return {{"flights", f.flights.size()},
          {"judged", f.judged},
          {"wobble_mm", measured(f.wobble_m)},
          {"noise_mm", measured(f.noise_m)},
          {"allowance_mm", f.allowance_m * 1e3},
          {"detected", f.detected},
          {"offset_mm", measured(f.offset_m)},
          {"offset_low_mm", measured(f.offset_low_m)},
          {"offset_high_mm", measured(f.offset_high_m)},
          {"smallest_offset_mm", finite_or_null(f.smallest_offset_m * 1e3)}};
}

/// report.json's image_scale: each recording's image scale as its tracks give it (a drop's
/// flights' fall acceleration, a ball's rolling height), the scale, whether it is off and whether
/// the diagnosis read it so.
nlohmann::json image_scale_json(const DiagnoseResult& r) {
  nlohmann::json recordings = nlohmann::json::array();
  for (const auto& [name, g, applied] : r.image_scale) {
    const bool flights = g.source == ScaleSource::FreeFlights;
    recordings.push_back({{"recording", name},
                          {"from", std::string(to_string(g.source))},
                          {"samples", g.samples},
                          {flights ? "fall_acceleration_m_s2" : "height_m", g.measured},
                          {flights ? "expected_m_s2" : "expected_m", g.expected},
                          {flights ? "standard_error_m_s2" : "standard_error_m", g.standard_error},
                          {"scale", g.scale()},
                          {"tolerance", g.tolerance()},
                          {"off", g.off()},
                          {"applied", applied}});
  }
  return {{"mode", std::string(to_string(r.image_scale_mode))}, {"recordings", std::move(recordings)}};
}

/// report.json's ensemble: the recorded outcomes against replays over the unknown release.
nlohmann::json ensemble_json(const EnsembleReport& e) {
  auto comparisons_json = [&](const std::vector<OutcomeComparison>& list) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& c : list) {
      out.push_back({{"recording", e.recordings.at(c.recording)},
                     {"outcome", outcome_name(c.outcome)},
                     {"statistic", statistic_name(c.statistic)},
                     {"recorded_value", c.recorded_value},
                     {"replayed_value", c.ensemble_value},
                     {"recorded_mean", c.recorded_mean},
                     {"recorded_sd", c.recorded_sd},
                     {"recorded_n", c.recorded_n},
                     {"replayed_mean", c.ensemble_mean},
                     {"replayed_sd", c.ensemble_sd},
                     {"replays", c.ensemble_n},
                     {"floor", c.floor},
                     {"z", c.z}});
    }
    return out;
  };
  const nlohmann::json outcomes = comparisons_json(e.null_comparisons);
  nlohmann::json tried = nlohmann::json::array();
  const auto library = effect_library();
  for (const auto& h : e.hypotheses) {
    const EffectSpec& spec = effect_spec(library, h.effect);
    nlohmann::json values = nlohmann::json::object();
    for (std::size_t k = 0; k < spec.parameters.size() && k < h.values.size(); ++k)
      values[spec.parameters[k].name] = h.values[k];
    tried.push_back({{"name", spec.name},
                     {"values", values},
                     {"calibrated", coefficients_json(h.base)},
                     {"chi2", h.chi2},
                     {"dispersion", h.dispersion},
                     {"delta_bic", h.delta_bic()},
                     {"fresh_delta_bic", finite_or_null(h.fresh_delta_bic)},
                     {"first_delta_bic", finite_or_null(h.first_delta_bic)},
                     {"plausible", h.plausible},
                     {"start", calibration_start_name(h.start)},
                     {"comparisons", comparisons_json(h.comparisons)}});
  }
  nlohmann::json detect = nlohmann::json::array();
  for (const auto& d : e.detectability) {
    detect.push_back({{"name", effect_spec(library, d.effect).name},
                      {"strong_signal", d.strong_signal},
                      {"replay_noise", d.replay_noise},
                      {"needed", d.needed},
                      {"trials_needed", finite_or_null(d.trials_needed)},
                      {"misfit_limited", d.misfit_limited},
                      {"advice", trials_advice_name(d.advice)},
                      {"strong_rejection", d.strong_rejection},
                      {"strong_resolution", finite_or_null(d.strong_resolution)},
                      {"dispersion", d.dispersion}});
  }
  return {{"replays", e.replays},
          {"trials", e.trials},
          {"detectability", detect},
          {"outcomes", e.outcomes},
          {"null_chi2", e.null_chi2},
          {"null_fit", null_fit_name(e.null_fit)},
          {"calibrated", coefficients_json(e.calibrated)},
          {"calibrated_here", e.calibrated_here},
          {"comparisons", outcomes},
          {"hypotheses", tried}};
}

/// report.json's phases: each recording's phases judged against the noise.
nlohmann::json phases_json(const std::vector<PhaseReport>& phases) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& p : phases) {
    out.push_back({{"recording", p.recording},
                   {"phase", std::string(phase_name(p.phase))},
                   {"values", p.values},
                   {"chi2_per_value", p.chi2_per_value},
                   {"p_value", p.p_value},
                   {"significant", p.significant},
                   {"bias_x_mm", p.bias_x_mm},
                   {"bias_z_mm", p.bias_z_mm},
                   {"axis", p.axis == Axis::Z ? "z" : "x"},
                   {"growth_power", p.growth_power},
                   {"end_residual_mm", p.end_residual_mm},
                   {"improved_chi2_per_value", p.improved_chi2_per_value},
                   {"misfit_per_value", finite_or_null(p.misfit_per_value)},
                   {"large_misfit_level", p.large_misfit_level},
                   {"statement", p.statement}});
  }
  return out;
}

/// report.json's hypotheses: each candidate fitted frame by frame and its checks.
nlohmann::json hypotheses_json(const std::vector<HypothesisReport>& hypotheses) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& h : hypotheses) {
    nlohmann::json values = nlohmann::json::object();
    for (const auto& v : h.values) values[v.name] = v.value;
    out.push_back({{"name", h.name},
                   {"fitted", h.fitted},
                   {"values", values},
                   {"coefficients", coefficients_json(h.base)},
                   {"values_used", h.values_used},
                   {"delta_chi2", h.delta_chi2},
                   {"delta_bic", h.delta_bic},
                   {"heldout_delta_chi2", h.heldout_delta_chi2},
                   {"plausible", h.plausible},
                   {"improves_heldout", h.improves_heldout},
                   {"clears_signature", h.clears_signature},
                   {"clears_large_misfit", h.clears_large_misfit},
                   {"all_trials_delta_bic", finite_or_null(h.all_trials_delta_bic)},
                   {"beats_refitted_null", h.beats_refitted_null},
                   {"flagged_excess_before", h.flagged_excess_before},
                   {"flagged_excess_after", h.flagged_excess_after},
                   {"worsened_phases", h.worsened_phases},
                   {"passes", h.passes},
                   {"evaluations", h.evaluations},
                   {"fit_start", std::string(fit_start_name(h.fit_start))},
                   {"profile_searched", h.profile_searched},
                   {"smallest_detectable", finite_or_null(h.smallest_detectable)},
                   {"detectable_at_any_magnitude", h.detectable_at_any_magnitude},
                   {"replay_shown", finite_or_null(h.replay_shown)},
                   {"strong_delta_chi2", finite_or_null(h.strong_delta_chi2)},
                   {"strong_resolution_chi2", finite_or_null(h.strong_resolution_chi2)},
                   {"strong_preferred_in", preferred_json(h.strong_preferred_in)}});
  }
  return out;
}

}  // namespace

nlohmann::json diagnosis_report_json(const DiagnoseResult& r, const std::string& clump_name) {
  nlohmann::json j;
  j["format"] = "clumpforge-diagnosis/1";
  j["clump"] = clump_name;
  j["verdict"] = verdict_name(r);
  j["basis"] = std::string(basis_name(r.basis));
  j["statement"] = r.statement;
  j["candidates"] = r.candidates;
  j["experiment"] = r.experiment;
  j["effect_parameters"] = nlohmann::json::object();
  for (const auto& p : r.effect_parameters) {
    j["effect_parameters"][p.name] = {{"value", p.value},
                                      {"low", p.low},
                                      {"high", p.high},
                                      {"curvature_half_width", finite_or_null(p.curvature_half_width)},
                                      {"by_recording", nlohmann::json::object()}};
    for (const auto& [recording, value] : p.by_recording)
      j["effect_parameters"][p.name]["by_recording"][recording] = value;
  }
  j["summaries_only"] = r.summaries_only;
  j["decidable"] = r.decidable;
  j["undecidable"] = r.undecidable;
  j["undecided_because"] = std::string(undecided_because_name(r.undecided_because));
  j["noise_m"] = nlohmann::json::object();
  for (const auto& [name, s] : r.noise_m) j["noise_m"][name] = s;
  j["baseline"] = coefficients_json(r.baseline);
  j["calibrated_per_test"] = coefficients_json(r.calibrated_per_test);
  j["polish"] = nlohmann::json::array();
  for (const PolishShare& p : r.polish)
    j["polish"].push_back({{"surface", p.surface},
                           {"test", std::string(to_string(p.test))},
                           {"chi2_calibrated", p.chi2_calibrated},
                           {"chi2_polished", p.chi2_polished}});
  j["refitted_on_all"] = r.refitted_on_all.empty() ? nlohmann::json() : coefficients_json(r.refitted_on_all);
  j["improved"] = coefficients_json(r.improved);
  j["uncalibrated"] = r.uncalibrated;
  j["particle_model"] = particle_model_json(r);
  j["flights"] = r.flights ? flights_json(*r.flights) : nlohmann::json();
  j["image_scale"] = image_scale_json(r);
  if (r.ensemble) j["ensemble"] = ensemble_json(*r.ensemble);
  if (r.gate_retry) {
    const GateRetry& g = *r.gate_retry;
    j["gate_retry"] = {{"gate", gate_name(g.gate)},          {"value", g.value},
                       {"threshold", g.threshold},           {"replays_first", g.replays_first},
                       {"replays_second", g.replays_second}, {"replayed_first", g.replayed_first},
                       {"seconds_first", g.seconds_first},   {"seconds_second", g.seconds_second},
                       {"seconds_checks", g.seconds_checks}, {"held", g.held},
                       {"checks", nlohmann::json::array()},  {"statement", g.statement}};
    for (const GateCheck& k : g.checks)
      j["gate_retry"]["checks"].push_back({{"gate", gate_name(k.gate)},
                                           {"first", k.first},
                                           {"second", k.second},
                                           {"threshold", k.threshold},
                                           {"held", k.held}});
  }
  j["fit"] = {{"before", quality_json(r.before)}, {"after", quality_json(r.after)}};
  if (const auto& h = r.heldout_outcomes) {
    j["fit"]["heldout_outcomes"] = {{"training_trials", h->training_trials},
                                    {"heldout_trials", h->heldout_trials},
                                    {"statistics", h->statistics},
                                    {"chi2_null", h->chi2_null},
                                    {"chi2_named", h->chi2_named},
                                    {"rms_z_null", h->rms_z_null()},
                                    {"rms_z_named", h->rms_z_named()},
                                    {"improvement", h->improvement()},
                                    {"values", h->values},
                                    {"rung", h->rung},
                                    {"replays", h->replays},
                                    {"seconds", h->seconds}};
  }
  if (const auto& h = r.heldout_flights) {
    j["fit"]["heldout_flights"] = {{"training_flights", h->training_flights},
                                   {"heldout_flights", h->heldout_flights},
                                   {"offset_m", h->offset_m},
                                   {"wobble_m", h->wobble_m},
                                   {"without_m", h->without_m},
                                   {"with_m", h->with_m},
                                   {"improvement", h->improvement()}};
  }
  j["phases"] = phases_json(r.phases);
  j["hypotheses"] = hypotheses_json(r.hypotheses);
  auto phases_of = [](const std::vector<PhaseOf>& list) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& u : list) {
      out.push_back({{"recording", u.recording},
                     {"phase", std::string(phase_name(u.phase))},
                     {"chi2_per_value", u.chi2_per_value},
                     {"where", u.where}});
    }
    return out;
  };
  j["unexplained"] = phases_of(r.unexplained);
  j["outliers"] = phases_of(r.outliers);
  j["notes"] = r.notes;
  j["parted"] = nlohmann::json::array();
  for (const auto& p : r.parted) j["parted"].push_back({{"recording", p.recording}, {"seconds", p.seconds}});
  j["tracked_trials"] = r.tracked_trials;
  j["training_trials"] = r.training_trials;
  j["trial_replays"] = r.evaluations;
  j["replays_reused"] = r.replays_reused;
  j["seconds"] = r.seconds;
  j["stage_seconds"] = nlohmann::json::array();
  for (const auto& st : r.stage_seconds)
    j["stage_seconds"].push_back({{"stage", stage_name(st.stage)}, {"seconds", st.seconds}});
  return j;
}

// What the figures need beside report.json: each recording's first trial against both models.
std::string diagnosis_tracks_json(const DiagnoseResult& r) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& t : r.tracks) {
    out.push_back({{"recording", t.recording},
                   {"t", t.t},
                   {"x", t.x},
                   {"z", t.z},
                   {"baseline_t", t.baseline_t},
                   {"baseline_x", t.baseline_x},
                   {"baseline_z", t.baseline_z},
                   {"improved_t", t.improved_t},
                   {"improved_x", t.improved_x},
                   {"improved_z", t.improved_z},
                   {"horizon", finite_or_null(t.horizon)}});
  }
  return out.dump() + "\n";
}

Result<DiagnoseRun> run_diagnose_job(const DiagnoseJob& job, const RunContext& context) {
  if (!job.mesh.empty() && !job.library.empty())
    return fail(ErrorCode::InvalidArgument, "give exactly one of --mesh and --library, not both");
  auto set = read_recording_paths(job.recordings);
  if (!set) return std::unexpected(set.error());
  const std::vector<Recording>& recordings = set->recordings;
  const std::vector<std::string>& names = set->names;
  auto stated = stated_particle(*set);
  if (!stated) return std::unexpected(stated.error());
  auto choice = particle_choice(job, *stated);
  if (!choice) return std::unexpected(choice.error());
  auto table = job.materials.empty() ? Result<MaterialTable>(default_material_table()) : read_materials(job.materials);
  if (!table) return std::unexpected(table.error());
  for (const auto& r : recordings) {
    if (auto s = table->find(r.surface); !s) return std::unexpected(s.error());
  }
  auto model = particle_models(job, *choice, *stated, context);
  if (!model) return std::unexpected(model.error());
  DiagnoseOptions options = job.options;
  options.finer_clumps = std::move(model->finer);
  auto result = diagnose(model->clump, *table, recordings, names, options, context);
  if (!result) return std::unexpected(result.error());
  const auto& ladder = model->ladder;
  if (!ladder.empty()) {
    result->notes.insert(
        result->notes.begin(),
        fmt::format("particle model: adaptive clump of {} spheres, the first of {} whose surface lies within {:.3g} "
                    "mm RMS of the mesh",
                    model->clump.spheres.size(),
                    fmt::join(ladder | std::views::transform([](const auto& l) {
                                return fmt::format("{} ({:.3f} mm)", l.first, l.second * 1e3);
                              }),
                              ", "),
                    job.options.model_accuracy_m * 1e3 / 3.0));
  }
  // The clump diagnosed: the one the replayed tracks converged with.
  const std::string diagnosed = result->particle_model ? result->particle_model->diagnosed : model->clump.name;
  Clump clump = std::move(model->clump);
  for (auto& f : options.finer_clumps) {
    if (f.name == diagnosed) clump = std::move(f);
  }
  DiagnoseRun run{.result = std::move(*result), .clump = std::move(clump), .report = {}};
  run.report = diagnosis_report_json(run.result, run.clump.name);
  run.report["wall_mass"] = std::string(wall_mass_name(job.options.lab.contact.wall_mass));
  run.report["drop_drift"] = std::string(drift_at_name(job.options.drift_at));
  run.report["held_starts"] = job.options.held_starts;
  run.report["seed"] = job.options.seed;  // the release orientations drawn: the same seed, the same report
  run.report["particle"] = {
      {"mesh", choice->mesh.empty() ? nlohmann::json() : nlohmann::json(choice->mesh)},
      {"mesh_from", choice->mesh.empty()
                        ? nlohmann::json()
                        : nlohmann::json(choice->mesh_from_recordings ? "recordings" : "command_line")},
      {"mesh_units", choice->mesh.empty() ? nlohmann::json() : nlohmann::json(choice->units)},
      {"library", job.library.empty() ? nlohmann::json() : nlohmann::json(job.library)},
      {"density_kg_m3", choice->density},
      {"density_from", std::string(density_from_name(choice->density_from))}};
  run.report["keys_not_read"] = keys_not_read_json(recordings, set->manifests);
  return run;
}

}  // namespace clumpforge::cli
