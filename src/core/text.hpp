#pragma once
/// Small text helpers shared by the parsers.
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>

namespace clumpforge {

std::string_view trim(std::string_view text);
/// Levenshtein distance between two strings.
std::size_t edit_distance(std::string_view a, std::string_view b);
/// " (did you mean 'x'?)" for the closest candidate within two edits, else "".
std::string did_you_mean(std::string_view input, std::initializer_list<std::string_view> candidates);
std::string did_you_mean(std::string_view input, std::span<const std::string> candidates);

}  // namespace clumpforge
