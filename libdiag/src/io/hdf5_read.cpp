// The recording reader (diag/io/hdf5.hpp) and read_hdf5_arrays: every file opened once through
// hdf5_file.hpp (structure checked there), read first by the crash guard's child
// (crash_guard.hpp).
#include <hdf5.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "crash_guard.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/hdf5_arrays.hpp"
#include "diag/io/input_file.hpp"
#include "diag/io/printable.hpp"
#include "hdf5_chunks.hpp"
#include "hdf5_file.hpp"
#include "hdf5_handle.hpp"
#include "hdf5_recording_format.hpp"

namespace diag {

using hdf5_detail::check;
using hdf5_detail::checked;
using hdf5_detail::hdf5_error_detail;
using hdf5_detail::Hdf5Source;
using hdf5_detail::Hid;
using hdf5_detail::kFormatVersion;
using hdf5_detail::kReservedAttributes;

namespace {

// An attribute that exists but cannot be read is damage, not absence: InputError naming it.
[[noreturn]] void unreadable(const std::string& where, const std::string& what) {
  const std::string detail = hdf5_error_detail();
  throw InputError(format_error(
      where, what, "cannot be read (corrupted file?)" + (detail.empty() ? "" : ": " + detail)));
}

// Reads a scalar (or one-element) attribute or dataset as text: strings (variable or fixed
// length) as they are, integers and floats printed (floats with round-trip precision).
// Returns nullopt for other types and shapes; throws InputError when the value cannot be read or a
// fixed-length string is longer than kMaxStringBytes. `read(mem_type, buffer)` performs the
// H5?read.
constexpr std::size_t kMaxStringBytes = std::size_t{64} << 20;

std::optional<std::string> read_as_text(hid_t file_type, hid_t space, const std::string& where,
                                        const std::string& what,
                                        const std::function<herr_t(hid_t, void*)>& read) {
  if (H5Sget_simple_extent_npoints(space) != 1) return std::nullopt;
  switch (H5Tget_class(file_type)) {
    case H5T_STRING: {
      Hid mem_type(H5Tcopy(H5T_C_S1), H5Tclose);
      if (!mem_type.valid()) unreadable(where, what);
      H5Tset_cset(mem_type.get(), H5Tget_cset(file_type));
      if (H5Tis_variable_str(file_type) > 0) {
        H5Tset_size(mem_type.get(), H5T_VARIABLE);
        char* text = nullptr;
        if (read(mem_type.get(), &text) < 0) unreadable(where, what);
        std::string out = text != nullptr ? text : "";
        H5free_memory(text);
        return out;
      }
      const std::size_t size = H5Tget_size(file_type);
      if (size == 0 || size > kMaxStringBytes) {
        throw InputError(format_error(
            where, what, "string of " + std::to_string(size) + " bytes (corrupted file?)"));
      }
      H5Tset_size(mem_type.get(), size + 1);
      H5Tset_strpad(mem_type.get(), H5T_STR_NULLTERM);
      std::vector<char> buffer(size + 1, '\0');
      if (read(mem_type.get(), buffer.data()) < 0) unreadable(where, what);
      std::string out(buffer.data());
      if (H5Tget_strpad(file_type) == H5T_STR_SPACEPAD) {
        out.erase(out.find_last_not_of(' ') + 1);
      }
      return out;
    }
    case H5T_INTEGER: {
      if (H5Tget_sign(file_type) == H5T_SGN_NONE) {
        unsigned long long value = 0;
        if (read(H5T_NATIVE_ULLONG, &value) < 0) unreadable(where, what);
        return std::to_string(value);
      }
      long long value = 0;
      if (read(H5T_NATIVE_LLONG, &value) < 0) unreadable(where, what);
      return std::to_string(value);
    }
    case H5T_FLOAT: {
      double value = 0;
      if (read(H5T_NATIVE_DOUBLE, &value) < 0) unreadable(where, what);
      char text[32];
      std::snprintf(text, sizeof text, "%.17g", value);
      return std::string(text);
    }
    default:
      return std::nullopt;
  }
}

// Opens attribute `name` of `obj`; an invalid Hid when it does not exist.
Hid open_attribute(hid_t obj, const char* name, const std::string& where, const std::string& what) {
  const htri_t exists = H5Aexists(obj, name);
  if (exists < 0) unreadable(where, what);
  if (exists == 0) return Hid(-1, H5Aclose);
  Hid attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!attr.valid()) unreadable(where, what);
  return attr;
}

std::optional<std::string> attribute_text(hid_t obj, const char* name, const std::string& where,
                                          const std::string& what) {
  const std::string field = what + ": attribute " + name;
  Hid attr = open_attribute(obj, name, where, field);
  if (!attr.valid()) return std::nullopt;
  Hid type(H5Aget_type(attr.get()), H5Tclose);
  Hid space(H5Aget_space(attr.get()), H5Sclose);
  if (!type.valid() || !space.valid()) unreadable(where, field);
  return read_as_text(type.get(), space.get(), where, field, [&](hid_t mem_type, void* buffer) {
    return H5Aread(attr.get(), mem_type, buffer);
  });
}

std::optional<double> attribute_double(hid_t obj, const char* name, const std::string& where,
                                       const std::string& what) {
  const std::string field = what + ": attribute " + name;
  Hid attr = open_attribute(obj, name, where, field);
  if (!attr.valid()) return std::nullopt;
  Hid type(H5Aget_type(attr.get()), H5Tclose);
  Hid space(H5Aget_space(attr.get()), H5Sclose);
  if (!type.valid() || !space.valid()) unreadable(where, field);
  const H5T_class_t cls = H5Tget_class(type.get());
  if ((cls != H5T_FLOAT && cls != H5T_INTEGER) || H5Sget_simple_extent_npoints(space.get()) != 1) {
    return std::nullopt;
  }
  double value = 0;
  if (H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &value) < 0) unreadable(where, field);
  return value;
}

