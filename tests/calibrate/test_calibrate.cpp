// The study's calibration procedure: its statistics, and recovery of known coefficients.
#include <gtest/gtest.h>

#include <cmath>

#include "calibrate/joint.hpp"
#include "calibrate/paper.hpp"
#include "io/clump_library.hpp"
#include "support/test_support.hpp"

namespace clumpforge {

TEST(Statistics, QuadraticFitRecoversExactCoefficients) {
  // The study's restitution fit on steel, sampled at its levels: an exact quadratic.
  std::vector<double> x, y;
  for (double e = 0.1; e < 0.85; e += 0.1) {
    x.push_back(e);
    y.push_back(232.238 * e * e - 131.922 * e + 30.622);
  }
  const auto fit = fit_quadratic(x, y);
  EXPECT_NEAR(fit.a, 232.238, 1e-9);
  EXPECT_NEAR(fit.b, -131.922, 1e-9);
  EXPECT_NEAR(fit.c, 30.622, 1e-9);
  EXPECT_NEAR(fit.r_squared, 1.0, 1e-12);
  // The study's inversion: 57.2 mm gives e = 0.7257 with its printed coefficients (it quotes
  // 0.728); the other root is below 0.1.
  const auto roots = solve_in_range(fit, 57.2, 0.1, 0.8);
  ASSERT_EQ(roots.size(), 1u);
  EXPECT_NEAR(roots[0], 0.7257, 0.0005);
  // The rolling fit on soil: 49.7 mm -> 0.033 (the study's value); the second root is outside.
  const QuadraticFit soil{3979.59, -1128.78, 83.26};
  const auto soil_roots = solve_in_range(soil, 49.7, 0.01, 0.05);
  ASSERT_EQ(soil_roots.size(), 1u);
  EXPECT_NEAR(soil_roots[0], 0.0333, 0.0005);
}

TEST(Statistics, FTestAgainstKnownQuantiles) {
  // F(2, 5) upper 5 % point is 5.786; F(2, 4) upper 1 % point is 18.0.
  EXPECT_NEAR(f_distribution_upper_tail(5.786, 2, 5), 0.05, 2e-4);
  EXPECT_NEAR(f_distribution_upper_tail(18.0, 2, 4), 0.01, 2e-4);
  EXPECT_NEAR(incomplete_beta(2, 3, 0.4), 0.5248, 1e-4);
  std::vector<double> x{1, 2, 3, 4, 5, 6}, noisy{1.1, 3.9, 9.2, 15.8, 25.1, 36.2};
  const auto fit = fit_quadratic(x, noisy);
  EXPECT_GT(fit.r_squared, 0.99);
  EXPECT_LT(fit.p_value, 1e-4);
}

TEST(Statistics, QuadraticFitsStandardErrorOfItsSquareTerm) {
  // For x symmetric about 0 the x^2 column is orthogonal to x, and a's standard error is the
  // closed form s / sqrt(sum (x^2 - mean x^2)^2), s^2 = SSE / (n - 3); a scatter four times as
  // wide gives four times the error, and an exact quadratic none.
  std::vector<double> x, y, wide, exact;
  const double scatter[] = {0.3, -0.1, -0.4, 0.2, 0.5, -0.3, 0.1, -0.2, 0.4};
  for (int i = 0; i < 9; ++i) {
    x.push_back(i - 4.0);
    exact.push_back(2.0 * x.back() * x.back() - x.back() + 1.0);
    y.push_back(exact.back() + scatter[i]);
    wide.push_back(exact.back() + 4.0 * scatter[i]);
  }
  const auto fit = fit_quadratic(x, y);
  double sse = 0.0, mean_square = 0.0, spread = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) sse += std::pow(y[i] - fit(x[i]), 2), mean_square += x[i] * x[i] / 9.0;
  for (double v : x) spread += std::pow(v * v - mean_square, 2);
  EXPECT_NEAR(fit.a_standard_error, std::sqrt(sse / 6.0 / spread), 1e-12);
  EXPECT_NEAR(fit_quadratic(x, wide).a_standard_error, 4.0 * fit.a_standard_error, 1e-12);
  EXPECT_NEAR(fit_quadratic(x, exact).a_standard_error, 0.0, 1e-9);
  EXPECT_TRUE(std::isnan(fit_quadratic({0, 1, 2}, {0, 1, 4}).a_standard_error));
}

