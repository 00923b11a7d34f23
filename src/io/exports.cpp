#include "io/exports.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>

#include "core/atomic_file.hpp"
#include "core/text.hpp"
#include "core/version.hpp"
#include "io/centring_weights.hpp"
#include "io/export_detail.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

namespace {
constexpr std::array<std::pair<std::string_view, ExportFormat>, 8> kFormats{{{"liggghts", ExportFormat::Liggghts},
                                                                             {"yade", ExportFormat::Yade},
                                                                             {"edem", ExportFormat::Edem},
                                                                             {"pfc", ExportFormat::Pfc},
                                                                             {"mercurydpm", ExportFormat::MercuryDpm},
                                                                             {"chrono", ExportFormat::Chrono},
                                                                             {"vtk", ExportFormat::Vtk},
                                                                             {"csv", ExportFormat::Csv}}};
}  // namespace

namespace export_detail {

// Scalars (mass, inertia, volume) keep every bit; sphere coordinates keep 10 digits,
// a tenth of a nanometre on a 10 mm particle, and half the file size.
std::string number(double value) {
  return fmt::format("{:.17g}", value);
}
std::string coordinate(double value) {
  return fmt::format("{:.10g}", value);
}

std::string identifier(const std::string& name) {
  std::string id;
  for (char c : name) id += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  if (id.empty() || std::isdigit(static_cast<unsigned char>(id[0]))) id = "clump_" + id;
  return id;
}

fs::path sibling(const fs::path& output, const std::string& suffix) {
  return output.parent_path() / (output.stem().string() + suffix);
}

std::string provenance(const Clump& c) {
  return one_line_text(fmt::format(
      "clumpforge {} clump '{}' ({} method, {} spheres); source mesh sha256 {}; frame: principal axes, "
      "centre of mass at the origin; SI units",
      kVersion, c.name, to_string(c.method), c.spheres.size(), c.source_sha256.empty() ? "unknown" : c.source_sha256));
}

// A Python literal of `text` (UTF-8): quotes and backslashes escaped, control characters as \xNN.
std::string python_string(std::string_view text) {
  std::string out = "'";
  for (char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\\' || c == '\'')
      out += fmt::format("\\{}", c);
    else if (byte < 0x20 || byte == 0x7F)
      out += fmt::format("\\x{:02X}", byte);
    else
      out += c;
  }
  return out + "'";
}

std::string liggghts_fix(const Clump& c, const std::string& sphere_file, const LiggghtsTemplate& ids) {
  const Eigen::Matrix3d& I = c.inertia;
  return fmt::format(
      "fix pts_{} all particletemplate/multisphere {} atom_type {} density constant {} nspheres {} ntry 1000000 "
      "spheres file {} scale 1.0 type {} mass {} inertia_tensor {} {} {} {} {} {} use_density\n",
      identifier(c.name), ids.seed, ids.atom_type, number(c.density), c.spheres.size(), sphere_file, ids.type,
      number(c.mass), number(I(0, 0)), number(I(0, 1)), number(I(0, 2)), number(I(1, 1)), number(I(1, 2)),
      number(I(2, 2)));
}

Files liggghts(const Clump& c, const fs::path& output, const LiggghtsTemplate& ids) {
  // LIGGGHTS-PUBLIC fix particletemplate/multisphere: one "x y z r" line per sphere, '#'
  // comments allowed, as many lines as nspheres; `scale` is mandatory after `file`.
  std::string spheres = "# " + provenance(c) + "\n";
  for (const auto& s : c.spheres)
    spheres += fmt::format("{} {} {} {}\n", coordinate(s.centre.x()), coordinate(s.centre.y()),
                           coordinate(s.centre.z()), coordinate(s.radius));
  std::string snippet = fmt::format(
      "# {}\n"
      "# The body's true mass and inertia tensor (about the centre of mass, in the file's frame) override\n"
      "# LIGGGHTS' Monte-Carlo estimate; with use_density the volume is mass / density and the spheres are\n"
      "# taken as already centred on the centre of mass, as they are.\n",
      provenance(c));
  snippet += liggghts_fix(c, output.filename().string(), ids);
  return {{output, spheres}, {fs::path(output.string() + ".in"), snippet}};
}

