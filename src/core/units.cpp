#include "core/units.hpp"

#include <array>
#include <charconv>
#include <cmath>

#include "core/text.hpp"

namespace clumpforge {

double metres_per(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::Millimetre: return 1e-3;
    case LengthUnit::Centimetre: return 1e-2;
    case LengthUnit::Metre: return 1.0;
  }
  return 1.0;
}

std::string_view to_string(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::Millimetre: return "mm";
    case LengthUnit::Centimetre: return "cm";
    case LengthUnit::Metre: return "m";
  }
  return "m";
}

Result<LengthUnit> parse_length_unit(std::string_view text) {
  static constexpr std::array<std::pair<std::string_view, LengthUnit>, 3> kUnits{{
      {"mm", LengthUnit::Millimetre}, {"cm", LengthUnit::Centimetre}, {"m", LengthUnit::Metre}}};
  for (const auto& [name, unit] : kUnits) {
    if (text == name) return unit;
  }
  return fail(ErrorCode::InvalidArgument,
              "unknown length unit '" + std::string(text) + "'" +
                  did_you_mean(text, {"mm", "cm", "m"}) + " (expected mm, cm or m)");
}

Result<double> parse_length(std::string_view text) {
  const std::string_view trimmed = trim(text);
  const char* begin = trimmed.data();
  const char* end = begin + trimmed.size();
  double value = 0.0;
  auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc{} || !std::isfinite(value)) {
    return fail(ErrorCode::InvalidArgument,
                "'" + std::string(text) + "' is not a length (expected e.g. 2mm or 0.002m)");
  }
  const std::string_view unit_text = trim(std::string_view(ptr, static_cast<std::size_t>(end - ptr)));
  if (unit_text.empty()) {
    return fail(ErrorCode::InvalidArgument,
                "'" + std::string(text) + "' has no unit (write e.g. 2mm or 0.002m)");
  }
  auto unit = parse_length_unit(unit_text);
  if (!unit) return std::unexpected(unit.error());
  return value * metres_per(*unit);
}

}  // namespace clumpforge
