// libFuzzer target: WAV import (RIFF chunk check, then libsndfile).
#include <cstddef>
#include <cstdint>

#include "diag/io/import.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".wav", data, size);
  fuzz::expect_input_error_only([&] { diag::import_recording(path); });
  return 0;
}
