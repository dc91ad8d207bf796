// libFuzzer target: geardiag HDF5 readers, recordings (RecordingReader, read_recording) and the
// face-gear stiffness tables (diag::read_hdf5_arrays through sim::facegear::load_table_hdf5); the
// forked survey contains crashes inside the HDF5 library.
#include <cstddef>
#include <cstdint>

#include "diag/io/hdf5.hpp"
#include "fuzz_input.hpp"
#include "sim/facegear/description.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".h5", data, size);
  fuzz::expect_input_error_only([&] {
    diag::RecordingReader reader(path);
    (void)reader.metadata();
    (void)reader.format_attributes();
    (void)reader.gearbox_json();
  });
  fuzz::expect_input_error_only([&] { diag::read_recording(path); });
  fuzz::expect_input_error_only([&] {
    sim::facegear::FaceGearPair pair;
    sim::facegear::load_table_hdf5(path, pair, pair.drive, pair.coast);
  });
  return 0;
}
