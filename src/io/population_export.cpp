#include <fmt/format.h>

#include <cmath>
#include <numeric>
#include <set>

#include "core/atomic_file.hpp"
#include "core/text.hpp"
#include "io/export_detail.hpp"
#include "io/exports.hpp"

namespace clumpforge {
namespace fs = std::filesystem;
using export_detail::Files;
using export_detail::identifier;
using export_detail::number;

namespace {
// LIGGGHTS wants every random seed of a simulation a distinct prime above 10000.
std::uint64_t next_prime(std::uint64_t n) {
  for (++n;; ++n) {
    bool prime = n > 1;
    for (std::uint64_t d = 2; d * d <= n && prime; ++d) prime = n % d != 0;
    if (prime) return n;
  }
}

// The primary file name of one clump inside a population folder.
fs::path member_file(ExportFormat format, const std::string& id) {
  switch (format) {
    case ExportFormat::Liggghts:
      return id + ".multisphere";
    case ExportFormat::Yade:
      return id + ".txt";
    case ExportFormat::Edem:
      return id + ".tsv";
    case ExportFormat::Pfc:
      return id + ".p3dat";
    case ExportFormat::MercuryDpm:
      return "";
    case ExportFormat::Chrono:
      return id + ".csv";
    case ExportFormat::Vtk:
      return id + ".vtp";
    case ExportFormat::Csv:
      return id + ".csv";
  }
  return id;
}

Result<std::pair<std::vector<double>, std::vector<double>>> fractions(const std::vector<Clump>& clumps,
                                                                      const PopulationOptions& options) {
  std::vector<double> given = options.fractions.empty() ? std::vector<double>(clumps.size(), 1.0) : options.fractions;
  if (given.size() != clumps.size()) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{} fractions for {} clumps: give one per clump", given.size(), clumps.size()));
  }
  for (double f : given) {
    if (!(f > 0.0) || !std::isfinite(f)) {
      return fail(ErrorCode::InvalidArgument, fmt::format("fraction {} is not a positive number", f));
    }
  }
  // number fraction n_k and mass fraction m_k = n_k M_k / sum n_j M_j.
  std::vector<double> by_number(clumps.size()), by_mass(clumps.size());
  for (std::size_t k = 0; k < clumps.size(); ++k) {
    by_number[k] = options.basis == FractionBasis::Number ? given[k] : given[k] / clumps[k].mass;
    by_mass[k] = options.basis == FractionBasis::Mass ? given[k] : given[k] * clumps[k].mass;
  }
  for (auto* v : {&by_number, &by_mass}) {
    const double total = std::accumulate(v->begin(), v->end(), 0.0);
    for (double& f : *v) f /= total;
  }
  return std::pair{by_number, by_mass};
}

std::string liggghts_population(const std::vector<Clump>& clumps, const std::vector<double>& shares,
                                FractionBasis basis) {
  std::string text = fmt::format(
      "# clumpforge population of {} clumps: one template per clump (distinct prime seeds, body types 1..{}, atom type "
      "1),\n# and the distribution `pdd` to insert them as a mixture by {} fraction, e.g.\n"
      "#   include population.in\n"
      "#   fix ins all insert/pack seed <a prime not used here> distributiontemplate pdd ...\n"
      "# Each template's mass and inertia tensor are the body's (see each clump's file header).\n",
      clumps.size(), clumps.size(), basis == FractionBasis::Number ? "number" : "mass");
  std::uint64_t seed = 15485863;
  for (std::size_t k = 0; k < clumps.size(); ++k) {
    seed = next_prime(seed);
    const std::string id = identifier(clumps[k].name);
    text += export_detail::liggghts_fix(clumps[k], id + ".multisphere",
                                        {.seed = seed, .type = static_cast<int>(k) + 1, .atom_type = 1});
  }
  text += fmt::format("fix pdd all particledistribution/discrete/{} {} {}",
                      basis == FractionBasis::Number ? "numberbased" : "massbased", next_prime(seed), clumps.size());
  for (std::size_t k = 0; k < clumps.size(); ++k)
    text += fmt::format(" pts_{} {}", identifier(clumps[k].name), number(shares[k]));
  return text + "\n";
}
}  // namespace

