// libFuzzer target: gearbox description JSON (diag::load_gearbox).
#include <cstddef>
#include <cstdint>

#include "diag/gearbox/gearbox.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".json", data, size);
  fuzz::expect_input_error_only([&] { diag::load_gearbox(path); });
  return 0;
}
