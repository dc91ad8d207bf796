#include "diag/io/hdf5_arrays.hpp"

#include <hdf5.h>

#include "diag/error.hpp"
#include "diag/io/output_file.hpp"

namespace diag {

namespace {

// Closes an HDF5 identifier on scope exit.
class Id {
 public:
  Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Id() {
    if (id_ >= 0) close_(id_);
  }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  hid_t get() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void check(bool ok, const std::string& where, const std::string& what) {
  if (!ok) throw InputError(format_error(where, what, "HDF5 write failed"));
}

void string_attribute(hid_t obj, const std::string& name, const std::string& value,
                      const std::string& where) {
  Id type(H5Tcopy(H5T_C_S1), H5Tclose);
  check(type.get() >= 0 && H5Tset_size(type.get(), std::max<std::size_t>(1, value.size())) >= 0,
        where, name);
  Id space(H5Screate(H5S_SCALAR), H5Sclose);
  Id attr(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
          H5Aclose);
  check(attr.get() >= 0 && H5Awrite(attr.get(), type.get(), value.c_str()) >= 0, where, name);
}

}  // namespace

void write_hdf5_arrays(const std::filesystem::path& path, const std::vector<Hdf5Array>& arrays,
                       const std::map<std::string, std::string>& root_attributes) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const std::string where = path.string();
  for (const Hdf5Array& a : arrays) {
    std::size_t n = 1;
    for (std::size_t d : a.shape) n *= d;
    if ((a.shape.empty() ? a.data.size() : n) != a.data.size() || a.path.empty() ||
        a.path[0] != '/') {
      throw InputError(format_error(where, a.path, "array shape does not match its data"));
    }
  }
  write_output_file_via(path, [&](const std::filesystem::path& file) {
    Id fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
    check(H5Pset_obj_track_times(fcpl.get(), 0) >= 0, where, "file properties");
    Id fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18) >= 0, where,
          "file properties");
    Id f(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), H5Fclose);
    if (f.get() < 0) throw InputError(format_error(where, "", "cannot create the HDF5 file"));
    {
      Id root(H5Gopen2(f.get(), "/", H5P_DEFAULT), H5Gclose);
      for (const auto& [k, v] : root_attributes) string_attribute(root.get(), k, v, where);
    }
    // Groups made here, without timestamps (intermediate groups made by HDF5 would carry them).
    Id gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
    check(H5Pset_obj_track_times(gcpl.get(), 0) >= 0, where, "group properties");
    auto make_groups = [&](const std::string& p) {
      for (std::size_t slash = p.find('/', 1); slash != std::string::npos;
           slash = p.find('/', slash + 1)) {
        const std::string g = p.substr(0, slash);
        if (H5Lexists(f.get(), g.c_str(), H5P_DEFAULT) > 0) continue;
        Id grp(H5Gcreate2(f.get(), g.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose);
        check(grp.get() >= 0, where, g);
      }
    };
    Id dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    check(H5Pset_obj_track_times(dcpl.get(), 0) >= 0, where, "dataset properties");
    for (const Hdf5Array& a : arrays) {
      std::vector<hsize_t> dims;
      if (a.shape.empty()) {
        dims.push_back(a.data.size());
      } else {
        for (std::size_t d : a.shape) dims.push_back(d);
      }
      make_groups(a.path);
      Id space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
      Id ds(H5Dcreate2(f.get(), a.path.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                       dcpl.get(), H5P_DEFAULT),
            H5Dclose);
      check(ds.get() >= 0, where, a.path);
      if (!a.data.empty()) {
        check(H5Dwrite(ds.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.data.data()) >=
                  0,
              where, a.path);
      }
      if (!a.unit.empty()) string_attribute(ds.get(), "unit", a.unit, where);
    }
  });
}

}  // namespace diag
