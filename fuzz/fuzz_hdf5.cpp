// libFuzzer target: geardiag HDF5 recording reader (RecordingReader, read_recording; the forked
// survey contains crashes inside the HDF5 library).
#include <cstddef>
#include <cstdint>

#include "diag/io/hdf5.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".h5", data, size);
  fuzz::expect_input_error_only([&] {
    diag::RecordingReader reader(path);
    (void)reader.metadata();
    (void)reader.format_attributes();
    (void)reader.gearbox_json();
  });
  fuzz::expect_input_error_only([&] { diag::read_recording(path); });
  return 0;
}
