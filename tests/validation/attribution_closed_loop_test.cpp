// Closed loop: random sporadic defects simulated on random three-shaft gearboxes (tooth counts
// 18..60, so shaft periods are mostly incommensurate), with runout 0.05 deg, mesh TE 0.005 deg,
// noise 0.002 deg RMS and 16-bit encoders, sizes 0.1..1 deg at the output; attributed from the
// angles alone and compared with the truth. Targets from the issue: >= 98 % right shaft for
// single defects, >= 95 % of defects attributed in two-defect cases, sizes within 15 %, no finding
// on healthy cases.
#include <gtest/gtest.h>

#include <iostream>

#include "validate/attribution_loop.hpp"

namespace {

TEST(AttributionClosedLoop, MeetsTheAttributionTargetsOverRandomGearboxesAndDefects) {
  validate::AttributionLoopOptions opt;
  opt.cases = 240;
  opt.seed = 20261122;
  opt.random_gearbox = true;
  std::mt19937_64 rng(1);
  const auto gb = validate::random_three_shaft(rng);  // unused when random_gearbox is set
  const auto r = validate::run_attribution_loop(gb, opt);
  std::cout << validate::format_report(r);
  ASSERT_GT(r.single_total, 50);
  ASSERT_GT(r.two_defects_total, 40);
  ASSERT_GT(r.healthy_total, 15);
  EXPECT_GE(r.single_correct, 0.98 * r.single_total);
  EXPECT_GE(r.two_defects_attributed, 0.95 * r.two_defects_total);
  EXPECT_EQ(r.healthy_clean, r.healthy_total);
  EXPECT_GE(r.sizes_within_tolerance, 0.98 * r.sizes_checked);
}

}  // namespace
