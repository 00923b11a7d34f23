#pragma once
/// Length units at the edges of the tool. Everything inside is SI (metres).
#include <string>
#include <string_view>

#include "clumpforge/error.hpp"

namespace clumpforge {

enum class LengthUnit { Millimetre, Centimetre, Metre };

/// Metres in one `unit` (mm -> 1e-3).
double metres_per(LengthUnit unit);
/// "mm", "cm" or "m".
std::string_view to_string(LengthUnit unit);
/// Parses "mm", "cm" or "m"; a near miss gets a "did you mean" message.
Result<LengthUnit> parse_length_unit(std::string_view text);
/// Parses a length with its unit, "2mm", "0.2 m", "1.5cm"; a bare number is an error
/// (a length without a unit is ambiguous). Returns metres.
Result<double> parse_length(std::string_view text);

}  // namespace clumpforge
