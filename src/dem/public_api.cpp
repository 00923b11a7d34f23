// The installed interface of the dem module (<clumpforge/dem.hpp>) over the library's own.
#include <cmath>

#include "clumpforge/dem.hpp"
#include "core/public_types.hpp"
#include "dem/lab.hpp"
#include "dem/materials.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {

Result<LabOutcome> run_lab_test(const SphereClump& clump, const LabRequest& request, const RunContext& context) {
  auto internal = to_clump(clump);
  if (!internal) return std::unexpected(internal.error());
  if (request.trials < 1 || request.trials > 100000)
    return fail(ErrorCode::InvalidArgument, "trials must be between 1 and 100000");
  Recording setup;
  setup.test = request.test;
  setup.surface = request.surface;
  setup.release_height = request.release_height;
  setup.incline_deg = request.incline_deg;
  setup.start_distance = request.start_distance;
  if (auto ok = check_lab_setup(setup); !ok) return std::unexpected(ok.error());
  LabOptions options;
  options.trials = request.trials;
  options.seed = request.seed;
  auto run = run_lab_test(*internal, default_material_table(), setup, options, context);
  if (!run) return std::unexpected(run.error());
  LabOutcome out{.quantity = std::string(summary_key(request.test)), .values = run->recording.summaries()};
  const SampleSpread spread = sample_spread(out.values);
  out.mean = spread.mean;
  out.standard_deviation = spread.sd;
  return out;
}

}  // namespace clumpforge
