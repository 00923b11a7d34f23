#include "mesh/ply.hpp"

#include <fmt/format.h>

#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace clumpforge {
namespace {

enum class Scalar { I8, U8, I16, U16, I32, U32, F32, F64 };
enum class Encoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

std::optional<Scalar> scalar_of(std::string_view name) {
  struct Named {
    std::string_view name;
    Scalar scalar;
  };
  static constexpr Named kNames[] = {
      {"char", Scalar::I8},   {"int8", Scalar::I8},     {"uchar", Scalar::U8},   {"uint8", Scalar::U8},
      {"short", Scalar::I16}, {"int16", Scalar::I16},   {"ushort", Scalar::U16}, {"uint16", Scalar::U16},
      {"int", Scalar::I32},   {"int32", Scalar::I32},   {"uint", Scalar::U32},   {"uint32", Scalar::U32},
      {"float", Scalar::F32}, {"float32", Scalar::F32}, {"double", Scalar::F64}, {"float64", Scalar::F64}};
  for (const Named& n : kNames)
    if (n.name == name) return n.scalar;
  return std::nullopt;
}

std::size_t size_of(Scalar s) {
  switch (s) {
    case Scalar::I8:
    case Scalar::U8:
      return 1;
    case Scalar::I16:
    case Scalar::U16:
      return 2;
    case Scalar::I32:
    case Scalar::U32:
    case Scalar::F32:
      return 4;
    case Scalar::F64:
      return 8;
  }
  return 8;
}

bool is_integer(Scalar s) {
  return s != Scalar::F32 && s != Scalar::F64;
}

struct Property {
  std::string name;
  Scalar type = Scalar::F32;         ///< of the value, or of a list's items
  std::optional<Scalar> count_type;  ///< set for a list
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  std::size_t line = 0;  ///< where the header declares it
};

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;
  std::size_t data_offset = 0;  ///< the first byte after end_header's line
  std::size_t lines = 0;        ///< the header's lines
};

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

class Failure {
 public:
  explicit Failure(const std::filesystem::path& path) : path_(path.string()) {}
  std::unexpected<Error> at_line(std::size_t line, std::string_view what) const {
    return fail(ErrorCode::ParseError, fmt::format("'{}': line {}: {}", path_, line, what));
  }
  std::unexpected<Error> in(std::string_view element, std::uint64_t record, std::string_view what) const {
    return fail(ErrorCode::ParseError, fmt::format("'{}': {} {}: {}", path_, element, record + 1, what));
  }
  std::unexpected<Error> whole(std::string_view what) const {
    return fail(ErrorCode::ParseError, fmt::format("'{}': {}", path_, what));
  }

 private:
  std::string path_;
};

/// One header line (after "ply"): its declaration added to `h`; true at end_header.
Result<bool> header_line(const std::vector<std::string_view>& w, std::size_t line, Header& h, const Failure& bad) {
  if (w.empty() || w[0] == "comment" || w[0] == "obj_info") return false;
  if (w[0] == "end_header") return true;
  if (w[0] == "format") {
    if (w.size() != 3 || w[2] != "1.0") return bad.at_line(line, "a format line is 'format ENCODING 1.0'");
    if (w[1] == "ascii")
      h.encoding = Encoding::Ascii;
    else if (w[1] == "binary_little_endian")
      h.encoding = Encoding::BinaryLittleEndian;
    else if (w[1] == "binary_big_endian")
      h.encoding = Encoding::BinaryBigEndian;
    else
      return bad.at_line(line, fmt::format("unknown encoding '{}'", w[1]));
    return false;
  }
  if (w[0] == "element") {
    std::uint64_t count = 0;
    if (w.size() != 3 || std::from_chars(w[2].data(), w[2].data() + w[2].size(), count).ec != std::errc{})
      return bad.at_line(line, "an element line is 'element NAME COUNT'");
    h.elements.push_back({std::string(w[1]), count, {}, line});
    return false;
  }
  if (w[0] == "property") {
    if (h.elements.empty()) return bad.at_line(line, "a property before any element");
    Property p;
    if (w.size() == 5 && w[1] == "list") {
      p.count_type = scalar_of(w[2]);
      const auto item = scalar_of(w[3]);
      if (!p.count_type || !item || !is_integer(*p.count_type))
        return bad.at_line(line, "a list property is 'property list INTEGER-TYPE TYPE NAME'");
      p.type = *item;
      p.name = std::string(w[4]);
    } else if (w.size() == 3) {
      const auto type = scalar_of(w[1]);
      if (!type) return bad.at_line(line, fmt::format("unknown property type '{}'", w[1]));
      p.type = *type;
      p.name = std::string(w[2]);
    } else {
      return bad.at_line(line, "a property line is 'property TYPE NAME' or 'property list COUNT-TYPE TYPE NAME'");
    }
    h.elements.back().properties.push_back(std::move(p));
    return false;
  }
  return bad.at_line(line, fmt::format("'{}' is not a PLY header keyword", w[0]));
}

