// The scenario of a dynamic run (JSON): operating point, drive, damping, bearings, friction and
// oil, tooth faults, manufacturing errors, sensors, integrator. Every field is optional; the
// defaults are DynamicsOptions' and RunOptions'. The form is documented in docs/formats.md
// ("Scenario description"); unknown fields and bad values are refused naming the field.
#pragma once

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "sim/dynamics/simulate.hpp"

namespace sim {

struct Scenario {
  DynamicsOptions dynamics;
  RunOptions run;
};

Scenario parse_scenario(const nlohmann::json& j, const std::string& where);
Scenario load_scenario(const std::filesystem::path& path);

}  // namespace sim
