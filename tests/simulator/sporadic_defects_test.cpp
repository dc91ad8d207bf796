// Kinematic simulator of sporadic defects against the seed-003 example and its mechanics.
#include "sim/kinematic/sporadic_defects.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/truth.hpp"
#include "diag/units.hpp"

namespace {

using diag::units::deg_to_rad;
using diag::units::rad_to_deg;
using nlohmann::json;

json seed_gearbox(const json& defects) {
  json j = json::parse(R"({"shafts": [{"name": "input"}, {"name": "counter"}, {"name": "output"}],
   "gears": [{"name": "z1", "shaft": "input",   "teeth": 18, "module_mm": 3.0},
             {"name": "z2", "shaft": "counter", "teeth": 36, "module_mm": 3.0},
             {"name": "z3", "shaft": "counter", "teeth": 18, "module_mm": 3.0},
             {"name": "z4", "shaft": "output",  "teeth": 36, "module_mm": 3.0}],
   "meshes": [{"driver": "z1", "driven": "z2"}, {"driver": "z3", "driven": "z4"}],
   "input": {"shaft": "input", "speed_rpm": 30.0, "torque_nm": 50.0}})");
  j["defects"] = defects;
  return j;
}

// Onsets (input angle where the lag leaves zero) and heights of the lag pulses.
struct Pulse {
  double onset_deg, height_deg;
};
std::vector<Pulse> pulses(const sim::KinematicResult& r) {
  std::vector<Pulse> out;
  const auto& e = r.irregularity_rad;
  constexpr double kZero = 1e-12;  // exact kinematics: the lag is zero between pulses
  for (std::size_t i = 1; i < e.size(); ++i) {
    if (e[i - 1] <= kZero && e[i] > kZero) {
      std::size_t k = i;
      double h = 0;
      while (k < e.size() && e[k] > kZero) h = std::max(h, e[k++]);
      out.push_back({rad_to_deg(r.input_angle_rad[i - 1]), rad_to_deg(h)});
      i = k;
    }
  }
  return out;
}

sim::KinematicOptions exact(double step_deg = 0.01) {
  sim::KinematicOptions o;
  o.step_rad = deg_to_rad(step_deg);
  return o;
}

// Seed 003, Fig. 7a: 1 deg on z2, f_20 = 10 deg -> 0.5 deg at the output every 720 deg of
// input, first at 20 deg.
TEST(SporadicDefects, DefectOnZ2ReproducesTheSeedFigure7a) {
  const auto gb = diag::parse_gearbox(
      seed_gearbox({{{"gear", "z2"}, {"size_deg", 1.0}, {"phase_deg", 10.0}}}), "gb");
  const auto r = sim::simulate_kinematic(gb, exact());
  const auto p = pulses(r);
  ASSERT_EQ(p.size(), 12u);            // 24 input revolutions / 2
  constexpr double kAngleTol = 0.011;  // one 0.01 deg step
  for (std::size_t k = 0; k < p.size(); ++k) {
    EXPECT_NEAR(p[k].onset_deg, 20.0 + 720.0 * k, kAngleTol);
    EXPECT_NEAR(p[k].height_deg, 0.5, 1e-9);
  }
  EXPECT_DOUBLE_EQ(r.truth["defects"][0]["first_event_input_rad"].get<double>(), deg_to_rad(20.0));
  EXPECT_NEAR(r.truth["defects"][0]["size_output_rad"].get<double>(), deg_to_rad(0.5), 1e-15);
}

// The recording's truth reads back typed (diag/io/truth.hpp) with the vocabulary's kind.
TEST(SporadicDefects, TheRecordingsTruthIsTyped) {
  const auto gb = diag::parse_gearbox(
      seed_gearbox({{{"gear", "z2"}, {"size_deg", 1.0}, {"phase_deg", 10.0}, {"type", "pitting"}}}),
      "gb");
  const auto t = diag::parse_truth(sim::to_recording(gb, sim::simulate_kinematic(gb, exact(0.1))),
                                   "kinematic");
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(t->kind, "kinematic");
  ASSERT_EQ(t->defects.size(), 1u);
  EXPECT_EQ(t->defects[0].kind, diag::FaultKind::kPit);  // the alias, stored by its one name
  EXPECT_EQ(t->defects[0].shaft, "counter");
  EXPECT_DOUBLE_EQ(t->defects[0].period_input_rev, 2.0);
  EXPECT_NEAR(t->defects[0].size_gear_rad, deg_to_rad(1.0), 1e-15);
  EXPECT_TRUE(t->extra.contains("revolutions"));  // model-specific: kept as written
}

// Fig. 7b: 1 deg on z4, f_40 = 5 deg -> 1 deg every 1440 deg, first at 20 deg.
TEST(SporadicDefects, DefectOnZ4ReproducesTheSeedFigure7b) {
  const auto gb = diag::parse_gearbox(
      seed_gearbox({{{"gear", "z4"}, {"size_deg", 1.0}, {"phase_deg", 5.0}}}), "gb");
  const auto p = pulses(sim::simulate_kinematic(gb, exact()));
  ASSERT_EQ(p.size(), 6u);
  for (std::size_t k = 0; k < p.size(); ++k) {
    EXPECT_NEAR(p[k].onset_deg, 20.0 + 1440.0 * k, 0.011);
    EXPECT_NEAR(p[k].height_deg, 1.0, 1e-9);
  }
}