Result<Files> yade(const Clump& c, const fs::path& output) {
  // YADE ymport.textClumps format: whitespace-separated "x y z r clumpId", '#' lines
  // skipped, no blank lines (they crash the reader).
  std::string text = "#format x_y_z_r_clumpId\n# " + provenance(c) + "\n";
  for (const auto& s : c.spheres)
    text += fmt::format("{} {} {} {} 0\n", coordinate(s.centre.x()), coordinate(s.centre.y()), coordinate(s.centre.z()),
                        coordinate(s.radius));
  // YADE's Clump::updateProperties puts the clump's reference point at its members' volume
  // centroid (overlaps counted twice) and its axes along their principal axes: the members
  // are clumped with radii whose volumes put both on the body's, then given their own.
  auto weights = centring_weights(c.spheres, c.inertia);
  if (!weights) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("yade export of clump '{}': {}", c.name, weights.error().message));
  }
  std::string radii;
  for (std::size_t i = 0; i < c.spheres.size(); ++i) {
    const double own = 4.0 / 3.0 * std::numbers::pi * std::pow(c.spheres[i].radius, 3);
    radii += fmt::format("{}{}", i % 4 == 0 ? "\n    " : " ",
                         number(c.spheres[i].radius * std::cbrt(weights->volumes[i] / own)) + ",");
  }
  const Eigen::Matrix3d& I = c.inertia;
  std::string script = fmt::format(
      "# {}\n"
      "# Builds the clump in YADE with the body's centre of mass, principal axes, mass and inertia. In a YADE script:\n"
      "#   exec(open({}).read()); clump_id = add_clump(material=my_material, position=Vector3(0, 0, 0.1))\n"
      "# `position` is where the body's centre of mass goes; `orientation` (a Quaternion) turns the file's frame.\n"
      "# YADE places a clump at its members' volume centroid (overlaps counted twice) with axes along their\n"
      "# principal axes. The members are therefore clumped with the weighting radii below, whose volumes put\n"
      "# that centroid on the body's centre of mass and those axes on the body's principal axes (computed by\n"
      "# clumpforge: centroid within 1e-9 m, axes within 1e-6 deg), and then given their true radii and\n"
      "# masses; the clump's mass and inertia are set to the body's.\n"
      "import os\n"
      "from math import pi\n"
      "from yade import utils\n"
      "from yade.minieigenHP import Vector3, Matrix3, Quaternion\n"
      "CF_SPHERES_FILE = os.path.join(os.path.dirname(os.path.abspath(globals().get('__file__', {}))), {})\n"
      "CF_MASS = {}  # kg\n"
      "CF_INERTIA = Matrix3({}, {}, {},\n                     {}, {}, {},\n                     {}, {}, {})  # kg m^2, "
      "file frame, about the centre of mass\n"
      "CF_DENSITY = {}  # kg/m^3\n"
      "CF_WEIGHTING_RADII = [{}\n]  # m, one per sphere in file order\n"
      "\n"
      "def add_clump(material=None, position=Vector3(0, 0, 0), orientation=None, spheres_file=None):\n"
      "    # orientation: a Quaternion turning the file's frame into the world's (None: the file's).\n"
      "    kw = {{}} if material is None else {{'material': material}}\n"
      "    path = spheres_file or CF_SPHERES_FILE\n"
      "    if not os.path.exists(path):\n"
      "        path = os.path.join(os.getcwd(), {})\n"
      "    rows = [line.split() for line in open(path) if line.strip() and not line.startswith('#')]\n"
      "    if len(rows) != len(CF_WEIGHTING_RADII):\n"
      "        raise ValueError('%s has %d spheres, this script expects %d' % (path, len(rows), "
      "len(CF_WEIGHTING_RADII)))\n"
      "    turn = Matrix3.Identity if orientation is None else orientation.toRotationMatrix()\n"
      "    centres = [turn * Vector3(float(r[0]), float(r[1]), float(r[2])) for r in rows]\n"
      "    members = [utils.sphere(position + x, w, **kw) for x, w in zip(centres, CF_WEIGHTING_RADII)]\n"
      "    clump_id, member_ids = O.bodies.appendClumped(members)\n"
      "    for member_id, row in zip(member_ids, rows):\n"
      "        member = O.bodies[member_id]\n"
      "        radius = float(row[3])\n"
      "        member.shape.radius = radius\n"
      "        member.state.mass = member.material.density * 4.0 / 3.0 * pi * radius ** 3\n"
      "        member.state.inertia = Vector3(1, 1, 1) * 0.4 * member.state.mass * radius ** 2\n"
      "    state = O.bodies[clump_id].state\n"
      "    rotation = state.ori.toRotationMatrix()\n"
      "    local = rotation.transpose() * (turn * CF_INERTIA * turn.transpose()) * rotation\n"
      "    state.mass = CF_MASS\n"
      "    state.inertia = Vector3(local[0, 0], local[1, 1], local[2, 2])\n"
      "    return clump_id\n",
      provenance(c), python_string(sibling(output, ".py").filename().string()),
      python_string(sibling(output, ".py").filename().string()), python_string(output.filename().string()),
      number(c.mass), number(I(0, 0)), number(I(0, 1)), number(I(0, 2)), number(I(1, 0)), number(I(1, 1)),
      number(I(1, 2)), number(I(2, 0)), number(I(2, 1)), number(I(2, 2)), number(c.density), radii,
      python_string(output.filename().string()));
  return Files{{output, text}, {sibling(output, ".py"), script}};
}

