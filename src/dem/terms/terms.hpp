#pragma once
/// Extra physics as small pluggable terms. A new term is one new header in this folder
/// (a struct with its parameters and an `apply` overload) and one line in `PhysicsTerm`.
#include <variant>

#include "dem/terms/air_drag.hpp"

namespace clumpforge {

using PhysicsTerm = std::variant<QuadraticAirDrag>;

}  // namespace clumpforge
