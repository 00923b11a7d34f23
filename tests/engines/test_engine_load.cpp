// Every export right for every clump, as the engines themselves report it after loading:
// the real LIGGGHTS and YADE load bundled lattice and adaptive clumps of three tubers, and
// the body each engine holds is compared with clumpforge's report (issue 13, item 1):
// mass and principal moments to 1e-6 relative, the centre of mass to 1 um, the principal
// axes to 0.01 deg, every sphere where the clump has it (1 nm) with its radius.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cctype>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "io/clump_library.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {

struct Bundled {
  std::string tuber;
  std::string clump;
};
void PrintTo(const Bundled& b, std::ostream* os) {
  *os << b.tuber << " " << b.clump;
}

// What an engine reports of the body it built.
struct EngineBody {
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();  ///< about the engine's body axes
  Eigen::Matrix3d axes = Eigen::Matrix3d::Zero();     ///< columns: the body axes in the world
  std::vector<Sphere> members;                        ///< world positions
};

std::vector<double> numbers_after(const std::string& line) {
  std::istringstream fields(line);
  std::string key;
  fields >> key;
  std::vector<double> values;
  for (double v = 0.0; fields >> v;) values.push_back(v);
  return values;
}

// Reads the "CF_KEY v..." lines; CF_MEMBER lines (x y z r) accumulate.
EngineBody parse_report(const std::string& output) {
  EngineBody body;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    const auto v = numbers_after(line);
    if (line.rfind("CF_MASS ", 0) == 0 && v.size() == 1) body.mass = v[0];
    if (line.rfind("CF_POS ", 0) == 0 && v.size() == 3) body.com = {v[0], v[1], v[2]};
    if (line.rfind("CF_INERTIA ", 0) == 0 && v.size() == 3) body.moments = {v[0], v[1], v[2]};
    if (line.rfind("CF_AXES ", 0) == 0 && v.size() == 9) {
      for (int k = 0; k < 9; ++k) body.axes(k % 3, k / 3) = v[static_cast<std::size_t>(k)];
    }
    if (line.rfind("CF_MEMBER ", 0) == 0 && v.size() == 4) body.members.push_back({{v[0], v[1], v[2]}, v[3]});
  }
  return body;
}

// A LIGGGHTS custom dump's last snapshot ("id x y z radius" rows, sorted by id).
std::vector<Sphere> read_dump(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<Sphere> atoms;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      atoms.clear();
      continue;
    }
    std::istringstream fields(line);
    double id = 0.0, x = 0.0, y = 0.0, z = 0.0, r = 0.0;
    if (line.rfind("ITEM", 0) != 0 && (fields >> id >> x >> y >> z >> r)) atoms.push_back({{x, y, z}, r});
  }
  return atoms;
}

class EngineLoad : public ::testing::TestWithParam<Bundled> {
 protected:
  void SetUp() override {
    library_ = test::source_dir() / "clumps" / (GetParam().tuber + ".h5");
    auto clumps = read_clump_library(library_);
    ASSERT_TRUE(clumps) << clumps.error().message;
    for (auto& c : *clumps) {
      if (c.name == GetParam().clump) clump_ = c;
    }
    ASSERT_EQ(clump_.name, GetParam().clump);
    dir_ = std::make_unique<test::ScratchDir>("engine-load-" + GetParam().tuber + "-" + GetParam().clump);
  }
  std::string export_to(const std::string& format, const std::string& name) const {
    const auto run = test::run_clumpforge(fmt::format("export '{}' --clump {} --format {} -o '{}'", library_.string(),
                                                      clump_.name, format, (*dir_ / name).string()));
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return (*dir_ / name).string();
  }

