#pragma once
/// Turning a broken scan into a closed, outward, 2-manifold triangle mesh without
/// self-intersections.
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/run_context.hpp"
#include "mesh/topology.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

struct RepairOptions {
  /// A component whose area is below this fraction of the largest component's is debris, [0, 1).
  double debris_area_fraction = 0.02;
  /// Refuse when hole patches would make up more than this fraction of the closed
  /// surface: the scan then saw too little of the body to close it credibly, (0, 1].
  double max_patch_area_fraction = 0.3;
  /// Rounds of "remove the intersecting faces and a growing ring around them, refill", >= 0.
  int self_intersection_rounds = 5;
  /// Refine and fair hole patches (curved patches); false gives flat minimal patches.
  bool fair_holes = true;
};

/// What one repair step changed, as named counts (and areas in m^2).
struct RepairStep {
  std::string name;
  std::vector<std::pair<std::string, double>> changes;
};

struct RepairResult {
  TriangleSoup soup;               ///< the repaired body [m]
  MeshStats after;                 ///< its statistics (self-intersections counted: 0)
  std::vector<RepairStep> steps;   ///< in the order they ran
  std::vector<Diagnostic> notes;
};

/// The steps, in this fixed order: duplicate and degenerate faces; unused vertices;
/// non-manifold edges and vertices; debris; consistent outward orientation; holes;
/// self-intersections. Fails with the name of the step that could not reach its goal,
/// or when the result is not a closed 2-manifold without self-intersections.
Result<RepairResult> repair_mesh(TriangleSoup soup, const RepairOptions& options = {}, const RunContext& context = {});

/// Topology statistics plus the self-intersection count: the `before`/`after` report.
MeshStats analyze_mesh(const TriangleSoup& soup);

}  // namespace clumpforge
