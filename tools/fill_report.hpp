#pragma once
#include <nlohmann/json.hpp>

#include "core/clump.hpp"

namespace clumpforge::cli {
/// The clump's error report under the documented --json keys.
nlohmann::json error_to_json(const ClumpError& error);
nlohmann::json clump_to_json(const Clump& clump);
}  // namespace clumpforge::cli
