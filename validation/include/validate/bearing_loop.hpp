// Closed-loop validation of diagnose_bearings_from_signal (detect/bearing/bearing_diagnosis.hpp) on
// signals from the bearing kinematics (sim/bearing/bearing_signal.hpp): every fault class (outer
// race, inner race, rolling element, cage, and healthy) at every shaft speed, impact amplitude
// ("size") and SNR of the grid, several seeds each; the answer is compared with the truth and
// counted as
//   right  - the class named (healthy: nothing named; cage: the cage note, never a finding),
//   silent - nothing named (for a cage fault, nothing at all),
//   wrong  - another part named (healthy: any finding).
// Validation is the one place besides the tests where simulator and detectors meet.
//
// The bearing is the CWRU drive-end SKF 6205 (9 balls, P_d 39.04 mm, B_d 7.94 mm). Per case the
// nuisance parameters are drawn from the case's seed: mean slip uniform in [0, 1 %] (the rate is
// below the kinematic one, within the detector's 1 % window), interval jitter uniform in
// [0.2, 1 %], resonance uniform in [2, 4.5] kHz with damping uniform in [3, 8 %], the defect's
// load-zone phase; ball faults also inner-strike gain uniform in [0.3, 0.8] and a track
// probability uniform in [0.6, 1]. Every case carries shaft orders 1..5 (amplitude 2 / h) and a
// gear mesh at 27.3 x the shaft rate (amplitude 2, harmonics 1..3), in the unit of the impact
// amplitude A: interference that prewhitening has to remove, 6 dB over the impacts' peak at size
// 1 and 3.5 dB under it at size 3.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "detect/bearing/bearing_diagnosis.hpp"
#include "sim/bearing/bearing_signal.hpp"

namespace validate {

struct BearingLoopOptions {
  std::vector<sim::BearingFaultKind> classes = {
      sim::BearingFaultKind::kNone, sim::BearingFaultKind::kOuterRace,
      sim::BearingFaultKind::kInnerRace, sim::BearingFaultKind::kRollingElement,
      sim::BearingFaultKind::kCage};
  std::vector<double> shaft_hz = {20.0, 30.0, 45.0};         // shaft speeds [Hz], each > 0
  std::vector<double> sizes = {1.0, 3.0};                    // impact amplitudes A [unit], each > 0
  std::vector<double> snr_db = {-20.0, -15.0, -10.0, -5.0};  // fault power / noise power [dB]
  int seeds = 2;                                             // seeds per grid point, >= 1
  std::uint64_t first_seed = 101;  // seeds first_seed .. first_seed + seeds - 1; the decision
                                   // was tuned on seeds 1-3, 101 on is the report set
  double fs_hz = 12000.0;          // sampling rate [Hz] (CWRU's fault records)
  double duration_s = 4.0;         // record length [s], > 0
  detect::BearingDiagnosisOptions detector;
  // Called after each case, e.g. to show progress; empty: nothing. The results do not depend
  // on it.
  std::function<void()> on_case_done;

  void validate() const;  // throws diag::InputError naming the field
};

enum class Outcome { kRight, kSilent, kWrong };
const char* to_string(Outcome o);  // "right", "silent", "wrong"

struct BearingCase {
  sim::BearingFaultKind truth = sim::BearingFaultKind::kNone;
  double shaft_hz = 0, size = 0, snr_db = 0;
  std::uint64_t seed = 0;
  std::string answer;  // the finding's fault, "cage_note", or "" (nothing)
  Outcome outcome = Outcome::kSilent;
};

struct OutcomeCount {
  int right = 0, silent = 0, wrong = 0;
  int total() const { return right + silent + wrong; }
};

struct BearingLoopReport {
  std::vector<BearingCase> cases;
  // Counts by class, and by class x SNR (snr index as in the options).
  std::vector<OutcomeCount> by_class;                   // classes order
  std::vector<std::vector<OutcomeCount>> by_class_snr;  // [class][snr]
  std::vector<double> snr_db;
  std::vector<sim::BearingFaultKind> classes;
};

BearingLoopReport run_bearing_loop(const BearingLoopOptions& options);

// The right / silent / wrong table by class x SNR (a markdown table) and one line per wrong case.
std::string format_report(const BearingLoopReport& r);

}  // namespace validate