// The output stops during the gap: the lag grows at exactly the nominal output speed (slope
// 1/u = 0.25 per input radian), and the output never turns backwards.
TEST(SporadicDefects, TheDrivenSideStopsThenCatchesUp) {
  const auto gb = diag::parse_gearbox(
      seed_gearbox({{{"gear", "z1"}, {"size_deg", 2.0}, {"phase_deg", 90.0}}}), "gb");
  const auto r = sim::simulate_kinematic(gb, exact());
  const auto& out = r.output_angle_rad;
  std::size_t stopped = 0;
  for (std::size_t i = 1; i < out.size(); ++i) {
    ASSERT_GE(out[i], out[i - 1]);
    if (out[i] == out[i - 1]) ++stopped;
  }
  // Each pass stops the output while the input turns 2 deg (the gap on z1): 200 steps of 0.01
  // deg, per input revolution, over 24 revolutions.
  EXPECT_NEAR(static_cast<double>(stopped), 24 * 200, 24 * 2);
  const auto p = pulses(r);
  ASSERT_FALSE(p.empty());
  EXPECT_NEAR(p[0].height_deg, 2.0 / 4.0, 1e-9);  // size / u_1, u_1 = 4
}

// Fig. 9: two defects passing together overlap: the output stays stopped while either gap is
// taken up, so the lag is not the sum of the two pulses.
TEST(SporadicDefects, CoincidingDefectsOverlapRatherThanAdd) {
  const json both = {{{"gear", "z2"}, {"size_deg", 1.0}, {"phase_deg", 10.0}},
                     {{"gear", "z4"}, {"size_deg", 1.0}, {"phase_deg", 5.0}}};
  const auto gb = diag::parse_gearbox(seed_gearbox(both), "gb");
  const auto r = sim::simulate_kinematic(gb, exact());
  const auto a = sim::simulate_kinematic(
      diag::parse_gearbox(seed_gearbox(json::array({both[0]})), "a"), exact());
  const auto b = sim::simulate_kinematic(
      diag::parse_gearbox(seed_gearbox(json::array({both[1]})), "b"), exact());
  // Worked by hand: both gaps open at 20 deg of input. The output is stopped from 20 to 24 deg
  // (the counter stops 20..22 for z2's gap, and z4's 1 deg gap holds until 24), so the lag
  // rises at 1/u to 1 deg at 24 deg; at 22 deg it is 0.5 deg, where the naive sum of the two
  // single-defect pulses is 1.0 deg.
  double max_both = 0, max_diff = 0;
  for (std::size_t i = 0; i < r.irregularity_rad.size(); ++i) {
    max_both = std::max(max_both, r.irregularity_rad[i]);
    const double sum = a.irregularity_rad[i] + b.irregularity_rad[i];
    max_diff = std::max(max_diff, sum - r.irregularity_rad[i]);
    ASSERT_LE(r.irregularity_rad[i], sum + 1e-12);
  }
  // The output holds its previous sample's angle on the step where a gap opens: one step of
  // input (0.01 deg) is 0.0025 deg of lag at the output.
  constexpr double kOneStepDeg = 0.0025 + 1e-9;
  EXPECT_NEAR(rad_to_deg(max_both), 1.0, kOneStepDeg);
  EXPECT_NEAR(rad_to_deg(max_diff), 0.5, kOneStepDeg);
  const std::size_t at22 = static_cast<std::size_t>(std::lround(22.0 / 0.01));
  EXPECT_NEAR(rad_to_deg(r.irregularity_rad[at22]), 0.5, kOneStepDeg);
  EXPECT_NEAR(rad_to_deg(a.irregularity_rad[at22] + b.irregularity_rad[at22]), 1.0,
              2 * kOneStepDeg);
}

TEST(SporadicDefects, HealthyGearboxHasNoIrregularityAndTheSameSeedGivesTheSameSamples) {
  const auto gb = diag::parse_gearbox(seed_gearbox(json::array()), "gb");
  const auto r = sim::simulate_kinematic(gb, exact(0.1));
  for (double e : r.irregularity_rad) ASSERT_NEAR(e, 0.0, 1e-12);
  sim::KinematicOptions o = exact(0.1);
  o.noise_output_rad = 1e-5;
  o.runout_output_rad = 1e-4;
  o.encoder_counts_per_rev = 4096;
  const auto x = sim::simulate_kinematic(gb, o), y = sim::simulate_kinematic(gb, o);
  EXPECT_EQ(x.output_angle_rad, y.output_angle_rad);
  o.seed = 2;
  EXPECT_NE(sim::simulate_kinematic(gb, o).output_angle_rad, x.output_angle_rad);
}

TEST(SporadicDefects, RefusesAStepTooCoarseForTheDefectSayingWhatStepIsNeeded) {
  const auto gb = diag::parse_gearbox(
      seed_gearbox({{{"gear", "z1"}, {"size_deg", 0.1}, {"phase_deg", 0.0}}}), "gb");
  try {
    sim::simulate_kinematic(gb, exact(0.05));
    FAIL() << "expected InputError";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("step_rad"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("z1"), std::string::npos);
  }
}

}  // namespace
