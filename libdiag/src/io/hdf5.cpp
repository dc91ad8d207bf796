#include "diag/io/hdf5.hpp"

#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/output_file.hpp"

namespace diag {

namespace {

constexpr char kFormatName[] = "geardiag-recording";
// 2: every channel carries role, shaft, mesh, ppr, and the root the recorded speed_rpm. Format-1
// files are still read, their roles inferred (infer_format1_roles).
constexpr int kFormatVersion = 2;
// Root attributes owned by the format; Recording::metadata may not use these keys.
constexpr std::array<const char*, 6> kReservedAttributes = {
    "format", "format_version", "creator", "git_revision", "input_speed_rpm", "roles_stated"};
// HDF5 limits a chunk to 4 GiB; 2^26 float64 samples (512 MiB) stays far below it.
constexpr std::size_t kMaxChunkSamples = std::size_t{1} << 26;

// Owns an HDF5 identifier and closes it with the matching H5?close.
class Hid {
 public:
  using Closer = herr_t (*)(hid_t);
  Hid(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Hid() { close(); }
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  Hid(Hid&& other) noexcept : id_(std::exchange(other.id_, -1)), closer_(other.closer_) {}
  Hid& operator=(Hid&&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Returns the result of the close call (negative on failure; 0 when nothing to close).
  herr_t close() {
    herr_t result = 0;
    if (id_ >= 0) result = closer_(id_);
    id_ = -1;
    return result;
  }

 private:
  hid_t id_;
  Closer closer_;
};

// HDF5 prints its error stack to stderr by default; geardiag reports errors itself.
void silence_hdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

// The innermost message of the current HDF5 error stack ("" when empty), e.g. "unable to open
// file" or "No space left on device". Call it right after the failing HDF5 call.
std::string hdf5_error_detail() {
  std::string detail;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* err, void* data) -> herr_t {
        if (n == 0 && err->desc != nullptr) *static_cast<std::string*>(data) = err->desc;
        return 0;
      },
      &detail);
  return detail;
}

[[noreturn]] void throw_hdf5(const std::string& where, const std::string& what) {
  const std::string detail = hdf5_error_detail();
  throw std::runtime_error(
      format_error(where, what, "HDF5 error" + (detail.empty() ? "" : ": " + detail)));
}

void check(herr_t status, const std::string& where, const std::string& what) {
  if (status < 0) throw_hdf5(where, what);
}

Hid checked(hid_t id, Hid::Closer closer, const std::string& where, const std::string& what) {
  if (id < 0) throw_hdf5(where, what);
  return Hid(id, closer);
}

Hid utf8_string_type() {
  Hid type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), H5T_VARIABLE) < 0 ||
      H5Tset_cset(type.get(), H5T_CSET_UTF8) < 0) {
    throw_hdf5("write_recording", "string type");
  }
  return type;
}

// ---- writing -------------------------------------------------------------------------------

struct Writer {
  const std::string& where;  // the requested path, for messages
  const Hdf5WriteOptions& options;

  void string_attribute(hid_t obj, const std::string& name, const std::string& value,
                        const std::string& what) const {
    Hid type = utf8_string_type();
    Hid space = checked(H5Screate(H5S_SCALAR), H5Sclose, where, what);
    Hid attr =
        checked(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose, where, what + ": attribute " + name);
    const char* text = value.c_str();
    check(H5Awrite(attr.get(), type.get(), &text), where, what + ": attribute " + name);
  }

  void double_attribute(hid_t obj, const std::string& name, double value,
                        const std::string& what) const {
    Hid space = checked(H5Screate(H5S_SCALAR), H5Sclose, where, what);
    Hid attr = checked(
        H5Acreate2(obj, name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
        H5Aclose, where, what + ": attribute " + name);
    check(H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, &value), where, what + ": attribute " + name);
  }

