// Every export format read back: spheres, mass and inertia as written.
#include <dirent.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>

#include "io/exports.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {
Clump clump_for_export() {
  Clump c;
  c.name = "lattice-2mm";
  // A cross about the centre of mass, radii a little different (YADE's weighting can centre it).
  const std::array<Eigen::Vector3d, 5> centres{
      Eigen::Vector3d{0, 0, 0}, {2e-3, 0, 0}, {-2e-3, 0, 0}, {0, 3e-3, 0}, {0, -3e-3, 0}};
  for (int i = 0; i < 5; ++i) c.spheres.push_back({centres[static_cast<std::size_t>(i)], 1e-3 + 1e-5 * i});
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

void expect_spheres(const std::vector<std::vector<double>>& rows, const Clump& c, double scale,
                    bool radius_first = false) {
  ASSERT_EQ(rows.size(), c.spheres.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& s = c.spheres[i];
    const std::array<double, 4> expected = radius_first
                                               ? std::array{s.radius, s.centre.x(), s.centre.y(), s.centre.z()}
                                               : std::array{s.centre.x(), s.centre.y(), s.centre.z(), s.radius};
    for (int k = 0; k < 4; ++k)
      EXPECT_NEAR(rows[i][k], expected[k] * scale, 1e-12 * scale) << "sphere " << i;  // 10 digits of mm-sized values
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

  const auto chrono = write(ExportFormat::Chrono, "t.csv");
  expect_spheres(numeric_rows(chrono[0], 'x'), c, 1.0);
  EXPECT_DOUBLE_EQ(value_after(test::read_text(chrono[1]), "mass_kg"), c.mass);
  EXPECT_DOUBLE_EQ(value_after(test::read_text(chrono[1]), "volume_m3"), c.body_volume);  // for SetVolume

  const auto vtk = write(ExportFormat::Vtk, "t.vtp");
  const std::string vtp = test::read_text(vtk[0]);
  EXPECT_NE(vtp.find("NumberOfPoints=\"5\""), std::string::npos);
  EXPECT_NE(vtp.find("Name=\"radius\""), std::string::npos);

  const auto csv = write(ExportFormat::Csv, "plain.csv");
  expect_spheres(numeric_rows(csv[0], 'x'), c, 1.0);
}

// MercuryDPM's reader (Drivers/Clump/ClumpHeaders/ClumpInput.h), parsing as it parses: the
// clump names are the sub-folders of the Clumps folder, sorted, the first two ("." and "..")
// dropped; every number through std::stof; pebbles "x,y,z,r" per line of
// <Name>/Clump/Clump.txt; the mass the first token of <Name>/Inertia/Mass.txt; TOI and PD
// three comma-separated values per line.
struct MercuryClump {
  std::string name;
  std::vector<std::array<double, 4>> pebbles;
  double mass = 0.0;
  std::vector<double> toi, pd;
};
std::vector<std::string> comma_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  for (std::string field; std::getline(in, field, ',');) fields.push_back(field);
  return fields;
}
std::vector<double> mercury_rows_of_three(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::in | std::ios::binary);
  std::vector<double> values;
  for (std::string line; std::getline(in, line);) {
    const auto fields = comma_fields(line);
    for (int k = 0; k < 3; ++k) values.push_back(std::stof(fields.at(static_cast<std::size_t>(k))));
  }
  return values;
}
std::vector<MercuryClump> read_as_mercurydpm(const std::filesystem::path& clumps_dir) {
  std::vector<std::string> names;
  DIR* dir = opendir(clumps_dir.c_str());
  while (dirent* entry = readdir(dir)) {
    if (entry->d_type == DT_DIR) names.emplace_back(entry->d_name);
  }
  closedir(dir);
  std::sort(names.begin(), names.end());
  names.erase(names.begin(), names.begin() + 2);
  std::vector<MercuryClump> clumps;
  for (const auto& name : names) {
    MercuryClump c{name, {}, 0.0, {}, {}};
    const std::filesystem::path root = clumps_dir / name;
    std::ifstream pebbles(root / "Clump" / "Clump.txt", std::ios::in | std::ios::binary);
    for (std::string line; std::getline(pebbles, line);) {
      const auto f = comma_fields(line);
      c.pebbles.push_back({std::stof(f.at(0)), std::stof(f.at(1)), std::stof(f.at(2)), std::stof(f.at(3))});
    }
    std::ifstream mass(root / "Inertia" / "Mass.txt", std::ios::in | std::ios::binary);
    std::string token;
    mass >> token;
    c.mass = std::stof(token);
    c.toi = mercury_rows_of_three(root / "Inertia" / "TOI.txt");
    c.pd = mercury_rows_of_three(root / "Inertia" / "PD.txt");
    clumps.push_back(c);
  }
  return clumps;
}

