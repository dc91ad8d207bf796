// Closed-loop validation of locate_gear_damage (detect/gear/gear_damage.hpp) on realistic gears:
// random tooth faults (root crack, chip, missing tooth, spall) on random gears of one or several
// gearboxes are simulated with the dynamic model (sim/dynamics/simulate.hpp) at random speed,
// load and sensor noise, and, for healthy and faulty cases alike, with ISO 1328 pitch errors of a
// random accuracy grade (DynamicsOptions::accuracy_grade, Gaussian sigma = f_pt / 3) and a random
// runout of every gear (DynamicsOptions::runout_m): real gears are never perfect, and a locator
// validated on perfect gears called every real gearbox damaged. Each recording goes to
// the detector and its answer is compared with the shaft that carries the faulty gear: right,
// silent (no finding, or "ambiguous") or wrong shaft; healthy cases count false alarms. Besides
// the detector's own operating point the loop keeps every shaft's score and gates, so that the
// report gives the ROC: detection (right shaft) and false-alarm rates as the score threshold
// moves. Validation is the one place besides the tests where simulator and detectors meet.
//
// Fault sizes are drawn uniformly in the ranges below; each case also records its severity, the
// position of its size inside its kind's range (0: smallest, 1: largest; 1 for a missing tooth),
// by which the report bins sizes (thirds).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "detect/gear/gear_damage.hpp"
#include "diag/gearbox/gearbox.hpp"

namespace validate {

struct GearDamageLoopOptions {
  int cases = 100;              // random cases, >= 1 (spread over the gearboxes in turn)
  double healthy_share = 0.25;  // share of healthy cases, [0, 1]
  std::uint64_t seed = 1;       // the whole loop is reproducible from this seed
  double min_rpm = 1800.0;      // input speed, uniform in [min_rpm, max_rpm] [rpm], > 0
  double max_rpm = 2600.0;
  double min_torque_nm = 30.0;  // input torque, uniform [N m], > 0
  double max_torque_nm = 80.0;
  double min_noise_m_per_s2 = 2.0;  // accelerometer noise RMS, uniform [m/s^2], >= 0
  double max_noise_m_per_s2 = 10.0;
  // ISO 1328-1 accuracy grade of every gear's pitch errors, an integer uniform in [min, max];
  // 0 (both): perfect gears. [0, 12]. Grades 5-8: precision to ordinary commercial gears.
  int min_accuracy_grade = 5, max_accuracy_grade = 8;
  // Runout (eccentricity) of every gear, uniform in [min, max] [m], >= 0.
  double min_runout_m = 0.0, max_runout_m = 20e-6;
  // Fault kinds drawn with equal probability among those enabled.
  bool root_crack = true, chip = true, missing = true, spall = true;
  // Crack length as a fraction of the largest the stiffness model accepts
  // (1.8 x root half-thickness / sin(crack angle)), uniform in [min, max], (0, 1].
  double min_crack_fraction = 0.3, max_crack_fraction = 0.95;
  // Chip depth along the profile from the tip, as a fraction of the module, uniform, (0, 2].
  double min_chip_modules = 0.25, max_chip_modules = 1.0;
  // Spall: centred on the pitch point, over the whole face, length along the line of action as
  // a fraction of the module, uniform in (0, 2], and depth (the gap it opens) in [m], uniform,
  // > 0.
  double min_spall_modules = 0.3, max_spall_modules = 1.5;
  double min_spall_depth_m = 5e-6, max_spall_depth_m = 30e-6;
  double fs_hz = 10000.0;              // output sampling rate [Hz]
  int slowest_shaft_revolutions = 11;  // recorded revolutions of the slowest shaft, >= 3 more
                                       // than detector.min_revolutions (the resampling kernel
                                       // needs margins at both ends)
  int steps_per_period = 20;           // RK4 steps per period of the highest natural frequency
                                       // (see sim::RunOptions)
  // NA4-style: each case is also simulated healthy (the same gears: the same pitch errors and
  // runout, speed and load; its own sensor noise) and given to the detector as its baseline
  // (GearDamageOptions::baseline). Doubles the simulation time.
  bool baseline = false;
  detect::GearDamageOptions detector;
  // Called after each case, e.g. to show progress; empty: nothing. The results do not depend
  // on it.
  std::function<void()> on_case_done;

  void validate() const;  // throws diag::InputError naming the field
};

// One shaft's evidence as the decision sees it (for the ROC).
struct ShaftEvidence {
  std::string shaft;
  double frequency_hz = 0;
  double score = 0;           // ShaftDamage::score (NaN: skipped)
  bool gates_passed = false;  // ShaftDamage::significant
};

struct GearDamageCase {
  std::string gearbox;  // Gearbox::name()
  bool faulty = false;
  std::string gear, truth_shaft;  // empty when healthy
  std::string kind;  // the fault vocabulary's "crack" | "chip" | "missing" | "spall"; "" healthy
  int tooth = 0;
  double size_m = 0;    // crack length, chip depth, spall length; 0 for a missing tooth
  double severity = 0;  // position of the size in its range [0, 1]; missing tooth: 1
  int accuracy_grade = 0;
  double runout_m = 0, rpm = 0, torque_nm = 0, noise_m_per_s2 = 0;
  detect::GearDamageResult result;
  std::vector<ShaftEvidence> evidence;
  std::string found_shaft;  // first finding's shaft, "" when none
  // faulty: "right" (status damaged on the truth shaft), "silent" (no finding or ambiguous),
  // "wrong" (damaged on another shaft); healthy: "right" (no finding) or "false_alarm".
  std::string outcome;
  bool correct = false;  // outcome == "right"
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

// The cases are spread over the gearboxes in turn (case i on gearboxes[i % size]).
GearDamageLoopReport run_gear_damage_loop(std::span<const diag::Gearbox> gearboxes,
                                          const GearDamageLoopOptions& options);
GearDamageLoopReport run_gear_damage_loop(const diag::Gearbox& gb,
                                          const GearDamageLoopOptions& options);

// The decision at another score threshold: the slowest shaft whose gates pass and whose score
// exceeds `threshold` ("" when none), as locate_gear_damage decides at damaged_score.
std::string decide_at(const GearDamageCase& c, double threshold);

// Outcome counts of one group of cases (a fault kind and size bin, or the healthy cases).
struct OutcomeCounts {
  int total = 0, right = 0, silent = 0, wrong = 0;
};
// Per fault kind and size third ("root_crack small", ...; "missing"), and "healthy" (right: no
// finding; wrong: false alarm), at the detector's threshold.
std::vector<std::pair<std::string, OutcomeCounts>> outcome_table(const GearDamageLoopReport& r);

// ROC points: at each threshold, the share of faulty cases put on the right shaft (per kind and
// overall), the share put on a wrong shaft, and the share of healthy cases with a finding.
struct RocPoint {
  double threshold = 0;
  double false_alarm_rate = 0;                // healthy cases with any finding
  double detection_rate = 0, wrong_rate = 0;  // faulty cases, right / wrong shaft
  std::vector<std::pair<std::string, double>> detection_by_kind;
};
std::vector<RocPoint> roc(const GearDamageLoopReport& r, std::span<const double> thresholds);

// One line per case that went wrong, the outcome table and a ROC over a range of thresholds.
std::string format_report(const GearDamageLoopReport& r);

}  // namespace validate
