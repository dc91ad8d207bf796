// Wear histories (seed 004 and Archard): where wear goes, what it does to the transmission error,
// and the two laws against each other.
#include "sim/wear/wear.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "diag/error.hpp"
#include "sim/mesh/mesh_stiffness.hpp"

namespace {

diag::Gearbox pair_box(double torque_nm = 50.0, int z1 = 18, int z2 = 36) {
  nlohmann::json j = nlohmann::json::parse(R"({"shafts": [{"name": "in"}, {"name": "out"}],
   "gears": [{"name": "pinion", "shaft": "in", "teeth": 18, "module_mm": 3.0, "face_width_mm": 20},
             {"name": "wheel", "shaft": "out", "teeth": 36, "module_mm": 3.0, "face_width_mm": 20}],
   "meshes": [{"driver": "pinion", "driven": "wheel"}],
   "input": {"shaft": "in", "speed_rpm": 1000.0}})");
  j["input"]["torque_nm"] = torque_nm;
  j["gears"][0]["teeth"] = z1;
  j["gears"][1]["teeth"] = z2;
  return diag::parse_gearbox(j, "gb.json");
}

// Small and fast: 41 profile points, 16 TE angles per mesh period.
sim::WearOptions quick(sim::WearLaw law, int steps = 4, double cycles = 2e6) {
  sim::WearOptions o;
  o.law = law;
  o.steps = steps;
  o.cycles = cycles;
  o.profile_points = 41;
  o.te_points_per_mesh = 16;
  return o;
}

std::size_t argmax(const std::vector<double>& v) {
  return static_cast<std::size_t>(std::max_element(v.begin(), v.end()) - v.begin());
}

// lambda = 0 at the pitch point (a grid node): no sliding, no wear by either law; the driver's
// deepest wear lies in its dedendum (approach, below the pitch point). (The seed's intensity is
// largest at the very start of the active profile, lambda1 -> -inf towards the base circle, but
// only while that point is in contact: see wear_contact_test.cpp.)
TEST(Wear, ZeroAtThePitchPointAndDeepestInTheDriversDedendum) {
  const diag::Gearbox gb = pair_box();
  const double sp = gb.meshes()[0].pair.s_pitch_m();
  for (auto law : {sim::WearLaw::kArchard, sim::WearLaw::kSeed004}) {
    const sim::WearHistory h = sim::simulate_wear(gb, 0, quick(law));
    const auto& d1 = h.depth_driver_m.back();
    const auto pitch = static_cast<std::size_t>(
        std::find(h.roll_driver_m.begin(), h.roll_driver_m.end(), sp) - h.roll_driver_m.begin());
    ASSERT_LT(pitch, d1.size()) << "the grid has a node at the pitch point";
    const double deepest = d1[argmax(d1)];
    EXPECT_GT(deepest, 0.0);
    EXPECT_LT(d1[pitch], 1e-12 * deepest);  // round-off of lambda at the pitch point
    const auto& d2 = h.depth_driven_m.back();
    const auto pitch2 =
        static_cast<std::size_t>(std::find(h.roll_driven_m.begin(), h.roll_driven_m.end(),
                                           gb.meshes()[0].pair.loa_length_m() - sp) -
                                 h.roll_driven_m.begin());
    ASSERT_LT(pitch2, d2.size());
    EXPECT_LT(d2[pitch2], 1e-12 * deepest);
    EXPECT_LT(h.roll_driver_m[argmax(d1)], sp);
  }
}

// Archard in physical units: where one pair carries the whole load (single-tooth contact), one
// pass wears k_w (F / b) |lambda1|; a block of N driver revolutions wears N times that on the
// driver (closed form, round-off only).
TEST(Wear, ArchardDepthInTheSingleContactZoneIsKTimesLoadTimesSpecificSliding) {
  const diag::Gearbox gb = pair_box();
  const diag::GearPair& p = gb.meshes()[0].pair;
  sim::WearOptions o = quick(sim::WearLaw::kArchard, 1, 1e5);
  const sim::WearHistory h = sim::simulate_wear(gb, 0, o);
  const double lo = p.s_end_m() - p.base_pitch_m(), hi = p.s_start_m() + p.base_pitch_m();
  int checked = 0;
  for (std::size_t i = 0; i < h.roll_driver_m.size(); ++i) {
    const double s = h.roll_driver_m[i];
    if (s < lo + 1e-6 || s > hi - 1e-6) continue;
    const double lam = std::abs(p.kinematics(s, 1.0).specific_sliding_1);
    const double expect = o.cycles * o.archard_coefficient_m2_per_n * h.normal_force_n / 0.02 * lam;
    EXPECT_NEAR(h.depth_driver_m[0][i], expect, 1e-9 * expect + 1e-18);
    ++checked;
  }
  EXPECT_GE(checked, 5);
  // F = T / r_b1.
  EXPECT_NEAR(h.normal_force_n, 50.0 / p.driver().base_radius_m(), 1e-9);
}

