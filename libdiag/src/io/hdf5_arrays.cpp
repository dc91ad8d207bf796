#include "diag/io/hdf5_arrays.hpp"

#include <hdf5.h>

#include "diag/error.hpp"
#include "diag/io/output_file.hpp"
#include "hdf5_file.hpp"
#include "hdf5_handle.hpp"

namespace diag {

using hdf5_detail::Hid;

namespace {

void check(bool ok, const std::string& where, const std::string& what) {
  if (!ok) throw InputError(format_error(where, what, "HDF5 write failed"));
}

void string_attribute(hid_t obj, const std::string& name, const std::string& value,
                      const std::string& where) {
  Hid type(H5Tcopy(H5T_C_S1), H5Tclose);
  check(type.get() >= 0 && H5Tset_size(type.get(), std::max<std::size_t>(1, value.size())) >= 0,
        where, name);
  Hid space(H5Screate(H5S_SCALAR), H5Sclose);
  Hid attr(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
           H5Aclose);
  check(attr.get() >= 0 && H5Awrite(attr.get(), type.get(), value.c_str()) >= 0, where, name);
}

}  // namespace

void write_hdf5_arrays(const std::filesystem::path& path, const std::vector<Hdf5Array>& arrays,
                       const std::map<std::string, std::string>& root_attributes) {
  const auto library = hdf5_detail::hold_hdf5();
  const std::string where = path.string();
  for (const Hdf5Array& a : arrays) {
    std::size_t n = 1;
    for (std::size_t d : a.shape) n *= d;
    if ((a.shape.empty() ? a.data.size() : n) != a.data.size() || a.path.empty() ||
        a.path[0] != '/') {
      throw InputError(format_error(where, a.path, "array shape does not match its data"));
    }
  }
  (void)check_output_path(path);  // before the file is built
  Hid fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  check(fcpl.valid() && H5Pset_obj_track_times(fcpl.get(), 0) >= 0, where, "file properties");
  Hid fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  check(fapl.valid() && H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18) >= 0,
        where, "file properties");
  // Made in memory, then written by write_output_file (hdf5_file.hpp): a full disk is one clear
  // error, the previous file intact.
  const std::string bytes =
      hdf5_detail::hdf5_file_bytes(where, fcpl.get(), fapl.get(), [&](hid_t file) {
        {
          Hid root(H5Gopen2(file, "/", H5P_DEFAULT), H5Gclose);
          for (const auto& [k, v] : root_attributes) string_attribute(root.get(), k, v, where);
        }
        // Groups made here, without timestamps (intermediate groups made by HDF5 would carry them).
        Hid gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
        check(H5Pset_obj_track_times(gcpl.get(), 0) >= 0, where, "group properties");
        auto make_groups = [&](const std::string& p) {
          for (std::size_t slash = p.find('/', 1); slash != std::string::npos;
               slash = p.find('/', slash + 1)) {
            const std::string g = p.substr(0, slash);
            if (H5Lexists(file, g.c_str(), H5P_DEFAULT) > 0) continue;
            Hid grp(H5Gcreate2(file, g.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose);
            check(grp.get() >= 0, where, g);
          }
        };
        Hid dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
        check(H5Pset_obj_track_times(dcpl.get(), 0) >= 0, where, "dataset properties");
        for (const Hdf5Array& a : arrays) {
          std::vector<hsize_t> dims;
          if (a.shape.empty()) {
            dims.push_back(a.data.size());
          } else {
            for (std::size_t d : a.shape) dims.push_back(d);
          }
          make_groups(a.path);
          Hid space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                    H5Sclose);
          Hid ds(H5Dcreate2(file, a.path.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                            dcpl.get(), H5P_DEFAULT),
                 H5Dclose);
          check(ds.get() >= 0, where, a.path);
          if (!a.data.empty()) {
            check(H5Dwrite(ds.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                           a.data.data()) >= 0,
                  where, a.path);
          }
          if (!a.unit.empty()) string_attribute(ds.get(), "unit", a.unit, where);
        }
      });
  write_output_file(path, bytes);
}

}  // namespace diag
