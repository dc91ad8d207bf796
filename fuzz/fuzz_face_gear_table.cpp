// libFuzzer target: face-gear stiffness tables (sim/facegear/description.hpp), CSV and HDF5 (the
// reader dispatches on the content: an HDF5 signature reads it through read_hdf5_arrays, with
// the project's one HDF5 open and the crash guard; anything else is the CSV table).
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>

#include "fuzz_input.hpp"
#include "sim/facegear/description.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::input_file(".table", data, size);
  const nlohmann::json description = {
      {"face_gear_pair",
       {{"pinion_teeth", 15}, {"gear_teeth", 121}, {"stiffness_table", path.string()}}},
      {"input", {{"speed_rpm", 4000}, {"torque_nm", 300}}}};
  fuzz::expect_input_error_only(
      [&] { (void)sim::facegear::parse_description(description, path.string()); });
  return 0;
}