  void int_attribute(hid_t obj, const std::string& name, int value, const std::string& what) const {
    Hid space = checked(H5Screate(H5S_SCALAR), H5Sclose, where, what);
    Hid attr =
        checked(H5Acreate2(obj, name.c_str(), H5T_STD_I32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose, where, what + ": attribute " + name);
    check(H5Awrite(attr.get(), H5T_NATIVE_INT, &value), where, what + ": attribute " + name);
  }

  // Object creation properties shared by groups and datasets: no timestamps, so that the same
  // recording always gives the same bytes.
  Hid group_plist() const {
    Hid gcpl = checked(H5Pcreate(H5P_GROUP_CREATE), H5Pclose, where, "group properties");
    check(H5Pset_obj_track_times(gcpl.get(), 0), where, "group properties");
    check(H5Pset_link_creation_order(gcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED),
          where, "group properties");
    return gcpl;
  }

  void string_dataset(hid_t parent, const std::string& name, const std::string& value) const {
    const std::string what = "/" + name;
    Hid type = utf8_string_type();
    Hid space = checked(H5Screate(H5S_SCALAR), H5Sclose, where, what);
    Hid dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, where, what);
    check(H5Pset_obj_track_times(dcpl.get(), 0), where, what);
    Hid ds = checked(H5Dcreate2(parent, name.c_str(), type.get(), space.get(), H5P_DEFAULT,
                                dcpl.get(), H5P_DEFAULT),
                     H5Dclose, where, what);
    const char* text = value.c_str();
    check(H5Dwrite(ds.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &text), where, what);
  }

  void signal_dataset(hid_t group, const std::string& group_name, const Signal& s) const {
    const std::string what = "/" + group_name + "/" + s.name;
    const hsize_t length = s.samples.size();
    const hsize_t chunk = std::min<hsize_t>({options.chunk_samples, length, kMaxChunkSamples});
    Hid space = checked(H5Screate_simple(1, &length, nullptr), H5Sclose, where, what);
    Hid dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, where, what);
    check(H5Pset_obj_track_times(dcpl.get(), 0), where, what);
    check(H5Pset_chunk(dcpl.get(), 1, &chunk), where, what);
    if (options.deflate_level > 0) {
      // Byte shuffling groups the exponent bytes of neighbouring samples: deflate then
      // compresses float64 vibration data noticeably better. h5py and MATLAB both decode it.
      check(H5Pset_shuffle(dcpl.get()), where, what + ": shuffle filter");
      check(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(options.deflate_level)), where,
            what + ": deflate filter");
    }
    Hid ds = checked(H5Dcreate2(group, s.name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                dcpl.get(), H5P_DEFAULT),
                     H5Dclose, where, what);
    check(H5Dwrite(ds.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.samples.data()),
          where, what);
    double_attribute(ds.get(), "fs_hz", s.fs_hz, what);
    string_attribute(ds.get(), "unit", s.unit, what);
    string_attribute(ds.get(), "direction", std::string(to_string(s.direction)), what);
    string_attribute(ds.get(), "location", s.location, what);
    // The tacho group holds tachos whatever the in-memory role says; a tacho counts at least
    // one pulse per revolution.
    const bool tacho = group_name == "tacho";
    string_attribute(ds.get(), "role", std::string(to_string(tacho ? Role::kTacho : s.role)), what);
    string_attribute(ds.get(), "shaft", s.shaft, what);
    string_attribute(ds.get(), "mesh", s.mesh, what);
    int_attribute(ds.get(), "ppr", tacho ? std::max(1, s.ppr) : s.ppr, what);
  }

  void signal_group(hid_t file, const std::string& group_name,
                    const std::vector<Signal>& signals) const {
    Hid gcpl = group_plist();
    Hid group = checked(H5Gcreate2(file, group_name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT),
                        H5Gclose, where, "/" + group_name);
    for (const Signal& s : signals) signal_dataset(group.get(), group_name, s);
  }

  void file(const std::string& tmp_path, const Recording& rec) const {
    // The file creation property list is also the root group's creation property list.
    Hid fcpl = checked(H5Pcreate(H5P_FILE_CREATE), H5Pclose, where, "file properties");
    check(H5Pset_obj_track_times(fcpl.get(), 0), where, "file properties");
    check(H5Pset_link_creation_order(fcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED),
          where, "file properties");
    Hid fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, where, "file properties");
    // A fixed format version (1.8 objects) gives reproducible bytes across library versions
    // and stays readable by MATLAB's HDF5 1.8.
    check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18), where,
          "file properties");
    check(H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG), where, "file properties");

    Hid file(H5Fcreate(tmp_path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), H5Fclose);
    if (!file.valid()) {
      const std::string detail = hdf5_error_detail();
      throw InputError(format_error(where, "",
                                    "cannot create " + tmp_path +
                                        " (does the directory exist and is it writable?)" +
                                        (detail.empty() ? "" : ": " + detail)));
    }
    {
      Hid root = checked(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose, where, "/");
      string_attribute(root.get(), "format", kFormatName, "/");
      int_attribute(root.get(), "format_version", kFormatVersion, "/");
      string_attribute(root.get(), "creator", std::string("geardiag ") + GEARDIAG_VERSION, "/");
      string_attribute(root.get(), "git_revision", GEARDIAG_GIT_REVISION, "/");
      if (rec.speed_rpm > 0) double_attribute(root.get(), "input_speed_rpm", rec.speed_rpm, "/");
      int_attribute(root.get(), "roles_stated", rec.roles_stated ? 1 : 0, "/");
      for (const auto& [key, value] : rec.metadata) {
        string_attribute(root.get(), key, value, "/");
      }
    }
    signal_group(file.get(), "signals", rec.signals);
    if (!rec.tachos.empty()) signal_group(file.get(), "tacho", rec.tachos);
    if (!rec.gearbox_json.empty()) string_dataset(file.get(), "gearbox", rec.gearbox_json);
    if (!rec.truth_json.empty()) string_dataset(file.get(), "truth", rec.truth_json);
    check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), where, "flush");
    check(file.close(), where, "close");
  }
};

