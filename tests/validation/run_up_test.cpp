// `analyze` on a run-up (docs/cli/analyze.md, "Varying speed"): the two-stage box
// (testdata/gearbox/three_shaft.json) accelerated linearly from 500 to 3000 rpm at the input, with
// a tacho on the input shaft, simulated with the dynamic simulator (10 kHz, sensor noise 4 m/s^2
// as in the closed loop). A cracked or chipped counter-shaft gear must be put on the counter
// shaft; a healthy run-up must give no gear_damage finding.
#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "detect/analysis/analyze.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "report/report.hpp"
#include "sim/dynamics/simulate.hpp"
#include "two_stage_case.hpp"

namespace {

constexpr double kFromRpm = 500.0;
constexpr double kToRpm = 3000.0;
// 9 s: the output shaft (1/4 of the input) turns (500 + 3000) / 2 / 60 / 4 x 9 = 32.8 times,
// well above the locator's min_revolutions (8) and enough for its noise estimate.
constexpr double kDurationS = 9.0;

diag::Gearbox two_stage() { return two_stage_case::gearbox(0.5 * (kFromRpm + kToRpm)); }

enum class Fault { kNone, kChip, kCrack };

// The run-up with the fault on `gear`: a chip of 0.8 module (analyze_gear_damage_test's) or the
// demo's 1.5 mm root crack.
diag::Recording simulate_run_up(const diag::Gearbox& gb, Fault fault, const std::string& gear) {
  std::optional<sim::GearFault> f;
  if (fault == Fault::kChip) f = two_stage_case::chip(gear);
  if (fault == Fault::kCrack) f = two_stage_case::root_crack(gear, 1.5e-3);
  return two_stage_case::simulate(gb, sim::SpeedProfile::ramp(kFromRpm, kToRpm, 0.0, kDurationS),
                                  kDurationS, f);
}

using two_stage_case::of_kind;

void print_run(const std::string& what, const detect::AnalysisResult& r) {
  std::cout << what << ": speed " << r.speed.min_rpm << "-" << r.speed.max_rpm << " rpm\n";
  if (!r.gear_damage) return;
  std::cout << " status " << r.gear_damage->status << ", note: " << r.gear_damage->note << "\n";
  for (const auto& s : r.gear_damage->shafts) {
    std::cout << "  " << s.shaft << ": revs " << s.revolutions << " score " << s.score << " fm4 "
              << s.fm4 << " snr " << s.snr << " level " << s.level << " share " << s.exclusive_share
              << " damaged " << s.damaged << "\n";
  }
}

// Measured (seed 3): counter tooth score 47 (damaged above 20), SNR 19, level 0.12 (the input
// shaft, flagged by the fold of the counter's fault, score 41, is faster: the slowest flagged
// shaft wins; the counter's period is 2 x the input's, which the note says). Before the fix: no
// finding, every shaft smeared (SNR 0.8-1.0): a cubic t(k) was off the true pulses by up to 5
// revolutions.
TEST(RunUp, AChippedCounterGearIsAFindingOnTheCounterShaft) {
  const diag::Gearbox gb = two_stage();
  const detect::AnalysisResult r =
      detect::analyze_recording(simulate_run_up(gb, Fault::kChip, "z3"), &gb);
  print_run("chip z3", r);
  ASSERT_TRUE(r.gear_damage.has_value());
  EXPECT_FALSE(r.speed.stationary);
  const auto found = of_kind(r, "gear_damage");
  ASSERT_EQ(found.size(), 1u) << report::to_json(r)["gear_damage"].dump(1);
  EXPECT_EQ(found[0].shaft, "counter");
}

// The crack is the smallest fault here: at steady speed (1000, 1750, 3000 rpm, the same 9 s) its
// counter shaft level is 0.0051-0.0057, against min_level 0.005, and in this run-up 0.0054-0.0062
// (seeds 1-4), SNR 2.4 (seed 3; 3.5 with the tooth score) against min_snr 2: a finding at the
// locator's own margin, not a loosened one; tooth score 27 (seed 3) against 20. Before the fix (a
// cubic t(k), the plain average): no finding at all on the counter shaft (SNR 0.8), and with only
// the pulse fit fixed, the crack went to the input shaft (score 27, the counter's SNR 1.1).
TEST(RunUp, ACrackedCounterGearIsAFindingOnTheCounterShaft) {
  const diag::Gearbox gb = two_stage();
  const detect::AnalysisResult r =
      detect::analyze_recording(simulate_run_up(gb, Fault::kCrack, "z2"), &gb);
  print_run("crack z2", r);
  ASSERT_TRUE(r.gear_damage.has_value());
  const auto found = of_kind(r, "gear_damage");
  ASSERT_EQ(found.size(), 1u) << report::to_json(r)["gear_damage"].dump(1);
  EXPECT_EQ(found[0].shaft, "counter");
}

// Measured (seed 3): SNR 1.4, 1.0, 0.7 on input, counter, output (noise alone: 1), levels below
// min_level: nothing is scored.
TEST(RunUp, AHealthyRunUpHasNoGearDamageFinding) {
  const diag::Gearbox gb = two_stage();
  const detect::AnalysisResult r =
      detect::analyze_recording(simulate_run_up(gb, Fault::kNone, ""), &gb);
  print_run("healthy", r);
  ASSERT_TRUE(r.gear_damage.has_value());
  EXPECT_TRUE(of_kind(r, "gear_damage").empty()) << report::to_json(r)["gear_damage"].dump(1);
}

// The other shafts' gears in the same run-up: the chip is put on its own shaft, never on another
// (the slowest flagged shaft wins; the input shaft is flagged too by z4's fault, which folds into
// the faster shafts' averages).
struct OwnShaftCase {
  std::string gear, shaft;
};
class RunUpOwnShaft : public ::testing::TestWithParam<OwnShaftCase> {};

TEST_P(RunUpOwnShaft, AChippedGearIsAFindingOnItsOwnShaft) {
  const diag::Gearbox gb = two_stage();
  const detect::AnalysisResult r =
      detect::analyze_recording(simulate_run_up(gb, Fault::kChip, GetParam().gear), &gb);
  print_run("chip " + GetParam().gear, r);
  const auto found = of_kind(r, "gear_damage");
  ASSERT_EQ(found.size(), 1u) << report::to_json(r)["gear_damage"].dump(1);
  EXPECT_EQ(found[0].shaft, GetParam().shaft);
}

INSTANTIATE_TEST_SUITE_P(RunUpChip, RunUpOwnShaft,
                         ::testing::Values(OwnShaftCase{"z1", "input"},
                                           OwnShaftCase{"z4", "output"}),
                         [](const auto& info) { return info.param.gear; });

}  // namespace
