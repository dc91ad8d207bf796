#include "validate/gear_damage_loop.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"

namespace {

diag::Gearbox two_stage() {
  return diag::load_gearbox(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
}

TEST(GearDamageLoop, IsReproducibleFromItsSeedAndCountsEveryCase) {
  validate::GearDamageLoopOptions o;
  o.cases = 3;
  o.healthy_share = 1.0 / 3.0;
  o.seed = 11;
  const diag::Gearbox gb = two_stage();
  const auto a = validate::run_gear_damage_loop(gb, o);
  const auto b = validate::run_gear_damage_loop(gb, o);
  ASSERT_EQ(a.cases.size(), 3u);
  EXPECT_EQ(a.healthy_total, 1);
  EXPECT_EQ(a.faulty_total, 2);
  EXPECT_EQ(a.faulty_correct + a.faulty_missed + a.faulty_wrong_shaft + a.faulty_ambiguous,
            a.faulty_total);
  for (std::size_t i = 0; i < a.cases.size(); ++i) {
    const auto& ca = a.cases[i];
    const auto& cb = b.cases[i];
    EXPECT_EQ(ca.gear, cb.gear);
    EXPECT_EQ(ca.tooth, cb.tooth);
    EXPECT_EQ(ca.size_m, cb.size_m);
    EXPECT_EQ(ca.rpm, cb.rpm);
    EXPECT_EQ(ca.result.status, cb.result.status);
    ASSERT_EQ(ca.result.shafts.size(), cb.result.shafts.size());
    for (std::size_t s = 0; s < ca.result.shafts.size(); ++s) {
      // Same seed, same arithmetic: the same bytes.
      EXPECT_EQ(ca.result.shafts[s].score, cb.result.shafts[s].score);
    }
    if (ca.faulty) {
      EXPECT_EQ(ca.truth_shaft, gb.gears()[gb.gear_index(ca.gear)].shaft);
      EXPECT_GE(ca.rpm, o.min_rpm);
      EXPECT_LE(ca.rpm, o.max_rpm);
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
  o.root_crack = o.chip = o.missing = false;
  EXPECT_THROW(o.validate(), diag::InputError);
  o = {};
  o.slowest_shaft_revolutions = o.detector.min_revolutions;
  EXPECT_THROW(o.validate(), diag::InputError);
}

// The acceptance criterion of the closed loop (issue 5): 100 random cases (cracked, chipped or
// missing tooth on a random gear, random tooth, size, speed, load and noise; a quarter healthy),
// the right shaft in >= 95 % of the faulty cases and no finding on any healthy one (the numbers
// are printed). Measured at this commit: seed 2024 (this test) 75/75 faulty cases on the right
// shaft and no false alarm in 25; seeds 1 and 7 (not in CI) 74/75 (a 4.2 mm root crack on the
// input gear scored 4.8 < 5) and 75/75, no false alarm in either. Before the
// revolution-by-revolution pulse correction (GearDamageOptions::refine_speed) healthy cases near
// 2243 rpm raised false alarms from the tacho's quantisation (gear_damage_test.cpp,
// TachoQuantisationIsCorrectedFromTheMeshLinePhase).
TEST(GearDamageLoop, FindsTheDamagedShaftInNinetyFivePercentOfRandomCases) {
  validate::GearDamageLoopOptions o;
  o.cases = 100;
  o.healthy_share = 0.25;
  o.seed = 2024;
  const auto r = validate::run_gear_damage_loop(two_stage(), o);
  std::printf("%s", validate::format_report(r).c_str());
  constexpr double kRequiredAccuracy = 0.95;
  EXPECT_GE(r.faulty_accuracy(), kRequiredAccuracy);
  EXPECT_EQ(r.healthy_false_alarms, 0);
}

}  // namespace