void validate_for_write(const std::string& where, const Recording& rec,
                        const Hdf5WriteOptions& options) {
  if (options.chunk_samples < 1) {
    throw InputError(format_error(where, "Hdf5WriteOptions.chunk_samples", "must be >= 1"));
  }
  if (options.deflate_level < 0 || options.deflate_level > 9) {
    throw InputError(format_error(where, "Hdf5WriteOptions.deflate_level",
                                  std::to_string(options.deflate_level) + " is not in 0 ... 9"));
  }
  for (const auto* group : {&rec.signals, &rec.tachos}) {
    std::set<std::string_view> names;
    for (const Signal& s : *group) {
      validate(s, where);
      if (!names.insert(s.name).second) {
        throw InputError(format_error(
            where, "channel '" + s.name + "'",
            std::string("appears twice in ") + (group == &rec.signals ? "signals" : "tachos")));
      }
    }
  }
  if (!(rec.speed_rpm >= 0) || !std::isfinite(rec.speed_rpm)) {
    throw InputError(format_error(where, "input_speed_rpm",
                                  std::to_string(rec.speed_rpm) + " is not a finite speed >= 0"));
  }
  for (const auto* group : {&rec.signals, &rec.tachos}) {
    for (const Signal& s : *group) {
      if (s.ppr < 0) {
        throw InputError(format_error(where, "channel '" + s.name + "': ppr", "must be >= 0"));
      }
    }
  }
  for (const auto& [key, value] : rec.metadata) {
    if (key.empty()) throw InputError(format_error(where, "metadata", "empty key"));
    for (const char* reserved : kReservedAttributes) {
      if (key == reserved) {
        throw InputError(format_error(where, "metadata '" + key + "'",
                                      "reserved for the file format; use another key"));
      }
    }
  }
}

// ---- reading -------------------------------------------------------------------------------

