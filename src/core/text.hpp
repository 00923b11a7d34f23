#pragma once
/// Small text helpers shared by the parsers.
#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <optional>
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

/// `text` for one line of a comment in a script or a report: printable (printable_text), with
/// a newline and a tab written as \x0A and \x09. A name or a path written into a script's
/// comment would otherwise end the comment and start a command.
std::string one_line_text(std::string_view text);

/// `text` as one field of a CSV row (RFC 4180): quoted, with each quote doubled, when it holds a
/// comma, a quote or a line break; else as it is. A scan's file name may hold any of them.
std::string csv_field(std::string_view text);

/// The bytes of the file at `path`, at most `limit` of them; nullopt when it cannot be opened or
/// read (a missing file, a folder, no permission). The one whole-file reader the parsers share.
std::optional<std::string> read_file_bytes(const std::filesystem::path& path,
                                           std::size_t limit = std::numeric_limits<std::size_t>::max());

/// The deepest nesting of arrays and objects a JSON file clumpforge reads may have: a recording's
/// manifest nests four deep. A parser holds deeper text, but copying or writing the value back
/// recurses once per level, and 200,000 levels kept among a manifest's extra keys overflowed the
/// stack (a crash, not a message).
inline constexpr int kMaxJsonDepth = 64;
/// The 1-based line where JSON `text` first nests deeper than `max_depth` arrays and objects
/// (nullopt: it never does). Brackets inside strings, escaped quotes included, do not count.
std::optional<std::size_t> json_nesting_beyond(std::string_view text, int max_depth = kMaxJsonDepth);

}  // namespace clumpforge
