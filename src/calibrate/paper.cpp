#include "calibrate/paper.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numeric>

namespace clumpforge {
namespace {

std::vector<double> steps(double low, double high, double step) {
  std::vector<double> values;
  for (int i = 0; low + i * step <= high + 1e-9; ++i) values.push_back(std::round((low + i * step) * 1e6) / 1e6);
  return values;
}

double mean(const std::vector<double>& v) {
  return sample_spread(v).mean;
}

std::optional<double> study_value(const std::string& parameter, const std::string& surface) {
  // The seed study's calibrated values (../shared/reference/seed-facts.md).
  if (surface == "Q235") return parameter == "restitution" ? 0.728 : parameter == "static_friction" ? 0.41 : 0.02;
  if (surface == "soil") return parameter == "restitution" ? 0.44 : parameter == "static_friction" ? 0.76 : 0.033;
  return std::nullopt;
}

double& coefficient(Interaction& i, const std::string& parameter) {
  if (parameter == "restitution") return i.restitution;
  if (parameter == "static_friction") return i.static_friction;
  return i.rolling_friction;
}

const Recording* find_recording(const std::vector<Recording>& recordings, const std::string& surface, LabTest test) {
  for (const auto& r : recordings) {
    if (r.surface == surface && r.test == test && !r.summaries().empty()) return &r;
  }
  return nullptr;
}

struct Responses {
  std::vector<double> values;       // study units
  double apparent_restitution = 0;  // drop: mean sqrt(h/H)
  double rotation_of_impact = 0;    // drop: mean share of the impact energy turned into rotation
  double contacts = 0;              // drop: mean spheres touching at the first impact
};

// One run of `trials` trials, packed as the trials' responses then the three impact means (the
// team's map carries numbers only).
Result<std::vector<double>> run_packed(const Clump& clump, const MaterialTable& table, const Recording& setup,
                                       const Interaction& interaction, const PaperOptions& options) {
  LabOptions lab = options.lab;
  lab.trials = options.trials_per_level;
  lab.interaction = interaction;
  auto result = run_lab_test(clump, table, setup, lab);
  if (!result) return std::unexpected(result.error());
  std::vector<double> out;
  for (double v : result->recording.summaries()) out.push_back(study_units(setup.test, v));
  double apparent = 0.0, rotation = 0.0, contacts = 0.0;
  for (const auto& d : result->impacts) {
    apparent += d.apparent_restitution / static_cast<double>(result->impacts.size());
    rotation += d.rotation_of_impact / static_cast<double>(result->impacts.size());
    contacts += d.first_contacts / static_cast<double>(result->impacts.size());
  }
  out.insert(out.end(), {apparent, rotation, contacts});
  return out;
}

Responses unpack(const std::vector<double>& packed) {
  Responses r;
  r.values.assign(packed.begin(), packed.end() - 3);
  r.apparent_restitution = packed[packed.size() - 3];
  r.rotation_of_impact = packed[packed.size() - 2];
  r.contacts = packed.back();
  return r;
}

// Every run of `runs` (one interaction each) shared among the team's ranks, in that order.
Result<std::vector<Responses>> run_all(const Clump& clump, const MaterialTable& table, const Recording& setup,
                                       const std::vector<Interaction>& runs, const PaperOptions& options,
                                       const Team& team) {
  std::vector<std::size_t> order(runs.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  auto packed = team.map(order, static_cast<std::size_t>(options.trials_per_level) + 3,
                         [&](std::size_t i) { return run_packed(clump, table, setup, runs[i], options); });
  if (!packed) return std::unexpected(packed.error());
  std::vector<Responses> out;
  for (const auto& p : *packed) out.push_back(unpack(p));
  return out;
}

// Picks the calibrated value among the roots in range, saying what it did when there is not
// exactly one.
void choose(ParameterCalibration& p) {
  const double low = p.levels.front().value, high = p.levels.back().value;
  p.roots = solve_in_range(p.fit, p.measured_mean, low, high);
  if (p.roots.size() == 1) {
    p.calibrated = p.roots.front();
    return;
  }
  const bool rising = p.levels.back().mean >= p.levels.front().mean;
  if (p.roots.size() == 2) {
    // The root on the branch whose slope follows the sweep's trend.
    const double slope0 = 2 * p.fit.a * p.roots[0] + p.fit.b;
    p.calibrated = (slope0 >= 0) == rising ? p.roots[0] : p.roots[1];
    p.flag =
        fmt::format("two roots in range ({:.4g} and {:.4g}); took {:.4g}, on the branch following the sweep's trend",
                    p.roots[0], p.roots[1], p.calibrated);
    return;
  }
  // None: the measured mean is outside what the swept range produces; take the nearer end.
  const double at_low = std::abs(p.fit(low) - p.measured_mean), at_high = std::abs(p.fit(high) - p.measured_mean);
  p.calibrated = at_low < at_high ? low : high;
  p.flag = fmt::format(
      "no root in [{:g}, {:g}]: the fitted curve spans {:.4g} to {:.4g}, the measured mean is {:.4g}; took the nearer "
      "end "
      "{:g}",
      low, high, p.fit(low), p.fit(high), p.measured_mean, p.calibrated);
}
}  // namespace

std::vector<double> paper_levels(const std::string& parameter, const std::string& surface) {
  const bool steel = surface == "Q235", soil = surface == "soil";
  if (parameter == "restitution")
    return steel ? steps(0.1, 0.8, 0.1) : soil ? steps(0.05, 0.65, 0.1) : steps(0.05, 0.85, 0.1);
  if (parameter == "static_friction")
    return steel ? steps(0.1, 0.7, 0.1) : soil ? steps(0.3, 0.9, 0.1) : steps(0.1, 0.9, 0.1);
  return steel ? steps(0.01, 0.07, 0.01) : soil ? steps(0.01, 0.05, 0.01) : steps(0.01, 0.07, 0.01);
}

Result<PaperCalibration> calibrate_paper(const Clump& clump, const MaterialTable& table,
                                         const std::vector<Recording>& recordings, const PaperOptions& options,
                                         const RunContext& context, const Team& team) {
  if (options.trials_per_level < 1) return fail(ErrorCode::InvalidArgument, "trials per level must be at least 1");
  if (auto ok = check_stated_density(recordings, clump.density, fmt::format("the clump '{}'", clump.name)); !ok)
    return std::unexpected(ok.error());
  std::vector<std::string> surfaces;
  for (const auto& r : recordings) {
    if (std::find(surfaces.begin(), surfaces.end(), r.surface) == surfaces.end()) surfaces.push_back(r.surface);
  }
  if (surfaces.empty()) return fail(ErrorCode::InvalidArgument, "no recordings to calibrate against");
  PaperCalibration calibration;
  struct Step {
    std::string parameter;
    LabTest test;
  };
  const std::vector<Step> order{
      {"restitution", LabTest::Drop}, {"static_friction", LabTest::Tilt}, {"rolling_friction", LabTest::Roll}};
  std::size_t done = 0;
  for (const auto& surface : surfaces) {
    if (auto known = table.find(surface); !known) return std::unexpected(known.error());
    Interaction current = table.interaction(options.lab.particle_material, surface).value_or(Interaction{});
    for (const auto& [parameter, test] : order) {
      context.report(fmt::format("{} on {}", parameter, surface),
                     static_cast<double>(done++) / (3.0 * surfaces.size()));
      const Recording* recording = find_recording(recordings, surface, test);
      if (!recording) {
        calibration.notes.push_back(fmt::format("{}: no {} recording; {} kept at {}", surface, to_string(test),
                                                parameter, coefficient(current, parameter)));
        continue;
      }
      ParameterCalibration p;
      p.parameter = parameter;
      p.test = test;
      p.surface = surface;
      p.study_value = study_value(parameter, surface);
      // What the study held during each sweep: friction and rolling friction zero for the
      // restitution sweep, rolling friction zero for the friction sweep.
      p.held = current;
      if (parameter == "restitution") p.held.static_friction = p.held.rolling_friction = 0.0;
      if (parameter == "static_friction") p.held.rolling_friction = 0.0;
      std::vector<double> xs, ys;
      std::vector<Interaction> runs;
      for (double level : paper_levels(parameter, surface)) {
        runs.push_back(p.held);
        coefficient(runs.back(), parameter) = level;
        xs.push_back(level);
      }
      auto responses = run_all(clump, table, *recording, runs, options, team);
      if (!responses) return std::unexpected(responses.error());
      for (std::size_t i = 0; i < xs.size(); ++i) {
        p.levels.push_back({xs[i], (*responses)[i].values, mean((*responses)[i].values)});
        ys.push_back(p.levels.back().mean);
      }
      p.fit = fit_quadratic(xs, ys);
      std::vector<double> measured;
      for (double v : recording->summaries()) measured.push_back(study_units(test, v));
      p.measured_mean = mean(measured);
      choose(p);
      coefficient(current, parameter) = p.calibrated;
      Interaction verify = current;
      if (parameter == "static_friction") verify.rolling_friction = 0.0;
      if (parameter == "restitution") verify.static_friction = verify.rolling_friction = 0.0;
      auto checked = run_all(clump, table, *recording, {verify}, options, team);
      if (!checked) return std::unexpected(checked.error());
      const Responses* check = &checked->front();
      p.verification_mean = mean(check->values);
      p.verification_responses = check->values;
      p.measured = measured;
      p.verification_apparent_restitution = check->apparent_restitution;
      p.verification_rotation_of_impact = check->rotation_of_impact;
      p.verification_contacts_at_impact = check->contacts;
      p.verification_error = (p.verification_mean - p.measured_mean) / p.measured_mean;
      calibration.steps.push_back(std::move(p));
    }
    calibration.results.emplace_back(surface, current);
  }
  context.report("calibration", 1.0);
  return calibration;
}

}  // namespace clumpforge
