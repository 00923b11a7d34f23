// report.json as diagnosis_report_json writes it from a DiagnoseResult (tools/diagnose_job.hpp),
// without running a diagnosis: what the ensemble section says of its null and of each
// candidate tried.
#include <gtest/gtest.h>

#include "diagnose_job.hpp"

namespace clumpforge {
namespace {

SurfaceParameters surface(const char* name, double restitution) {
  SurfaceParameters s;
  s.surface = name;
  s.interaction.restitution = restitution;
  s.interaction.static_friction = 0.4;
  s.interaction.rolling_friction = 0.02;
  return s;
}

}  // namespace

// The null's standing (NullFit) becomes its name only here; each candidate tried carries the
// coefficients it was calibrated with beside its own values (the strong viscoelastic case of 36
// trials per set-up reached an exponent of 0.32 on coefficients the report did not show), and
// which start of its calibration was kept (CalibrationStart).
TEST(DiagnoseReport, TheEnsembleSaysHowItsNullStandsAndWhatEachCandidateWasCalibratedWith) {
  DiagnoseResult result;
  result.verdict = Verdict::None;
  EnsembleReport e;
  e.outcomes = 16;
  e.null_chi2 = 20.0;
  e.calibrated = {surface("Q235", 0.557)};
  EnsembleHypothesis h;
  h.effect = Effect::ViscoelasticRestitution;
  h.values = {0.32};
  h.base = {surface("Q235", 0.64)};
  h.chi2 = 12.0;
  EnsembleHypothesis held = h;
  held.start = CalibrationStart::HeldLevel;
  e.hypotheses = {h, held};
  for (const NullFit fit : {NullFit::Consistent, NullFit::OneFarOutcome, NullFit::Inconsistent}) {
    e.null_fit = fit;
    result.ensemble = e;
    const nlohmann::json j = cli::diagnosis_report_json(result, "adaptive-256");
    const auto& ens = j.at("ensemble");
    EXPECT_EQ(ens.at("null_fit"), null_fit_name(fit));
    EXPECT_DOUBLE_EQ(ens.at("calibrated").at("Q235").at("restitution").get<double>(), 0.557);
    const auto& tried = ens.at("hypotheses").at(0);
    EXPECT_EQ(tried.at("name"), "viscoelastic_restitution");
    EXPECT_DOUBLE_EQ(tried.at("values").at("exponent").get<double>(), 0.32);
    EXPECT_DOUBLE_EQ(tried.at("calibrated").at("Q235").at("restitution").get<double>(), 0.64);
    EXPECT_EQ(tried.at("start"), "proposal");
    EXPECT_EQ(ens.at("hypotheses").at(1).at("start"), "held_level");
  }
  EXPECT_EQ(null_fit_name(NullFit::OneFarOutcome), "one_far_outcome");
}

}  // namespace clumpforge
