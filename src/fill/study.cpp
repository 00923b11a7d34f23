#include "fill/study.hpp"

#include <fmt/format.h>

#include <chrono>

namespace clumpforge {

Result<std::vector<StudyRow>> run_resolution_study(const PreparedBody& body, const StudyOptions& options,
                                                   const RunContext& context) {
  std::vector<StudyRow> rows;
  std::vector<FillOptions> runs;
  for (double d : options.lattice_diameters) runs.push_back({.method = FillMethod::Lattice, .diameter = d});
  for (int n : options.adaptive_budgets) runs.push_back({.method = FillMethod::Adaptive, .max_spheres = n});
  for (std::size_t i = 0; i < runs.size(); ++i) {
    context.report("resolution study", static_cast<double>(i) / static_cast<double>(runs.size()));
    const auto started = std::chrono::steady_clock::now();
    auto filled = fill_body(body, runs[i]);
    if (!filled) return std::unexpected(filled.error());
    StudyRow row;
    row.method = runs[i].method;
    row.parameter = row.method == FillMethod::Lattice ? runs[i].diameter : runs[i].max_spheres;
    row.name = row.method == FillMethod::Lattice ? fmt::format("lattice-{:g}mm", runs[i].diameter * 1e3)
                                                 : fmt::format("adaptive-{}", runs[i].max_spheres);
    row.clump = std::move(filled->clump);
    row.fill_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    rows.push_back(std::move(row));
    if (context.should_stop()) return fail(ErrorCode::Cancelled, "study cancelled");
  }
  context.report("resolution study", 1.0);
  return rows;
}

}  // namespace clumpforge
