#include "validate/gear_damage_loop.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"

namespace {

// Floors on the report set below, measured at this commit (the loop is deterministic; the
// margins are for other compilers' and the sanitizer build's round-off, which can move a case
// across a threshold): without a baseline 0 false alarms in 16 healthy cases, 0 wrong shafts,
// 14 of 32 faulty cases right (every missing tooth, 11 of 11); with a baseline 11 of 12 right, 0
// wrong, 0 false alarms in 4.
constexpr int kMaxFalseAlarms = 1;
constexpr int kMaxWrongShaft = 1;
constexpr double kMinMissingRight = 0.85;
constexpr double kMinRight = 0.4;
constexpr double kMinRightWithBaseline = 0.75;

diag::Gearbox load(const std::string& name) {
  return diag::load_gearbox(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/" + name);
}

// The report set (docs/validation.md, "The damaged-shaft locator on realistic gears"): the two
// gearboxes the thresholds were never tuned on (17/44 x 21/50 and the single-stage 29/47) and the
// two they were tuned on (with other seeds there), all with non-integer ratios but the three-shaft
// box.
std::vector<diag::Gearbox> report_gearboxes() {
  return {load("two_stage_17_44_21_50.json"), load("single_stage_29_47.json"),
          load("two_stage_23_41_19_53.json"), load("three_shaft.json")};
}

TEST(GearDamageLoop, IsReproducibleFromItsSeedAndCountsEveryCase) {
  validate::GearDamageLoopOptions o;
  o.cases = 3;
  o.healthy_share = 1.0 / 3.0;
  o.seed = 11;
  const std::vector<diag::Gearbox> gbs = {load("single_stage_29_47.json"),
                                          load("three_shaft.json")};
  const auto a = validate::run_gear_damage_loop(gbs, o);
  const auto b = validate::run_gear_damage_loop(gbs, o);
  ASSERT_EQ(a.cases.size(), 3u);
  EXPECT_EQ(a.healthy_total, 1);
  EXPECT_EQ(a.faulty_total, 2);
  EXPECT_EQ(a.faulty_correct + a.faulty_missed + a.faulty_wrong_shaft + a.faulty_ambiguous,
            a.faulty_total);
  for (std::size_t i = 0; i < a.cases.size(); ++i) {
    const auto& ca = a.cases[i];
    const auto& cb = b.cases[i];
    EXPECT_EQ(ca.gearbox, gbs[i % 2].name());
    EXPECT_EQ(ca.gear, cb.gear);
    EXPECT_EQ(ca.tooth, cb.tooth);
    EXPECT_EQ(ca.size_m, cb.size_m);
    EXPECT_EQ(ca.rpm, cb.rpm);
    EXPECT_EQ(ca.accuracy_grade, cb.accuracy_grade);
    EXPECT_EQ(ca.runout_m, cb.runout_m);
    EXPECT_GE(ca.accuracy_grade, o.min_accuracy_grade);
    EXPECT_LE(ca.accuracy_grade, o.max_accuracy_grade);
    EXPECT_GE(ca.runout_m, o.min_runout_m);
    EXPECT_LE(ca.runout_m, o.max_runout_m);
    EXPECT_EQ(ca.result.status, cb.result.status);
    ASSERT_EQ(ca.result.shafts.size(), cb.result.shafts.size());
    for (std::size_t s = 0; s < ca.result.shafts.size(); ++s) {
      // Same seed, same arithmetic: the same bytes.
      EXPECT_EQ(ca.result.shafts[s].score, cb.result.shafts[s].score);
    }
    if (ca.faulty) {
      EXPECT_EQ(ca.truth_shaft, gbs[i % 2].gears()[gbs[i % 2].gear_index(ca.gear)].shaft);
      EXPECT_GE(ca.rpm, o.min_rpm);
      EXPECT_LE(ca.rpm, o.max_rpm);
    }
  }
  // The ROC at the detector's own threshold is the detector's decision (no case here is
  // "ambiguous", which the ROC does not model).
  const double th = o.detector.damaged_fm4;
  for (const auto& c : a.cases) {
    if (c.result.status != "ambiguous") {
      EXPECT_EQ(validate::decide_at(c, th), c.found_shaft);
    }
  }
}

TEST(GearDamageLoop, BadOptionsAreRefused) {
  validate::GearDamageLoopOptions o;
  o.cases = 0;
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.max_rpm = o.min_rpm - 1;
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.root_crack = o.chip = o.missing = o.spall = false;
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.slowest_shaft_revolutions = o.detector.min_revolutions;
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.max_accuracy_grade = 13;
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.min_accuracy_grade = 7;
  o.max_accuracy_grade = 6;
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.max_runout_m = -1e-6;
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.max_spall_depth_m = 0.5 * o.min_spall_depth_m;
  EXPECT_THROW(o.validate(), diag::InputError);
}

// The acceptance: realistic gears (ISO 1328 grades 5-8, runout 0-20 um on every gear,
// healthy and faulty alike) on four gearboxes, two never used for tuning, seed 2024 (tuning
// used seed 11). The locator must rarely claim damage on a healthy box and almost never name
// the wrong shaft; it is allowed to be silent, and is on small cracks, chips and spalls whose
// effect on the vibration is below that of the largest pitch deviation of the gear (without a
// baseline that cannot be told apart: docs/validation.md ("The damaged-shaft locator") gives
// the rates per class and the ROC). Every missing tooth must be found.
TEST(GearDamageLoop, RealisticGearsRaiseFewFalseAlarmsAndNoWrongShaft) {
  validate::GearDamageLoopOptions o;
  o.cases = 48;
  o.healthy_share = 1.0 / 3.0;
  o.seed = 2024;
  const auto r = validate::run_gear_damage_loop(report_gearboxes(), o);
  std::printf("%s", validate::format_report(r).c_str());
  ASSERT_EQ(r.healthy_total, 16);
  EXPECT_LE(r.healthy_false_alarms, kMaxFalseAlarms);
  EXPECT_LE(r.faulty_wrong_shaft, kMaxWrongShaft);
  int missing = 0, missing_right = 0;
  for (const auto& c : r.cases) {
    if (c.kind != "missing") continue;
    ++missing;
    missing_right += c.correct;
  }
  EXPECT_GE(missing_right, kMinMissingRight * missing);
  EXPECT_GE(r.faulty_correct, kMinRight * r.faulty_total);
}

// With a healthy baseline of the same gears (NA4-style: the pitch errors' pattern subtracted),
// seed 2025: most faults are found, none on a wrong shaft, no false alarm.
TEST(GearDamageLoop, AHealthyBaselineCancelsThePitchErrors) {
  validate::GearDamageLoopOptions o;
  o.cases = 16;
  o.healthy_share = 0.25;
  o.seed = 2025;
  o.baseline = true;
  const auto r = validate::run_gear_damage_loop(report_gearboxes(), o);
  std::printf("%s", validate::format_report(r).c_str());
  EXPECT_EQ(r.healthy_false_alarms, 0);
  EXPECT_EQ(r.faulty_wrong_shaft, 0);
  EXPECT_GE(r.faulty_correct, kMinRightWithBaseline * r.faulty_total);
}

}  // namespace
