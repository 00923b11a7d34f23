#pragma once
/// Small text helpers shared by the parsers.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/error.hpp"

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

/// What the entry at `path` is when it exists but is not a regular file, links followed ("a
/// folder", "a named pipe", "a device", "a socket", or that its kind cannot be told); nothing for
/// a regular file or a missing path. A file a recording names must be regular: a named pipe
/// would hold the reader until something wrote to it, and a device may never end.
std::optional<std::string_view> not_a_regular_file(const std::filesystem::path& path);

/// The size of the file at `path` when it is larger than `max_bytes`, told without reading it;
/// nothing otherwise (or when its size cannot be told: its reader says why).
std::optional<std::uintmax_t> size_beyond(const std::filesystem::path& path, std::uintmax_t max_bytes);

/// The bytes of the file at `path`, at most `limit` of them; nullopt when it cannot be opened or
/// read (a missing file, a folder, no permission). The one whole-file reader the parsers share.
std::optional<std::string> read_file_bytes(const std::filesystem::path& path,
                                           std::size_t limit = std::numeric_limits<std::size_t>::max());

/// The largest JSON file clumpforge reads (a recording's manifest, --materials, --calibration, a
/// batch's item): a few kilobytes per hundred trials, and parsed JSON takes several times its
/// bytes in memory.
inline constexpr std::uintmax_t kMaxJsonBytes = 64ull << 20;

/// The whole file at `path` (read_file_bytes), refused with a message that names it and `what`
/// it was to be ("materials file", "calibration"): missing, a folder or a socket, larger than
/// `max_bytes` (a regular file told by its size, unread; a named pipe or a device read up to the
/// limit: `/dev/zero` as --materials filled the memory), or unreadable. A named pipe the user
/// names is read as a pipe (`--materials <(ssh host cat m.json)`): it waits for its writer.
Result<std::string> read_whole_file(const std::filesystem::path& path, std::string_view what,
                                    std::uintmax_t max_bytes = std::numeric_limits<std::uintmax_t>::max());

/// The deepest nesting of arrays and objects a JSON file clumpforge reads may have: a recording's
/// manifest nests four deep. A parser holds deeper text, but copying or writing the value back
/// recurses once per level, and 200,000 levels kept among a manifest's extra keys overflowed the
/// stack (a crash, not a message).
inline constexpr int kMaxJsonDepth = 64;
/// The 1-based line where JSON `text` first nests deeper than `max_depth` arrays and objects
/// (nullopt: it never does). Brackets inside strings, escaped quotes included, do not count.
std::optional<std::size_t> json_nesting_beyond(std::string_view text, int max_depth = kMaxJsonDepth);

}  // namespace clumpforge
