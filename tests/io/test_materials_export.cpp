// Calibrated materials in an engine's syntax, and stored calibrations read back.
#include <gtest/gtest.h>

#include "io/materials_export.hpp"
#include "io/materials_io.hpp"
#include "support/test_support.hpp"

namespace clumpforge {

TEST(MaterialsExport, LiggghtsHasEveryMaterialAndPairInAtomTypeOrder) {
  const auto text = export_materials(default_material_table(), {.format = ExportFormat::Liggghts});
  ASSERT_TRUE(text) << text.error().message;
  EXPECT_NE(
      text->find("variable cf_type_tuber equal 1\nvariable cf_type_Q235 equal 2\nvariable cf_type_soil equal 3\n"),
      std::string::npos);
  EXPECT_NE(text->find("youngsModulus peratomtype 5000000 206000000000 10000000\n"), std::string::npos) << *text;
  // 3 x 3 restitution matrix, row tuber: tuber-tuber 0.5, tuber-Q235 0.728, tuber-soil 0.44.
  EXPECT_NE(text->find("coefficientRestitution peratomtypepair 3 0.5 0.72799999999999998 0.44 0.72799999999999998"),
            std::string::npos)
      << *text;
  EXPECT_NE(text->find("lever arm R = contact point to the clump's centre of mass"), std::string::npos);
}

TEST(MaterialsExport, LiggghtsRollingFrictionScaledByTheClumpsLeverRatioWhenGiven) {
  const auto plain = export_materials(default_material_table(), {.format = ExportFormat::Liggghts});
  MaterialsExportOptions scaled{.format = ExportFormat::Liggghts};
  scaled.rolling_lever_ratio = 2.0;
  scaled.clump = "c";
  const auto text = export_materials(default_material_table(), scaled);
  ASSERT_TRUE(plain && text);
  EXPECT_NE(plain->find("coefficientRollingFriction peratomtypepair 3 0.02 0.02 0.033000000000000002"),
            std::string::npos)
      << *plain;
  EXPECT_NE(text->find("coefficientRollingFriction peratomtypepair 3 0.040000000000000001 0.040000000000000001 "
                       "0.066000000000000003"),
            std::string::npos)
      << *text;
  // Under LIGGGHTS' own conventions the coefficients carry over unchanged.
  MaterialsExportOptions liggghts{.format = ExportFormat::Liggghts,
                                  .contact = contact_settings(ContactConventions::Liggghts)};
  liggghts.rolling_lever_ratio = 2.0;
  const auto same = export_materials(default_material_table(), liggghts);
  ASSERT_TRUE(same);
  EXPECT_NE(same->find("coefficientRollingFriction peratomtypepair 3 0.02 0.02 0.033000000000000002"),
            std::string::npos);
}

TEST(MaterialsExport, LeverRatioOfASingleSphereIsOne) {
  Clump sphere;
  sphere.spheres = {{Eigen::Vector3d::Zero(), 5e-3}};
  EXPECT_NEAR(rolling_lever_ratio(sphere, 100), 1.0, 1e-12);
}

TEST(MaterialsExport, UnknownMaterialOrFormatIsRefused) {
  MaterialsExportOptions options{.format = ExportFormat::Liggghts};
  options.surfaces = {"marble"};
  EXPECT_FALSE(export_materials(default_material_table(), options));
  const auto vtk = export_materials(default_material_table(), {.format = ExportFormat::Vtk});
  ASSERT_FALSE(vtk);
  EXPECT_EQ(vtk.error().code, ErrorCode::InvalidArgument);
}

TEST(MaterialsExport, StoredCalibrationsOfBothMethodsAreApplied) {
  test::ScratchDir dir("calibration");
  test::write_text(dir / "joint.json",
                   R"({"method": "joint", "conventions": "liggghts", "surfaces": [{"surface": "Q235",
    "restitution": {"value": 0.6}, "static_friction": {"value": 0.3}, "rolling_friction": {"value": 0.01}}]})");
  test::write_text(dir / "paper.json",
                   R"({"method": "paper", "results": {"soil": {"restitution": 0.4, "static_friction": 0.7,
    "rolling_friction": 0.05}}})");
  const auto joint = apply_calibration(dir / "joint.json", default_material_table());
  ASSERT_TRUE(joint) << joint.error().message;
  EXPECT_EQ(joint->conventions, ContactConventions::Liggghts);
  EXPECT_DOUBLE_EQ(joint->table.interaction("tuber", "Q235")->restitution, 0.6);
  EXPECT_DOUBLE_EQ(joint->table.interaction("tuber", "soil")->restitution, 0.44);  // untouched
  const auto paper = apply_calibration(dir / "paper.json", default_material_table());
  ASSERT_TRUE(paper) << paper.error().message;
  EXPECT_EQ(paper->conventions, ContactConventions::Edem);  // none stated: clumpforge's default
  EXPECT_DOUBLE_EQ(paper->table.interaction("tuber", "soil")->rolling_friction, 0.05);
}