// True when `parent` has a hard link `name`; false when it has none. Soft links (which can loop)
// and external links (which name other files, /dev/zero included) are refused: a recording holds
// its objects itself.
bool hard_link_exists(hid_t parent, const char* name, const std::string& where,
                      const std::string& what) {
  const htri_t exists = H5Lexists(parent, name, H5P_DEFAULT);
  if (exists < 0) unreadable(where, what);
  if (exists == 0) return false;
  H5L_info_t info;
  if (H5Lget_info(parent, name, &info, H5P_DEFAULT) < 0) unreadable(where, what);
  if (info.type != H5L_TYPE_HARD) {
    const char* kind = info.type == H5L_TYPE_SOFT       ? "a soft link"
                       : info.type == H5L_TYPE_EXTERNAL ? "an external link"
                                                        : "a user-defined link";
    throw InputError(format_error(
        where, what,
        std::string("is ") + kind + "; the file must hold its groups and datasets itself"));
  }
  return true;
}

bool is_group(hid_t file, const char* path, const std::string& where) {
  if (!hard_link_exists(file, path, where, path)) return false;
  Hid obj(H5Oopen(file, path, H5P_DEFAULT), H5Oclose);
  if (!obj.valid()) unreadable(where, path);
  return H5Iget_type(obj.get()) == H5I_GROUP;
}

// Link names of a group in creation order when the group tracks it, else in name order.
std::vector<std::string> link_names(hid_t group, const std::string& where,
                                    const std::string& what) {
  H5G_info_t info;
  if (H5Gget_info(group, &info) < 0) unreadable(where, what);
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
    if (size < 0 || static_cast<std::size_t>(size) > kMaxStringBytes) unreadable(where, what);
    std::string name(static_cast<std::size_t>(size) + 1, '\0');
    if (H5Lget_name_by_idx(group, ".", index, H5_ITER_INC, i, name.data(), name.size(),
                           H5P_DEFAULT) < 0) {
      unreadable(where, what);
    }
    name.resize(static_cast<std::size_t>(size));
    names.push_back(std::move(name));
  }
  return names;
}

