// MATLAB 7.3 .mat files (mat_file.hpp): HDF5 files with a 512-byte MATLAB header first. Read by
// geardiag, not matio, so that they go through the one HDF5 open of the project
// (hdf5_file.hpp: opened once, structure checked: no external storage, links or virtual data,
// no chunks never written, declared sizes held by the file) and the crash guard
// (crash_guard.hpp). The layout follows MATLAB's "MAT-File Versions" page and what MATLAB
// writes: every variable is a root object carrying the attribute MATLAB_class ("double",
// "single", "int8" ... "uint64", "char", "logical", "cell", "struct", ...); a numeric array is a
// dataset whose HDF5 dimensions are MATLAB's reversed (MATLAB stores column-major), a complex one
// a compound {real, imag}, a sparse one a group (MATLAB_sparse), an empty one a dataset of its
// dimensions with MATLAB_empty = 1; "#refs#" and "#subsystem#" hold what cells and objects
// reference.
#include <hdf5.h>

#include <cstring>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "crash_guard.hpp"
#include "diag/error.hpp"
#include "hdf5_file.hpp"
#include "hdf5_handle.hpp"
#include "mat_file.hpp"

namespace diag::mat {

using hdf5_detail::Hdf5Source;
using hdf5_detail::Hid;

namespace {

[[noreturn]] void damaged(const std::string& where, const std::string& name,
                          const std::string& reason) {
  throw InputError(format_error(where, "variable '" + name + "'", reason));
}

// The text of a string attribute (fixed or variable length); nullopt when absent or not a string.
std::optional<std::string> string_attribute(hid_t obj, const char* attr_name,
                                            const std::string& where, const std::string& name) {
  const htri_t exists = H5Aexists(obj, attr_name);
  if (exists < 0) damaged(where, name, std::string("attribute ") + attr_name + " unreadable");
  if (exists == 0) return std::nullopt;
  const Hid attr(H5Aopen(obj, attr_name, H5P_DEFAULT), H5Aclose);
  const Hid type(attr.valid() ? H5Aget_type(attr.get()) : -1, H5Tclose);
  const Hid space(attr.valid() ? H5Aget_space(attr.get()) : -1, H5Sclose);
  if (!type.valid() || !space.valid()) {
    damaged(where, name, std::string("attribute ") + attr_name + " unreadable");
  }
  if (H5Tget_class(type.get()) != H5T_STRING || H5Sget_simple_extent_npoints(space.get()) != 1) {
    return std::nullopt;
  }
  if (H5Tis_variable_str(type.get()) > 0) {
    const Hid mem(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mem.get(), H5T_VARIABLE);
    char* text = nullptr;
    if (H5Aread(attr.get(), mem.get(), &text) < 0) {
      damaged(where, name, std::string("attribute ") + attr_name + " unreadable");
    }
    std::string out = text != nullptr ? text : "";
    H5free_memory(text);
    return out;
  }
  const std::size_t size = H5Tget_size(type.get());
  if (size == 0 || size > 4096) return std::nullopt;
  const Hid mem(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(mem.get(), size + 1);
  H5Tset_strpad(mem.get(), H5T_STR_NULLTERM);
  std::vector<char> buffer(size + 1, '\0');
  if (H5Aread(attr.get(), mem.get(), buffer.data()) < 0) {
    damaged(where, name, std::string("attribute ") + attr_name + " unreadable");
  }
  return std::string(buffer.data());
}

std::vector<std::string> root_names(hid_t file, const std::string& where) {
  std::vector<std::string> names;
  const herr_t status = H5Literate(
      file, H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
        static_cast<std::vector<std::string>*>(data)->emplace_back(name);
        return 0;
      },
      &names);
  if (status < 0) throw InputError(format_error(where, "", "cannot list the variables"));
  return names;
}

const std::map<std::string, bool>& numeric_classes() {
  // MATLAB_class -> integer class
  static const std::map<std::string, bool> classes = {
      {"double", false}, {"single", false}, {"int8", true},   {"uint8", true}, {"int16", true},
      {"uint16", true},  {"int32", true},   {"uint32", true}, {"int64", true}, {"uint64", true}};
  return classes;
}

std::vector<Variable> read_variables(const Hdf5Source& source, std::vector<std::string>* notes) {
  const std::string& where = source.where();
  const Hid file = source.open();
  std::vector<Variable> vars;
  for (const std::string& name : root_names(file.get(), where)) {
    if (name.empty() || name[0] == '#') continue;  // #refs#, #subsystem#: not variables
    H5L_info_t link;
    if (H5Lget_info(file.get(), name.c_str(), &link, H5P_DEFAULT) < 0) {
      damaged(where, name, "unreadable link");
    }
    if (link.type != H5L_TYPE_HARD) continue;
    const Hid obj(H5Oopen(file.get(), name.c_str(), H5P_DEFAULT), H5Oclose);
    if (!obj.valid()) damaged(where, name, "cannot be opened (corrupted file?)");
    const std::string cls = string_attribute(obj.get(), "MATLAB_class", where, name).value_or("");
    if (H5Iget_type(obj.get()) != H5I_DATASET) {
      if (notes != nullptr && H5Aexists(obj.get(), "MATLAB_sparse") > 0) {
        notes->push_back("variable " + name + " skipped: a sparse matrix, not a channel");
      }
      continue;
    }
    const auto numeric = numeric_classes().find(cls);
    if (numeric == numeric_classes().end()) continue;        // char, logical, cell, ...: not data
    if (H5Aexists(obj.get(), "MATLAB_empty") > 0) continue;  // its dimensions, not values
    const Hid type(H5Dget_type(obj.get()), H5Tclose);
    const Hid space(H5Dget_space(obj.get()), H5Sclose);
    if (!type.valid() || !space.valid()) damaged(where, name, "unreadable (corrupted file?)");
    const H5T_class_t tc = H5Tget_class(type.get());
    if (tc != H5T_INTEGER && tc != H5T_FLOAT) continue;  // complex: a compound {real, imag}
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 1 || rank > H5S_MAX_RANK) damaged(where, name, "corrupted dimensions");
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    if (H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) != rank) {
      damaged(where, name, "corrupted dimensions");
    }
    Variable v;
    v.name = name;
    v.dims.assign(dims.rbegin(), dims.rend());  // MATLAB's order
    // The size was checked against the stored bytes when the file was opened (hdf5_file.hpp).
    const auto n = static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.get()));
    v.values.resize(n);
    if (n > 0 &&
        H5Dread(obj.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.values.data()) < 0) {
      damaged(where, name, "cannot read its values (corrupted file?)");
    }
    v.integer_class = numeric->second;
    if (n == 1 && (cls == "int64" || cls == "uint64")) {
      if (cls == "int64") {
        long long value = 0;
        if (H5Dread(obj.get(), H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, &value) >= 0) {
          v.exact_text = std::to_string(value);
        }
      } else {
        unsigned long long value = 0;
        if (H5Dread(obj.get(), H5T_NATIVE_ULLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, &value) >= 0) {
          v.exact_text = std::to_string(value);
        }
      }
    }
    vars.push_back(std::move(v));
  }
  return vars;
}

// Any error but InputError (an HDF5 call failing, memory) is damage to the file: exit 2.
std::vector<Variable> reading(const Hdf5Source& source, std::vector<std::string>* notes) {
  const auto library = hdf5_detail::hold_hdf5();
  try {
    return read_variables(source, notes);
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw InputError(format_error(source.where(), "", "too large to read into memory"));
  } catch (const std::exception& e) {
    throw InputError(format_error(source.where(), "",
                                  std::string("cannot read (corrupted file?): ") + e.what()));
  }
}

}  // namespace

std::vector<Variable> read_mat73_variables(const std::filesystem::path& path,
                                           std::vector<std::string>* notes) {
  const Hdf5Source source(path, false);  // opened once: the guard's child reads this descriptor
  hdf5_detail::run_guarded(source.where(), [&] { (void)reading(source, nullptr); });
  return reading(source, notes);
}

}  // namespace diag::mat
