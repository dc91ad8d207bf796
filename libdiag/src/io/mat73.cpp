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

#include <algorithm>
#include <cstring>
#include <map>
#include <optional>
#include <span>
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

// Every real numeric variable; with `values` false only the scalars' values are read, the
// others described (their dimensions).
std::vector<Variable> read_variables(const Hdf5Source& source, std::vector<std::string>* notes,
                                     bool values) {
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
    v.integer_class = numeric->second;
    if (!values && n > 1) {
      v.described = true;
      vars.push_back(std::move(v));
      continue;
    }
    v.values.resize(n);
    if (n > 0 &&
        H5Dread(obj.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.values.data()) < 0) {
      damaged(where, name, "cannot read its values (corrupted file?)");
    }
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
std::vector<Variable> reading(const Hdf5Source& source, std::vector<std::string>* notes,
                              bool values = true) {
  const auto library = hdf5_detail::hold_hdf5();
  try {
    return read_variables(source, notes, values);
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw InputError(format_error(source.where(), "", "too large to read into memory"));
  } catch (const std::exception& e) {
    throw InputError(format_error(source.where(), "",
                                  std::string("cannot read (corrupted file?): ") + e.what()));
  }
}

// Samples [first, first + out.size()) of the vector variable `name` (HDF5 dimensions 1 x n or
// n x 1), with the library held.
void read_vector_span(hid_t file, const std::string& where, const std::string& name,
                      std::uint64_t first, std::span<double> out) {
  const Hid ds(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose);
  const Hid space(ds.valid() ? H5Dget_space(ds.get()) : -1, H5Sclose);
  hsize_t dims[2] = {0, 0};
  if (!space.valid() || H5Sget_simple_extent_ndims(space.get()) != 2 ||
      H5Sget_simple_extent_dims(space.get(), dims, nullptr) != 2 ||
      (dims[0] != 1 && dims[1] != 1)) {
    damaged(where, name, "no longer a vector (changed while read?)");
  }
  const bool along_second = dims[0] == 1;
  const hsize_t start[2] = {along_second ? 0 : first, along_second ? first : 0};
  const hsize_t count[2] = {along_second ? 1 : out.size(), along_second ? out.size() : 1};
  const hsize_t n = out.size();
  const Hid memory(H5Screate_simple(1, &n, nullptr), H5Sclose);
  if (H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0 ||
      !memory.valid() ||
      H5Dread(ds.get(), H5T_NATIVE_DOUBLE, memory.get(), space.get(), H5P_DEFAULT, out.data()) <
          0) {
    damaged(where, name,
            "cannot read samples " + std::to_string(first) + " .. " +
                std::to_string(first + out.size()) + " (corrupted file?)");
  }
}

std::uint64_t element_count(const Variable& v) {
  std::uint64_t n = 1;
  for (std::size_t d : v.dims) n *= d;
  return n;
}

// A level 7.3 file's vectors read frame by frame (mat73_frames).
class Mat73Frames final : public VariableFrames {
 public:
  Mat73Frames(const std::filesystem::path& path, const Assemble& assemble)
      : source_(path, false), file_(-1, H5Fclose) {
    const std::string& where = source_.where();
    // The child reads every value, by blocks, so that a file that would crash or hang the
    // library is refused before this process reads it.
    hdf5_detail::run_guarded(where, [&] {
      const std::vector<Variable> vars = reading(source_, nullptr, false);
      const Hid file = source_.open();
      std::vector<double> block(std::size_t{1} << 16);
      for (const Variable& v : vars) {
        if (!v.described || v.dims.size() != 2 || (v.dims[0] != 1 && v.dims[1] != 1)) continue;
        for (std::uint64_t at = 0, n = element_count(v); at < n; at += block.size()) {
          const std::size_t count =
              static_cast<std::size_t>(std::min<std::uint64_t>(block.size(), n - at));
          read_vector_span(file.get(), where, v.name, at, std::span<double>(block).first(count));
        }
      }
    });
    std::vector<std::string> notes;
    std::vector<Variable> vars = reading(source_, &notes, false);
    std::map<std::string, std::uint64_t> lengths;
    for (const Variable& v : vars) lengths[v.name] = element_count(v);
    set_recording(assemble(vars, notes), path, where,
                  [&](std::size_t, const Signal& s) { return lengths.at(s.name); });
    file_ = source_.open();
  }

 private:
  void read_span(std::size_t i, std::uint64_t first, std::span<double> out) const override {
    const auto library = hdf5_detail::hold_hdf5();
    read_vector_span(file_.get(), where(), variable(i), first, out);
  }

  Hdf5Source source_;
  Hid file_;  // closed before source_'s descriptor
};

}  // namespace

std::shared_ptr<const FrameSource> mat73_frames(const std::filesystem::path& path,
                                                const Assemble& assemble) {
  return std::make_shared<const Mat73Frames>(path, assemble);
}

std::vector<Variable> read_mat73_variables(const std::filesystem::path& path,
                                           std::vector<std::string>* notes) {
  const Hdf5Source source(path, false);  // opened once: the guard's child reads this descriptor
  hdf5_detail::run_guarded(source.where(), [&] { (void)reading(source, nullptr); });
  return reading(source, notes);
}

}  // namespace diag::mat