Files edem(const Clump& c, const fs::path& output) {
  // EDEM Creator, multi-sphere particle: a sphere table to paste (position and physical /
  // contact radius, mm, centred on the centre of mass and aligned to the principal axes).
  std::string table = "X (mm)\tY (mm)\tZ (mm)\tPhysical Radius (mm)\tContact Radius (mm)\n";
  for (const auto& s : c.spheres) {
    table += fmt::format("{:.9g}\t{:.9g}\t{:.9g}\t{:.9g}\t{:.9g}\n", s.centre.x() * 1e3, s.centre.y() * 1e3,
                         s.centre.z() * 1e3, s.radius * 1e3, s.radius * 1e3);
  }
  const Eigen::Vector3d m = c.inertia.diagonal();  // about x, y, z of the table
  std::string summary = fmt::format(
      "{}\n\nEnter these in EDEM's particle properties (override 'Calculate Properties'):\n"
      "mass_kg = {}\nvolume_m3 = {}\nvolume_mm3 = {}\ndensity_kg_m3 = {}\n"
      "moment_of_inertia_kg_m2 = {} {} {}\nmoment_of_inertia_kg_mm2 = {} {} {}\n"
      "The spheres are centred on the centre of mass and aligned with the principal axes (x, y, z above).\n",
      provenance(c), number(c.mass), number(c.body_volume), number(c.body_volume * 1e9), number(c.density),
      number(m.x()), number(m.y()), number(m.z()), number(m.x() * 1e6), number(m.y() * 1e6), number(m.z() * 1e6));
  return {{output, table}, {sibling(output, "-properties.txt"), summary}};
}

Files pfc(const Clump& c, const fs::path& output) {
  // Itasca PFC 3D `clump template create`: pebbles given as radius and position; templates
  // have unit density, so the inertia given is the tensor divided by the density.
  std::string text = "; " + provenance(c) + "\n";
  text +=
      fmt::format("clump template create name '{}' ...\n    pebbles {} ...\n", identifier(c.name), c.spheres.size());
  for (const auto& s : c.spheres) {
    text += fmt::format("        {} {} {} {} ...\n", coordinate(s.radius), coordinate(s.centre.x()),
                        coordinate(s.centre.y()), coordinate(s.centre.z()));
  }
  const Eigen::Matrix3d unit = c.inertia / c.density;
  text +=
      fmt::format("    volume {} ...\n    inertia {} {} {} {} {} {}\n", number(c.body_volume), number(unit(0, 0)),
                  number(unit(1, 1)), number(unit(2, 2)), number(unit(0, 1)), number(unit(0, 2)), number(unit(1, 2)));
  return {{output, text}};
}

// The layout's folder and file names, from the reader: today's MercuryDPM
// (Drivers/Clump/ClumpHeaders/ClumpInput.h) or the old MultiParticle driver (clump/ClumpIO.h).
struct MercuryNames {
  const char* clump_dir;
  const char* pebbles;
  const char* inertia_dir;
  const char* mass;
  const char* toi;
  const char* pd;
};
MercuryNames mercury_names(MercuryLayout layout) {
  if (layout == MercuryLayout::Legacy) return {"clump", "clump.txt", "inertia", "mass.txt", "toi.txt", "pd.txt"};
  return {"Clump", "Clump.txt", "Inertia", "Mass.txt", "TOI.txt", "PD.txt"};
}

