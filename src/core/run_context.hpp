#pragma once
// The public definition (installed as <clumpforge/run_context.hpp>).
#include "clumpforge/run_context.hpp"