Result<Header> read_header(std::string_view bytes, const Failure& bad) {
  Header h;
  std::size_t pos = 0, line = 0;
  bool format = false;
  while (pos < bytes.size()) {
    const std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) break;
    std::string_view text = bytes.substr(pos, end - pos);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    pos = end + 1;
    ++line;
    const auto w = words(text);
    if (line == 1) {
      if (w.size() != 1 || w[0] != "ply") return bad.at_line(1, "a PLY file opens with the line 'ply'");
      continue;
    }
    format = format || (!w.empty() && w[0] == "format");
    auto done = header_line(w, line, h, bad);
    if (!done) return std::unexpected(done.error());
    if (*done) {
      if (!format) return bad.at_line(line, "the header has no format line");
      h.data_offset = pos;
      h.lines = line;
      return h;
    }
  }
  return bad.whole("the header has no 'end_header' line");
}

/// Binary records, bounds-checked.
class BinaryCursor {
 public:
  BinaryCursor(std::string_view data, bool big_endian) : data_(data), big_(big_endian) {}
  std::size_t left() const { return data_.size() - pos_; }
  /// The next value of `type`, or nullopt past the end.
  std::optional<double> next(Scalar type) {
    const std::size_t n = size_of(type);
    if (left() < n) return std::nullopt;
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    if (big_ != (std::endian::native == std::endian::big))
      for (std::size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    switch (type) {
      case Scalar::I8:
        return static_cast<double>(std::bit_cast<std::int8_t>(b[0]));
      case Scalar::U8:
        return static_cast<double>(b[0]);
      case Scalar::I16:
        return static_cast<double>(load<std::int16_t>(b));
      case Scalar::U16:
        return static_cast<double>(load<std::uint16_t>(b));
      case Scalar::I32:
        return static_cast<double>(load<std::int32_t>(b));
      case Scalar::U32:
        return static_cast<double>(load<std::uint32_t>(b));
      case Scalar::F32:
        return static_cast<double>(load<float>(b));
      case Scalar::F64:
        return load<double>(b);
    }
    return std::nullopt;
  }

 private:
  template <class T>
  static T load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }
  std::string_view data_;
  std::size_t pos_ = 0;
  bool big_ = false;
};

/// Ascii records: whitespace-separated numbers.
class AsciiCursor {
 public:
  explicit AsciiCursor(std::string_view data) : data_(data) {}
  std::size_t left() const { return data_.size() - pos_; }
  std::optional<double> next(Scalar type) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (pos_ == start) return std::nullopt;
    double v = 0.0;
    const auto [end, ec] = std::from_chars(data_.data() + start, data_.data() + pos_, v);
    if (ec != std::errc{} || end != data_.data() + pos_) return std::nullopt;
    if (is_integer(type) && v != std::floor(v)) return std::nullopt;
    return v;
  }

 private:
  std::string_view data_;
  std::size_t pos_ = 0;
};

/// The fewest bytes a record of `e` can take: a list may be empty.
std::size_t min_record(const Element& e, Encoding enc) {
  std::size_t n = 0;
  for (const Property& p : e.properties)
    n += enc == Encoding::Ascii ? 2 : size_of(p.count_type ? *p.count_type : p.type);
  return std::max<std::size_t>(n, 1);
}

struct Roles {
  int x = -1, y = -1, z = -1, indices = -1;
};

Roles roles_of(const Element& e) {
  Roles r;
  for (std::size_t k = 0; k < e.properties.size(); ++k) {
    const Property& p = e.properties[k];
    const int i = static_cast<int>(k);
    if (p.count_type && (p.name == "vertex_indices" || p.name == "vertex_index")) r.indices = i;
    if (!p.count_type && p.name == "x") r.x = i;
    if (!p.count_type && p.name == "y") r.y = i;
    if (!p.count_type && p.name == "z") r.z = i;
  }
  return r;
}

