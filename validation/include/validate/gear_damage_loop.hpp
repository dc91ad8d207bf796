// Closed-loop validation of locate_gear_damage (detect/gear/gear_damage.hpp): random tooth faults
// (root crack, chip, missing tooth) on random gears of a gearbox are simulated with the dynamic
// model (sim/dynamics/simulate.hpp) at random speed, load and sensor noise, together with healthy
// cases; each recording goes to the detector and its answer is compared with the shaft that
// carries the faulty gear. Validation is the one place besides the tests where simulator and
// detectors meet.
//
// Fault sizes are drawn uniformly inside the ranges below, the ranges the loop's target (95 %)
// is claimed for on the two-stage box of testdata/gearbox/three_shaft.json (module 3 mm, 20 mm
// face). Smaller cracks and chips change the mesh stiffness less and give a smaller
// once-per-revolution impulse; where detection ends for them has not been mapped.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "detect/gear/gear_damage.hpp"
#include "diag/gearbox/gearbox.hpp"

namespace validate {

struct GearDamageLoopOptions {
  int cases = 100;              // random cases, >= 1
  double healthy_share = 0.25;  // share of healthy cases, [0, 1]
  std::uint64_t seed = 1;       // the whole loop is reproducible from this seed
  double min_rpm = 1800.0;      // input speed, uniform in [min_rpm, max_rpm] [rpm], > 0
  double max_rpm = 2600.0;
  double min_torque_nm = 30.0;  // input torque, uniform [N m], > 0
  double max_torque_nm = 80.0;
  double min_noise_m_per_s2 = 2.0;  // accelerometer noise RMS, uniform [m/s^2], >= 0
  double max_noise_m_per_s2 = 10.0;
  // Fault kinds drawn with equal probability among those enabled.
  bool root_crack = true, chip = true, missing = true;
  // Crack length as a fraction of the largest the stiffness model accepts
  // (1.8 x root half-thickness / sin(crack angle)), uniform in [min, max], (0, 1].
  double min_crack_fraction = 0.5, max_crack_fraction = 0.95;
  // Chip depth along the profile from the tip, as a fraction of the module, uniform, (0, 2].
  double min_chip_modules = 0.5, max_chip_modules = 1.0;
  double fs_hz = 10000.0;              // output sampling rate [Hz]
  int slowest_shaft_revolutions = 11;  // recorded revolutions of the slowest shaft, >= 3 more
                                       // than detector.min_revolutions (the resampling kernel
                                       // needs margins at both ends)
  int steps_per_period = 20;           // RK4 steps per period of the highest natural frequency (see
                                       // sim::RunOptions; 10 keeps RK4 stable and the loop fast)
  detect::GearDamageOptions detector;

  void validate() const;  // throws diag::InputError naming the field
};

struct GearDamageCase {
  bool faulty = false;
  std::string gear, truth_shaft;  // empty when healthy
  std::string kind;               // "root_crack" | "chip" | "missing" | "" (healthy)
  int tooth = 0;
  double size_m = 0;
  double rpm = 0, torque_nm = 0, noise_m_per_s2 = 0;
  detect::GearDamageResult result;
  std::string found_shaft;  // first finding's shaft, "" when none
  bool correct = false;     // faulty: status "damaged" on the truth shaft; healthy: no finding
};

struct GearDamageLoopReport {
  std::vector<GearDamageCase> cases;
  int faulty_total = 0, faulty_correct = 0, faulty_missed = 0, faulty_wrong_shaft = 0,
      faulty_ambiguous = 0;
  int healthy_total = 0, healthy_false_alarms = 0;
  double faulty_accuracy() const {
    return faulty_total ? double(faulty_correct) / faulty_total : 1;
  }
};

GearDamageLoopReport run_gear_damage_loop(const diag::Gearbox& gb,
                                          const GearDamageLoopOptions& options);

// One line per case that went wrong and a summary table.
std::string format_report(const GearDamageLoopReport& r);

}  // namespace validate
