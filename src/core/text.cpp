#include "core/text.hpp"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <new>
#include <vector>

#include "core/error.hpp"

namespace clumpforge {

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const std::size_t substitution = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitution});
      diagonal = above;
    }
  }
  return row[b.size()];
}

namespace {
template <class Range>
std::string closest(std::string_view input, const Range& candidates) {
  std::string_view best;
  std::size_t best_distance = 3;
  for (const auto& candidate : candidates) {
    const std::size_t distance = edit_distance(input, candidate);
    if (distance < best_distance) {
      best_distance = distance;
      best = std::string_view(candidate);
    }
  }
  if (best.empty() || best == input) return {};
  return " (did you mean '" + std::string(best) + "'?)";
}

}  // namespace

std::string did_you_mean(std::string_view input, std::initializer_list<std::string_view> candidates) {
  return closest(input, candidates);
}
std::string did_you_mean(std::string_view input, std::span<const std::string> candidates) {
  return closest(input, candidates);
}

namespace {
/// What an entry of `type` is when it is there but not a regular file, in words.
std::optional<std::string_view> irregular_kind(std::filesystem::file_type type) {
  namespace fs = std::filesystem;
  switch (type) {
    case fs::file_type::regular:
    case fs::file_type::not_found:
      return std::nullopt;
    case fs::file_type::directory:
      return "a folder";
    case fs::file_type::fifo:
      return "a named pipe";
    case fs::file_type::block:
    case fs::file_type::character:
      return "a device";
    case fs::file_type::socket:
      return "a socket";
    default:
      return "its kind cannot be told (a loop of links, or no permission to look)";
  }
}
}  // namespace

std::optional<std::string_view> not_a_regular_file(const std::filesystem::path& path) {
  std::error_code ec;
  return irregular_kind(std::filesystem::status(path, ec).type());
}

std::optional<std::uintmax_t> size_beyond(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size <= max_bytes) return std::nullopt;
  return size;
}

Result<std::string> read_whole_file(const std::filesystem::path& path, std::string_view what,
                                    std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  const std::string name = "'" + path.string() + "'", kind(what);
  const auto beyond = [&](const std::string& size) {
    return fail(ErrorCode::InvalidArgument, name + ": " + size + " bytes, beyond the limit of " +
                                                std::to_string(max_bytes >> 20) + " MiB for a " + kind);
  };
  std::error_code ec;
  const fs::file_type type = fs::status(path, ec).type();
  if (type == fs::file_type::not_found) return fail(ErrorCode::NotFound, name + ": no such " + kind);
  if (type != fs::file_type::regular && type != fs::file_type::fifo && type != fs::file_type::character)
    return fail(ErrorCode::InvalidArgument, name + " is not a file: " + std::string(*irregular_kind(type)));
  if (const auto size = size_beyond(path, max_bytes)) return beyond(std::to_string(*size));
  const std::size_t limit = static_cast<std::size_t>(std::min<std::uintmax_t>(max_bytes, SIZE_MAX - 1));
  std::optional<std::string> bytes;
  try {
    bytes = read_file_bytes(path, limit + 1);
  } catch (const std::bad_alloc&) {
    return fail(ErrorCode::IoError, name + ": too large to hold in this process's memory, for a " + kind);
  }
  if (!bytes) return fail(ErrorCode::IoError, name + ": cannot read the " + kind);
  if (bytes->size() > limit) return beyond("more than " + std::to_string(limit));
  return std::move(*bytes);
}

std::optional<std::string> read_file_bytes(const std::filesystem::path& path, std::size_t limit) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::string bytes;
  constexpr std::size_t kChunk = 1 << 16;
  // A regular file's size and one chunk more, where its end is found: read without a copy.
  if (const auto size = std::filesystem::file_size(path, ec); !ec)
    bytes.reserve(static_cast<std::size_t>(std::min<std::uintmax_t>(size + kChunk, limit)));
  while (bytes.size() < limit) {
    const std::size_t want = std::min(kChunk, limit - bytes.size());
    const std::size_t had = bytes.size();
    // Grown by doubling, but never past the limit: from half of it straight to it. A pipe read to
    // a 2 GiB limit held 4 GiB and its copy as the string doubled (4.2 GB resident, bad_alloc
    // under a 4 GB cap); now at most 1 GiB and the 2 GiB it moves into. (A string's own reserve
    // doubles at least, so the bytes move into a new one that reserves just that.)
    if (bytes.capacity() < had + want) {
      std::string grown;
      grown.reserve(bytes.capacity() >= limit / 2 ? limit : std::max(had + want, 2 * bytes.capacity()));
      grown.append(bytes);
      bytes.swap(grown);
    }
    bytes.resize(had + want);
    in.read(bytes.data() + had, static_cast<std::streamsize>(want));
    bytes.resize(had + static_cast<std::size_t>(in.gcount()));
    if (!in) break;
  }
  if (in.bad()) return std::nullopt;
  return bytes;
}

std::string one_line_text(std::string_view text) {
  std::string out;
  for (char c : printable_text(text)) {
    if (c == '\n')
      out += "\\x0A";
    else if (c == '\t')
      out += "\\x09";
    else
      out += c;
  }
  return out;
}

std::string csv_field(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::optional<std::size_t> json_nesting_beyond(std::string_view text, int max_depth) {
  int depth = 0;
  std::size_t line = 1;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (c == '\n') ++line;
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return line;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::nullopt;
}

}  // namespace clumpforge
