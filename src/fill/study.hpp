#pragma once
/// The resolution trade-off: spheres against error against fill time.
#include <string>
#include <vector>

#include "fill/fill.hpp"

namespace clumpforge {

struct StudyOptions {
  std::vector<double> lattice_diameters{1e-3, 2e-3, 4e-3};             ///< [m]
  std::vector<int> adaptive_budgets{16, 32, 64, 128, 256, 512, 1024};  ///< sphere counts
};

struct StudyRow {
  std::string name;  ///< "lattice-2mm", "adaptive-128"
  FillMethod method = FillMethod::Lattice;
  double parameter = 0.0;     ///< diameter [m] or budget
  Clump clump;                ///< the fill, with its error report (`clump.error`)
  double fill_seconds = 0.0;  ///< wall time of the fill and its error report
};

/// Fills `body` with every lattice diameter and adaptive budget (in that order).
Result<std::vector<StudyRow>> run_resolution_study(const PreparedBody& body, const StudyOptions& options,
                                                   const RunContext& context = {});

}  // namespace clumpforge