namespace {
std::string python_list(const std::vector<std::string>& items) {
  std::string out = "[";
  for (std::size_t k = 0; k < items.size(); ++k) out += (k ? ", " : "") + items[k];
  return out + "]";
}

std::string yade_population(const std::vector<Clump>& clumps, const std::vector<double>& by_number,
                            const std::vector<double>& by_mass) {
  std::vector<std::string> names, numbers, masses, kg;
  for (std::size_t k = 0; k < clumps.size(); ++k) {
    names.push_back("'" + identifier(clumps[k].name) + "'");
    numbers.push_back(number(by_number[k]));
    masses.push_back(number(by_mass[k]));
    kg.push_back(number(clumps[k].mass));
  }
  return fmt::format(
      "# clumpforge population of {} clumps for YADE: one template script per clump (<name>.py, defining\n"
      "# add_clump), and add_mixture to insert them as a mixture by number fraction. In a YADE script:\n"
      "#   exec(open('population.py').read())\n"
      "#   placed = add_mixture([Vector3(x, y, z), ...], material=my_material, seed=1)  # [(clump_id, template), ...]\n"
      "# Every clump is built by its template's add_clump: the body's mass, centre of mass at the position,\n"
      "# principal axes and moments (see its header).\n"
      "import os\n"
      "import random\n"
      "from math import cos, pi, sin, sqrt\n"
      "from yade.minieigenHP import Quaternion, Vector3\n"
      "CF_POPULATION_DIR = os.path.dirname(os.path.abspath(globals().get('__file__', 'population.py')))\n"
      "CF_TEMPLATES = {}\n"
      "CF_NUMBER_FRACTIONS = {}\n"
      "CF_MASS_FRACTIONS = {}\n"
      "CF_MASSES = {}  # kg\n"
      "\n"
      "def _load_template(name):\n"
      "    path = os.path.join(CF_POPULATION_DIR, name + '.py')\n"
      "    if not os.path.exists(path):\n"
      "        path = os.path.join(os.getcwd(), name + '.py')\n"
      "    namespace = {{'__file__': path}}\n"
      "    exec(open(path).read(), namespace)\n"
      "    return namespace['add_clump']\n"
      "\n"
      "CF_ADD_CLUMP = [_load_template(name) for name in CF_TEMPLATES]\n"
      "\n"
      "def random_orientation(rng):\n"
      "    # uniform over rotations (Shoemake's subgroup algorithm)\n"
      "    u1, u2, u3 = rng.random(), rng.random(), rng.random()\n"
      "    a, b = sqrt(1 - u1), sqrt(u1)\n"
      "    return Quaternion(b * cos(2 * pi * u3), a * sin(2 * pi * u2), a * cos(2 * pi * u2), b * sin(2 * pi * u3))\n"
      "\n"
      "def add_mixture(positions, material=None, seed=1, orientation='random'):\n"
      "    # One clump at each position (its centre of mass), the template drawn by number fraction from a\n"
      "    # seeded generator; orientation 'random' (uniform) or 'template' (the files' frame).\n"
      "    rng = random.Random(seed)\n"
      "    placed = []\n"
      "    for position in positions:\n"
      "        k = rng.choices(range(len(CF_TEMPLATES)), weights=CF_NUMBER_FRACTIONS)[0]\n"
      "        turn = random_orientation(rng) if orientation == 'random' else None\n"
      "        placed.append((CF_ADD_CLUMP[k](material=material, position=position, orientation=turn), "
      "CF_TEMPLATES[k]))\n"
      "    return placed\n",
      clumps.size(), python_list(names), python_list(numbers), python_list(masses), python_list(kg));
}

std::string population_table(const std::vector<Clump>& clumps, const std::vector<fs::path>& primaries,
                             const std::vector<double>& by_number, const std::vector<double>& by_mass) {
  std::string csv = "name,identifier,file,mass_kg,volume_m3,density_kg_m3,spheres,number_fraction,mass_fraction\n";
  for (std::size_t k = 0; k < clumps.size(); ++k) {
    const Clump& c = clumps[k];
    // The file is relative to the population's folder and named by the identifier: no quoting.
    csv += fmt::format("{},{},{},{},{},{},{},{},{}\n", csv_field(c.name), identifier(c.name),
                       primaries[k].generic_string(), number(c.mass), number(c.body_volume), number(c.density),
                       c.spheres.size(), number(by_number[k]), number(by_mass[k]));
  }
  return csv;
}
}  // namespace

Result<PopulationResult> export_population(const std::vector<Clump>& clumps, const PopulationOptions& options,
                                           const fs::path& dir) {
  if (clumps.size() < 2) return fail(ErrorCode::InvalidArgument, "a population needs at least two clumps");
  std::set<std::string> ids;
  for (const auto& c : clumps) {
    if (!ids.insert(identifier(c.name)).second) {
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("two clumps are both named '{}' in the population: give them distinct names",
                              identifier(c.name)));
    }
  }
  auto shares = fractions(clumps, options);
  if (!shares) return std::unexpected(shares.error());
  const auto& [by_number, by_mass] = *shares;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) {
    return fail(ErrorCode::InvalidArgument, fmt::format("population export: '{}' must be a directory", dir.string()));
  }
  fs::create_directories(dir, ec);
  if (ec) return fail(ErrorCode::IoError, fmt::format("cannot create '{}': {}", dir.string(), ec.message()));
  Files files;
  std::vector<fs::path> primaries;
  for (const auto& c : clumps) {
    const fs::path primary = dir / member_file(options.format, identifier(c.name));
    auto built = export_detail::format_files(c, {.format = options.format, .mercury_layout = options.mercury_layout},
                                             options.format == ExportFormat::MercuryDpm ? dir : primary);
    if (!built) return std::unexpected(built.error());
    primaries.push_back(fs::relative(built->front().first, dir));
    // The LIGGGHTS templates live in population.in (distinct seeds and types), not in per-clump snippets.
    for (auto& file : *built) {
      if (options.format != ExportFormat::Liggghts || file.first.extension() != ".in") files.push_back(std::move(file));
    }
  }
  files.insert(files.begin(), {dir / "population.csv", population_table(clumps, primaries, by_number, by_mass)});
  if (options.format == ExportFormat::Liggghts) {
    files.push_back(
        {dir / "population.in",
         liggghts_population(clumps, options.basis == FractionBasis::Number ? by_number : by_mass, options.basis)});
  }
  if (options.format == ExportFormat::Yade)
    files.push_back({dir / "population.py", yade_population(clumps, by_number, by_mass)});
  if (auto ok = write_files_atomically(files); !ok) return std::unexpected(ok.error());
  PopulationResult result{{}, by_number, by_mass};
  for (const auto& f : files) result.files.push_back(f.first);
  return result;
}

}  // namespace clumpforge
