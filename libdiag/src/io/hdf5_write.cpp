// The recording writer (diag/io/hdf5.hpp): the file is made in memory (hdf5_file.hpp) and its
// bytes written by write_output_file, so a full disk or a failed write is one clear error, exit 2,
// with the previous file intact and no temporary file left.
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <string_view>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/output_file.hpp"
#include "diag/version.hpp"
#include "hdf5_file.hpp"
#include "hdf5_handle.hpp"
#include "hdf5_recording_format.hpp"

namespace diag {

using hdf5_detail::check;
using hdf5_detail::checked;
using hdf5_detail::Hid;
using hdf5_detail::kFormatName;
using hdf5_detail::kFormatVersion;
using hdf5_detail::kReservedAttributes;

namespace {

// HDF5 limits a chunk to 4 GiB; 2^26 float64 samples (512 MiB) stays far below it.
constexpr std::size_t kMaxChunkSamples = std::size_t{1} << 26;

Hid utf8_string_type() {
  Hid type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), H5T_VARIABLE) < 0 ||
      H5Tset_cset(type.get(), H5T_CSET_UTF8) < 0) {
    hdf5_detail::throw_hdf5("write_recording", "string type");
  }
  return type;
}

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

  // The file's creation and access properties: no timestamps, creation order tracked, a fixed
  // format version (1.8 objects: reproducible bytes across library versions, readable by MATLAB's
  // HDF5 1.8).
  Hid file_create_plist() const {
    // The file creation property list is also the root group's creation property list.
    Hid fcpl = checked(H5Pcreate(H5P_FILE_CREATE), H5Pclose, where, "file properties");
    check(H5Pset_obj_track_times(fcpl.get(), 0), where, "file properties");
    check(H5Pset_link_creation_order(fcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED),
          where, "file properties");
    return fcpl;
  }
  Hid file_access_plist() const {
    Hid fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, where, "file properties");
    check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18), where,
          "file properties");
    return fapl;
  }

  void fill(hid_t file, const Recording& rec) const {
    {
      Hid root = checked(H5Gopen2(file, "/", H5P_DEFAULT), H5Gclose, where, "/");
      string_attribute(root.get(), "format", kFormatName, "/");
      int_attribute(root.get(), "format_version", kFormatVersion, "/");
      string_attribute(root.get(), "creator", std::string("geardiag ") + diag::version(), "/");
      string_attribute(root.get(), "git_revision", diag::git_revision(), "/");
      if (rec.speed_rpm > 0) double_attribute(root.get(), "input_speed_rpm", rec.speed_rpm, "/");
      int_attribute(root.get(), "roles_stated", rec.roles_stated ? 1 : 0, "/");
      for (const auto& [key, value] : rec.metadata) {
        string_attribute(root.get(), key, value, "/");
      }
    }
    signal_group(file, "signals", rec.signals);
    if (!rec.tachos.empty()) signal_group(file, "tacho", rec.tachos);
    if (!rec.gearbox_json.empty()) string_dataset(file, "gearbox", rec.gearbox_json);
    if (!rec.truth_json.empty()) string_dataset(file, "truth", rec.truth_json);
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

}  // namespace

void write_recording(const std::filesystem::path& path, const Recording& rec,
                     const Hdf5WriteOptions& options) {
  const std::string where = path.string();
  validate_for_write(where, rec, options);
  const auto library = hdf5_detail::hold_hdf5();
  // Checked before the file is built.
  (void)check_output_path(path);
  const Writer writer{where, options};
  const Hid fcpl = writer.file_create_plist();
  const Hid fapl = writer.file_access_plist();
  const std::string bytes = hdf5_detail::hdf5_file_bytes(
      where, fcpl.get(), fapl.get(), [&](hid_t file) { writer.fill(file, rec); });
  write_output_file(path, bytes);
}

}  // namespace diag
