#include "io/clump_library.hpp"

#include <fmt/format.h>
#include <hdf5.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <set>

#include "core/atomic_file.hpp"
#include "core/isolated.hpp"
#include "core/sha256.hpp"
#include "core/text.hpp"
#include "core/version.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

namespace {

// Owns an HDF5 identifier and closes it with the matching function.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept : id_(other.id_), close_(other.close_) { other.id_ = -1; }
  Handle& operator=(Handle&&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// The library never prints: HDF5's automatic error stack printing is off while we work.
class QuietHdf5 {
 public:
  QuietHdf5() {
    H5Eget_auto2(H5E_DEFAULT, &function_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, function_, data_); }

 private:
  H5E_auto2_t function_ = nullptr;
  void* data_ = nullptr;
};

struct Hdf5Failure {
  std::string what;
};

void check(herr_t status, const std::string& what) {
  if (status < 0) throw Hdf5Failure{what};
}

// ---- writing ---------------------------------------------------------------------------

void write_string_attribute(hid_t object, const char* name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  check(H5Tset_size(type.get(), std::max<std::size_t>(1, value.size())), name);
  check(H5Tset_strpad(type.get(), H5T_STR_NULLPAD), name);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attribute(H5Acreate2(object, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  check(attribute.ok() ? 0 : -1, name);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  check(H5Awrite(attribute.get(), type.get(), padded.data()), name);
}

void write_double_attribute(hid_t object, const char* name, double value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attribute(H5Acreate2(object, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  check(attribute.ok() ? 0 : -1, name);
  check(H5Awrite(attribute.get(), H5T_NATIVE_DOUBLE, &value), name);
}

void write_int_attribute(hid_t object, const char* name, long long value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attribute(H5Acreate2(object, name, H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  check(attribute.ok() ? 0 : -1, name);
  check(H5Awrite(attribute.get(), H5T_NATIVE_LLONG, &value), name);
}

void write_dataset(hid_t group, const char* name, std::initializer_list<hsize_t> dims, const double* data) {
  const std::vector<hsize_t> shape(dims);
  Handle space(H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr), H5Sclose);
  // No modification times in object headers: the same clumps give the same bytes.
  Handle properties(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_obj_track_times(properties.get(), false);
  Handle dataset(H5Dcreate2(group, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, properties.get(), H5P_DEFAULT),
                 H5Dclose);
  check(dataset.ok() ? 0 : -1, name);
  check(H5Dwrite(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), name);
}

void write_vector(hid_t group, const char* name, const Eigen::Vector3d& v) {
  write_dataset(group, name, {3}, v.data());
}

void write_matrix(hid_t group, const char* name, const Eigen::Matrix3d& m) {
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> rows = m;
  write_dataset(group, name, {3, 3}, rows.data());
}

Handle create_group(hid_t parent, const char* name, bool track_order = false) {
  Handle properties(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
  if (track_order) H5Pset_link_creation_order(properties.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
  H5Pset_obj_track_times(properties.get(), false);
  Handle group(H5Gcreate2(parent, name, H5P_DEFAULT, properties.get(), H5P_DEFAULT), H5Gclose);
  check(group.ok() ? 0 : -1, name);
  return group;
}

void write_error_report(hid_t clump_group, const ClumpError& e) {
  Handle group = create_group(clump_group, "error");
  write_int_attribute(group.get(), "sphere_count", e.sphere_count);
  write_double_attribute(group.get(), "volume_error", e.volume_error);
  write_double_attribute(group.get(), "mass_error", e.mass_error);
  write_double_attribute(group.get(), "com_offset_m", e.com_offset_norm);
  write_double_attribute(group.get(), "axis_error_deg", e.axis_error_deg);
  write_double_attribute(group.get(), "surface_rms_m", e.surface_rms);
  write_double_attribute(group.get(), "surface_max_m", e.surface_max);
  write_double_attribute(group.get(), "dice", e.dice);
  write_double_attribute(group.get(), "integration_spacing_m", e.integration_spacing);
  write_double_attribute(group.get(), "body_grid_volume_error", e.body_grid_volume_error);
  write_int_attribute(group.get(), "surface_samples", e.surface_samples);
  write_vector(group.get(), "com_offset_vector_m", e.com_offset);
  write_vector(group.get(), "principal_moment_errors", e.principal_moment_errors);
  write_vector(group.get(), "principal_moment_errors_mass_matched", e.principal_moment_errors_mass_matched);
  Handle u = create_group(group.get(), "union");
  write_double_attribute(u.get(), "volume_m3", e.union_properties.volume);
  write_double_attribute(u.get(), "mass_kg", e.union_properties.mass);
  write_vector(u.get(), "centre_of_mass_m", e.union_properties.centre_of_mass);
  write_matrix(u.get(), "inertia_kg_m2", e.union_properties.inertia);
  write_vector(u.get(), "principal_moments_kg_m2", e.union_properties.principal_moments);
  write_matrix(u.get(), "principal_axes", e.union_properties.principal_axes);
}

void write_clump(hid_t clumps_group, const Clump& clump) {
  Handle group = create_group(clumps_group, clump.name.c_str());
  write_string_attribute(group.get(), "name", clump.name);
  write_string_attribute(group.get(), "method", std::string(to_string(clump.method)));
  write_string_attribute(group.get(), "units", "m");
  write_string_attribute(group.get(), "frame", "principal axes of the body, centre of mass at the origin");
  write_double_attribute(group.get(), "density_kg_m3", clump.density);
  write_double_attribute(group.get(), "mass_kg", clump.mass);
  write_double_attribute(group.get(), "body_volume_m3", clump.body_volume);
  write_string_attribute(group.get(), "source_mesh_sha256", clump.source_sha256);
  write_string_attribute(group.get(), "tool_version", kVersion);
  std::vector<double> spheres(clump.spheres.size() * 4);
  for (std::size_t i = 0; i < clump.spheres.size(); ++i) {
    spheres[4 * i + 0] = clump.spheres[i].centre.x();
    spheres[4 * i + 1] = clump.spheres[i].centre.y();
    spheres[4 * i + 2] = clump.spheres[i].centre.z();
    spheres[4 * i + 3] = clump.spheres[i].radius;
  }
  write_dataset(group.get(), "spheres", {clump.spheres.size(), 4}, spheres.data());
  {
    Handle dataset(H5Dopen2(group.get(), "spheres", H5P_DEFAULT), H5Dclose);
    write_string_attribute(dataset.get(), "columns", "x y z r");
    write_string_attribute(dataset.get(), "units", "m");
  }
  write_matrix(group.get(), "inertia_kg_m2", clump.inertia);
  write_vector(group.get(), "principal_moments_kg_m2", clump.principal_moments);
  Handle parameters = create_group(group.get(), "parameters");
  for (const auto& [key, value] : clump.parameters) write_double_attribute(parameters.get(), key.c_str(), value);
  write_error_report(group.get(), clump.error);
}

// ---- reading ---------------------------------------------------------------------------

struct Reader {
  std::string source;

  [[noreturn]] void damaged(const std::string& what) const {
    throw Hdf5Failure{fmt::format("'{}' is damaged: {}", source, what)};
  }
  bool has_attribute(hid_t object, const char* name) const { return H5Aexists(object, name) > 0; }
  std::string string_attribute(hid_t object, const char* name) const {
    Handle attribute(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
    if (!attribute.ok()) damaged(fmt::format("attribute '{}' is missing", name));
    Handle type(H5Aget_type(attribute.get()), H5Tclose);
    if (H5Tget_class(type.get()) != H5T_STRING) damaged(fmt::format("attribute '{}' is not a string", name));
    if (H5Tis_variable_str(type.get()) > 0) {
      char* text = nullptr;
      Handle memory(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(memory.get(), H5T_VARIABLE);
      if (H5Aread(attribute.get(), memory.get(), &text) < 0) damaged(fmt::format("attribute '{}' unreadable", name));
      std::string value = text != nullptr ? text : "";
      H5free_memory(text);
      return value;
    }
    const std::size_t size = H5Tget_size(type.get());
    std::string value(size, '\0');
    if (H5Aread(attribute.get(), type.get(), value.data()) < 0) damaged(fmt::format("attribute '{}' unreadable", name));
    return value.substr(0, value.find('\0'));
  }
  double double_attribute(hid_t object, const char* name) const {
    Handle attribute(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
    if (!attribute.ok()) damaged(fmt::format("attribute '{}' is missing", name));
    double value = 0.0;
    if (H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, &value) < 0)
      damaged(fmt::format("attribute '{}' unreadable", name));
    return value;
  }
  std::vector<double> dataset(hid_t group, const char* name, std::vector<hsize_t> expected_dims) const {
    Handle dataset(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
    if (!dataset.ok()) damaged(fmt::format("dataset '{}' is missing", name));
    Handle space(H5Dget_space(dataset.get()), H5Sclose);
    const int rank = H5Sget_simple_extent_ndims(space.get());
    std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
    H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
    if (dims.size() != expected_dims.size()) damaged(fmt::format("dataset '{}' has rank {}", name, rank));
    hsize_t count = 1;
    for (std::size_t k = 0; k < dims.size(); ++k) {
      if (expected_dims[k] != 0 && dims[k] != expected_dims[k])
        damaged(fmt::format("dataset '{}' has the wrong shape", name));
      count *= dims[k];
    }
    std::vector<double> values(count);
    if (count > 0 && H5Dread(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0) {
      damaged(fmt::format("dataset '{}' unreadable", name));
    }
    return values;
  }
  Eigen::Vector3d vector(hid_t group, const char* name) const {
    const auto v = dataset(group, name, {3});
    return {v[0], v[1], v[2]};
  }
  Eigen::Matrix3d matrix(hid_t group, const char* name) const {
    const auto v = dataset(group, name, {3, 3});
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m(r, c) = v[3 * r + c];
    }
    return m;
  }
  Handle open_group(hid_t parent, const char* name) const {
    Handle group(H5Gopen2(parent, name, H5P_DEFAULT), H5Gclose);
    if (!group.ok()) damaged(fmt::format("group '{}' is missing", name));
    return group;
  }

  ClumpError error_report(hid_t clump_group) const {
    Handle group = open_group(clump_group, "error");
    ClumpError e;
    e.sphere_count = static_cast<int>(double_attribute(group.get(), "sphere_count"));
    e.volume_error = double_attribute(group.get(), "volume_error");
    e.mass_error = double_attribute(group.get(), "mass_error");
    e.com_offset_norm = double_attribute(group.get(), "com_offset_m");
    e.axis_error_deg = double_attribute(group.get(), "axis_error_deg");
    e.surface_rms = double_attribute(group.get(), "surface_rms_m");
    e.surface_max = double_attribute(group.get(), "surface_max_m");
    e.dice = double_attribute(group.get(), "dice");
    e.integration_spacing = double_attribute(group.get(), "integration_spacing_m");
    e.body_grid_volume_error = double_attribute(group.get(), "body_grid_volume_error");
    e.surface_samples = static_cast<int>(double_attribute(group.get(), "surface_samples"));
    e.com_offset = vector(group.get(), "com_offset_vector_m");
    e.principal_moment_errors = vector(group.get(), "principal_moment_errors");
    e.principal_moment_errors_mass_matched = vector(group.get(), "principal_moment_errors_mass_matched");
    Handle u = open_group(group.get(), "union");
    e.union_properties.volume = double_attribute(u.get(), "volume_m3");
    e.union_properties.mass = double_attribute(u.get(), "mass_kg");
    e.union_properties.centre_of_mass = vector(u.get(), "centre_of_mass_m");
    e.union_properties.inertia = matrix(u.get(), "inertia_kg_m2");
    e.union_properties.principal_moments = vector(u.get(), "principal_moments_kg_m2");
    e.union_properties.principal_axes = matrix(u.get(), "principal_axes");
    return e;
  }

  Clump clump(hid_t clumps_group, const std::string& name) const {
    Handle group = open_group(clumps_group, name.c_str());
    Clump c;
    c.name = string_attribute(group.get(), "name");
    const std::string method = string_attribute(group.get(), "method");
    if (method != "lattice" && method != "adaptive")
      damaged(fmt::format("clump '{}' has unknown method '{}'", name, method));
    c.method = method == "lattice" ? FillMethod::Lattice : FillMethod::Adaptive;
    if (string_attribute(group.get(), "units") != "m") damaged(fmt::format("clump '{}' is not in metres", name));
    c.density = double_attribute(group.get(), "density_kg_m3");
    c.mass = double_attribute(group.get(), "mass_kg");
    c.body_volume = double_attribute(group.get(), "body_volume_m3");
    c.source_sha256 = string_attribute(group.get(), "source_mesh_sha256");
    const auto spheres = dataset(group.get(), "spheres", {0, 4});
    c.spheres.resize(spheres.size() / 4);
    for (std::size_t i = 0; i < c.spheres.size(); ++i) {
      c.spheres[i] = {{spheres[4 * i], spheres[4 * i + 1], spheres[4 * i + 2]}, spheres[4 * i + 3]};
      if (!(c.spheres[i].radius > 0.0))
        damaged(fmt::format("clump '{}' sphere {} has radius {}", name, i, c.spheres[i].radius));
    }
    if (c.spheres.empty()) damaged(fmt::format("clump '{}' has no spheres", name));
    c.inertia = matrix(group.get(), "inertia_kg_m2");
    c.principal_moments = vector(group.get(), "principal_moments_kg_m2");
    if (!(c.mass > 0.0) || !(c.principal_moments.minCoeff() > 0.0)) {
      damaged(fmt::format("clump '{}' has a non-positive mass or moment of inertia", name));
    }
    Handle parameters = open_group(group.get(), "parameters");
    H5O_info_t info;
    H5Oget_info2(parameters.get(), &info, H5O_INFO_NUM_ATTRS);  // HDF5 1.10 API
    for (hsize_t a = 0; a < info.num_attrs; ++a) {
      char key[256] = {};
      H5Aget_name_by_idx(parameters.get(), ".", H5_INDEX_CRT_ORDER, H5_ITER_INC, a, key, sizeof(key), H5P_DEFAULT);
      c.parameters.emplace_back(key, double_attribute(parameters.get(), key));
    }
    c.error = error_report(group.get());
    return c;
  }
};

std::vector<std::string> child_names(hid_t group) {
  std::vector<std::string> names;
  H5G_info_t info;
  H5Gget_info(group, &info);
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    char name[1024] = {};
    H5_index_t index = H5_INDEX_CRT_ORDER;
    if (H5Lget_name_by_idx(group, ".", index, H5_ITER_INC, i, name, sizeof(name), H5P_DEFAULT) < 0) {
      H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof(name), H5P_DEFAULT);
    }
    names.emplace_back(name);
  }
  return names;
}
}  // namespace

namespace {
Result<void> check_names(std::span<const Clump> clumps, std::string_view where) {
  std::set<std::string> names;
  for (const auto& clump : clumps) {
    if (clump.name.empty() || clump.name.find('/') != std::string::npos || !names.insert(clump.name).second) {
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("{}clump name '{}' is empty, has a '/' or repeats", where, clump.name));
    }
  }
  return {};
}

// ---- the seal: a checksum of the whole file in its first bytes ------------------------------
//
// HDF5's default format carries no checksums, and libhdf5 can crash or hang on a damaged file
// before it reports anything. So the file is written with a user block (bytes HDF5 leaves to the
// writer; readers find the superblock after it), and once HDF5 has closed it those bytes are set
// to a header holding the SHA-256 and length of everything after them. A reader checks the seal
// before libhdf5 opens the file.

constexpr std::size_t kSealBytes = 512;  // HDF5's smallest user block
constexpr std::string_view kSealMagic = "clumpforge sealed HDF5 file v1\n";
constexpr std::string_view kHdf5Signature = "\x89HDF\r\n\x1a\n";

std::string seal_header(std::string_view sealed) {
  std::string header = fmt::format("{}sha256 {}\nbytes {}\n", kSealMagic, sha256_hex(sealed), sealed.size());
  header.resize(kSealBytes, '\0');
  return header;
}

/// The largest clump library read: 2 GiB (a thousand clumps of 2000 spheres take 64 MB).
constexpr std::uintmax_t kMaxLibraryBytes = 2ull << 30;

Result<std::string> read_bytes(const fs::path& path) {
  return read_whole_file(path, "clump library", kMaxLibraryBytes);
}

// Writes the seal over the user block of the closed file at `temporary`.
Result<void> seal(const fs::path& temporary, const fs::path& path) {
  auto bytes = read_bytes(temporary);
  if (!bytes) return std::unexpected(bytes.error());
  if (bytes->size() < kSealBytes || bytes->substr(kSealBytes, kHdf5Signature.size()) != kHdf5Signature)
    return fail(ErrorCode::IoError, fmt::format("writing '{}': HDF5 did not leave the user block", path.string()));
  const std::string header = seal_header(std::string_view(*bytes).substr(kSealBytes));
  std::fstream out(temporary, std::ios::binary | std::ios::in | std::ios::out);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.close();
  if (!out) return fail(ErrorCode::IoError, fmt::format("writing '{}' failed at its seal", path.string()));
  return {};
}

// Checks a file's seal before libhdf5 reads it. A file that starts with HDF5's own signature has
// no seal (written before the seal, or by another program) and is let through unchecked; one
// whose seal does not match its bytes is refused.
Result<void> check_seal(std::string_view all, const fs::path& path) {
  if (all.starts_with(kHdf5Signature)) return {};
  const bool hdf5_after_block = all.size() > kSealBytes && all.substr(kSealBytes).starts_with(kHdf5Signature);
  if (!all.starts_with(kSealMagic) && !hdf5_after_block) return {};  // not ours: HDF5 itself says what it is
  if (all.size() <= kSealBytes || seal_header(all.substr(kSealBytes)) != all.substr(0, kSealBytes)) {
    return fail(ErrorCode::ParseError,
                fmt::format("'{}' is damaged: its bytes do not match the SHA-256 and length clumpforge sealed it "
                            "with (it changed after it was written, by damage or by another program; write it "
                            "again, or remove the seal with 'h5unjam -i FILE -o COPY' to read it unchecked)",
                            path.string()));
  }
  return {};
}

// Where HDF5 looks for its superblock: at 0, then at 512, 1024, 2048, ... (after a user block).
bool has_hdf5_signature(std::string_view all) {
  for (std::size_t at = 0; at + kHdf5Signature.size() <= all.size(); at = at == 0 ? kSealBytes : 2 * at) {
    if (all.substr(at, kHdf5Signature.size()) == kHdf5Signature) return true;
  }
  return false;
}

// Opens the bytes already read and checked as a read-only HDF5 file in memory (the core driver
// with a file image), so that libhdf5 reads exactly the bytes the seal was checked on and the
// file is read from disk once. HDF5 copies the image: `all` may be freed once this returns.
Handle open_image(std::string_view all) {
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!access.ok() || H5Pset_fapl_core(access.get(), 1 << 16, 0) < 0 ||
      H5Pset_file_image(access.get(), const_cast<char*>(all.data()), all.size()) < 0)
    return Handle(-1, H5Fclose);
  return Handle(H5Fopen("clumpforge-library-image", H5F_ACC_RDONLY, access.get()), H5Fclose);
}

// Writes the file's header attributes, then `body(file)`, then the seal, atomically.
template <class Body>
Result<void> write_library_file(const fs::path& path, Body&& body) {
  return write_path_atomically(path, [&](const fs::path& temporary) -> Result<void> {
    QuietHdf5 quiet;
    try {
      Handle creation(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
      check(H5Pset_userblock(creation.get(), kSealBytes), "the user block");
      Handle file(H5Fcreate(temporary.c_str(), H5F_ACC_TRUNC, creation.get(), H5P_DEFAULT), H5Fclose);
      if (!file.ok()) return fail(ErrorCode::IoError, fmt::format("cannot create HDF5 file '{}'", path.string()));
      write_string_attribute(file.get(), "format", kClumpLibraryFormat);
      write_int_attribute(file.get(), "schema_version", kClumpSchemaVersion);
      write_string_attribute(file.get(), "tool_version", kVersion);
      body(file.get());
    } catch (const Hdf5Failure& failure) {
      return fail(ErrorCode::IoError, fmt::format("writing '{}' failed at '{}'", path.string(), failure.what));
    }
    return seal(temporary, path);
  });
}

// The clumps in a library's bytes, read by libhdf5 from memory (open_image); `bytes` is freed
// once libhdf5 holds its own copy.
Result<std::vector<Clump>> clumps_in_image(std::string& bytes, const fs::path& path) {
  QuietHdf5 quiet;
  try {
    Handle file = open_image(bytes);
    std::string().swap(bytes);  // libhdf5 holds its own copy of the image now
    if (!file.ok()) return fail(ErrorCode::ParseError, fmt::format("'{}' is a damaged HDF5 file", path.string()));
    const Reader reader{path.string()};
    if (!reader.has_attribute(file.get(), "format") ||
        reader.string_attribute(file.get(), "format") != kClumpLibraryFormat) {
      return fail(ErrorCode::ParseError,
                  fmt::format("'{}' is an HDF5 file but not a clumpforge clump library (no format "
                              "attribute '{}')",
                              path.string(), kClumpLibraryFormat));
    }
    const double version = reader.double_attribute(file.get(), "schema_version");
    if (version > kClumpSchemaVersion) {
      return fail(ErrorCode::ParseError,
                  fmt::format("'{}' uses clump schema v{}; this clumpforge reads v{} (upgrade it)", path.string(),
                              version, kClumpSchemaVersion));
    }
    std::vector<Clump> clumps;
    if (H5Lexists(file.get(), "scans", H5P_DEFAULT) > 0) {
      // A population (clumpforge batch): /scans/<scan>/clumps/<clump>, named "<scan>/<clump>".
      Handle scans = reader.open_group(file.get(), "scans");
      for (const auto& scan : child_names(scans.get())) {
        Handle scan_group = reader.open_group(scans.get(), scan.c_str());
        Handle group = reader.open_group(scan_group.get(), "clumps");
        for (const auto& name : child_names(group.get())) {
          clumps.push_back(reader.clump(group.get(), name));
          clumps.back().name = scan + "/" + clumps.back().name;
        }
      }
    } else {
      Handle group = reader.open_group(file.get(), "clumps");
      for (const auto& name : child_names(group.get())) clumps.push_back(reader.clump(group.get(), name));
    }
    if (clumps.empty()) return fail(ErrorCode::ParseError, fmt::format("'{}' holds no clumps", path.string()));
    return clumps;
  } catch (const Hdf5Failure& failure) {
    return fail(ErrorCode::ParseError, failure.what);
  }
}

// A library without a seal (written before it, or by another program) cannot be checked before
// libhdf5 reads it, and libhdf5 1.10 crashes on some damaged files inside its own calls (11 of
// 1000 one-byte changes, bench/damaged_library.py). So it is read first in a child process: one
// that crashes, or has not finished in a minute (and a second per 16 MiB), is refused with the
// file's name; one that ends is read again here, from the same bytes.
// (The child frees its own copy of `bytes` as it reads them; the caller's stay as they are.)
Result<void> try_unsealed(std::string& bytes, const fs::path& path) {
  const auto timeout = std::chrono::seconds(60 + static_cast<long>(bytes.size() >> 24));
  const IsolatedResult tried = run_isolated([&] { return clumps_in_image(bytes, path).has_value(); }, timeout);
  const std::string unsealed =
      "it has no clumpforge seal to be checked by (written before the seal, or by another program)";
  if (tried.end == IsolatedEnd::Crashed)
    return fail(
        ErrorCode::ParseError,
        fmt::format("'{}' is a damaged HDF5 file: libhdf5 crashed reading it ({}, in a process of its own); {}",
                    path.string(), tried.signal ? signal_name(tried.signal) : "a sanitizer's report", unsealed));
  if (tried.end == IsolatedEnd::TimedOut)
    return fail(ErrorCode::ParseError,
                fmt::format("'{}' is a damaged HDF5 file: libhdf5 had not read it after {} s; {}", path.string(),
                            timeout.count(), unsealed));
  return {};
}
}  // namespace

Result<void> write_clump_library(const fs::path& path, std::span<const Clump> clumps) {
  if (auto ok = check_names(clumps, ""); !ok) return ok;
  return write_library_file(path, [&](hid_t file) {
    Handle group = create_group(file, "clumps", true);
    for (const auto& clump : clumps) write_clump(group.get(), clump);
  });
}

Result<void> write_population_library(const fs::path& path, std::span<const ScanClumps> scans) {
  std::set<std::string> scan_names;
  for (const auto& scan : scans) {
    if (scan.scan.empty() || scan.scan.find('/') != std::string::npos || !scan_names.insert(scan.scan).second)
      return fail(ErrorCode::InvalidArgument, fmt::format("scan name '{}' is empty, has a '/' or repeats", scan.scan));
    if (auto ok = check_names(scan.clumps, "scan '" + scan.scan + "': "); !ok) return ok;
  }
  return write_library_file(path, [&](hid_t file) {
    Handle all = create_group(file, "scans", true);
    for (const auto& scan : scans) {
      Handle group = create_group(all.get(), scan.scan.c_str(), false);
      Handle clumps = create_group(group.get(), "clumps", true);
      for (const auto& clump : scan.clumps) write_clump(clumps.get(), clump);
    }
  });
}

Result<std::vector<Clump>> read_clump_library(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return fail(ErrorCode::NotFound, fmt::format("'{}': no such file", path.string()));
  if (fs::is_directory(path, ec))
    return fail(ErrorCode::InvalidArgument, fmt::format("'{}' is a directory", path.string()));
  auto bytes = read_bytes(path);
  if (!bytes) return std::unexpected(bytes.error());
  if (auto sealed = check_seal(*bytes, path); !sealed) return std::unexpected(sealed.error());
  if (!has_hdf5_signature(*bytes)) {
    return fail(
        ErrorCode::ParseError,
        fmt::format("'{}' is not an HDF5 file (expected a clump library from 'clumpforge fill')", path.string()));
  }
  if (!bytes->starts_with(kSealMagic)) {
    if (auto tried = try_unsealed(*bytes, path); !tried) return std::unexpected(tried.error());
  }
  return clumps_in_image(*bytes, path);
}

Result<Clump> select_clump(std::vector<Clump> clumps, std::string_view name, std::string_view source) {
  std::string names;
  for (const auto& c : clumps) names += (names.empty() ? "" : ", ") + c.name;
  if (name.empty()) {
    if (clumps.size() == 1) return std::move(clumps.front());
    return fail(ErrorCode::InvalidArgument,
                fmt::format("'{}' holds {} clumps ({}); choose one with --clump", source, clumps.size(), names));
  }
  for (auto& c : clumps) {
    if (c.name == name) return std::move(c);
  }
  return fail(ErrorCode::InvalidArgument, fmt::format("'{}' has no clump '{}' (it has {})", source, name, names));
}

}  // namespace clumpforge