// A scalar string dataset that holds JSON (/gearbox, /truth); nullopt when absent. Text that is
// not JSON is refused here, before anything copies it into another file.
std::optional<std::string> json_dataset(hid_t file, const char* path, const std::string& where) {
  if (!hard_link_exists(file, path, where, path)) return std::nullopt;
  Hid ds(H5Dopen2(file, path, H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) {
    throw InputError(format_error(where, path, "is not a dataset"));
  }
  Hid type(H5Dget_type(ds.get()), H5Tclose);
  Hid space(H5Dget_space(ds.get()), H5Sclose);
  if (!type.valid() || !space.valid()) unreadable(where, path);
  if (H5Tget_class(type.get()) != H5T_STRING) {
    throw InputError(format_error(where, path, "expected a scalar string dataset"));
  }
  auto text = read_as_text(type.get(), space.get(), where, path, [&](hid_t mem_type, void* buffer) {
    return H5Dread(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer);
  });
  if (!text) throw InputError(format_error(where, path, "expected a scalar string dataset"));
  if (!nlohmann::json::accept(*text)) {
    throw InputError(format_error(where, path, "is not valid JSON (corrupted file?)"));
  }
  return text;
}

// The bytes a channel's samples occupy in the file are checked against its declared length
// before anything is allocated: a corrupted dataspace cannot declare 10^18 samples. Unfiltered
// data must be all there; deflated data can expand at most 1032:1 (RFC 1951).
void check_storage(hid_t ds, hsize_t length, std::size_t element_size, const std::string& where,
                   const std::string& what) {
  constexpr hsize_t kMaxInflateRatio = 1032;
  const hsize_t stored = H5Dget_storage_size(ds);
  Hid dcpl(H5Dget_create_plist(ds), H5Pclose);
  if (!dcpl.valid()) unreadable(where, what);
  const int filters = H5Pget_nfilters(dcpl.get());
  if (filters < 0) unreadable(where, what);
  const hsize_t max_length =
      filters == 0 ? stored / element_size : stored / element_size * kMaxInflateRatio + 1;
  if (stored == 0 || length > max_length) {
    throw InputError(format_error(where, what,
                                  "declares " + std::to_string(length) + " samples but stores " +
                                      std::to_string(stored) +
                                      " bytes (truncated or corrupted file)"));
  }
}

// Sampling rates a recording may state [Hz].
constexpr double kMinFsHz = 1e-3, kMaxFsHz = 1e9;

// The crash guard's child (crash_guard.hpp) reads everything RecordingReader and read_recording
// read (survey_recording: the samples too when they are at most kSurveySampleBytes), or the
// arrays read_hdf5_arrays reads.
constexpr std::uint64_t kSurveySampleBytes = std::uint64_t{16} << 20;

}  // namespace