TEST(PaperCalibration, RecoversTheRestitutionThatMadeTheRecording) {
  // A recording made by the DEM with e = 0.55, calibrated by the study's sweep (same seed,
  // so the same orientations: common random numbers) comes back within 0.05.
  auto clumps = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  const Clump clump = *select_clump(std::move(*clumps), "lattice-4mm", "tuber-default.h5");
  Recording setup;
  setup.test = LabTest::Drop;
  setup.surface = "Q235";
  LabOptions lab;
  lab.trials = 10;
  lab.interaction = Interaction{0.55, 0.0, 0.0};
  const auto made = run_lab_test(clump, default_material_table(), setup, lab);
  ASSERT_TRUE(made);
  PaperOptions options;
  options.trials_per_level = 10;
  const auto calibration = calibrate_paper(clump, default_material_table(), {made->recording}, options);
  ASSERT_TRUE(calibration) << calibration.error().message;
  ASSERT_EQ(calibration->steps.size(), 1u);
  const auto& step = calibration->steps[0];
  EXPECT_EQ(step.parameter, "restitution");
  EXPECT_EQ(step.levels.size(), 8u);  // 0.1 .. 0.8, the study's steel range
  EXPECT_GT(step.fit.r_squared, 0.9);
  EXPECT_NEAR(step.calibrated, 0.55, 0.05) << step.flag;
  EXPECT_LT(std::abs(step.verification_error), 0.1);
  EXPECT_EQ(calibration->notes.size(), 2u);  // no tilt or roll recording: kept, and said so
}

}  // namespace clumpforge

namespace clumpforge {

TEST(JointCalibration, RecoversCoefficientsThatMadeTheRecordings) {
  // Drop, tilt and roll recordings made by the DEM with known coefficients on steel; the
  // joint fit (same orientation ensemble) finds them, inside its intervals, with a small chi^2.
  auto clumps = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  const Clump clump = *select_clump(std::move(*clumps), "lattice-4mm", "tuber-default.h5");
  const Interaction truth{0.6, 0.5, 0.04};
  std::vector<Recording> recordings;
  for (LabTest test : {LabTest::Drop, LabTest::Tilt, LabTest::Roll}) {
    Recording setup;
    setup.test = test;
    setup.surface = "Q235";
    setup.composite = Composite::FourSquare;
    LabOptions lab;
    lab.trials = test == LabTest::Tilt ? 2 : 10;
    lab.interaction = truth;
    recordings.push_back(run_lab_test(clump, default_material_table(), setup, lab)->recording);
  }
  JointOptions options;
  const auto results = calibrate_joint(clump, default_material_table(), recordings, options);
  ASSERT_TRUE(results) << results.error().message;
  ASSERT_EQ(results->size(), 1u);
  const auto& r = results->front();
  EXPECT_NEAR(r.restitution.value, truth.restitution, 0.05);
  EXPECT_NEAR(r.static_friction.value, truth.static_friction, 0.03);
  EXPECT_NEAR(r.rolling_friction.value, truth.rolling_friction, 0.03);
  EXPECT_LE(r.static_friction.low, r.static_friction.value);
  EXPECT_GE(r.static_friction.high, r.static_friction.value);
  EXPECT_LT(r.chi_squared, 1.0);
  for (const auto& t : r.residuals) EXPECT_LT(std::abs(t.z()), 1.0);
}

}  // namespace clumpforge
