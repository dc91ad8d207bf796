// Named numeric columns with their units, grouped in a tree: how the curves of an analysis leave
// the program (`geardiag analyze --curves OUT.h5`, the Python module's analyze()). One HDF5 file,
// readable by h5py and MATLAB (h5read(file, '/channels/a1/psd/frequency_hz')) without this
// project:
//
//   /                          attributes: format ("geardiag-curves"), format_version (1),
//                              creator ("geardiag <version>"), plus the caller's root texts
//   /<group path>              one HDF5 group per DataGroup (intermediate groups created);
//                              attributes: description, axis (the first column's name), the
//                              group's numbers (float64) and texts (UTF-8 strings)
//   /<group path>/<column>     float64 dataset, 1-D (or DataColumn::shape); attribute unit (empty
//                              when unknown)
//
// Written through diag/io/output_file.hpp (a temporary file renamed into place: a failed run
// never leaves a half-written file).
#pragma once

#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace diag {

struct DataColumn {
  std::string name;  // dataset name: no '/', not empty
  std::string unit;  // e.g. "Hz", "(m/s^2)^2/Hz"; empty when unknown
  std::vector<double> values;
  std::vector<std::size_t> shape = {};  // empty: 1-D; else the dataset's dimensions (row-major,
                                        // their product values.size()), e.g. {time, frequency}
};

struct DataGroup {
  std::string path;         // "channels/a1/psd": '/'-separated names, no leading '/', not empty
  std::string description;  // what the group holds, one line
  std::vector<DataColumn> columns;  // the first is the axis of the others
  std::map<std::string, double> numbers;
  std::map<std::string, std::string> texts;
};

// Throws InputError naming `what` (an option such as "--curves") and the path for an unwritable
// output, and naming the group for a bad group or column name or two groups with the same path.
void write_data_groups(const std::filesystem::path& path, std::span<const DataGroup> groups,
                       const std::map<std::string, std::string>& root_texts = {},
                       const std::string& what = {});

}  // namespace diag
