#pragma once
// The public definition (installed as <clumpforge/error.hpp>).
#include "clumpforge/error.hpp"
