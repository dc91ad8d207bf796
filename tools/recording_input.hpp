// A recording as `analyze` and `batch` read it: a geardiag HDF5 file, else an import (CSV, WAV,
// MAT) with the --fs given.
#pragma once

#include <optional>
#include <string>

#include "diag/io/hdf5.hpp"
#include "diag/io/recording.hpp"

namespace geardiag {

// A long HDF5 recording is read as its first part within `limits` (diag::ReadLimits, hdf5.hpp:
// read by blocks, memory bounded whatever the file's length; *cut set when it was cut); the
// default limits read the whole file. Imports (CSV, WAV, MAT) are read whole. Throws
// diag::InputError naming the file.
diag::Recording load_recording(const std::string& file, std::optional<double> fs_hz,
                               const diag::ReadLimits& limits = {}, bool* cut = nullptr);

}  // namespace geardiag