// Worn flanks are no longer conjugate: the unloaded TE and its mesh harmonics grow with cycles
// (from the ~1e-8 rad numerical floor of perfect involutes).
TEST(Wear, TransmissionErrorAndItsMeshHarmonicsGrowWithCycles) {
  for (auto law : {sim::WearLaw::kArchard, sim::WearLaw::kSeed004}) {
    const sim::WearHistory h = sim::simulate_wear(pair_box(), 0, quick(law, 4, 4e6));
    ASSERT_EQ(h.cycles.size(), 4u);
    EXPECT_LT(h.te_peak_to_peak_new_rad, 1e-7);
    for (std::size_t k = 1; k < h.cycles.size(); ++k) {
      EXPECT_GT(h.te_peak_to_peak_rad[k], h.te_peak_to_peak_rad[k - 1]);
    }
    EXPECT_GT(h.te_peak_to_peak_rad.back(), 100 * h.te_peak_to_peak_new_rad);
    EXPECT_GT(h.te_harmonics_rad.back()[0], 2 * h.te_harmonics_rad.front()[0]);
    EXPECT_GT(h.te_harmonics_rad.back()[1], 2 * h.te_harmonics_rad.front()[1]);
  }
}

// The reported TE is that of the geometry the dynamic simulator runs: the worn state's gap
// g(s) = h1(s) + h2(T1T2 - s) put on every pair through MeshStiffness::set_profile_gap (the
// dynamic simulator's own path: its contacts at each driver angle, pair_gap resampled on the
// stiffness grid); the first pair to touch has the smallest gap, TE = -min gap / r_b2. Over 512
// driver angles of one mesh period its peak-to-peak must equal the history's (64 positions) within
// 3 % (the history samples 64 points of a piecewise-linear min, the stiffness grid resamples the
// gap) at every step of an Archard history of the 18/36 pair. (The rolled TE, which finds corner
// contact beyond the tracked flank, is close to it early in the life and smaller later: 820
// against 1161 urad at 1e7 cycles.)
TEST(Wear, ReportedTeIsTheGapTheDynamicSimulatorRuns) {
  const diag::Gearbox gb = pair_box();
  sim::WearOptions o = quick(sim::WearLaw::kArchard, 3, 6e6);
  o.te_points_per_mesh = 64;
  const sim::WearHistory h = sim::simulate_wear(gb, 0, o);
  const diag::GearPair& p = gb.meshes()[0].pair;
  for (std::size_t k = 0; k < h.cycles.size(); ++k) {
    const sim::WornPair w = sim::worn_pair(h, k);
    std::vector<double> s_m, gap_m;
    sim::worn_profile_gap(p, w, s_m, gap_m);
    sim::MeshStiffness ms(p);
    ms.set_profile_gap(s_m, gap_m);
    double lo = 1e300, hi = -1e300;
    for (int i = 0; i < 512; ++i) {
      const double phi = p.mesh_period_rad() * i / 512.0;
      const sim::MeshContacts c = ms.contacts(phi);
      double g = 1e300;
      for (int j = 0; j < c.count; ++j) {
        g = std::min(g,
                     ms.pair_gap(c.pairs[j].s_m, c.pairs[j].driver_tooth, c.pairs[j].driven_tooth));
      }
      const double te = -g / p.driven().base_radius_m();
      lo = std::min(lo, te);
      hi = std::max(hi, te);
    }
    EXPECT_NEAR(h.te_peak_to_peak_rad[k], hi - lo, 0.03 * (hi - lo)) << "step " << k;
    EXPECT_NEAR(w.te_peak_to_peak_rad, h.te_peak_to_peak_rad[k], 1e-15);
  }
}

