// The gear's bore (`bore_diameter_mm`, GearSpec::bore_diameter_m): parsed strictly and validated
// (0 <= bore < root diameter), the default (not given) is the stiffness model's old hidden
// choice r_int = 0.5 r_f, and the bore moves the seed pair's mesh stiffness as Sainsot's rim term
// says; the ISO 6336 cross-check is restated for the bores it covers.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <utility>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "sim/mesh/mesh_stiffness.hpp"

namespace {

// The seed pair (z = 49/51, m = 4 mm, b = 20 mm) with both bores given (mm; < 0: not given).
nlohmann::json seed_pair_json(double bore1_mm, double bore2_mm) {
  nlohmann::json j = {
      {"shafts", {{{"name", "input"}}, {{"name", "output"}}}},
      {"gears",
       {{{"name", "pinion"},
         {"shaft", "input"},
         {"teeth", 49},
         {"module_mm", 4.0},
         {"face_width_mm", 20.0}},
        {{"name", "wheel"},
         {"shaft", "output"},
         {"teeth", 51},
         {"module_mm", 4.0},
         {"face_width_mm", 20.0}}}},
      {"meshes", {{{"driver", "pinion"}, {"driven", "wheel"}}}},
      {"input", {{"shaft", "input"}, {"speed_rpm", 3000.0}, {"torque_nm", 2000.0}}}};
  if (bore1_mm >= 0) j["gears"][0]["bore_diameter_mm"] = bore1_mm;
  if (bore2_mm >= 0) j["gears"][1]["bore_diameter_mm"] = bore2_mm;
  return j;
}

double mean_stiffness_n_per_mm_um(double ratio) {  // both bores = ratio x root diameter
  const double df1 = 4.0 * (49 / 2.0 - 1.25) * 2, df2 = 4.0 * (51 / 2.0 - 1.25) * 2;  // [mm]
  const diag::Gearbox gb =
      diag::parse_gearbox(seed_pair_json(ratio * df1, ratio * df2), "seed_pair.json");
  const diag::GearPair& p = gb.meshes()[0].pair;
  return sim::to_n_per_mm_um(sim::MeshStiffness(p).mean_mesh_stiffness() / 0.020);
}

TEST(Bore, FieldIsParsedAndValidated) {
  const diag::Gearbox gb = diag::parse_gearbox(seed_pair_json(40, -1), "gb.json");
  EXPECT_DOUBLE_EQ(gb.gears()[0].spec.bore_diameter_m, 0.040);
  EXPECT_LT(gb.gears()[1].spec.bore_diameter_m, 0.0);  // not given: the default
  // Root diameter of the pinion: 4 (49 - 2.5) = 186 mm.
  EXPECT_NO_THROW(diag::parse_gearbox(seed_pair_json(0, 185.9), "gb.json"));
  for (double bad : {186.0, 200.0, -1.0}) {
    nlohmann::json j = seed_pair_json(-1, -1);
    j["gears"][0]["bore_diameter_mm"] = bad;
    EXPECT_THROW(diag::parse_gearbox(j, "gb.json"), diag::InputError) << bad;
  }
  nlohmann::json j = seed_pair_json(-1, -1);
  j["gears"][0]["bore_diameter_mm"] = "40";
  EXPECT_THROW(diag::parse_gearbox(j, "gb.json"), diag::InputError);
}

// Not giving the bore keeps the results of before the field existed: it equals a bore of half the
// root diameter exactly (the same h_fi = 2); a bore given on the gear overrides the option.
TEST(Bore, DefaultIsHalfTheRootDiameter) {
  const diag::Gearbox def = diag::parse_gearbox(seed_pair_json(-1, -1), "a.json");
  const double k_default = sim::MeshStiffness(def.meshes()[0].pair).mean_mesh_stiffness();
  EXPECT_NEAR(mean_stiffness_n_per_mm_um(0.5) * 0.020 * 1e9, k_default, 1e-9 * k_default);
}

// The seed pair's mean stiffness per face width against the bore. Measured (N/(mm um)): ratio
// 0.5 -> 20.6, 0.2 -> 13.5 (docs/validation.md); a solid disc (bore 0) is held at the 0.2
// value (mesh_stiffness.cpp: Sainsot's fit is not extrapolated). ISO 6336-1 method B gives
// c_gamma_alpha = 22.0 for every bore (C_R = 1: ISO's rim factor concerns webbed blanks, not the
// bore of a solid disc), so the cross-check holds only for the default bore: PEM/ISO = 0.94 at
// ratio 0.5, 0.61 at 0.2. The +-15 % band of the ISO test (mesh_stiffness_test.cpp) is a
// statement about bores near half the root diameter, not about gears in general.
TEST(Bore, MovesTheSeedPairsMeshStiffnessAndIsoDoesNotSeeIt) {
  const double k05 = mean_stiffness_n_per_mm_um(0.5), k02 = mean_stiffness_n_per_mm_um(0.2);
  EXPECT_NEAR(k05, 20.6, 0.05);
  EXPECT_NEAR(k02, 13.5, 0.05);
  EXPECT_NEAR(mean_stiffness_n_per_mm_um(0.0), k02, 1e-9 * k02);
  const diag::Gearbox gb = diag::parse_gearbox(seed_pair_json(-1, -1), "a.json");
  const double iso =
      sim::to_n_per_mm_um(sim::iso6336_method_b(gb.meshes()[0].pair).c_gamma_alpha_n_per_m2);
  EXPECT_NEAR(k05 / iso, 0.94, 0.01);
  EXPECT_NEAR(k02 / iso, 0.61, 0.01);
}

// The trend is physical (one might expect a smaller bore to give a stiffer mesh).
// Sainsot's FE models clamp the gear body at the bore (the shaft holds the gear there), and the
// mesh stiffness relates the contact to the rotation of that shaft: the body between the root
// circle and the bore is in series with the teeth. A thicker rim is a longer path, so a smaller
// bore gives a softer mesh, as the fit says. The elementary check: an annular disc (thickness
// b, shear modulus G) clamped at r_i and twisted at r_f turns by
//     theta = T / (4 pi G b) (1 / r_i^2 - 1 / r_f^2)        (plane stress, axisymmetric shear)
// i.e. along the line of action a compliance r_b^2 (1/r_i^2 - 1/r_f^2) / (4 pi G b) per gear.
// Between bore ratios 0.5 and r, the change in the seed pair's mesh compliance from Sainsot's
// fit must have the disc's sign (more compliant for a smaller bore, at every ratio checked) and
// be of its size: measured 0.68 (r = 0.4), 0.66 (0.3), 0.62 (0.2) of the disc's change; bound
// [0.4, 1.0] (the fit is local, its rim not the whole disc: the same order, not equality).
TEST(Bore, SmallerBoreSoftensTheMeshAsTheClampedDiscTwists) {
  const double b = 0.020, G = 206e9 / (2 * 1.3);
  const double rf1 = 4.0 * (49 / 2.0 - 1.25) * 1e-3, rf2 = 4.0 * (51 / 2.0 - 1.25) * 1e-3;
  const double rb1 = 2.0 * 49 * std::cos(20 * std::numbers::pi / 180) * 1e-3;
  const double rb2 = rb1 * 51 / 49;
  auto disc = [&](double ratio) {  // both gears' disc compliance along the LOA [m/N]
    double c = 0;
    for (const auto& [rb, rf] : {std::pair{rb1, rf1}, {rb2, rf2}}) {
      const double ri = ratio * rf;
      c += rb * rb * (1 / (ri * ri) - 1 / (rf * rf)) / (4 * std::numbers::pi * G * b);
    }
    return c;
  };
  auto mesh = [&](double ratio) {  // mesh compliance [m/N]
    return 1.0 / (mean_stiffness_n_per_mm_um(ratio) * 1e9 * b);
  };
  double previous = mesh(0.9);
  for (double r : {0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2}) {
    const double c = mesh(r);
    EXPECT_GT(c, previous) << "ratio " << r;
    previous = c;
    if (r < 0.5) {
      const double share = (c - mesh(0.5)) / (disc(r) - disc(0.5));
      EXPECT_GT(share, 0.4) << "ratio " << r;
      EXPECT_LT(share, 1.0) << "ratio " << r;
    }
  }
}

}  // namespace
