#include "recording_input.hpp"

#include <filesystem>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/import.hpp"

namespace geardiag {

diag::Recording load_recording(const std::string& file, std::optional<double> fs_hz,
                               const diag::ReadLimits& limits, bool* cut) {
  const std::filesystem::path path(file);
  if (!std::filesystem::exists(path)) throw diag::InputError(file + ": no such file");
  try {
    if (diag::is_hdf5_file(path)) return diag::read_recording(path, limits, cut);
    diag::ImportOptions io;
    io.fs_hz = fs_hz;
    return diag::import_recording(path, io);
  } catch (const diag::InputError& e) {
    const std::string what = e.what();
    if (what.find(file) != std::string::npos) throw;
    throw diag::InputError(file + ": " + what);
  }
}

}  // namespace geardiag
