#pragma once
// The public definition (installed as <clumpforge/units.hpp>).
#include "clumpforge/units.hpp"
