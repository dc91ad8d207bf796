// libFuzzer target: channel map JSON (diag::load_channel_map).
#include <cstddef>
#include <cstdint>

#include "diag/io/channels.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".json", data, size);
  fuzz::expect_input_error_only([&] { diag::load_channel_map(path); });
  return 0;
}