TEST(Exports, MercuryDpmReadsTheCurrentLayoutAsItsReaderParsesIt) {
  test::ScratchDir dir("export-mercury");
  const Clump c = clump_for_export();
  const auto clumps_dir = dir / "Clumps";
  ASSERT_TRUE(export_clump(c, ExportOptions{.format = ExportFormat::MercuryDpm}, clumps_dir));
  const auto read = read_as_mercurydpm(clumps_dir);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].name, "lattice_2mm");
  ASSERT_EQ(read[0].pebbles.size(), c.spheres.size());
  for (std::size_t i = 0; i < c.spheres.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(read[0].pebbles[i][static_cast<std::size_t>(k)], c.spheres[i].centre[k], 1e-9);
    EXPECT_NEAR(read[0].pebbles[i][3], c.spheres[i].radius, 1e-6 * c.spheres[i].radius);
  }
  EXPECT_NEAR(read[0].mass, c.mass, 1e-6 * c.mass);  // float, as the reader keeps it
  ASSERT_EQ(read[0].toi.size(), 9u);
  ASSERT_EQ(read[0].pd.size(), 9u);
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(read[0].toi[static_cast<std::size_t>(3 * r + k)], c.inertia(r, k), 1e-6 * c.inertia.norm());
      EXPECT_EQ(read[0].pd[static_cast<std::size_t>(3 * r + k)], r == k ? 1.0 : 0.0);
    }
  }
  // The old lower-case layout only on request; the current reader finds nothing in it.
  const auto legacy_dir = dir / "Legacy";
  ASSERT_TRUE(export_clump(
      c, ExportOptions{.format = ExportFormat::MercuryDpm, .mercury_layout = MercuryLayout::Legacy}, legacy_dir));
  EXPECT_TRUE(std::filesystem::exists(legacy_dir / "lattice_2mm" / "clump" / "clump.txt"));
  EXPECT_TRUE(std::filesystem::exists(legacy_dir / "lattice_2mm" / "inertia" / "toi.txt"));
  EXPECT_FALSE(std::filesystem::exists(legacy_dir / "lattice_2mm" / "Clump" / "Clump.txt"));
}

TEST(Exports, ChronoCsvReadsByItsHeaderNames) {
  // DEMClumpTemplate::ReadComponentFromFile: a CSV read by the column names x, y, z, r.
  test::ScratchDir dir("export-chrono");
  const Clump c = clump_for_export();
  const auto files = export_clump(c, ExportFormat::Chrono, dir / "t.csv");
  ASSERT_TRUE(files);
  std::ifstream in(files->files[0]);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(comma_fields(header), (std::vector<std::string>{"x", "y", "z", "r"}));
  std::size_t rows = 0;
  for (std::string line; std::getline(in, line); ++rows) {
    const auto f = comma_fields(line);
    ASSERT_EQ(f.size(), 4u);
    EXPECT_NEAR(std::stof(f[3]), c.spheres.at(rows).radius, 1e-6 * c.spheres.at(rows).radius);
  }
  EXPECT_EQ(rows, c.spheres.size());
}

