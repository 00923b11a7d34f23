#include "sdf/signed_distance.hpp"

#include <fmt/format.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>

#include <limits>
#include <mutex>

namespace clumpforge {

struct SignedDistance::Impl {
  openvdb::FloatGrid::Ptr grid;
  double voxel_size = 0.0;
};

SignedDistance::SignedDistance() = default;
SignedDistance::~SignedDistance() = default;
SignedDistance::SignedDistance(const SignedDistance&) = default;
SignedDistance& SignedDistance::operator=(const SignedDistance&) = default;
SignedDistance::SignedDistance(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

double SignedDistance::voxel_size() const { return impl_ ? impl_->voxel_size : 0.0; }
std::size_t SignedDistance::active_voxels() const { return impl_ ? impl_->grid->activeVoxelCount() : 0; }

double SignedDistance::distance(const Eigen::Vector3d& p) const {
  openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
      impl_->grid->getConstAccessor(), impl_->grid->transform());
  return sampler.wsSample(openvdb::Vec3d(p.x(), p.y(), p.z()));
}

void SignedDistance::distances(std::span<const Eigen::Vector3d> points, std::span<double> out) const {
  openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
      impl_->grid->getConstAccessor(), impl_->grid->transform());
  for (std::size_t i = 0; i < points.size(); ++i) {
    out[i] = sampler.wsSample(openvdb::Vec3d(points[i].x(), points[i].y(), points[i].z()));
  }
}

double resolve_voxel_size(const SdfOptions& options) {
  return options.voxel_size > 0.0 ? options.voxel_size : options.feature_size / options.voxels_per_feature;
}

namespace {
// Bridges OpenVDB's interrupter to the run context (progress and cancellation).
class ContextInterrupter : public openvdb::util::NullInterrupter {
 public:
  explicit ContextInterrupter(const RunContext& context) : context_(context) {}
  bool wasInterrupted(int percent = -1) override {
    if (percent >= 0) context_.report("signed distance", percent / 100.0);
    return context_.should_stop();
  }

 private:
  const RunContext& context_;
};

void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}
}  // namespace

Result<SignedDistance> compute_signed_distance(const TriangleSoup& body, const SdfOptions& options,
                                               const RunContext& context) {
  if (body.faces.empty()) return fail(ErrorCode::InvalidMesh, "signed distance: the body has no faces");
  const double voxel = resolve_voxel_size(options);
  if (!(voxel > 0.0) || !std::isfinite(voxel) || !(options.exterior_band_voxels >= 1.0)) {
    return fail(ErrorCode::InvalidArgument, fmt::format("signed distance: voxel size {} m is not positive", voxel));
  }
  const Eigen::Vector3d size = bounding_box(body).size() / voxel;
  if ((size.array() + 2.0).prod() > 1e9) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("signed distance: voxel size {:.3g} m would need {:.3g} voxels for this body; choose a "
                            "larger voxel",
                            voxel, (size.array() + 2.0).prod()));
  }
  initialize_openvdb();
  std::vector<openvdb::Vec3s> points;
  points.reserve(body.points.size());
  for (const auto& p : body.points) points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(body.faces.size());
  for (const auto& f : body.faces) triangles.emplace_back(f[0], f[1], f[2]);
  const std::vector<openvdb::Vec4I> quads;
  auto transform = openvdb::math::Transform::createLinearTransform(voxel);
  ContextInterrupter interrupter(context);
  openvdb::FloatGrid::Ptr grid;
  try {
    grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
        interrupter, *transform, points, triangles, quads, static_cast<float>(options.exterior_band_voxels),
        std::numeric_limits<float>::max());
  } catch (const std::exception& e) {
    return fail(ErrorCode::InvalidMesh, fmt::format("signed distance: OpenVDB failed: {}", e.what()));
  }
  if (context.should_stop()) return fail(ErrorCode::Cancelled, "signed distance cancelled");
  auto impl = std::make_shared<SignedDistance::Impl>();
  impl->grid = grid;
  impl->voxel_size = voxel;
  return SignedDistance(std::move(impl));
}

}  // namespace clumpforge