// Reads a scalar (or one-element) attribute or dataset as text: strings (variable or fixed
// length) as they are, integers and floats printed (floats with round-trip precision).
// Returns nullopt for other types and shapes. `read(mem_type, buffer)` performs the H5?read.
std::optional<std::string> read_as_text(hid_t file_type, hid_t space,
                                        const std::function<herr_t(hid_t, void*)>& read) {
  if (H5Sget_simple_extent_npoints(space) != 1) return std::nullopt;
  switch (H5Tget_class(file_type)) {
    case H5T_STRING: {
      Hid mem_type(H5Tcopy(H5T_C_S1), H5Tclose);
      if (!mem_type.valid()) return std::nullopt;
      H5Tset_cset(mem_type.get(), H5Tget_cset(file_type));
      if (H5Tis_variable_str(file_type) > 0) {
        H5Tset_size(mem_type.get(), H5T_VARIABLE);
        char* text = nullptr;
        if (read(mem_type.get(), &text) < 0) return std::nullopt;
        std::string out = text != nullptr ? text : "";
        H5free_memory(text);
        return out;
      }
      const std::size_t size = H5Tget_size(file_type);
      H5Tset_size(mem_type.get(), size + 1);
      H5Tset_strpad(mem_type.get(), H5T_STR_NULLTERM);
      std::vector<char> buffer(size + 1, '\0');
      if (read(mem_type.get(), buffer.data()) < 0) return std::nullopt;
      std::string out(buffer.data());
      if (H5Tget_strpad(file_type) == H5T_STR_SPACEPAD) {
        out.erase(out.find_last_not_of(' ') + 1);
      }
      return out;
    }
    case H5T_INTEGER: {
      if (H5Tget_sign(file_type) == H5T_SGN_NONE) {
        unsigned long long value = 0;
        if (read(H5T_NATIVE_ULLONG, &value) < 0) return std::nullopt;
        return std::to_string(value);
      }
      long long value = 0;
      if (read(H5T_NATIVE_LLONG, &value) < 0) return std::nullopt;
      return std::to_string(value);
    }
    case H5T_FLOAT: {
      double value = 0;
      if (read(H5T_NATIVE_DOUBLE, &value) < 0) return std::nullopt;
      char text[32];
      std::snprintf(text, sizeof text, "%.17g", value);
      return std::string(text);
    }
    default:
      return std::nullopt;
  }
}

std::optional<std::string> attribute_text(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) return std::nullopt;
  Hid attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!attr.valid()) return std::nullopt;
  Hid type(H5Aget_type(attr.get()), H5Tclose);
  Hid space(H5Aget_space(attr.get()), H5Sclose);
  if (!type.valid() || !space.valid()) return std::nullopt;
  return read_as_text(type.get(), space.get(), [&](hid_t mem_type, void* buffer) {
    return H5Aread(attr.get(), mem_type, buffer);
  });
}

std::optional<double> attribute_double(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) return std::nullopt;
  Hid attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!attr.valid()) return std::nullopt;
  Hid type(H5Aget_type(attr.get()), H5Tclose);
  Hid space(H5Aget_space(attr.get()), H5Sclose);
  const H5T_class_t cls = type.valid() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
  if ((cls != H5T_FLOAT && cls != H5T_INTEGER) || H5Sget_simple_extent_npoints(space.get()) != 1) {
    return std::nullopt;
  }
  double value = 0;
  if (H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &value) < 0) return std::nullopt;
  return value;
}

bool is_group(hid_t file, const char* path) {
  if (H5Lexists(file, path, H5P_DEFAULT) <= 0) return false;
  Hid obj(H5Oopen(file, path, H5P_DEFAULT), H5Oclose);
  return obj.valid() && H5Iget_type(obj.get()) == H5I_GROUP;
}

// Link names of a group in creation order when the group tracks it, else in name order.
std::vector<std::string> link_names(hid_t group, const std::string& where,
                                    const std::string& what) {
  H5G_info_t info;
  check(H5Gget_info(group, &info), where, what);
  H5_index_t index = H5_INDEX_NAME;
  {
    Hid gcpl(H5Gget_create_plist(group), H5Pclose);
    unsigned flags = 0;
    if (gcpl.valid() && H5Pget_link_creation_order(gcpl.get(), &flags) >= 0 &&
        (flags & H5P_CRT_ORDER_TRACKED) != 0) {
      index = H5_INDEX_CRT_ORDER;
    }
  }
  std::vector<std::string> names;
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t size =
        H5Lget_name_by_idx(group, ".", index, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
    if (size < 0) throw_hdf5(where, what);
    std::string name(static_cast<std::size_t>(size) + 1, '\0');
    if (H5Lget_name_by_idx(group, ".", index, H5_ITER_INC, i, name.data(), name.size(),
                           H5P_DEFAULT) < 0) {
      throw_hdf5(where, what);
    }
    name.resize(static_cast<std::size_t>(size));
    names.push_back(std::move(name));
  }
  return names;
}

