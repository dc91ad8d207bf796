// libFuzzer target: MATLAB .mat import (level 4 and 5 decoder, mat_file.cpp), and the same file
// read frame by frame (diag::open_recording_frames: level 5 surveyed by its elements' headers).
#include <cstddef>
#include <cstdint>

#include "diag/io/import.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".mat", data, size);
  diag::ImportOptions options;
  options.fs_hz = 12000.0;
  fuzz::expect_input_error_only([&] { diag::import_recording(path, options); });
  fuzz::expect_input_error_only([&] { fuzz::read_in_frames(path, 12000.0); });
  return 0;
}
