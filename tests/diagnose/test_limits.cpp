// The search for the smallest magnitude at which a candidate's replay shows (a `none`'s
// detection limit, docs/diagnose.md step 7), on responses of known shape: one that vanishes as
// the magnitude's square, one that vanishes slowly, and one whose law departs from the null's at
// any magnitude (epsd_rolling on lab-like's sphere rolls: 1.82, 0.0446 and 0.000845 of a strong
// 30 all showed, and the report claimed 0.000845 as if it were an edge).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "diagnose/stages.hpp"

using namespace clumpforge;
using diagnosis::Bracket;
using diagnosis::ReplaySignal;

namespace {

constexpr double kNeeded = 20.0;

/// A response of signal `s0 + s t^p` and misfit `m0 + m t^p` at a fraction t of the strong
/// magnitude (s0, m0: what any nonzero magnitude shows at once), and the fractions replayed.
struct Response {
  double s0 = 0.0, s = 1e4, m0 = 0.0, m = 50.0, p = 2.0;
  std::vector<double> asked;
  ReplaySignal at(double t) const { return ReplaySignal{s0 + s * std::pow(t, p), m0 + m * std::pow(t, p), kNeeded}; }
  diagnosis::FractionReplay replay() {
    return [this](double t) -> Result<std::optional<ReplaySignal>> {
      asked.push_back(t);
      return at(t);
    };
  }
};

}  // namespace

TEST(DetectionLimit, AResponseThatVanishesWithTheMagnitudeIsBracketedAtItsEdge) {
  Response quadratic;  // shows (both margins) from t = sqrt(1 / 50) = 0.141
  const double edge = std::sqrt(1.0 / quadratic.m);
  auto b = diagnosis::smallest_shown_fraction(quadratic.at(1.0), 10.0, quadratic.replay());
  ASSERT_TRUE(b.has_value());
  EXPECT_FALSE(b->any_magnitude);
  EXPECT_LE(b->tried.size(), static_cast<std::size_t>(diagnosis::kDetectableReplays));
  EXPECT_GE(b->shown, edge * (1.0 - 1e-9));
  EXPECT_LT(b->missed, edge);
  EXPECT_GT(b->missed, 0.0);  // bracketed from below: no replay at a vanishing magnitude needed
  for (double t : quadratic.asked) EXPECT_GT(t, diagnosis::kVanishingFraction);
}

TEST(DetectionLimit, AResponseThatVanishesSlowlyKeepsTheSmallestReplayShown) {
  // Every replay the budget allows shows (the edge lies at 1e-4 of the strong magnitude), so
  // one more replay asks whether the response vanishes at all: it does, and the claim stays the
  // smallest fraction a replay showed, the vanishing one the largest that did not.
  Response slow{.s = 1e4, .m = 10.0, .p = 0.25};
  auto b = diagnosis::smallest_shown_fraction(slow.at(1.0), 10.0, slow.replay());
  ASSERT_TRUE(b.has_value());
  EXPECT_FALSE(b->any_magnitude);
  ASSERT_EQ(b->tried.size(), static_cast<std::size_t>(diagnosis::kDetectableReplays) + 1);
  EXPECT_EQ(b->tried.back().first, diagnosis::kVanishingFraction);
  EXPECT_FALSE(b->tried.back().second);
  EXPECT_EQ(b->missed, diagnosis::kVanishingFraction);
  EXPECT_EQ(b->shown, b->tried[diagnosis::kDetectableReplays - 1].first);
  EXPECT_GE(slow.at(b->shown).shown(), 1.0);
}

TEST(DetectionLimit, ALawThatDepartsFromTheNullsAtAnyMagnitudeIsSaidSo) {
  // Any nonzero magnitude swaps the law (type A to type C): twice the margins at once.
  Response swapped{.s0 = 2.0 * kNeeded, .s = 1e4, .m0 = 2.0, .m = 50.0};
  auto b = diagnosis::smallest_shown_fraction(swapped.at(1.0), 10.0, swapped.replay());
  ASSERT_TRUE(b.has_value());
  EXPECT_TRUE(b->any_magnitude);
  EXPECT_EQ(b->shown, diagnosis::kVanishingFraction);
  EXPECT_EQ(b->missed, 0.0);
  ASSERT_EQ(b->tried.size(), static_cast<std::size_t>(diagnosis::kDetectableReplays) + 1);
  for (const auto& [t, shows] : b->tried) EXPECT_TRUE(shows) << t;

  // A strong magnitude that does not show, at the top of its range, asks no replay at all.
  Response faint{.s = 1.0, .m = 0.01};
  auto none = diagnosis::smallest_shown_fraction(faint.at(1.0), 1.0, faint.replay());
  ASSERT_TRUE(none.has_value());
  EXPECT_FALSE(none->any_magnitude);
  EXPECT_TRUE(std::isnan(none->shown));
  EXPECT_TRUE(faint.asked.empty());
}