TEST(Exports, APopulationHasEveryClumpsFilesAndItsFractionsInEveryFormat) {
  const Clump a = clump_for_export();
  Clump b = clump_for_export();
  b.name = "other-2mm";
  b.mass *= 3.0;
  for (auto format : {ExportFormat::Liggghts, ExportFormat::Yade, ExportFormat::Edem, ExportFormat::Pfc,
                      ExportFormat::MercuryDpm, ExportFormat::Chrono, ExportFormat::Vtk, ExportFormat::Csv}) {
    test::ScratchDir dir("population");
    const auto out = dir / "mix";
    const auto written =
        export_population({a, b}, {.format = format, .fractions = {1.0, 1.0}, .basis = FractionBasis::Number}, out);
    ASSERT_TRUE(written) << to_string(format) << ": " << written.error().message;
    // Equal numbers, the second three times as heavy: mass fractions 1/4 and 3/4.
    EXPECT_NEAR(written->number_fractions[0], 0.5, 1e-15);
    EXPECT_NEAR(written->mass_fractions[0], 0.25, 1e-15);
    EXPECT_NEAR(written->mass_fractions[1], 0.75, 1e-15);
    const std::string csv = test::read_text(out / "population.csv");
    EXPECT_NE(csv.find("lattice-2mm,lattice_2mm,"), std::string::npos) << csv;
    EXPECT_NE(csv.find("other-2mm,other_2mm,"), std::string::npos) << csv;
    EXPECT_GE(written->files.size(), 3u) << to_string(format);
    for (const auto& f : written->files) EXPECT_TRUE(std::filesystem::exists(f)) << f;
    if (format == ExportFormat::MercuryDpm) {
      EXPECT_EQ(read_as_mercurydpm(out).size(), 2u);
    }
    if (format == ExportFormat::Liggghts) {
      const std::string in = test::read_text(out / "population.in");
      EXPECT_NE(in.find("particletemplate/multisphere 15485867 atom_type 1"), std::string::npos) << in;
      EXPECT_NE(in.find("particletemplate/multisphere 15485917 atom_type 1"), std::string::npos) << in;
      EXPECT_NE(in.find("type 2 mass"), std::string::npos);
      EXPECT_NE(in.find("particledistribution/discrete/numberbased 15485927 2 pts_lattice_2mm 0.5 pts_other_2mm 0.5"),
                std::string::npos)
          << in;
    }
  }
}

TEST(Exports, APopulationTableReadsBackWithCommasAndQuotesInItsNames) {
  test::ScratchDir dir("population-names");
  Clump a = clump_for_export();
  a.name = "tuber, left";
  Clump b = clump_for_export();
  b.name = "tuber \"right\"";
  const auto out = dir / "mix";
  ASSERT_TRUE(export_population({a, b}, {.format = ExportFormat::Csv}, out));
  // Python's csv module, as a user reads it: every row as wide as the header, the names whole.
  const auto read =
      test::run_command(fmt::format("python3 -c \"import csv, sys; rows = list(csv.reader(open(sys.argv[1]))); "
                                    "print(len(set(map(len, rows))), rows[1][0], '|', rows[2][0])\" '{}'",
                                    (out / "population.csv").string()));
  ASSERT_EQ(read.exit_code, 0) << read.err;
  EXPECT_EQ(read.out, "1 tuber, left | tuber \"right\"\n");
}

TEST(Exports, APopulationRefusesClashingNamesAndWrongFractionsAndWritesNothing) {
  test::ScratchDir dir("population");
  const Clump a = clump_for_export();
  const auto same = export_population({a, a}, {.format = ExportFormat::Csv}, dir / "mix");
  ASSERT_FALSE(same);
  EXPECT_EQ(same.error().code, ErrorCode::InvalidArgument);
  Clump b = a;
  b.name = "b";
  EXPECT_FALSE(export_population({a, b}, {.format = ExportFormat::Csv, .fractions = {1.0}}, dir / "mix"));
  EXPECT_FALSE(export_population({a, b}, {.format = ExportFormat::Csv, .fractions = {1.0, -2.0}}, dir / "mix"));
  EXPECT_FALSE(export_population({a}, {.format = ExportFormat::Csv}, dir / "mix"));
  EXPECT_EQ(test::count_files(dir.path()), 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "mix"));
}

