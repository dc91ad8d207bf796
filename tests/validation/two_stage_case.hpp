// The closed-loop case the analyze tests share: the two-stage box
// (testdata/gearbox/three_shaft.json) in the dynamic simulator at 10 kHz with 4 m/s^2 sensor noise,
// 50 N m, seed 3 and no mesh channels (the gear-damage loop's setting), with or without one tooth
// fault.
#pragma once

#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "sim/dynamics/simulate.hpp"

namespace two_stage_case {

// The description with its nominal input speed set to `rpm`.
inline nlohmann::json description(double rpm) {
  std::ifstream in(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["input"]["speed_rpm"] = rpm;
  return j;
}

inline diag::Gearbox gearbox(double rpm) {
  return diag::parse_gearbox(description(rpm),
                             "three_shaft.json at " + std::to_string(rpm) + " rpm");
}

// A chip of 0.8 module (3 mm module) on tooth 5 of `gear`.
inline sim::GearFault chip(const std::string& gear) {
  sim::GearFault f;
  f.gear = gear;
  f.fault.kind = sim::ToothFault::Kind::kChip;
  f.fault.tooth = 5;
  f.fault.size_m = 0.8 * 3e-3;
  return f;
}

// A root crack of depth_m on tooth 5 of `gear` (the demo's: 1.5 mm).
inline sim::GearFault root_crack(const std::string& gear, double depth_m) {
  sim::GearFault f = chip(gear);
  f.fault.kind = sim::ToothFault::Kind::kRootCrack;
  f.fault.size_m = depth_m;
  return f;
}

// Manufacturing errors of every gear: ISO 1328 pitch errors of `accuracy_grade` (0: none) and an
// eccentricity of runout_m, their phases from the seed.
struct Errors {
  int accuracy_grade = 0;
  double runout_m = 0;
};

// `seed` draws the gears' errors and, unless noise_seed is given, the sensor noise; a separate
// noise_seed gives a second measurement of the same gears. The input torque is `torque_nm`.
inline diag::Recording simulate(const diag::Gearbox& gb, const sim::SpeedProfile& speed,
                                double duration_s, const std::optional<sim::GearFault>& fault,
                                const Errors& errors = {}, std::uint64_t seed = 3,
                                std::optional<std::uint64_t> noise_seed = std::nullopt,
                                double torque_nm = 50.0) {
  sim::DynamicsOptions dyn;
  dyn.speed = speed;
  dyn.input_torque_nm = torque_nm;
  if (fault) dyn.faults.push_back(*fault);
  dyn.accuracy_grade = errors.accuracy_grade;
  dyn.runout_m = errors.runout_m;
  dyn.seed = seed;
  sim::RunOptions run;
  run.duration_s = duration_s;
  run.fs_hz = 10000.0;
  run.accel_noise_m_per_s2 = 4.0;
  run.seed = noise_seed.value_or(seed);
  run.mesh_channels = false;
  return sim::to_recording(gb, sim::simulate_dynamic(gb, dyn, run));
}

inline std::vector<detect::Finding> of_kind(const detect::AnalysisResult& r,
                                            const std::string& kind) {
  std::vector<detect::Finding> out;
  for (const auto& f : r.findings) {
    if (f.kind == kind) out.push_back(f);
  }
  return out;
}

}  // namespace two_stage_case
