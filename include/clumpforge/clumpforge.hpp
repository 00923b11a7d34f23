#pragma once
/// clumpforge's installed C++ interface, all modules (target clumpforge::clumpforge):
/// value types in SI units built from the standard library only, results as
/// std::expected<T, clumpforge::Error>. See docs/cpp-package.md.
#include "clumpforge/core.hpp"
#include "clumpforge/dem.hpp"
#include "clumpforge/error.hpp"
#include "clumpforge/fill.hpp"
#include "clumpforge/io.hpp"
#include "clumpforge/mesh.hpp"
#include "clumpforge/run_context.hpp"
#include "clumpforge/units.hpp"
