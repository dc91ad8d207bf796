// libFuzzer target: simulation scenario JSON (sim::load_scenario).
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "sim/dynamics/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".json", data, size);
  fuzz::expect_input_error_only([&] { sim::load_scenario(path); });
  return 0;
}
