// clumpforge materials [--materials FILE]: the material table as a materials file (JSON).
#include <iostream>
#include <memory>

#include "cli_common.hpp"
#include "commands.hpp"
#include "io/materials_io.hpp"

namespace clumpforge::cli {

Command add_materials_command(CLI::App& app) {
  auto file = std::make_shared<std::string>();
  CLI::App* sub = app.add_subcommand("materials", "Print the DEM's materials and interaction table as a materials file");
  sub->add_option("--materials", *file, "A materials file to apply over the built-in table first");
  return {sub, [file] {
            auto table = file->empty() ? Result<MaterialTable>(default_material_table()) : read_materials(*file);
            if (!table) return report_error("materials", table.error());
            std::cout << materials_json(*table);
            return kExitOk;
          }};
}

}  // namespace clumpforge::cli
