// A defect given as a flank deviation (gearbox defects[i].profile) drives the kinematic simulator
// through the seed-003 route: rolling the mate over the contour gives the angle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/geometry/profile.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/units.hpp"
#include "sim/dynamics/scenario.hpp"
#include "sim/kinematic/sporadic_defects.hpp"
#include "sim/mesh/profile_fault.hpp"

namespace {

using diag::units::deg_to_rad;
using nlohmann::json;

// Seed 003's gearbox (testdata: z1 = z3 = 18, z2 = z4 = 36, m = 3 mm) with one defect.
diag::Gearbox seed_box(const json& defect) {
  json j = diag::load_json_file(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
  j["defects"] = json::array({defect});
  return diag::parse_gearbox(j, "gb.json");
}

// A chip over the whole active flank of z2 (roll from the form circle to the tip), depth in um.
json z2_chip(double depth_um) {
  const diag::Gearbox gb = seed_box({{"gear", "z2"}, {"size_deg", 0.1}});  // outlives the mesh
  const diag::Flank f = diag::generate_tooth(gb.meshes()[0].pair.driven()).flank;
  auto roll_deg = [&](double r) {
    return diag::units::rad_to_deg(std::sqrt(std::pow(r / f.base_radius_m, 2) - 1));
  };
  return {{"kind", "chip"},
          {"roll_deg", {roll_deg(f.form_radius_m), roll_deg(f.top_radius_m())}},
          {"depth_um", depth_um}};
}

double peak_output_lag(const diag::Gearbox& gb) {
  sim::KinematicOptions o;
  o.step_rad = deg_to_rad(0.002);
  o.revolutions = 3;
  const auto r = sim::simulate_kinematic(gb, o);
  return *std::max_element(r.irregularity_rad.begin(), r.irregularity_rad.end());
}

// The seed's example scaled to a size a single tooth can lose (0.1 deg on z2, f_20 = 10 deg):
// the chip r_b2 x 0.1 deg deep, rolled, gives the same defect size and the same output lag
// (0.05 deg) as the direct size_deg route, within 0.1 % (the rolling's 5 nm chords on 88 um).
TEST(ProfileDefect, ChipRouteAndDirectAngleAgreeForTheSeedExampleScaledToOneTenth) {
  const diag::Gearbox direct = seed_box({{"gear", "z2"}, {"size_deg", 0.1}, {"phase_deg", 10.0}});
  const double rb2 = direct.meshes()[0].pair.driven().base_radius_m();
  const double depth_um = 1e6 * rb2 * deg_to_rad(0.1);
  const diag::Gearbox rolled =
      seed_box({{"gear", "z2"}, {"profile", z2_chip(depth_um)}, {"phase_deg", 10.0}});
  const double size = rolled.defects()[0].size_rad;
  EXPECT_NEAR(size, deg_to_rad(0.1), 1e-3 * deg_to_rad(0.1));
  const double a = peak_output_lag(direct), b = peak_output_lag(rolled);
  EXPECT_NEAR(a, deg_to_rad(0.05), 1e-9);
  EXPECT_NEAR(b, a, 1e-3 * a);
}

// The seed's 1 deg itself: the chip 1 deg deep saturates where the neighbouring pairs take over
// (0.15 deg for this pair), so the rolled size is well below 1 deg; the kinematic simulator then
// shows half of it at the output.
TEST(ProfileDefect, SeedOneDegreeAsAChipIsLimitedByTheNeighbouringTeeth) {
  const double rb2 =
      seed_box({{"gear", "z2"}, {"size_deg", 0.1}}).meshes()[0].pair.driven().base_radius_m();
  const diag::Gearbox rolled =
      seed_box({{"gear", "z2"}, {"profile", z2_chip(1e6 * rb2 * deg_to_rad(1.0))}});
  const double size = rolled.defects()[0].size_rad;
  EXPECT_GT(size, deg_to_rad(0.1));
  EXPECT_LT(size, deg_to_rad(0.2));
  EXPECT_NEAR(peak_output_lag(rolled), 0.5 * size, 1e-3 * size);
}

TEST(ProfileDefect, BadProfileDefectsAreRefusedNamingTheField) {
  auto msg = [](const json& d) {
    try {
      seed_box(d);
    } catch (const diag::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(msg({{"gear", "z2"}, {"size_deg", 0.1}, {"profile", z2_chip(10)}}).find("size_deg"),
            std::string::npos);
  EXPECT_NE(
      msg({{"gear", "z2"}, {"profile", {{"kind", "chip"}, {"roll_deg", {5, 90}}, {"depth_um", 5}}}})
          .find("defects[0].profile: roll_deg"),
      std::string::npos);
  // A missing field is refused naming it (it read freed memory once: libFuzzer,
  // fuzz/regressions/gearbox_json/profile_without_roll.json).
  EXPECT_NE(msg({{"gear", "z2"}, {"profile", {{"kind", "chip"}, {"depth_um", 5}}}})
                .find("defects[0].profile.roll_deg: required field is missing"),
            std::string::npos)
      << msg({{"gear", "z2"}, {"profile", {{"kind", "chip"}, {"depth_um", 5}}}});
}

}  // namespace

namespace {

// The dynamic model takes the deviation as a full-width spall over its part of the path of
// contact, with the rolled lag as its gap: a 10 um chip over the whole flank of driven tooth 3 is a
// 10 um gap (within 0.1 %, the rolling's chords) for pairs with that tooth, none for the others.
TEST(ProfileDefect, DynamicModelTakesTheDeviationAsAGapOnItsTooth) {
  const diag::Gearbox gb = seed_box({{"gear", "z2"}, {"size_deg", 0.1}});  // outlives the pair
  const diag::GearPair& p = gb.meshes()[0].pair;
  const sim::ToothFault f = sim::profile_fault(p, false, 3, z2_chip(10.0), "scenario.json");
  EXPECT_EQ(f.kind, sim::ToothFault::Kind::kSpall);
  EXPECT_NEAR(f.depth_m, 10e-6, 1e-3 * 10e-6);
  EXPECT_NEAR(f.s_center_m - 0.5 * f.size_m, p.s_start_m(), 1e-12);
  EXPECT_NEAR(f.s_center_m + 0.5 * f.size_m, p.s_end_m(), 1e-12);
  const sim::MeshStiffness k(p, {}, {f});
  const double s = 0.5 * (p.s_start_m() + p.s_end_m());
  EXPECT_NEAR(k.pair_gap(s, 0, 3), f.depth_m, 1e-15);
  EXPECT_EQ(k.pair_gap(s, 0, 4), 0.0);
  // The scenario form: {"type": "profile", "gear", "tooth", "profile": {...}}.
  const sim::Scenario sc = sim::parse_scenario(
      {{"faults", {{{"gear", "z2"}, {"tooth", 3}, {"type", "profile"}, {"profile", z2_chip(10)}}}}},
      "scenario.json");
  ASSERT_EQ(sc.dynamics.faults.size(), 1u);
  EXPECT_FALSE(sc.dynamics.faults[0].profile_json.empty());
}

}  // namespace
