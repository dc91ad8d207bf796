// libFuzzer target: WAV import (RIFF chunk check, then libsndfile), and the same file read frame
// by frame (diag::open_recording_frames: kept open, a seek per frame).
#include <cstddef>
#include <cstdint>

#include "diag/io/import.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".wav", data, size);
  fuzz::expect_input_error_only([&] { diag::import_recording(path); });
  fuzz::expect_input_error_only([&] { fuzz::read_in_frames(path, 0.0); });
  return 0;
}