TEST(Exports, UnknownFormatGetsASuggestion) {
  const auto bad = parse_export_format("liggghs");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("did you mean 'liggghts'"), std::string::npos);
  for (auto f : {ExportFormat::Liggghts, ExportFormat::Yade, ExportFormat::Csv})
    EXPECT_EQ(*parse_export_format(to_string(f)), f);
}

TEST(Exports, NamesReachTheEnginesScriptsAsNamesNeverAsCommands) {
  test::ScratchDir dir("export-names");
  Clump c = clump_for_export();
  // A library may hold any name: a newline once ended the comment, and "--" an XML comment.
  c.name = "tuber--> \nshell touch pwned";
  ASSERT_TRUE(export_clump(c, ExportFormat::Liggghts, dir / "t.multisphere"));
  ASSERT_TRUE(export_clump(c, ExportFormat::Yade, dir / "it's.txt"));
  ASSERT_TRUE(export_clump(c, ExportFormat::Vtk, dir / "t.vtp"));
  for (const char* file : {"t.multisphere", "t.multisphere.in", "it's.txt", "it's.py"}) {
    std::ifstream in(dir / file);
    ASSERT_TRUE(in) << file;
    std::string line;
    while (std::getline(in, line)) EXPECT_NE(line.rfind("shell", 0), 0u) << file << ": " << line;
  }
  std::ifstream script(dir / "it's.py");
  const std::string text((std::istreambuf_iterator<char>(script)), {});
  EXPECT_NE(text.find("os.getcwd(), 'it\\'s.txt')"), std::string::npos) << text;
  // Python parses the script (YADE runs it in tests/engines).
  const auto parsed = test::run_command(
      fmt::format("python3 -c \"import ast, glob; [ast.parse(open(p).read()) for p in glob.glob('{}/*.py')]\"",
                  dir.path().string()));
  EXPECT_EQ(parsed.exit_code, 0) << parsed.err;
  const auto xml = test::run_command(
      fmt::format("python3 -c \"import xml.etree.ElementTree as E; E.parse('{}')\"", (dir / "t.vtp").string()));
  EXPECT_EQ(xml.exit_code, 0) << xml.err;
}

TEST(Exports, AFileNameLiggghtsCannotReadIsRefusedWritingNothing) {
  test::ScratchDir dir("export-names");
  for (const char* name : {"a b.multisphere", "a#b.multisphere", "a$b.multisphere", "a\"b.multisphere"}) {
    const auto refused = export_clump(clump_for_export(), ExportFormat::Liggghts, dir / name);
    ASSERT_FALSE(refused) << name;
    EXPECT_EQ(refused.error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(refused.error().message.find("LIGGGHTS cannot read the file name"), std::string::npos)
        << refused.error().message;
  }
  const auto not_utf8 = export_clump(clump_for_export(), ExportFormat::Yade, dir / "a\xff.txt");
  ASSERT_FALSE(not_utf8);
  EXPECT_NE(not_utf8.error().message.find("not UTF-8"), std::string::npos) << not_utf8.error().message;
  EXPECT_EQ(test::count_files(dir.path()), 0);
}

TEST(Exports, NothingIsWrittenWhenAnyFileCannotBe) {
  test::ScratchDir dir("export");
  EXPECT_FALSE(export_clump(clump_for_export(), ExportFormat::Liggghts, dir / "missing" / "t.multisphere"));
  EXPECT_EQ(test::count_files(dir.path()), 0);
}

}  // namespace clumpforge