// On the same new pair, one block of each law. With m = n = 0 the seed's intensity is |lambda|
// alone, and Archard's k_w F' |lambda| differs from it only by the load sharing: the depth
// profiles correlate > 0.95 on both gears (measured 0.97-0.997 over 18/31, 18/36, 18/61, 23/31,
// 23/36, 23/61 at 101 points). With m = -1/2 and n = 1 (the seed's curvature and a sliding-
// speed factor, the latter counting sliding a second time: why the default is now n = 0) the
// driver still correlates > 0.9 (measured 0.95-0.96), the driven gear less (measured 0.68-0.90):
// bounds 0.9 and 0.6.
TEST(Wear, ArchardAndTheSeedLawAgreeInShape) {
  for (const auto& [z1, z2] : {std::pair{18, 36}, {23, 61}}) {
    const diag::Gearbox gb = pair_box(50.0, z1, z2);
    // One explicit block (no sub-blocks): both laws at the new pair's per-pass rates.
    sim::WearOptions oa = quick(sim::WearLaw::kArchard, 1, 1e5);
    oa.substep_depth_m = 1e-3;
    const auto a = sim::simulate_wear(gb, 0, oa);
    sim::WearOptions o = quick(sim::WearLaw::kSeed004, 1, 1e5);
    o.seed_exponent_n = 1;
    const auto s = sim::simulate_wear(gb, 0, o);
    EXPECT_GT(sim::shape_correlation(a.depth_driver_m[0], s.depth_driver_m[0]), 0.9);
    EXPECT_GT(sim::shape_correlation(a.depth_driven_m[0], s.depth_driven_m[0]), 0.6);
    o.seed_exponent_m = 0;
    o.seed_exponent_n = 0;
    const auto l = sim::simulate_wear(gb, 0, o);
    EXPECT_GT(sim::shape_correlation(a.depth_driver_m[0], l.depth_driver_m[0]), 0.95);
    EXPECT_GT(sim::shape_correlation(a.depth_driven_m[0], l.depth_driven_m[0]), 0.95);
    // Calibrated scale: the seed law's worst point wears as much per pass as Archard's.
    auto deepest = [](const sim::WearHistory& h) {
      return std::max(*std::max_element(h.depth_driver_m[0].begin(), h.depth_driver_m[0].end()),
                      *std::max_element(h.depth_driven_m[0].begin(), h.depth_driven_m[0].end()));
    };
    EXPECT_NEAR(deepest(s), deepest(a), 1e-9 * deepest(a));
  }
}

TEST(Wear, StopsAtTheDepthLimit) {
  sim::WearOptions o = quick(sim::WearLaw::kSeed004, 50, 1e8);
  o.depth_limit_m = 20e-6;
  const auto h = sim::simulate_wear(pair_box(), 0, o);
  EXPECT_TRUE(h.stopped_at_limit);
  EXPECT_LT(h.cycles.size(), 50u);
  const double deepest =
      *std::max_element(h.depth_driver_m.back().begin(), h.depth_driver_m.back().end());
  EXPECT_GE(std::max(deepest, *std::max_element(h.depth_driven_m.back().begin(),
                                                h.depth_driven_m.back().end())),
            20e-6);
}

TEST(Wear, BadInputIsRefusedNamingTheField) {
  auto msg = [](const diag::Gearbox& gb, int mesh, sim::WearOptions o) {
    try {
      sim::simulate_wear(gb, mesh, o);
    } catch (const diag::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  sim::WearOptions o = quick(sim::WearLaw::kArchard);
  o.steps = 0;
  EXPECT_NE(msg(pair_box(), 0, o).find("steps"), std::string::npos);
  o = quick(sim::WearLaw::kArchard);
  o.cycles = -1;
  EXPECT_NE(msg(pair_box(), 0, o).find("cycles"), std::string::npos);
  EXPECT_NE(msg(pair_box(), 3, quick(sim::WearLaw::kArchard)).find("mesh"), std::string::npos);
  EXPECT_NE(msg(pair_box(0.0), 0, quick(sim::WearLaw::kArchard)).find("torque"), std::string::npos);
}

}  // namespace
