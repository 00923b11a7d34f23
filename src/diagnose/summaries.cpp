#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "diagnose/diagnose.hpp"
#include "diagnose/stages.hpp"
#include "numerics/minimize.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {

Result<DiagnoseResult> diagnose_summaries(const Clump& clump, const MaterialTable& table,
                                          const std::vector<Recording>& recordings,
                                          const std::vector<std::string>& names, const DiagnoseOptions& options,
                                          const RunContext& run) {
  const auto started = std::chrono::steady_clock::now();
  DiagnoseResult result;
  result.summaries_only = true;
  result.basis = Basis::SummariesOnly;
  result.verdict = Verdict::None;
  std::vector<std::string> drop_heights, starts;
  std::vector<std::string> gap_statements;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    const Recording& rec = recordings[r];
    const auto values = rec.summaries();
    if (values.empty()) continue;
    if (rec.test == LabTest::Roll)
      starts.push_back(fmt::format("{:g} mm on {}", rec.start_distance * 1000.0, rec.surface));
    if (rec.test != LabTest::Drop) continue;
    drop_heights.push_back(fmt::format("{:g} m on {}", rec.release_height, rec.surface));
    std::vector<double> ratios;
    for (double h : values) ratios.push_back(std::sqrt(std::max(h, 0.0) / rec.release_height));
    const SampleSpread measured = sample_spread(ratios);
    auto pair = table.interaction(options.lab.particle_material, rec.surface);
    if (!pair) return std::unexpected(pair.error());
    // The contact restitution whose DEM drops reproduce the measured mean rebound.
    LabOptions lab = options.lab;
    lab.trials = 16;
    lab.seed = options.seed;
    Recording setup = rec;
    setup.trials.clear();
    std::optional<Error> failure;
    LabResult last;
    auto mismatch = [&](double e) {
      Interaction i = *pair;
      i.restitution = e;
      lab.interaction = i;
      auto out = run_lab_test(clump, table, setup, lab);
      if (!out) {
        failure = out.error();
        return 1e9;
      }
      last = std::move(*out);
      return std::abs(sample_spread(last.recording.summaries()).mean - sample_spread(values).mean);
    };
    auto best = golden_section(mismatch, 0.05, 1.0, 2e-3, 20);
    if (failure) return std::unexpected(*failure);
    mismatch(best.x[0]);
    double apparent = 0.0, contacts = 0.0, rotation = 0.0;
    for (const auto& d : last.impacts) {
      apparent += d.apparent_restitution;
      contacts += d.first_contacts;
      rotation += d.rotation_of_impact;
    }
    const double n = static_cast<double>(std::max<std::size_t>(1, last.impacts.size()));
    result.baseline.push_back({rec.surface, last.interaction});
    gap_statements.push_back(
        fmt::format("{}: measured sqrt(h/H) {:.3f} +- {:.3f} (sd of {} trials); the DEM matches the mean rebound with "
                    "contact restitution e = {:.3f}, "
                    "where its own drops give sqrt(h/H) {:.3f} with {:.1f} spheres touching at impact and {:.0f} % of "
                    "the impact energy going into "
                    "rotation: the gap between the apparent and the contact restitution is the multi-contact damping "
                    "and rotation of an irregular "
                    "body at impact, which the DEM already contains, not missing physics",
                    names[r], measured.mean, measured.sd, ratios.size(), best.x[0], apparent / n, contacts / n,
                    100.0 * rotation / n));
    // Drag's bias on e from rebound heights is 0.2 % at 0.2 m (missing-physics digest): compare with the scatter.
    gap_statements.push_back(
        fmt::format("{}: air drag would lower sqrt(h/H) by about {:.2f} % at this height, against a trial-to-trial "
                    "scatter of {:.1f} % "
                    "(a standard error of {:.1f} % on the mean): summaries cannot see it",
                    names[r], 0.23 * rec.release_height / 0.2, 100.0 * measured.sd / measured.mean,
                    100.0 * measured.sd / measured.mean / std::sqrt(static_cast<double>(ratios.size()))));
    run.report("summaries", static_cast<double>(r + 1) / static_cast<double>(recordings.size()));
  }
  result.decidable = gap_statements;
  result.decidable.push_back("the coefficients e, mu_s and mu_r per surface, from the means (clumpforge calibrate)");
  result.undecidable = {
      fmt::format("air drag: its t^4 bending of the flights needs tracks of drops from 0.5 m or more (drops here: {})",
                  drop_heights.empty() ? "none" : fmt::format("{}", fmt::join(drop_heights, ", "))),
      fmt::format("speed-dependent restitution (viscoelastic or elastic-plastic): needs the rebound at two or more "
                  "drop heights on one "
                  "surface, or tracked multiple bounces (drops here: {})",
                  drop_heights.empty() ? "none" : fmt::format("{}", fmt::join(drop_heights, ", "))),
      "plastic substrate: needs tracks (the particle resting in its dent, the contact's length) or the rest height "
      "after landing",
      fmt::format("rolling resistance form (viscous or elastic-plastic vs constant torque): needs two or more start "
                  "distances or tracked "
                  "speed on the flat (start distances here: {})",
                  starts.empty() ? "none" : fmt::format("{}", fmt::join(starts, ", "))),
      "adhesion: needs particles of different mass (its share of the load falls with weight)",
      "centre-of-mass offset: needs tracked rolls (a once-per-turn wobble)",
      "static above kinetic friction: a slip angle gives mu_s only; the acceleration after onset needs a track",
  };
  result.statement = fmt::format(
      "These recordings have summaries only, so no missing physics can be named. What they decide: {}. What they "
      "cannot: {}.",
      fmt::join(result.decidable, "; "), fmt::join(result.undecidable, "; "));
  result.experiment =
      "film the drops from 0.5 and 1.0 m and the rolls at 1000 fps with sub-pixel centroid tracking, and add a second "
      "drop height and start distance";
  result.seconds = diagnosis::seconds_since(started);
  return result;
}

}  // namespace clumpforge
