// libFuzzer target: CSV import (diag::import_recording on a .csv file).
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
  return 0;
}
