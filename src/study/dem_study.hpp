#pragma once
/// The DEM side of the resolution study (`clumpforge study`, docs/study.md): which clump is
/// coarse enough for the DEM. Every clump runs the lab's tests (drop, tilt, roll) from random
/// release orientations; each test's outcomes (rebound height, slip angle, roll distance) are
/// a sample, compared with the reference clump's (the finest model of the body: the smallest
/// surface distance to the scan, unless named) by two two-sample tests: Welch's
/// test of the means and the Kolmogorov-Smirnov test of the distributions. A clump's tests form
/// one family, Holm-adjusted, so a clump as good as the reference is called different with
/// probability at most `significance`; and a significant difference counts only when it is
/// larger than a lab resolves (the tolerances: a difference of 1e-4 deg in a slip angle is real
/// for 30 trials and meaningless to a user). The study names the coarsest clump whose outcomes, and
/// those of every finer clump of its fill method, cannot be told from the reference's.
///
/// Each (clump, test, surface) is one work item with its own seed (from the run's seed and the
/// item's name); items are shared among the ranks of an MPI team and their outcomes summed, so
/// a plain run and any number of ranks give the same values.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"
#include "core/recording.hpp"
#include "core/run_context.hpp"
#include "parallel/team.hpp"

namespace clumpforge {

struct DemStudyOptions {
  std::vector<LabTest> tests{LabTest::Drop, LabTest::Tilt, LabTest::Roll};
  std::vector<std::string> surfaces{"Q235"};
  int trials = 30;             ///< release orientations per clump, test and surface, in [5, 10000]
  double significance = 0.05;  ///< family-wise per clump, in (0, 0.5]
  std::uint64_t seed = 1;
  /// The clump compared against; empty: the finest model of the body, the clump with the
  /// smallest RMS surface distance to the scan (the most spheres among equals).
  std::string reference;
  /// Differences smaller than what a lab resolves do not count, however significant: a height
  /// or distance read to 0.5 mm (a ruler, a video frame), a slip angle to 0.2 deg (the
  /// study's angle meter).
  double length_tolerance = 0.5e-3;  ///< [m]
  double angle_tolerance = 0.2;      ///< [deg]
};

/// One clump's outcomes in one test on one surface.
struct OutcomeSample {
  std::size_t clump = 0;  ///< index in the clumps given
  LabTest test = LabTest::Drop;
  std::string surface;
  std::vector<double> values;  ///< per trial: rebound height [m], slip angle [deg], roll distance [m]
  double mean = 0.0, sd = 0.0;
  double ci_half_width = 0.0;      ///< of the mean, 95 % (Student t)
  double seconds_per_trial = 0.0;  ///< wall time of the DEM (with the rank's threads)
  double steps_per_trial = 0.0;    ///< time steps
};

/// A clump's sample against the reference's.
struct SampleComparison {
  std::size_t clump = 0;
  LabTest test = LabTest::Drop;
  std::string surface;
  double difference = 0.0;                     ///< mean minus the reference's mean
  double difference_ci = 0.0;                  ///< its 95 % half-width (Welch)
  double detectable = 0.0;                     ///< the difference these trials find with 80 % power
  double welch_p = 1.0, ks_p = 1.0;            ///< raw
  double welch_p_holm = 1.0, ks_p_holm = 1.0;  ///< adjusted within the clump's family
  double ks_statistic = 0.0;
  double quantile_shift = 0.0;  ///< the largest difference of the samples' deciles (10-90 %)
  /// A test rejects (adjusted p below the significance) on a difference above the tolerance:
  /// Welch on the means' difference, KS on the deciles' shift.
  bool distinguishable = false;
};

struct ClumpDemVerdict {
  std::size_t clump = 0;
  int spheres = 0;
  bool reference = false;
  bool distinguishable = false;    ///< any of its outcomes differs from the reference's
  double smallest_p = 1.0;         ///< its smallest adjusted p (1 for the reference)
  double seconds_per_trial = 0.0;  ///< mean over its tests and surfaces
};

struct DemStudyResult {
  std::size_t reference = 0;
  std::vector<OutcomeSample> samples;         ///< clump by clump, then surface, then test
  std::vector<SampleComparison> comparisons;  ///< every clump but the reference
  std::vector<ClumpDemVerdict> verdicts;      ///< one per clump, in the order given
  /// The fewest spheres among clumps that pass together with every finer clump of their
  /// method (the reference when none does).
  std::size_t coarsest = 0;
  /// The clump of the reference's method with the most spheres below the reference's: when
  /// nothing coarser passes, its differing outcomes are those that have not converged.
  std::optional<std::size_t> next_coarser;

  /// A sample's comparison with the reference's (none for the reference's own samples).
  const SampleComparison* comparison(const OutcomeSample& sample) const;
};

/// Runs the study on `clumps` (at least two, distinct names). Under a distributed team every
/// rank calls it alike and every rank gets the whole result.
Result<DemStudyResult> run_dem_study(std::span<const Clump> clumps, const DemStudyOptions& options,
                                     const RunContext& context = {}, const Team& team = Team());

}  // namespace clumpforge
