// Named numeric arrays written to an HDF5 file (results that are not recordings: wear histories,
// tables). Written through write_output_file_via (diag/io/output_file.hpp): a failed run leaves no
// half-written file. Reproducible bytes: no timestamps, fixed format version (HDF5 1.8 objects), as
// write_recording.
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

}  // namespace diag