template <class Cursor>
Result<void> read_element(const Element& e, Encoding enc, Cursor& cursor, const Failure& bad, PlyMesh& out) {
  const bool vertex = e.name == "vertex", face = e.name == "face";
  const Roles r = roles_of(e);
  if (vertex && (r.x < 0 || r.y < 0 || r.z < 0))
    return bad.at_line(e.line, "the vertex element has no x, y and z properties");
  if (face && r.indices < 0)
    return bad.at_line(e.line, "the face element has no list named vertex_indices or vertex_index");
  if (e.count > cursor.left() / min_record(e, enc) || e.count > std::numeric_limits<int>::max())
    return bad.at_line(e.line, fmt::format("element '{}' declares {} records, more than the {} bytes left hold", e.name,
                                           e.count, cursor.left()));
  if (vertex) out.soup.points.reserve(out.soup.points.size() + e.count);
  std::vector<int> polygon;
  for (std::uint64_t i = 0; i < e.count; ++i) {
    double xyz[3] = {0.0, 0.0, 0.0};
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      const int role = static_cast<int>(k);
      if (!p.count_type) {
        const auto v = cursor.next(p.type);
        if (!v) return bad.in(e.name, i, fmt::format("property '{}' is missing or not a number", p.name));
        if (role == r.x) xyz[0] = *v;
        if (role == r.y) xyz[1] = *v;
        if (role == r.z) xyz[2] = *v;
        continue;
      }
      const auto n = cursor.next(*p.count_type);
      if (!n || *n < 0.0) return bad.in(e.name, i, fmt::format("list '{}' has no valid length", p.name));
      if (*n > static_cast<double>(cursor.left()))
        return bad.in(e.name, i, fmt::format("list '{}' of {} values runs past the end of the file", p.name, *n));
      polygon.clear();
      for (std::size_t j = 0; j < static_cast<std::size_t>(*n); ++j) {
        const auto v = cursor.next(p.type);
        if (!v)
          return bad.in(e.name, i, fmt::format("list '{}' ends early or holds a value that is not a number", p.name));
        if (role == r.indices) {
          if (!(*v >= 0.0 && *v < static_cast<double>(std::numeric_limits<int>::max()) && *v == std::floor(*v)))
            return bad.in(e.name, i, fmt::format("vertex index {} is not a vertex", *v));
          polygon.push_back(static_cast<int>(*v));
        }
      }
      if (role != r.indices) continue;
      if (polygon.size() < 3) {
        ++out.skipped_primitives;
        continue;
      }
      for (std::size_t j = 1; j + 1 < polygon.size(); ++j)
        out.soup.faces.push_back({polygon[0], polygon[j], polygon[j + 1]});
    }
    if (vertex) out.soup.points.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  return {};
}

template <class Cursor>
Result<PlyMesh> read_body(const Header& h, Cursor& cursor, const Failure& bad) {
  PlyMesh out;
  int vertex_elements = 0;
  for (const Element& e : h.elements) {
    vertex_elements += e.name == "vertex";
    if (auto ok = read_element(e, h.encoding, cursor, bad, out); !ok) return std::unexpected(ok.error());
  }
  if (vertex_elements != 1) return bad.whole("a PLY mesh has exactly one vertex element");
  const int vertices = static_cast<int>(out.soup.points.size());
  for (std::size_t f = 0; f < out.soup.faces.size(); ++f)
    for (int v : out.soup.faces[f])
      if (v >= vertices)
        return bad.whole(fmt::format("a face names vertex {}, but the file has {} vertices", v, vertices));
  return out;
}

}  // namespace

bool looks_like_ply(std::string_view bytes) {
  return bytes.size() > 3 && bytes.starts_with("ply") &&
         (bytes[3] == '\n' || bytes[3] == '\r' || bytes[3] == ' ' || bytes[3] == '\t');
}

Result<PlyMesh> parse_ply(std::string_view bytes, const std::filesystem::path& path) {
  const Failure bad(path);
  auto h = read_header(bytes, bad);
  if (!h) return std::unexpected(h.error());
  const std::string_view data = bytes.substr(h->data_offset);
  if (h->encoding == Encoding::Ascii) {
    AsciiCursor cursor(data);
    return read_body(*h, cursor, bad);
  }
  BinaryCursor cursor(data, h->encoding == Encoding::BinaryBigEndian);
  return read_body(*h, cursor, bad);
}

}  // namespace clumpforge
