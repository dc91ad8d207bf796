// libFuzzer target: MATLAB .mat import (level 4 and 5 decoder, mat_file.cpp).
#include <cstddef>
#include <cstdint>

#include "diag/io/import.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".mat", data, size);
  diag::ImportOptions options;
  options.fs_hz = 12000.0;
  fuzz::expect_input_error_only([&] { diag::import_recording(path, options); });
  return 0;
}