// A shared anonymous mapping of kSurveySampleBytes (reserved, not touched), made before the
// survey child is forked: the child decodes every channel's samples into it, one after the other
// in channels() order, and the parent copies them out when the child finished without error
// instead of decoding the file again (half the read of a small file).
struct SurveyedSamples {
  SurveyedSamples() {
    void* p = ::mmap(nullptr, kSurveySampleBytes, PROT_READ | PROT_WRITE,
                     MAP_SHARED | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (p != MAP_FAILED) data = static_cast<double*>(p);
  }
  ~SurveyedSamples() {
    if (data != nullptr) ::munmap(data, kSurveySampleBytes);
  }
  SurveyedSamples(const SurveyedSamples&) = delete;
  SurveyedSamples& operator=(const SurveyedSamples&) = delete;

  double* data = nullptr;              // nullptr when the mapping failed
  std::vector<std::uint64_t> offsets;  // per channel (channels() order) [samples]
};

namespace {

// Bytes of all channels' samples (as doubles).
std::uint64_t sample_bytes(const std::vector<ChannelInfo>& channels) {
  std::uint64_t total = 0;
  for (const ChannelInfo& c : channels) total += c.length * sizeof(double);
  return total;
}

// What RecordingReader and read_recording read (the samples too when they are at most
// kSurveySampleBytes: into `shared`, one channel after the other, when given).
void survey_recording(const RecordingReader& reader, double* shared) {
  (void)reader.metadata();
  (void)reader.format_attributes();
  (void)reader.gearbox_json();
  (void)reader.truth_json();
  (void)reader.speed_rpm();
  (void)reader.roles_stated();
  if (sample_bytes(reader.channels()) <= kSurveySampleBytes) {
    std::vector<double> own;
    for (const ChannelInfo& c : reader.channels()) {
      const auto n = static_cast<std::size_t>(c.length);
      if (shared == nullptr) own.resize(n);
      reader.read_block(c.group + "/" + c.name, 0,
                        std::span<double>(shared != nullptr ? shared : own.data(), n));
      if (shared != nullptr) shared += n;
    }
  }
}

// Runs a read of the file: an error that escapes as anything but InputError (an HDF5 call
// reported by check/checked, a length a corrupted field made impossible) is reported as damage
// to the file, exit 2, never as an internal error.
template <typename F>
auto reading(const std::string& where, F&& f) -> decltype(f()) {
  const auto library = hdf5_detail::hold_hdf5();
  try {
    return f();
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw InputError(format_error(where, "", "sizes too large to read (corrupted file?)"));
  } catch (const std::exception& e) {
    throw InputError(
        format_error(where, "", std::string("cannot read (corrupted file?): ") + e.what()));
  }
}

// A double is NaN or infinite exactly when its 11 exponent bits are all ones (IEEE 754).
constexpr std::uint64_t kExponentBits = 0x7FF0000000000000;

// Whether `values` has a NaN or infinity: branch-free over blocks of 8 (which the
// compiler vectorises), the exact sample located only when there is one.
bool any_non_finite(std::span<const double> values) {
  std::size_t i = 0;
  std::uint64_t bad = 0;
  for (; i + 8 <= values.size(); i += 8) {
    for (std::size_t k = 0; k < 8; ++k) {
      const auto bits = std::bit_cast<std::uint64_t>(values[i + k]);
      bad |= static_cast<std::uint64_t>((bits & kExponentBits) == kExponentBits);
    }
  }
  for (; i < values.size(); ++i) {
    bad |= static_cast<std::uint64_t>(!std::isfinite(values[i]));
  }
  return bad != 0;
}

void check_finite(std::span<const double> values, std::uint64_t offset, const std::string& where,
                  const std::string& what) {
  if (!any_non_finite(values)) return;
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

bool is_hdf5_file(const std::filesystem::path& path) {
  static constexpr char kSignature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  // Only a regular file is opened: opening a FIFO would wait for a writer.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  if (!in.read(head, sizeof head)) return false;
  return std::memcmp(head, kSignature, sizeof head) == 0;
}

RecordingReader::RecordingReader(const std::filesystem::path& path)
    : path_(path), decoded_(std::make_shared<DecodedChunk>()) {
  const std::string where = path.string();
  // Opened once: the guard's child and this process read the same file through its descriptor.
  source_ = std::make_shared<const Hdf5Source>(path, true);
  auto surveyed = hdf5_detail::in_guard_child() ? nullptr : std::make_shared<SurveyedSamples>();
  const bool survey_done = hdf5_detail::run_guarded(where, [&] {
    open_file();
    survey_recording(*this, surveyed ? surveyed->data : nullptr);
  });
  open_file();
  // The child read the same file's channels in the same order, and all of them without error.
  if (survey_done && surveyed && surveyed->data != nullptr && hdf5_detail::reuse_survey() &&
      sample_bytes(channels_) <= kSurveySampleBytes) {
    std::uint64_t at = 0;
    for (const ChannelInfo& c : channels_) {
      surveyed->offsets.push_back(at);
      at += c.length;
    }
    surveyed_ = std::move(surveyed);
  }
}

void RecordingReader::open_file() {
  const std::string where = path_.string();
  const auto library = hdf5_detail::hold_hdf5();
  Hid file = reading(where, [&] { return source_->open(); });
  file_ = file.release();
  try {
    reading(where, [&] { open_channels(); });
  } catch (...) {
    H5Fclose(file_);
    file_ = -1;
    throw;
  }
}

void RecordingReader::open_channels() {
  const std::string where = path_.string();
  if (!is_group(file_, "/signals", where)) {
    throw InputError(format_error(where, "",
                                  "not a geardiag recording (HDF5 file without a /signals "
                                  "group)"));
  }
  {
    Hid root = checked(H5Gopen2(file_, "/", H5P_DEFAULT), H5Gclose, where, "/");
    const auto version = attribute_double(root.get(), "format_version", where, "/");
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
    if (!is_group(file_, group_path.c_str(), where)) continue;
    Hid group =
        checked(H5Gopen2(file_, group_path.c_str(), H5P_DEFAULT), H5Gclose, where, group_path);
    for (const std::string& name : link_names(group.get(), where, group_path)) {
      const std::string what = group_path + "/" + name;
      if (!hard_link_exists(group.get(), name.c_str(), where, what)) unreadable(where, what);
      Hid obj(H5Oopen(group.get(), name.c_str(), H5P_DEFAULT), H5Oclose);
      if (!obj.valid()) unreadable(where, what);
      if (H5Iget_type(obj.get()) != H5I_DATASET) continue;  // not a channel
      Hid type(H5Dget_type(obj.get()), H5Tclose);
      Hid space(H5Dget_space(obj.get()), H5Sclose);
      if (!type.valid() || !space.valid()) unreadable(where, what);
      const H5T_class_t cls = H5Tget_class(type.get());
      const std::size_t element_size = H5Tget_size(type.get());
      if ((cls != H5T_FLOAT && cls != H5T_INTEGER) || element_size < 1 || element_size > 16) {
        throw InputError(format_error(where, what, "expected a numeric dataset"));
      }
      const int rank = H5Sget_simple_extent_ndims(space.get());
      if (rank != 1) {
        throw InputError(format_error(
            where, what, "expected a 1-D dataset, found rank " + std::to_string(rank)));
      }
      hsize_t length = 0;
      if (H5Sget_simple_extent_dims(space.get(), &length, nullptr) < 0) unreadable(where, what);
      if (length == 0) throw InputError(format_error(where, what, "has no samples"));
      check_storage(obj.get(), length, element_size, where, what);

      ChannelInfo info;
      info.name = name;
      info.group = group_name;
      info.length = length;
      const auto fs_hz = attribute_double(obj.get(), "fs_hz", where, what);
      if (!fs_hz) {
        throw InputError(format_error(where, what + ": fs_hz", "missing numeric attribute"));
      }
      if (!(*fs_hz >= kMinFsHz && *fs_hz <= kMaxFsHz)) {
        throw InputError(format_error(where, what + ": fs_hz",
                                      std::to_string(*fs_hz) + " is not a rate in [1e-3, 1e9] Hz"));
      }
      info.fs_hz = *fs_hz;
      info.unit = attribute_text(obj.get(), "unit", where, what).value_or("");
      info.location = attribute_text(obj.get(), "location", where, what).value_or("");
      const std::string direction =
          attribute_text(obj.get(), "direction", where, what).value_or("");
      try {
        info.direction = direction_from_string(direction);
      } catch (const InputError&) {
        throw InputError(format_error(where, what + ": direction",
                                      "unknown value '" + direction +
                                          "'; expected \"\", along_loa, normal_loa, "
                                          "horizontal, vertical, angle or tacho"));
      }
      // Names and labels are printed: an escape sequence in them would reach the terminal.
      for (const auto& [label, text] :
           {std::pair<const char*, const std::string*>{"name", &info.name},
            {"unit", &info.unit},
            {"location", &info.location}}) {
        if (has_control_characters(*text)) {
          throw InputError(
              format_error(where, printable_text(what) + ": " + label,
                           "'" + printable_text(*text) + "' holds a control character"));
        }
      }
      if (format_version_ >= 2) {
        const std::string role = attribute_text(obj.get(), "role", where, what).value_or("");
        try {
          info.role = role_from_string(role);
        } catch (const InputError&) {
          throw InputError(format_error(where, what + ": role",
                                        "unknown value '" + role +
                                            "'; expected vibration, tacho, angle, speed, force, "
                                            "displacement or other"));
        }
        info.shaft = attribute_text(obj.get(), "shaft", where, what).value_or("");
        info.mesh = attribute_text(obj.get(), "mesh", where, what).value_or("");
        const double ppr = attribute_double(obj.get(), "ppr", where, what).value_or(0.0);
        if (!(ppr >= 0 && ppr <= 1e6) || ppr != std::floor(ppr)) {
          throw InputError(format_error(where, what + ": ppr",
                                        std::to_string(ppr) + " is not an integer in [0, 1e6]"));
        }
        info.ppr = static_cast<int>(ppr);
        for (const auto& [label, text] :
             {std::pair<const char*, const std::string*>{"shaft", &info.shaft},
              {"mesh", &info.mesh}}) {
          if (has_control_characters(*text)) {
            throw InputError(
                format_error(where, printable_text(what) + ": " + label,
                             "'" + printable_text(*text) + "' holds a control character"));
          }
        }
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
  if (std::none_of(channels_.begin(), channels_.end(),
                   [](const ChannelInfo& c) { return c.group == "signals"; })) {
    throw InputError(format_error(where, "/signals", "holds no channels (an empty recording)"));
  }
}

RecordingReader::~RecordingReader() {
  if (file_ < 0) return;
  const auto library = hdf5_detail::hold_hdf5();
  H5Fclose(file_);
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
  const std::string where = path_.string();
  return reading(where, [&] { return json_dataset(file_, "/gearbox", where).value_or(""); });
}

std::string RecordingReader::truth_json() const {
  const std::string where = path_.string();
  return reading(where, [&] { return json_dataset(file_, "/truth", where).value_or(""); });
}

std::map<std::string, std::string> RecordingReader::metadata() const {
  const std::string where = path_.string();
  return reading(where, [&] {
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
      if (auto text = attribute_text(root.get(), name.c_str(), where, "/")) {
        out[printable_text(name)] = printable_text(*text);  // shown to the user
      }
    }
    return out;
  });
}

bool RecordingReader::roles_stated() const {
  const std::string where = path_.string();
  return reading(where, [&] {
    Hid root = checked(H5Gopen2(file_, "/", H5P_DEFAULT), H5Gclose, where, "/");
    return attribute_double(root.get(), "roles_stated", where, "/").value_or(1.0) != 0.0;
  });
}

double RecordingReader::speed_rpm() const {
  const std::string where = path_.string();
  const double rpm = reading(where, [&] {
    Hid root = checked(H5Gopen2(file_, "/", H5P_DEFAULT), H5Gclose, where, "/");
    return attribute_double(root.get(), "input_speed_rpm", where, "/").value_or(0.0);
  });
  if (!(rpm >= 0) || !std::isfinite(rpm)) {
    throw InputError(format_error(where, "input_speed_rpm",
                                  std::to_string(rpm) + " is not a finite speed >= 0"));
  }
  return rpm;
}

std::map<std::string, std::string> RecordingReader::format_attributes() const {
  const std::string where = path_.string();
  return reading(where, [&] {
    Hid root = checked(H5Gopen2(file_, "/", H5P_DEFAULT), H5Gclose, where, "/");
    std::map<std::string, std::string> out;
    for (const char* name : kReservedAttributes) {
      if (auto text = attribute_text(root.get(), name, where, "/")) out[name] = std::move(*text);
    }
    return out;
  });
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
  if (surveyed_) {
    const double* from =
        surveyed_->data + surveyed_->offsets[static_cast<std::size_t>(&c - channels_.data())];
    std::memcpy(out.data(), from + offset, out.size() * sizeof(double));
  } else {
    reading(where, [&] { read_samples(what, offset, out); });
  }
  check_finite(out, offset, where, what);
}

void RecordingReader::read_samples(const std::string& what, std::uint64_t offset,
                                   std::span<double> out) const {
  const std::string where = path_.string();
  Hid ds = checked(H5Dopen2(file_, what.c_str(), H5P_DEFAULT), H5Dclose, where, what);
  // Shuffled and deflated float64 chunks are decoded here (diag/io/hdf5_inflate.hpp).
  if (hdf5_detail::read_chunks_direct(ds.get(), where, what, offset, out, *decoded_)) return;
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
}

std::uint64_t samples_within(std::uint64_t length, double fs_hz, double t) {
  if (!std::isfinite(t)) return length;
  const double n = std::floor(t * fs_hz);
  if (n <= 0) return 0;
  return n >= static_cast<double>(length) ? length : static_cast<std::uint64_t>(n);
}

namespace {

std::vector<ChannelExtent> extents(const RecordingReader& reader) {
  std::vector<ChannelExtent> out;
  for (const ChannelInfo& c : reader.channels()) out.push_back({c.length, c.fs_hz});
  return out;
}

// The samples [t0 fs, t1 fs) of every channel of the file, with the file's description.
Recording read_span(const RecordingReader& reader, double t0,
                    double t1 = std::numeric_limits<double>::infinity()) {
  Recording rec;
  for (const ChannelInfo& c : reader.channels()) {
    Signal& s = (c.group == "signals" ? rec.signals : rec.tachos).emplace_back();
    s.identity() = c.identity();
    const std::uint64_t first = samples_within(c.length, c.fs_hz, t0);
    const std::uint64_t end = samples_within(c.length, c.fs_hz, t1);
    s.samples.resize(static_cast<std::size_t>(end > first ? end - first : 0));
    reader.read_block(c.group + "/" + c.name, first, s.samples);
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

}  // namespace

double seconds_within_limits(std::span<const ChannelExtent> channels, const ReadLimits& limits) {
  auto fits = [&](double t) {
    std::uint64_t sum = 0, longest = 0;
    for (const ChannelExtent& c : channels) {
      const std::uint64_t n = samples_within(c.length, c.fs_hz, t);
      sum += n;
      longest = std::max(longest, n);
    }
    return longest <= limits.max_channel_samples &&
           (sum <= limits.max_samples || longest <= limits.kept_channel_samples);
  };
  if (fits(std::numeric_limits<double>::infinity())) return std::numeric_limits<double>::infinity();
  // Bisection on t: every condition of fits() only fails more as t grows.
  double lo = 0, hi = 0;
  for (const ChannelExtent& c : channels) {
    hi = std::max(hi, static_cast<double>(c.length) / c.fs_hz);
  }
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (fits(mid) ? lo : hi) = mid;
  }
  return lo;
}

Recording read_recording_span(const RecordingReader& reader, double t0_s, double t1_s) {
  return reading(reader.path().string(), [&] { return read_span(reader, t0_s, t1_s); });
}

Recording read_recording(const std::filesystem::path& path) {
  RecordingReader reader(path);
  return reading(path.string(), [&] { return read_span(reader, 0); });
}

Recording read_recording(const std::filesystem::path& path, const ReadLimits& limits, bool* cut) {
  RecordingReader reader(path);
  return reading(path.string(), [&] {
    const std::vector<ChannelExtent> all = extents(reader);
    const double t = seconds_within_limits(all, limits);
    if (cut) *cut = std::isfinite(t);
    Recording rec = read_span(reader, 0, t);
    if (std::isfinite(t)) {
      double whole = 0, kept = 0;
      for (const ChannelInfo& c : reader.channels()) {
        whole = std::max(whole, static_cast<double>(c.length) / c.fs_hz);
        kept = std::max(kept, static_cast<double>(samples_within(c.length, c.fs_hz, t)) / c.fs_hz);
      }
      std::ostringstream note;
      note << std::setprecision(4) << "long recording: the first " << kept << " s of " << whole
           << " s analysed (kept in memory: at most " << limits.max_samples << " samples in all or "
           << limits.kept_channel_samples << " per channel, never over "
           << limits.max_channel_samples << " per channel)";
      rec.notes.push_back(note.str());
    }
    return rec;
  });
}

namespace {

// One numeric dataset of an untrusted file as doubles; nullopt when the path (or a group on it)
// does not exist. Every component of the path must be a hard link.
std::optional<Hdf5Array> read_numeric_dataset(hid_t file, const std::string& path,
                                              std::size_t max_values, const std::string& where) {
  if (path.size() < 2 || path[0] != '/' || path.back() == '/') {
    throw std::invalid_argument("read_hdf5_arrays: '" + path + "' is not an absolute path");
  }
  for (std::size_t slash = path.find('/', 1);; slash = path.find('/', slash + 1)) {
    const std::string prefix = path.substr(0, slash);
    if (!hard_link_exists(file, prefix.c_str(), where, prefix)) return std::nullopt;
    if (slash == std::string::npos) break;
    if (!is_group(file, prefix.c_str(), where)) {
      throw InputError(format_error(where, prefix, "is not a group"));
    }
  }
  Hid obj(H5Oopen(file, path.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.valid()) unreadable(where, path);
  if (H5Iget_type(obj.get()) != H5I_DATASET) {
    throw InputError(format_error(where, path, "is not a dataset"));
  }
  Hid ds = checked(H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose, where, path);
  Hid type(H5Dget_type(ds.get()), H5Tclose);
  Hid space(H5Dget_space(ds.get()), H5Sclose);
  if (!type.valid() || !space.valid()) unreadable(where, path);
  const H5T_class_t cls = H5Tget_class(type.get());
  if (cls != H5T_FLOAT && cls != H5T_INTEGER) {
    throw InputError(format_error(where, path, "must hold numbers (integer or float)"));
  }
  if (H5Sget_simple_extent_type(space.get()) != H5S_SIMPLE) {
    throw InputError(format_error(where, path, "must be a 1-D or 2-D array"));
  }
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 1 || rank > 2) {
    throw InputError(format_error(
        where, path,
        "must be a 1-D or 2-D array (it has " + std::to_string(rank) + " dimensions)"));
  }
  hsize_t dims[2] = {0, 0};
  if (H5Sget_simple_extent_dims(space.get(), dims, nullptr) != rank) unreadable(where, path);
  Hdf5Array out;
  out.path = path;
  hsize_t n = 1;
  for (int d = 0; d < rank; ++d) {
    if (dims[d] == 0) throw InputError(format_error(where, path, "is empty"));
    if (dims[d] > max_values / n) {
      throw InputError(format_error(
          where, path, "has more than " + std::to_string(max_values) + " values (refused)"));
    }
    n *= dims[d];
    out.shape.push_back(static_cast<std::size_t>(dims[d]));
  }
  check_storage(ds.get(), n, H5Tget_size(type.get()), where, path);
  out.data.resize(static_cast<std::size_t>(n));
  if (H5Dread(ds.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data.data()) < 0) {
    unreadable(where, path);
  }
  check_finite(out.data, 0, where, path);
  if (auto unit = attribute_text(ds.get(), "unit", where, path)) out.unit = *unit;
  return out;
}

std::map<std::string, Hdf5Array> read_arrays(const Hdf5Source& source,
                                             const std::vector<std::string>& names,
                                             std::size_t max_values) {
  const std::string& where = source.where();
  Hid file = source.open();
  std::map<std::string, Hdf5Array> out;
  for (const std::string& name : names) {
    if (auto a = read_numeric_dataset(file.get(), name, max_values, where)) {
      out.emplace(name, std::move(*a));
    }
  }
  return out;
}

}  // namespace

std::map<std::string, Hdf5Array> read_hdf5_arrays(const std::filesystem::path& path,
                                                  const std::vector<std::string>& names,
                                                  std::size_t max_values) {
  const std::string where = path.string();
  const Hdf5Source source(path, true);  // opened once: the guard's child reads this descriptor
  hdf5_detail::run_guarded(where, [&] { (void)read_arrays(source, names, max_values); });
  return reading(where, [&] { return read_arrays(source, names, max_values); });
}

}  // namespace diag