Files mercurydpm(const Clump& c, const fs::path& output, MercuryLayout layout) {
  // <name>/Clump/Clump.txt "x,y,z,r" lines; <name>/Inertia/Mass.txt, TOI.txt (3 rows of 3),
  // PD.txt (principal directions, 3 rows). The reader parses every number with std::stof.
  const MercuryNames names = mercury_names(layout);
  const fs::path root = output / identifier(c.name);
  std::string pebbles;
  for (const auto& s : c.spheres)
    pebbles += fmt::format("{},{},{},{}\n", coordinate(s.centre.x()), coordinate(s.centre.y()),
                           coordinate(s.centre.z()), coordinate(s.radius));
  std::string toi;
  for (int r = 0; r < 3; ++r)
    toi += fmt::format("{},{},{}\n", number(c.inertia(r, 0)), number(c.inertia(r, 1)), number(c.inertia(r, 2)));
  return {{root / names.clump_dir / names.pebbles, pebbles},
          {root / names.inertia_dir / names.mass, number(c.mass) + "\n"},
          {root / names.inertia_dir / names.toi, toi},
          {root / names.inertia_dir / names.pd, "1,0,0\n0,1,0\n0,0,1\n"}};
}

Files chrono(const Clump& c, const fs::path& output) {
  // Chrono DEM-Engine: LoadClumpType(mass, moi, "clump.csv", material) reads the CSV by its
  // header names x, y, z, r (DEMClumpTemplate::ReadComponentFromFile); moi is in the file's
  // (principal) frame; the template's volume is not derived from the spheres but set with
  // SetVolume (DEMClumpTemplate::volume), here the body's.
  std::string csv = "x,y,z,r\n";
  for (const auto& s : c.spheres)
    csv += fmt::format("{},{},{},{}\n", coordinate(s.centre.x()), coordinate(s.centre.y()), coordinate(s.centre.z()),
                       coordinate(s.radius));
  const Eigen::Vector3d m = c.inertia.diagonal();
  std::string props = fmt::format(
      "{{\n  \"comment\": \"{}\",\n  \"clump_file\": \"{}\",\n  \"mass_kg\": {},\n  \"moi_kg_m2\": [{}, {}, {}],\n"
      "  \"volume_m3\": {},\n"
      "  \"usage\": \"auto t = DEMSim.LoadClumpType(mass_kg, make_float3(moi_kg_m2...), clump_file, material); "
      "t->SetVolume(volume_m3);\"\n}}\n",
      provenance(c), output.filename().string(), number(c.mass), number(m.x()), number(m.y()), number(m.z()),
      number(c.body_volume));
  return {{output, csv}, {sibling(output, "-properties.json"), props}};
}

// `text` inside an XML comment, which may not hold "--".
std::string xml_comment(std::string text) {
  for (std::size_t at = text.find("--"); at != std::string::npos; at = text.find("--", at)) text.insert(at + 1, " ");
  return text;
}

Files vtk(const Clump& c, const fs::path& output) {
  // VTK XML PolyData: one vertex per sphere centre with "radius" point data; in ParaView
  // apply Glyph (sphere, scale by radius, factor 2 for diameter-sized glyphs).
  std::string points, radii, offsets, connectivity;
  for (std::size_t i = 0; i < c.spheres.size(); ++i) {
    const auto& s = c.spheres[i];
    points += fmt::format("{} {} {}\n", coordinate(s.centre.x()), coordinate(s.centre.y()), coordinate(s.centre.z()));
    radii += coordinate(s.radius) + "\n";
    connectivity += fmt::format("{}\n", i);
    offsets += fmt::format("{}\n", i + 1);
  }
  std::string text = fmt::format(
      "<?xml version=\"1.0\"?>\n<!-- {} -->\n"
      "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n"
      "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
      "NumberOfPolys=\"0\">\n"
      "      <PointData Scalars=\"radius\">\n        <DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n{} "
      "       </DataArray>\n"
      "      </PointData>\n      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" "
      "format=\"ascii\">\n{}        </DataArray>\n"
      "      </Points>\n      <Verts>\n        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n{}   "
      "     </DataArray>\n"
      "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n{}        </DataArray>\n      </Verts>\n"
      "    </Piece>\n  </PolyData>\n</VTKFile>\n",
      xml_comment(provenance(c)), c.spheres.size(), c.spheres.size(), radii, points, connectivity, offsets);
  return {{output, text}};
}

Files csv(const Clump& c, const fs::path& output) {
  std::string text = "x_m,y_m,z_m,r_m\n";
  for (const auto& s : c.spheres)
    text += fmt::format("{},{},{},{}\n", coordinate(s.centre.x()), coordinate(s.centre.y()), coordinate(s.centre.z()),
                        coordinate(s.radius));
  return {{output, text}};
}
}  // namespace export_detail

