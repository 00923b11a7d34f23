// A population of three exported tubers inserted as a mixture by the real LIGGGHTS and YADE:
// every inserted particle carries its template's mass and principal moments (issue 13, item 3).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <map>
#include <sstream>

#include "io/clump_library.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {

struct Inserted {
  std::string template_name;  ///< as the engine names it (YADE) or "" (LIGGGHTS)
  double mass = 0.0;
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();
  double com_error = 0.0;
  int members = 0;
};

// "CF_BODY <name-or-id> mass i1 i2 i3 [com_error members]" lines.
std::vector<Inserted> parse_bodies(const std::string& output) {
  std::vector<Inserted> bodies;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("CF_BODY ", 0) != 0) continue;
    std::istringstream fields(line.substr(8));
    Inserted b;
    fields >> b.template_name >> b.mass >> b.moments.x() >> b.moments.y() >> b.moments.z();
    fields >> b.com_error >> b.members;
    bodies.push_back(b);
  }
  return bodies;
}

class Population : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    for (const char* tuber : {"tuber-01", "tuber-05", "tuber-10"}) {
      auto clumps = read_clump_library(test::source_dir() / "clumps" / (std::string(tuber) + ".h5"));
      ASSERT_TRUE(clumps);
      auto clump = select_clump(std::move(*clumps), "lattice-2mm", tuber);
      ASSERT_TRUE(clump);
      templates_[std::string(tuber) + "_lattice-2mm"] = *clump;
    }
  }
  static std::string export_population(const test::ScratchDir& dir, const std::string& format) {
    const auto lib = [](const char* t) { return (test::source_dir() / "clumps" / (std::string(t) + ".h5")).string(); };
    const auto run = test::run_clumpforge(
        fmt::format("export '{}' '{}' '{}' --clump lattice-2mm --format {} --fractions 0.5,0.3,0.2 "
                    "--fraction-of mass -o '{}'",
                    lib("tuber-01"), lib("tuber-05"), lib("tuber-10"), format, (dir / "population").string()));
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return (dir / "population").string();
  }
  // The template an inserted body is, by its mass; then its moments must be that template's.
  static std::string expect_a_template(const Inserted& body) {
    for (const auto& [name, c] : templates_) {
      if (std::abs(body.mass - c.mass) > 1e-6 * c.mass) continue;
      Eigen::Vector3d engine = body.moments;
      std::sort(engine.data(), engine.data() + 3);
      const Eigen::Vector3d truth = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(c.inertia).eigenvalues();
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(engine(k), truth(k), 1e-6 * truth(k)) << name << " moment " << k;
      return name;
    }
    ADD_FAILURE() << "an inserted body of mass " << body.mass << " kg is none of the templates";
    return "";
  }
  static std::map<std::string, Clump> templates_;
};
std::map<std::string, Clump> Population::templates_;
}  // namespace

TEST_F(Population, LiggghtsInsertsAMixtureWhoseEveryParticleIsItsTemplate) {
  test::ScratchDir dir("population-liggghts");
  const std::string folder = export_population(dir, "liggghts");
  const auto run =
      test::run_command(fmt::format("cd '{}' && liggghts -in '{}' -var nbodies 12", folder,
                                    (test::source_dir() / "tests/engines/data/mixture.liggghts").string()));
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const auto bodies = parse_bodies(run.out);
  ASSERT_EQ(bodies.size(), 12u) << run.out;
  std::map<std::string, int> seen;
  for (const auto& b : bodies) ++seen[expect_a_template(b)];
  EXPECT_EQ(seen.size(), 3u) << "every template of the mixture is inserted";
}

TEST_F(Population, YadeInsertsAMixtureWhoseEveryParticleIsItsTemplate) {
  test::ScratchDir dir("population-yade");
  const std::string folder = export_population(dir, "yade");
  const auto run = test::run_command(fmt::format("cd '{}' && yade -n -x '{}' population.py 12", folder,
                                                 (test::source_dir() / "tests/engines/data/mixture_yade.py").string()));
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const auto bodies = parse_bodies(run.out);
  ASSERT_EQ(bodies.size(), 12u) << run.out;
  std::map<std::string, int> seen;
  for (const auto& b : bodies) {
    const std::string name = expect_a_template(b);
    ++seen[name];
    // YADE names the template: its identifier (tuber_01_lattice_2mm for tuber-01_lattice-2mm).
    std::string id = name;
    for (char& c : id) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    EXPECT_EQ(b.template_name, id);
    EXPECT_LT(b.com_error, 1e-6) << "centre of mass not at the position asked for";
    if (!name.empty()) {
      EXPECT_EQ(b.members, static_cast<int>(templates_.at(name).spheres.size()));
    }
  }
  EXPECT_EQ(seen.size(), 3u) << "every template of the mixture is inserted";
}

}  // namespace clumpforge
