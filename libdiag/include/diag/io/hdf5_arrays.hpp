// Named numeric arrays in an HDF5 file (results that are not recordings: wear histories,
// tables), written and read. Written through write_output_file_via (diag/io/output_file.hpp): a
// failed run leaves no half-written file. Reproducible bytes: no timestamps, fixed format version
// (HDF5 1.8 objects), as write_recording.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace diag {

struct Hdf5Array {
  std::string path;                // "/group/sub/name"; groups are created as needed
  std::vector<std::size_t> shape;  // row-major; empty: one-dimensional of data.size()
  std::vector<double> data;        // product(shape) values
  std::string unit;                // stored as the string attribute "unit" when not empty
};

// Throws InputError naming `path` when the file cannot be written or an array's shape does not
// match its data. `root_attributes` become string attributes of "/".
void write_hdf5_arrays(const std::filesystem::path& path, const std::vector<Hdf5Array>& arrays,
                       const std::map<std::string, std::string>& root_attributes = {});

// Reads the numeric datasets `names` (absolute paths, e.g. "/drive/stiffness_nm_per_rad") of a
// file users bring (tables), converted to double; a name that does not exist (nor a group on its
// path) is left out of the result, so the caller decides what is required. The file is
// untrusted, as in read_recording: a forked child reads it first (a crash inside the HDF5
// library refuses the file), and an InputError names the file and dataset for a file that is not
// HDF5, a soft or external link, an object that is not a dataset, a non-numeric type, a rank
// other than 1 or 2, an empty array, more than `max_values` values, stored bytes that cannot
// hold the declared shape, and NaN/Inf values. Hdf5Array::shape is the dataset's, row-major.
std::map<std::string, Hdf5Array> read_hdf5_arrays(const std::filesystem::path& path,
                                                  const std::vector<std::string>& names,
                                                  std::size_t max_values = std::size_t{1} << 24);

}  // namespace diag