std::optional<std::string> string_dataset(hid_t file, const char* path, const std::string& where) {
  if (H5Lexists(file, path, H5P_DEFAULT) <= 0) return std::nullopt;
  Hid ds(H5Dopen2(file, path, H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) {
    throw InputError(format_error(where, path, "is not a dataset"));
  }
  Hid type(H5Dget_type(ds.get()), H5Tclose);
  Hid space(H5Dget_space(ds.get()), H5Sclose);
  if (!type.valid() || !space.valid()) throw_hdf5(where, path);
  auto text = read_as_text(type.get(), space.get(), [&](hid_t mem_type, void* buffer) {
    return H5Dread(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer);
  });
  if (!text || H5Tget_class(type.get()) != H5T_STRING) {
    throw InputError(format_error(where, path, "expected a scalar string dataset"));
  }
  return text;
}

void check_finite(std::span<const double> values, std::uint64_t offset, const std::string& where,
                  const std::string& what) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw InputError(format_error(where, what,
                                    "sample " + std::to_string(offset + i) + " is " +
                                        (std::isnan(values[i]) ? "NaN" : "infinite") +
                                        "; samples must be finite"));
    }
  }
}

}  // namespace

// ---- public ---------------------------------------------------------------------------------

void write_recording(const std::filesystem::path& path, const Recording& rec,
                     const Hdf5WriteOptions& options) {
  silence_hdf5();
  const std::string where = path.string();
  validate_for_write(where, rec, options);

  // Checked before the file is built; a FIFO, device or "-" gets the bytes of a finished file.
  write_output_file_via(path, [&](const std::filesystem::path& file) {
    Writer{where, options}.file(file.string(), rec);
  });
}

bool is_hdf5_file(const std::filesystem::path& path) {
  static constexpr char kSignature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  if (!in.read(head, sizeof head)) return false;
  return std::memcmp(head, kSignature, sizeof head) == 0;
}

RecordingReader::RecordingReader(const std::filesystem::path& path) : path_(path) {
  silence_hdf5();
  const std::string where = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    throw InputError(format_error(where, "", "no such file"));
  }
  if (std::filesystem::is_directory(path, ec)) {
    throw InputError(format_error(where, "", "is a directory, not a recording"));
  }
  if (!is_hdf5_file(path)) {
    throw InputError(format_error(where, "", "not an HDF5 file (or truncated)"));
  }
  {
    Hid fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, where, "file properties");
    check(H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG), where, "file properties");
    file_ = H5Fopen(where.c_str(), H5F_ACC_RDONLY, fapl.get());
  }
  if (file_ < 0) {
    throw InputError(format_error(where, "", "not an HDF5 file (or truncated)"));
  }
  try {
    if (!is_group(file_, "/signals")) {
      throw InputError(format_error(where, "",
                                    "not a geardiag recording (HDF5 file without a /signals "
                                    "group)"));
    }
    {
      Hid root = checked(H5Gopen2(file_, "/", H5P_DEFAULT), H5Gclose, where, "/");
      const auto version = attribute_double(root.get(), "format_version");
      if (version && *version > kFormatVersion) {
        throw InputError(format_error(where, "format_version",
                                      std::to_string(static_cast<long long>(*version)) +
                                          " is newer than this geardiag reads (" +
                                          std::to_string(kFormatVersion) + ")"));
      }
      if (version && !(*version >= 1)) {
        throw InputError(format_error(where, "format_version",
                                      std::to_string(*version) + " is not a format version"));
      }
      format_version_ = version ? static_cast<int>(*version) : 1;
    }
    for (const char* group_name : {"signals", "tacho"}) {
      const std::string group_path = std::string("/") + group_name;
      if (!is_group(file_, group_path.c_str())) continue;
      Hid group =
          checked(H5Gopen2(file_, group_path.c_str(), H5P_DEFAULT), H5Gclose, where, group_path);
      for (const std::string& name : link_names(group.get(), where, group_path)) {
        const std::string what = group_path + "/" + name;
        Hid obj(H5Oopen(group.get(), name.c_str(), H5P_DEFAULT), H5Oclose);
        if (!obj.valid() || H5Iget_type(obj.get()) != H5I_DATASET) continue;  // not a channel
        Hid type(H5Dget_type(obj.get()), H5Tclose);
        Hid space(H5Dget_space(obj.get()), H5Sclose);
        if (!type.valid() || !space.valid()) throw_hdf5(where, what);
        const H5T_class_t cls = H5Tget_class(type.get());
        if (cls != H5T_FLOAT && cls != H5T_INTEGER) {
          throw InputError(format_error(where, what, "expected a numeric dataset"));
        }
        const int rank = H5Sget_simple_extent_ndims(space.get());
        if (rank != 1) {
          throw InputError(format_error(
              where, what, "expected a 1-D dataset, found rank " + std::to_string(rank)));
        }
        hsize_t length = 0;
        H5Sget_simple_extent_dims(space.get(), &length, nullptr);

        ChannelInfo info;
        info.name = name;
        info.group = group_name;
        info.length = length;
        const auto fs_hz = attribute_double(obj.get(), "fs_hz");
        if (!fs_hz) {
          throw InputError(format_error(where, what + ": fs_hz", "missing numeric attribute"));
        }
        if (!(*fs_hz > 0.0) || !std::isfinite(*fs_hz)) {
          throw InputError(format_error(where, what + ": fs_hz",
                                        std::to_string(*fs_hz) + " is not a finite rate > 0"));
        }
        info.fs_hz = *fs_hz;
        info.unit = attribute_text(obj.get(), "unit").value_or("");
        info.location = attribute_text(obj.get(), "location").value_or("");
        const std::string direction = attribute_text(obj.get(), "direction").value_or("");
        try {
          info.direction = direction_from_string(direction);
        } catch (const InputError&) {
          throw InputError(format_error(where, what + ": direction",
                                        "unknown value '" + direction +
                                            "'; expected \"\", along_loa, normal_loa, "
                                            "horizontal, vertical, angle or tacho"));
        }
        if (format_version_ >= 2) {
          const std::string role = attribute_text(obj.get(), "role").value_or("");
          try {
            info.role = role_from_string(role);
          } catch (const InputError&) {
            throw InputError(format_error(where, what + ": role",
                                          "unknown value '" + role +
                                              "'; expected vibration, tacho, angle, speed, force, "
                                              "displacement or other"));
          }
          info.shaft = attribute_text(obj.get(), "shaft").value_or("");
          info.mesh = attribute_text(obj.get(), "mesh").value_or("");
          const double ppr = attribute_double(obj.get(), "ppr").value_or(0.0);
          if (!(ppr >= 0 && ppr <= 1e6) || ppr != std::floor(ppr)) {
            throw InputError(format_error(where, what + ": ppr",
                                          std::to_string(ppr) + " is not an integer in [0, 1e6]"));
          }
          info.ppr = static_cast<int>(ppr);
          if (info.group == "tacho" && (info.role != Role::kTacho || info.ppr < 1)) {
            throw InputError(
                format_error(where, what, "a /tacho channel must have role tacho and ppr >= 1"));
          }
        } else if (info.group == "tacho") {
          info.role = Role::kTacho;
          info.shaft = info.location;
          info.ppr = 1;
        }
        channels_.push_back(std::move(info));
      }
    }
  } catch (...) {
    H5Fclose(file_);
    file_ = -1;
    throw;
  }
}

