// Every export format read back: spheres, mass and inertia as written.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "io/exports.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {
Clump clump_for_export() {
  Clump c;
  c.name = "lattice-2mm";
  for (int i = 0; i < 5; ++i) c.spheres.push_back({{1e-3 * i / 3.0, -2e-3 + 1e-3 * i, 0.5e-3 * i / 7.0}, 1e-3 + 1e-6 * i});
  c.density = 1085.0;
  c.mass = 3.7143881418471576e-3;
  c.body_volume = c.mass / c.density;
  c.principal_moments = {1.0981826897242900e-7, 1.4064971395594700e-7, 1.8135121057762300e-7};
  c.inertia = c.principal_moments.asDiagonal();
  c.source_sha256 = "abc";
  return c;
}

// Numbers of each non-comment line, split on whitespace, commas and tabs.
std::vector<std::vector<double>> numeric_rows(const std::filesystem::path& path, char comment = '#') {
  std::vector<std::vector<double>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == comment) continue;
    for (char& ch : line) ch = (ch == ',' || ch == '\t') ? ' ' : ch;
    std::istringstream fields(line);
    std::vector<double> row;
    double value = 0.0;
    while (fields >> value) row.push_back(value);
    if (!row.empty() && fields.eof()) rows.push_back(row);
  }
  return rows;
}

void expect_spheres(const std::vector<std::vector<double>>& rows, const Clump& c, double scale, bool radius_first = false) {
  ASSERT_EQ(rows.size(), c.spheres.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& s = c.spheres[i];
    const std::array<double, 4> expected = radius_first ? std::array{s.radius, s.centre.x(), s.centre.y(), s.centre.z()}
                                                        : std::array{s.centre.x(), s.centre.y(), s.centre.z(), s.radius};
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(rows[i][k], expected[k] * scale, 1e-12 * scale) << "sphere " << i;  // 10 digits of mm-sized values
  }
}

double value_after(const std::string& text, const std::string& key) {
  std::smatch match;
  const std::regex pattern(key + "[ =:\"]*([-+0-9.eE]+)");
  EXPECT_TRUE(std::regex_search(text, match, pattern)) << key;
  return std::stod(match[1]);
}
}  // namespace

TEST(Exports, EveryFormatReadsBack) {
  test::ScratchDir dir("export");
  const Clump c = clump_for_export();
  auto write = [&](ExportFormat f, const std::string& name) {
    auto r = export_clump(c, f, dir / name);
    EXPECT_TRUE(r) << r.error().message;
    return r ? r->files : std::vector<std::filesystem::path>{};
  };
  const auto liggghts = write(ExportFormat::Liggghts, "t.multisphere");
  expect_spheres(numeric_rows(liggghts[0]), c, 1.0);
  const std::string fix = test::read_text(liggghts[1]);
  EXPECT_NE(fix.find("nspheres 5"), std::string::npos);
  EXPECT_NE(fix.find("spheres file t.multisphere scale 1.0"), std::string::npos);
  EXPECT_DOUBLE_EQ(value_after(fix, "mass"), c.mass);
  EXPECT_DOUBLE_EQ(value_after(fix, "inertia_tensor"), c.inertia(0, 0));

  const auto yade = write(ExportFormat::Yade, "t.txt");
  auto yade_rows = numeric_rows(yade[0]);
  for (auto& row : yade_rows) {
    EXPECT_EQ(row.size(), 5u);
    EXPECT_EQ(row.back(), 0.0);  // clump id
  }
  expect_spheres(yade_rows, c, 1.0);
  EXPECT_EQ(test::read_text(yade[0]).find("\n\n"), std::string::npos);  // a blank line crashes textClumps
  EXPECT_DOUBLE_EQ(value_after(test::read_text(yade[1]), "CF_MASS"), c.mass);

  const auto edem = write(ExportFormat::Edem, "t.tsv");
  auto edem_rows = numeric_rows(edem[0], 'X');
  for (auto& row : edem_rows) row.pop_back();  // contact radius = physical radius
  for (std::size_t i = 0; i < edem_rows.size(); ++i) {
    for (int k = 0; k < 4; ++k) {
      const double expected = (k < 3 ? c.spheres[i].centre[k] : c.spheres[i].radius) * 1e3;
      EXPECT_NEAR(edem_rows[i][k], expected, 1e-8);
    }
  }
  EXPECT_DOUBLE_EQ(value_after(test::read_text(edem[1]), "mass_kg"), c.mass);

  const auto pfc = write(ExportFormat::Pfc, "t.p3dat");
  const std::string pfc_text = test::read_text(pfc[0]);
  EXPECT_NE(pfc_text.find("pebbles 5"), std::string::npos);
  EXPECT_DOUBLE_EQ(value_after(pfc_text, "volume"), c.body_volume);
  EXPECT_NEAR(value_after(pfc_text, "inertia"), c.inertia(0, 0) / c.density, 1e-20);

  const auto mercury = write(ExportFormat::MercuryDpm, "mercury");
  expect_spheres(numeric_rows(mercury[0]), c, 1.0);
  EXPECT_DOUBLE_EQ(numeric_rows(mercury[1])[0][0], c.mass);
  EXPECT_EQ(numeric_rows(mercury[2]).size(), 3u);

  const auto chrono = write(ExportFormat::Chrono, "t.csv");
  expect_spheres(numeric_rows(chrono[0], 'x'), c, 1.0);
  EXPECT_DOUBLE_EQ(value_after(test::read_text(chrono[1]), "mass_kg"), c.mass);

  const auto vtk = write(ExportFormat::Vtk, "t.vtp");
  const std::string vtp = test::read_text(vtk[0]);
  EXPECT_NE(vtp.find("NumberOfPoints=\"5\""), std::string::npos);
  EXPECT_NE(vtp.find("Name=\"radius\""), std::string::npos);

  const auto csv = write(ExportFormat::Csv, "plain.csv");
  expect_spheres(numeric_rows(csv[0], 'x'), c, 1.0);
}

TEST(Exports, UnknownFormatGetsASuggestion) {
  const auto bad = parse_export_format("liggghs");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("did you mean 'liggghts'"), std::string::npos);
  for (auto f : {ExportFormat::Liggghts, ExportFormat::Yade, ExportFormat::Csv}) EXPECT_EQ(*parse_export_format(to_string(f)), f);
}

TEST(Exports, NothingIsWrittenWhenAnyFileCannotBe) {
  test::ScratchDir dir("export");
  EXPECT_FALSE(export_clump(clump_for_export(), ExportFormat::Liggghts, dir / "missing" / "t.multisphere"));
  EXPECT_EQ(test::count_files(dir.path()), 0);
}

}  // namespace clumpforge
