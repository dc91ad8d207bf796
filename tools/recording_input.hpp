// A recording as `analyze` and `batch` read it: a geardiag HDF5 file, else an import (CSV, WAV,
// MAT) with the --fs given.
#pragma once

#include <optional>
#include <string>

#include "diag/io/recording.hpp"

namespace geardiag {

// Throws diag::InputError naming the file.
diag::Recording load_recording(const std::string& file, std::optional<double> fs_hz);

}  // namespace geardiag