Result<ExportFormat> parse_export_format(std::string_view name) {
  for (const auto& [key, format] : kFormats) {
    if (key == name) return format;
  }
  return fail(
      ErrorCode::InvalidArgument,
      fmt::format("unknown export format '{}'{} (liggghts, yade, edem, pfc, mercurydpm, chrono, vtk, csv)", name,
                  did_you_mean(name, {"liggghts", "yade", "edem", "pfc", "mercurydpm", "chrono", "vtk", "csv"})));
}

std::string_view to_string(ExportFormat format) {
  for (const auto& [key, value] : kFormats) {
    if (value == format) return key;
  }
  return "unknown";
}

Result<ExportResult> export_clump(const Clump& clump, ExportFormat format, const fs::path& output) {
  return export_clump(clump, ExportOptions{.format = format}, output);
}

namespace {
// The primary file's name as the engine's script reads it back: LIGGGHTS takes the `spheres
// file` argument up to the first blank, and reads `#` as a comment, `$` as a substitution and
// quotes as the argument's bounds; YADE's script is UTF-8 Python source holding it as a literal.
Result<void> check_name_in_script(ExportFormat format, const fs::path& output) {
  const std::string name = output.filename().string();
  if (format == ExportFormat::Liggghts) {
    const bool readable = std::none_of(name.begin(), name.end(), [](char c) {
      const auto byte = static_cast<unsigned char>(c);
      return byte <= 0x20 || byte == 0x7F || c == '#' || c == '$' || c == '"' || c == '\'';
    });
    if (!readable) {
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("liggghts export: LIGGGHTS cannot read the file name '{}' in its script (it ends a "
                              "word at a blank and reads #, $ and quotes as commands): give one without them",
                              name));
    }
  }
  if (format == ExportFormat::Yade && !is_valid_utf8(name)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("yade export: the file name '{}' is not UTF-8 text, and YADE's script must name it", name));
  }
  return {};
}
}  // namespace

namespace export_detail {
Result<Files> format_files(const Clump& clump, const ExportOptions& options, const fs::path& output) {
  const ExportFormat format = options.format;
  if (clump.spheres.empty() || !(clump.mass > 0.0) || !(clump.density > 0.0)) {
    return fail(ErrorCode::InvalidArgument, fmt::format("clump '{}' has no spheres or no mass", clump.name));
  }
  if (auto ok = check_name_in_script(format, output); !ok) return std::unexpected(ok.error());
  Files files;
  switch (format) {
    case ExportFormat::Liggghts:
      files = liggghts(clump, output, {});
      break;
    case ExportFormat::Yade: {
      auto built = yade(clump, output);
      if (!built) return std::unexpected(built.error());
      files = std::move(*built);
      break;
    }
    case ExportFormat::Edem:
      files = edem(clump, output);
      break;
    case ExportFormat::Pfc:
      files = pfc(clump, output);
      break;
    case ExportFormat::MercuryDpm: {
      std::error_code ec;
      if (fs::exists(output, ec) && !fs::is_directory(output, ec)) {
        return fail(ErrorCode::InvalidArgument,
                    fmt::format("mercurydpm export: '{}' must be a directory", output.string()));
      }
      const fs::path root = output / identifier(clump.name);
      const MercuryNames names = mercury_names(options.mercury_layout);
      for (const char* sub : {names.clump_dir, names.inertia_dir}) fs::create_directories(root / sub, ec);
      if (ec) return fail(ErrorCode::IoError, fmt::format("cannot create '{}'", root.string()));
      files = mercurydpm(clump, output, options.mercury_layout);
      break;
    }
    case ExportFormat::Chrono:
      files = chrono(clump, output);
      break;
    case ExportFormat::Vtk:
      files = vtk(clump, output);
      break;
    case ExportFormat::Csv:
      files = csv(clump, output);
      break;
  }
  // A companion named like the primary (`X.yade.py` given for YADE, whose companion is the
  // `.py` of the primary's stem) would overwrite it.
  for (std::size_t i = 1; i < files.size(); ++i) {
    if (files[i].first.lexically_normal() == files[0].first.lexically_normal())
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("{} export: '{}' would be both the primary file and its companion; give the primary "
                              "another extension (e.g. '{}')",
                              to_string(format), output.string(), sibling(output, ".txt").string()));
  }
  return files;
}
}  // namespace export_detail

Result<ExportResult> export_clump(const Clump& clump, const ExportOptions& options, const fs::path& output) {
  auto files = export_detail::format_files(clump, options, output);
  if (!files) return std::unexpected(files.error());
  if (auto ok = write_files_atomically(*files); !ok) return std::unexpected(ok.error());
  ExportResult result;
  for (const auto& [path, content] : *files) result.files.push_back(path);
  return result;
}

}  // namespace clumpforge