RecordingReader::~RecordingReader() {
  if (file_ >= 0) H5Fclose(file_);
}

const ChannelInfo& RecordingReader::channel(const std::string& name) const {
  // "group/name" selects a group explicitly; a bare name is looked up in signals, then tacho.
  std::string group;
  std::string bare = name;
  if (const auto slash = name.find('/'); slash != std::string::npos) {
    group = name.substr(0, slash);
    bare = name.substr(slash + 1);
  }
  for (const char* g : {"signals", "tacho"}) {
    if (!group.empty() && group != g) continue;
    for (const ChannelInfo& c : channels_) {
      if (c.group == g && c.name == bare) return c;
    }
  }
  std::string list;
  for (const ChannelInfo& c : channels_) list += (list.empty() ? "" : ", ") + c.name;
  throw InputError(format_error(
      path_.string(), "channel '" + name + "'",
      "no such channel; the recording has: " + (list.empty() ? std::string("none") : list)));
}

std::string RecordingReader::gearbox_json() const {
  return string_dataset(file_, "/gearbox", path_.string()).value_or("");
}

std::string RecordingReader::truth_json() const {
  return string_dataset(file_, "/truth", path_.string()).value_or("");
}

std::map<std::string, std::string> RecordingReader::metadata() const {
  const std::string where = path_.string();
  Hid root = checked(H5Gopen2(file_, "/", H5P_DEFAULT), H5Gclose, where, "/");
  std::vector<std::string> names;
  check(H5Aiterate2(
            root.get(), H5_INDEX_NAME, H5_ITER_INC, nullptr,
            [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
              static_cast<std::vector<std::string>*>(data)->emplace_back(name);
              return 0;
            },
            &names),
        where, "/ attributes");
  std::map<std::string, std::string> out;
  for (const std::string& name : names) {
    if (std::find_if(kReservedAttributes.begin(), kReservedAttributes.end(),
                     [&](const char* r) { return name == r; }) != kReservedAttributes.end()) {
      continue;
    }
    if (auto text = attribute_text(root.get(), name.c_str())) out[name] = std::move(*text);
  }
  return out;
}