  // The comparison both engines must pass (both insert the clump in the file's orientation).
  void expect_body(const EngineBody& body) const {
    ASSERT_EQ(body.members.size(), clump_.spheres.size());
    EXPECT_NEAR(body.mass, clump_.mass, 1e-6 * clump_.mass);
    // The members say where the body is: its spheres' file centres plus the origin.
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < clump_.spheres.size(); ++i) origin += body.members[i].centre - clump_.spheres[i].centre;
    origin /= static_cast<double>(clump_.spheres.size());
    double worst_member = 0.0, worst_radius = 0.0;
    for (std::size_t i = 0; i < clump_.spheres.size(); ++i) {
      worst_member = std::max(worst_member, (body.members[i].centre - origin - clump_.spheres[i].centre).norm());
      worst_radius = std::max(worst_radius, std::abs(body.members[i].radius - clump_.spheres[i].radius));
    }
    EXPECT_LT(worst_member, 1e-9) << "a sphere is not where the clump has it";
    EXPECT_LT(worst_radius, 1e-12);
    EXPECT_LT((body.com - origin).norm(), 1e-6)
        << "the engine's centre of mass is " << (body.com - origin).norm() * 1e6 << " um from the body's";
    // Principal axes and moments: each of clumpforge's axes against the engine's nearest.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> truth(clump_.inertia);
    for (int k = 0; k < 3; ++k) {
      int best = 0;
      for (int j = 1; j < 3; ++j) {
        if (std::abs(body.axes.col(j).dot(truth.eigenvectors().col(k))) >
            std::abs(body.axes.col(best).dot(truth.eigenvectors().col(k))))
          best = j;
      }
      const double cosine = std::min(1.0, std::abs(body.axes.col(best).normalized().dot(truth.eigenvectors().col(k))));
      EXPECT_LT(std::acos(cosine) * 180.0 / std::numbers::pi, 0.01) << "axis " << k;
      EXPECT_NEAR(body.moments(best), truth.eigenvalues()(k), 1e-6 * truth.eigenvalues()(k)) << "moment " << k;
    }
  }

  std::filesystem::path library_;
  Clump clump_;
  std::unique_ptr<test::ScratchDir> dir_;
};

TEST_P(EngineLoad, LiggghtsHoldsTheBodyClumpforgeReports) {
  export_to("liggghts", "clump.multisphere");
  std::string fix_id = "pts_" + clump_.name;  // the export's identifier: non-alphanumerics become '_'
  for (char& c : fix_id) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  const auto run = test::run_command(
      fmt::format("cd '{}' && liggghts -in '{}' -var template clump.multisphere.in -var fixid {} -var dump atoms.txt",
                  dir_->path().string(), (test::source_dir() / "tests/engines/data/load.liggghts").string(), fix_id));
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  EngineBody body = parse_report(run.out);
  body.members = read_dump(*dir_ / "atoms.txt");
  expect_body(body);
}

TEST_P(EngineLoad, YadeHoldsTheBodyClumpforgeReports) {
  export_to("yade", "clump.txt");
  const auto run =
      test::run_command(fmt::format("cd '{}' && yade -n -x '{}' clump.py 0.01 -0.02 0.03", dir_->path().string(),
                                    (test::source_dir() / "tests/engines/data/load_yade.py").string()));
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const EngineBody body = parse_report(run.out);
  expect_body(body);
  EXPECT_LT((body.com - Eigen::Vector3d(0.01, -0.02, 0.03)).norm(), 1e-6)
      << "add_clump's position is the centre of mass";
}

INSTANTIATE_TEST_SUITE_P(BundledTubers, EngineLoad,
                         ::testing::Values(Bundled{"tuber-default", "lattice-2mm"},
                                           Bundled{"tuber-default", "adaptive-340"},
                                           Bundled{"tuber-05", "adaptive-514"}, Bundled{"tuber-05", "lattice-2mm"},
                                           Bundled{"tuber-10", "lattice-2mm"}, Bundled{"tuber-10", "adaptive-272"}),
                         [](const auto& info) {
                           std::string name = info.param.tuber + "_" + info.param.clump;
                           for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

}  // namespace
}  // namespace clumpforge