TEST(MaterialsExport, ANameTheEnginesScriptsCannotHoldIsRefusedInAFileAndInATable) {
  // A name goes verbatim into a LIGGGHTS variable, a YADE label and an EDEM field: a blank
  // split LIGGGHTS' command, and a quote ran the rest of the name as Python.
  test::ScratchDir dir("material-names");
  const std::vector<std::string> bad{
      R"({"materials": [{"name": "Q235 steel", "youngs_modulus_pa": 2e11, "poisson_ratio": 0.3, "density_kg_m3": 7850}]})",
      R"({"materials": [{"name": "", "youngs_modulus_pa": 2e11, "poisson_ratio": 0.3, "density_kg_m3": 7850}]})",
      R"({"interactions": [{"a": "tuber", "b": "steel2", "restitution": 0.5, "static_friction": 0.5, "rolling_friction": 0}]})"};
  for (std::size_t k = 0; k < bad.size(); ++k) {
    const auto path = dir / ("bad" + std::to_string(k) + ".json");
    test::write_text(path, bad[k]);
    const auto r = read_materials(path);
    ASSERT_FALSE(r) << bad[k];
    EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(r.error().message.find(path.string()), std::string::npos) << r.error().message;
  }
  MaterialTable table = default_material_table();
  table.materials.push_back({"x']); import os #", 2e11, 0.3, 7850, "built in C++"});
  for (auto format : {ExportFormat::Liggghts, ExportFormat::Yade, ExportFormat::Edem}) {
    const auto refused = export_materials(table, {.format = format});
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("material name"), std::string::npos) << refused.error().message;
  }
  EXPECT_FALSE(materials_json(table));
  MaterialTable raw = default_material_table();
  raw.materials.front().source = "\xff\xfe";  // JSON text cannot hold it
  const auto not_utf8 = materials_json(raw);
  ASSERT_FALSE(not_utf8);
  EXPECT_NE(not_utf8.error().message.find("not UTF-8"), std::string::npos);
  EXPECT_TRUE(materials_json(default_material_table()));
}

TEST(MaterialsExport, TheProvenanceStaysInItsCommentLine) {
  MaterialsExportOptions options{.format = ExportFormat::Liggghts};
  options.provenance = "materials file a\nshell touch pwned\n.json";  // a Linux path may hold newlines
  for (auto format : {ExportFormat::Liggghts, ExportFormat::Yade, ExportFormat::Edem}) {
    options.format = format;
    const auto text = export_materials(default_material_table(), options);
    ASSERT_TRUE(text) << text.error().message;
    EXPECT_NE(text->find("materials file a\\x0Ashell touch pwned\\x0A.json"), std::string::npos) << *text;
    EXPECT_EQ(text->find("\nshell"), std::string::npos) << *text;
  }
}

TEST(MaterialsExport, MalformedCalibrationsAreRefusedNamingTheFile) {
  test::ScratchDir dir("calibration");
  const std::vector<std::string> bad{
      "{",
      "[]",
      R"({"method": "joint"})",
      R"({"method": "joint", "surfaces": [{"surface": "marble",
    "restitution": 0.5, "static_friction": 0.5, "rolling_friction": 0.0}]})",
      R"({"method": "paper", "results": {"Q235": {"restitution": 1.5, "static_friction": 0.5, "rolling_friction": 0}}})",
      R"({"method": "paper", "conventions": "pfc", "results": {"Q235": {"restitution": 0.5, "static_friction": 0.5, "rolling_friction": 0}}})"};
  for (std::size_t k = 0; k < bad.size(); ++k) {
    const auto path = dir / ("bad" + std::to_string(k) + ".json");
    test::write_text(path, bad[k]);
    const auto r = apply_calibration(path, default_material_table());
    ASSERT_FALSE(r) << bad[k];
    EXPECT_NE(r.error().message.find(path.string()), std::string::npos) << r.error().message;
  }
}

}  // namespace clumpforge