bool RecordingReader::roles_stated() const {
  Hid root = checked(H5Gopen2(file_, "/", H5P_DEFAULT), H5Gclose, path_.string(), "/");
  return attribute_double(root.get(), "roles_stated").value_or(1.0) != 0.0;
}

double RecordingReader::speed_rpm() const {
  Hid root = checked(H5Gopen2(file_, "/", H5P_DEFAULT), H5Gclose, path_.string(), "/");
  const double rpm = attribute_double(root.get(), "input_speed_rpm").value_or(0.0);
  if (!(rpm >= 0) || !std::isfinite(rpm)) {
    throw InputError(format_error(path_.string(), "input_speed_rpm",
                                  std::to_string(rpm) + " is not a finite speed >= 0"));
  }
  return rpm;
}

std::map<std::string, std::string> RecordingReader::format_attributes() const {
  Hid root = checked(H5Gopen2(file_, "/", H5P_DEFAULT), H5Gclose, path_.string(), "/");
  std::map<std::string, std::string> out;
  for (const char* name : kReservedAttributes) {
    if (auto text = attribute_text(root.get(), name)) out[name] = std::move(*text);
  }
  return out;
}

void RecordingReader::read_block(const std::string& name, std::uint64_t offset,
                                 std::span<double> out) const {
  const ChannelInfo& c = channel(name);
  const std::string where = path_.string();
  const std::string what = "/" + c.group + "/" + c.name;
  if (offset > c.length || out.size() > c.length - offset) {
    throw InputError(format_error(
        where, what,
        "samples [" + std::to_string(offset) + ", " + std::to_string(offset + out.size()) +
            ") are past the end (length " + std::to_string(c.length) + ")"));
  }
  if (out.empty()) return;
  Hid ds = checked(H5Dopen2(file_, what.c_str(), H5P_DEFAULT), H5Dclose, where, what);
  Hid file_space = checked(H5Dget_space(ds.get()), H5Sclose, where, what);
  const hsize_t start = offset;
  const hsize_t count = out.size();
  check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &start, nullptr, &count, nullptr),
        where, what);
  Hid mem_space = checked(H5Screate_simple(1, &count, nullptr), H5Sclose, where, what);
  if (H5Dread(ds.get(), H5T_NATIVE_DOUBLE, mem_space.get(), file_space.get(), H5P_DEFAULT,
              out.data()) < 0) {
    const std::string detail = hdf5_error_detail();
    throw InputError(format_error(
        where, what,
        "cannot read samples (corrupted file?)" + (detail.empty() ? "" : ": " + detail)));
  }
  check_finite(out, offset, where, what);
}

Recording read_recording(const std::filesystem::path& path) {
  RecordingReader reader(path);
  Recording rec;
  for (const ChannelInfo& c : reader.channels()) {
    Signal& s = (c.group == "signals" ? rec.signals : rec.tachos).emplace_back();
    s.name = c.name;
    s.fs_hz = c.fs_hz;
    s.unit = c.unit;
    s.direction = c.direction;
    s.location = c.location;
    s.samples.resize(static_cast<std::size_t>(c.length));
    s.role = c.role;
    s.shaft = c.shaft;
    s.mesh = c.mesh;
    s.ppr = c.ppr;
    reader.read_block(c.group + "/" + c.name, 0, s.samples);
  }
  rec.gearbox_json = reader.gearbox_json();
  rec.truth_json = reader.truth_json();
  rec.metadata = reader.metadata();
  rec.speed_rpm = reader.speed_rpm();
  if (reader.format_version() < 2) {
    infer_format1_roles(rec);
  } else {
    rec.roles_stated = reader.roles_stated();
  }
  return rec;
}

}  // namespace diag
