// libFuzzer target: CSV import (diag::import_recording on a .csv file), and the same file read
// frame by frame (diag::open_recording_frames: counted, then parsed row by row per frame).
#include <cstddef>
#include <cstdint>

#include "diag/io/import.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".csv", data, size);
  diag::ImportOptions options;
  options.fs_hz = 1000.0;  // so that a file without a time column is read, not refused at once
  fuzz::expect_input_error_only([&] { diag::import_recording(path, options); });
  fuzz::expect_input_error_only([&] { diag::import_recording(path); });
  fuzz::expect_input_error_only([&] { fuzz::read_in_frames(path, 1000.0); });
  return 0;
}
