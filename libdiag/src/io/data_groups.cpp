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

namespace diag {

namespace {

// An HDF5 identifier closed by `Close` when it goes out of scope; a negative one throws at once.
template <herr_t (*Close)(hid_t)>
struct Owned {
  hid_t id;
  Owned(hid_t h, const std::string& what) : id(h) {
    if (h < 0) throw std::runtime_error("curves: HDF5 error: " + what);
  }
  ~Owned() { Close(id); }
  Owned(const Owned&) = delete;
  Owned& operator=(const Owned&) = delete;
};
using Group = Owned<H5Gclose>;
using Space = Owned<H5Sclose>;
using Type = Owned<H5Tclose>;
using Attr = Owned<H5Aclose>;
using Dataset = Owned<H5Dclose>;
using Plist = Owned<H5Pclose>;

void put(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("curves: HDF5 error: " + what);
}

void text_attribute(hid_t obj, const std::string& name, const std::string& value) {
  const Type type(H5Tcopy(H5T_C_S1), name);
  put(H5Tset_size(type.id, H5T_VARIABLE), name);
  put(H5Tset_cset(type.id, H5T_CSET_UTF8), name);
  const Space space(H5Screate(H5S_SCALAR), name);
  const Attr attr(H5Acreate2(obj, name.c_str(), type.id, space.id, H5P_DEFAULT, H5P_DEFAULT), name);
  const char* text = value.c_str();
  put(H5Awrite(attr.id, type.id, &text), name);
}

void number_attribute(hid_t obj, const std::string& name, double value) {
  const Space space(H5Screate(H5S_SCALAR), name);
  const Attr attr(H5Acreate2(obj, name.c_str(), H5T_IEEE_F64LE, space.id, H5P_DEFAULT, H5P_DEFAULT),
                  name);
  put(H5Awrite(attr.id, H5T_NATIVE_DOUBLE, &value), name);
}

// Opens the group at `path` ("a/b/c"), creating the missing ones on the way.
hid_t open_or_create(hid_t file, const std::string& path) {
  std::string prefix;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    prefix += "/" + path.substr(start, end - start);
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) {
      put(H5Gclose(H5Gcreate2(file, prefix.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)),
          prefix);
    }
    start = end + 1;
  }
  return H5Gopen2(file, prefix.c_str(), H5P_DEFAULT);
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

void write_file(const std::filesystem::path& file, std::span<const DataGroup> groups,
                const std::map<std::string, std::string>& root_texts) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const Owned<H5Fclose> f(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                          "cannot create " + file.string());
  {
    const Group root(H5Gopen2(f.id, "/", H5P_DEFAULT), "/");
    text_attribute(root.id, "format", "geardiag-curves");
    number_attribute(root.id, "format_version", 1);
    text_attribute(root.id, "creator", std::string("geardiag ") + diag::version());
    for (const auto& [k, v] : root_texts) text_attribute(root.id, k, v);
  }
  for (const DataGroup& g : groups) {
    const Group group(open_or_create(f.id, g.path), g.path);
    text_attribute(group.id, "description", g.description);
    if (!g.columns.empty()) text_attribute(group.id, "axis", g.columns.front().name);
    for (const auto& [k, v] : g.numbers) number_attribute(group.id, k, v);
    for (const auto& [k, v] : g.texts) text_attribute(group.id, k, v);
    for (const DataColumn& c : g.columns) {
      const hsize_t n = c.values.size();
      // Fixed arrays (shape has at most 8 axes, check_names): GCC 12 warns falsely on a
      // std::vector<hsize_t> here (free-nonheap-object).
      std::array<hsize_t, 8> dims{}, chunk{};
      const int rank = c.shape.empty() ? 1 : static_cast<int>(c.shape.size());
      dims[0] = n;
      for (std::size_t d = 0; d < c.shape.size(); ++d) dims[d] = c.shape[d];
      const Space space(H5Screate_simple(rank, dims.data(), nullptr), c.name);
      const Plist dcpl(H5Pcreate(H5P_DATASET_CREATE), c.name);
      if (n > 0) {
        // Chunks of about 64 Ki values along the first axis (whole rows of the others).
        hsize_t row = 1;
        for (int d = 1; d < rank; ++d) row *= dims[static_cast<std::size_t>(d)];
        chunk = dims;
        chunk[0] = std::clamp<hsize_t>(65536 / row, 1, dims[0]);
        put(H5Pset_chunk(dcpl.id, rank, chunk.data()), c.name);
        put(H5Pset_deflate(dcpl.id, 4), c.name);
      }
      const Dataset ds(H5Dcreate2(group.id, c.name.c_str(), H5T_IEEE_F64LE, space.id, H5P_DEFAULT,
                                  dcpl.id, H5P_DEFAULT),
                       g.path + "/" + c.name);
      if (n > 0) {
        put(H5Dwrite(ds.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, c.values.data()),
            c.name);
      }
      text_attribute(ds.id, "unit", c.unit);
    }
  }
}

}  // namespace

void write_data_groups(const std::filesystem::path& path, std::span<const DataGroup> groups,
                       const std::map<std::string, std::string>& root_texts,
                       const std::string& what) {
  const std::string where = what.empty() ? path.string() : what + ": " + path.string();
  check_names(groups, where);
  write_output_file_via(
      path,
      [&](const std::filesystem::path& file) {
        try {
          write_file(file, groups, root_texts);
        } catch (const std::runtime_error& e) {
          if (dynamic_cast<const InputError*>(&e) != nullptr) throw;
          throw InputError(where + ": " + e.what());
        }
      },
      what);
}

}  // namespace diag
