// The curves file (data_groups.hpp): HDF5 groups of float64 columns with units.
#include "diag/io/data_groups.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <set>
#include <stdexcept>

#include "diag/error.hpp"
#include "diag/io/output_file.hpp"
#include "diag/version.hpp"
#include "hdf5_file.hpp"
#include "hdf5_handle.hpp"

namespace diag {

using hdf5_detail::Hid;

namespace {

// An HDF5 identifier that must be valid: a negative one throws at once.
Hid owned(hid_t id, Hid::Closer closer, const std::string& what) {
  if (id < 0) throw std::runtime_error("curves: HDF5 error: " + what);
  return Hid(id, closer);
}

void put(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("curves: HDF5 error: " + what);
}

void text_attribute(hid_t obj, const std::string& name, const std::string& value) {
  const Hid type = owned(H5Tcopy(H5T_C_S1), H5Tclose, name);
  put(H5Tset_size(type.get(), H5T_VARIABLE), name);
  put(H5Tset_cset(type.get(), H5T_CSET_UTF8), name);
  const Hid space = owned(H5Screate(H5S_SCALAR), H5Sclose, name);
  const Hid attr =
      owned(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
            H5Aclose, name);
  const char* text = value.c_str();
  put(H5Awrite(attr.get(), type.get(), &text), name);
}

void number_attribute(hid_t obj, const std::string& name, double value) {
  const Hid space = owned(H5Screate(H5S_SCALAR), H5Sclose, name);
  const Hid attr =
      owned(H5Acreate2(obj, name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
            H5Aclose, name);
  put(H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, &value), name);
}

// Group creation properties: no timestamps, so that the same curves give the same bytes.
Hid group_plist() {
  Hid gcpl = owned(H5Pcreate(H5P_GROUP_CREATE), H5Pclose, "group properties");
  put(H5Pset_obj_track_times(gcpl.get(), 0), "group properties");
  return gcpl;
}

// Opens the group at `path` ("a/b/c"), creating the missing ones on the way.
Hid open_or_create(hid_t file, const std::string& path) {
  const Hid gcpl = group_plist();
  std::string prefix;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    prefix += "/" + path.substr(start, end - start);
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) {
      owned(H5Gcreate2(file, prefix.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose,
            prefix);
    }
    start = end + 1;
  }
  return owned(H5Gopen2(file, prefix.c_str(), H5P_DEFAULT), H5Gclose, path);
}

void check_names(std::span<const DataGroup> groups, const std::string& where) {
  std::set<std::string> seen;
  for (const DataGroup& g : groups) {
    const bool bad_path = g.path.empty() || g.path.front() == '/' || g.path.back() == '/' ||
                          g.path.find("//") != std::string::npos;
    if (bad_path) throw InputError(format_error(where, g.path, "not a group path"));
    if (!seen.insert(g.path).second) {
      throw InputError(format_error(where, g.path, "two groups with this path"));
    }
    std::set<std::string> names;
    for (const DataColumn& c : g.columns) {
      if (c.name.empty() || c.name.find('/') != std::string::npos || !names.insert(c.name).second)
        throw InputError(format_error(where, g.path + "/" + c.name, "bad or repeated column name"));
      std::size_t count = c.shape.empty() ? c.values.size() : 1;
      for (std::size_t d : c.shape) count *= d;
      if (count != c.values.size() || c.shape.size() > 8)
        throw InputError(format_error(where, g.path + "/" + c.name,
                                      "shape does not hold the values (or more than 8 axes)"));
    }
  }
}

void write_file(hid_t f, std::span<const DataGroup> groups,
                const std::map<std::string, std::string>& root_texts) {
  {
    const Hid root = owned(H5Gopen2(f, "/", H5P_DEFAULT), H5Gclose, "/");
    text_attribute(root.get(), "format", "geardiag-curves");
    number_attribute(root.get(), "format_version", 1);
    text_attribute(root.get(), "creator", std::string("geardiag ") + diag::version());
    for (const auto& [k, v] : root_texts) text_attribute(root.get(), k, v);
  }
  for (const DataGroup& g : groups) {
    const Hid group = open_or_create(f, g.path);
    text_attribute(group.get(), "description", g.description);
    if (!g.columns.empty()) text_attribute(group.get(), "axis", g.columns.front().name);
    for (const auto& [k, v] : g.numbers) number_attribute(group.get(), k, v);
    for (const auto& [k, v] : g.texts) text_attribute(group.get(), k, v);
    for (const DataColumn& c : g.columns) {
      const hsize_t n = c.values.size();
      // Fixed arrays (shape has at most 8 axes, check_names): GCC 12 warns falsely on a
      // std::vector<hsize_t> here (free-nonheap-object).
      std::array<hsize_t, 8> dims{}, chunk{};
      const int rank = c.shape.empty() ? 1 : static_cast<int>(c.shape.size());
      dims[0] = n;
      for (std::size_t d = 0; d < c.shape.size(); ++d) dims[d] = c.shape[d];
      const Hid space = owned(H5Screate_simple(rank, dims.data(), nullptr), H5Sclose, c.name);
      const Hid dcpl = owned(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, c.name);
      // No timestamps: the same curves give the same bytes.
      put(H5Pset_obj_track_times(dcpl.get(), 0), c.name);
      if (n > 0) {
        // Chunks of about 64 Ki values along the first axis (whole rows of the others).
        hsize_t row = 1;
        for (int d = 1; d < rank; ++d) row *= dims[static_cast<std::size_t>(d)];
        chunk = dims;
        chunk[0] = std::clamp<hsize_t>(65536 / row, 1, dims[0]);
        put(H5Pset_chunk(dcpl.get(), rank, chunk.data()), c.name);
        put(H5Pset_deflate(dcpl.get(), 4), c.name);
      }
      const Hid ds = owned(H5Dcreate2(group.get(), c.name.c_str(), H5T_IEEE_F64LE, space.get(),
                                      H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
                           H5Dclose, g.path + "/" + c.name);
      if (n > 0) {
        put(H5Dwrite(ds.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, c.values.data()),
            c.name);
      }
      text_attribute(ds.get(), "unit", c.unit);
    }
  }
}

}  // namespace

void write_data_groups(const std::filesystem::path& path, std::span<const DataGroup> groups,
                       const std::map<std::string, std::string>& root_texts,
                       const std::string& what) {
  const std::string where = what.empty() ? path.string() : what + ": " + path.string();
  check_names(groups, where);
  (void)check_output_path(path, what);  // before the file is built
  std::string bytes;
  const auto library = hdf5_detail::hold_hdf5();
  try {
    // No timestamps on the root group either (the file creation properties are its own).
    const Hid fcpl = owned(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "file properties");
    put(H5Pset_obj_track_times(fcpl.get(), 0), "file properties");
    // Made in memory and written by write_output_file (hdf5_file.hpp): a failed write is one
    // clear error, never a corrupt file renamed into place.
    bytes = hdf5_detail::hdf5_file_bytes(where, fcpl.get(), H5P_DEFAULT,
                                         [&](hid_t file) { write_file(file, groups, root_texts); });
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const InputError*>(&e) != nullptr) throw;
    throw InputError(where + ": " + e.what());
  }
  write_output_file(path, bytes, what);
}

}  // namespace diag
