// Period matching and attribution on simulated kinematics with known truth.
#include "detect/attribution/period_matcher.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/units.hpp"
#include "sim/kinematic/sporadic_defects.hpp"

namespace {

using diag::units::deg_to_rad;
using nlohmann::json;

diag::Gearbox seed_gearbox(const json& defects) {
  json j = json::parse(R"({"shafts": [{"name": "input"}, {"name": "counter"}, {"name": "output"}],
   "gears": [{"name": "z1", "shaft": "input",   "teeth": 18, "module_mm": 3.0},
             {"name": "z2", "shaft": "counter", "teeth": 36, "module_mm": 3.0},
             {"name": "z3", "shaft": "counter", "teeth": 18, "module_mm": 3.0},
             {"name": "z4", "shaft": "output",  "teeth": 36, "module_mm": 3.0}],
   "meshes": [{"driver": "z1", "driven": "z2"}, {"driver": "z3", "driven": "z4"}],
   "input": {"shaft": "input", "speed_rpm": 30.0, "torque_nm": 50.0}})");
  j["defects"] = defects;
  return diag::parse_gearbox(j, "gb");
}

sim::KinematicOptions rig() {
  sim::KinematicOptions o;
  o.step_rad = deg_to_rad(0.02);
  o.runout_output_rad = deg_to_rad(0.05);
  o.mesh_te_output_rad = deg_to_rad(0.005);
  o.noise_output_rad = deg_to_rad(0.002);
  o.encoder_counts_per_rev = 1 << 16;
  return o;
}

detect::AttributionResult run(const diag::Gearbox& gb, const sim::KinematicOptions& o) {
  const auto r = sim::simulate_kinematic(gb, o);
  return detect::attribute_defects(r.input_angle_rad, r.output_angle_rad, gb, {});
}

constexpr double kSizeTol = 0.05;  // relative: noise 0.002 deg and 16-bit encoders vs >= 0.3 deg

TEST(PeriodMatcher, AttributesADefectOnZ2ToTheCountershaftWithItsSize) {
  const auto gb = seed_gearbox({{{"gear", "z2"}, {"size_deg", 1.0}, {"phase_deg", 10.0}}});
  const auto a = run(gb, rig());
  ASSERT_EQ(a.findings.size(), 1u);
  EXPECT_FALSE(a.multiplicity);
  const auto& f = a.findings[0];
  EXPECT_EQ(f.shaft, "counter");
  EXPECT_EQ(f.gears, (std::vector<std::string>{"z2", "z3"}));  // one shaft: either gear
  EXPECT_DOUBLE_EQ(f.evidence_value("period_input_rev"), 2.0);
  EXPECT_NEAR(f.evidence_value("measured_period_input_rev"), 2.0, 1e-3);
  EXPECT_NEAR(f.evidence_value("size_output_rad") / deg_to_rad(0.5), 1.0, kSizeTol);
  EXPECT_NEAR(f.size / deg_to_rad(1.0), 1.0, kSizeTol);
  EXPECT_NEAR(f.evidence_value("first_event_input_rad"), deg_to_rad(20.0), deg_to_rad(0.2));
  EXPECT_GT(f.confidence, 0.9);
}

TEST(PeriodMatcher, FindsTheSeedsTwoCoincidingDefectsAndNamesTheAlternative) {
  const auto gb = seed_gearbox({{{"gear", "z2"}, {"size_deg", 1.0}, {"phase_deg", 10.0}},
                                {{"gear", "z4"}, {"size_deg", 1.0}, {"phase_deg", 5.0}}});
  const auto a = run(gb, rig());
  ASSERT_EQ(a.findings.size(), 2u);
  EXPECT_FALSE(a.multiplicity);
  std::map<std::string, const detect::Finding*> by_shaft;
  for (const auto& f : a.findings) by_shaft[f.shaft] = &f;
  ASSERT_TRUE(by_shaft.count("counter") && by_shaft.count("output"));
  EXPECT_NEAR(by_shaft["counter"]->evidence_value("size_output_rad") / deg_to_rad(0.5), 1.0,
              kSizeTol);
  EXPECT_NEAR(by_shaft["output"]->evidence_value("size_output_rad") / deg_to_rad(1.0), 1.0,
              kSizeTol);
  EXPECT_FALSE(by_shaft["output"]->note.empty());
}

TEST(PeriodMatcher, SeparatesTwoDefectsOnOneShaftByPhase) {
  const auto gb = seed_gearbox({{{"gear", "z2"}, {"size_deg", 0.8}, {"phase_deg", 40.0}},
                                {{"gear", "z3"}, {"size_deg", 0.6}, {"phase_deg", 200.0}}});
  const auto a = run(gb, rig());
  ASSERT_EQ(a.findings.size(), 2u);
  for (const auto& f : a.findings) EXPECT_EQ(f.shaft, "counter");
  EXPECT_NEAR(a.findings[0].size / deg_to_rad(0.8), 1.0, kSizeTol);
  EXPECT_NEAR(a.findings[1].size / deg_to_rad(0.6), 1.0, kSizeTol);
}

TEST(PeriodMatcher, HealthyRecordingGivesNoFinding) {
  const auto a = run(seed_gearbox(json::array()), rig());
  EXPECT_TRUE(a.findings.empty());
  EXPECT_FALSE(a.multiplicity);
  EXPECT_EQ(a.status, detect::AttributionStatus::kHealthy);
}

TEST(PeriodMatcher, EventsThatNoPeriodExplainsGiveMultiplicity) {
  // A defect train every 3 input revolutions: no shaft of this gearbox turns with that period.
  auto r = sim::simulate_kinematic(seed_gearbox(json::array()), rig());
  const double p = 3 * 2 * M_PI;
  for (std::size_t i = 0; i < r.output_angle_rad.size(); ++i) {
    const double y = std::fmod(r.input_angle_rad[i] + 1.0, p);
    const double h = deg_to_rad(0.4);
    if (y < 0.05)
      r.output_angle_rad[i] -= h * y / 0.05;
    else if (y < 0.1)
      r.output_angle_rad[i] -= h * (0.1 - y) / 0.05;
  }
  const auto gb = seed_gearbox(json::array());
  const auto a = detect::attribute_defects(r.input_angle_rad, r.output_angle_rad, gb, {});
  EXPECT_TRUE(a.findings.empty());
  EXPECT_TRUE(a.multiplicity);
  EXPECT_GE(a.unexplained.size(), 7u);  // 24 / 3 trains
  EXPECT_EQ(a.status, detect::AttributionStatus::kMultiplicity);
}

// Overlap: a 14-tooth (undercut) input pinion driving 35 teeth: the countershaft turns once per
// 2.5 input revolutions, so with the counter defect's first event placed 0.3 deg after an input
// event, every second counter event falls inside an input pulse and leaves no event of its own.
// Both defects must be found and sized from their clear events, with no multiplicity.
diag::Gearbox overlap_gearbox(const json& defects) {
  json j = json::parse(R"({"shafts": [{"name": "input"}, {"name": "counter"}, {"name": "output"}],
   "gears": [{"name": "z1", "shaft": "input",   "teeth": 14, "module_mm": 3.0},
             {"name": "z2", "shaft": "counter", "teeth": 35, "module_mm": 3.0},
             {"name": "z3", "shaft": "counter", "teeth": 23, "module_mm": 3.0},
             {"name": "z4", "shaft": "output",  "teeth": 61, "module_mm": 3.0}],
   "meshes": [{"driver": "z1", "driven": "z2"}, {"driver": "z3", "driven": "z4"}],
   "input": {"shaft": "input", "speed_rpm": 30.0, "torque_nm": 50.0}})");
  j["defects"] = defects;
  return diag::parse_gearbox(j, "gb");
}

json overlapping_pair() {
  // Counter phase so that its first event is at input angle 360.3 deg: phase = 360.3 / 2.5.
  return {{{"gear", "z1"}, {"size_deg", 3.0}, {"phase_deg", 0.0}},
          {{"gear", "z2"}, {"size_deg", 0.6}, {"phase_deg", 360.3 / 2.5}}};
}

TEST(PeriodMatcher, SizesTwoOverlappingDefectsFromTheirClearEventsWithoutMultiplicity) {
  const auto gb = overlap_gearbox(overlapping_pair());
  EXPECT_FALSE(gb.warnings().empty());  // the undercut pinion is accepted with a warning
  const auto r = sim::simulate_kinematic(gb, rig());
  const auto a = detect::attribute_defects(r.input_angle_rad, r.output_angle_rad, gb, {});
  EXPECT_FALSE(a.multiplicity) << detect::format_table(a);
  ASSERT_EQ(a.findings.size(), 2u) << detect::format_table(a);
  std::map<std::string, const detect::Finding*> by_shaft;
  for (const auto& f : a.findings) by_shaft[f.shaft] = &f;
  ASSERT_TRUE(by_shaft.count("input") && by_shaft.count("counter"));
  EXPECT_NEAR(by_shaft["input"]->size / deg_to_rad(3.0), 1.0, kSizeTol);
  EXPECT_NEAR(by_shaft["counter"]->size / deg_to_rad(0.6), 1.0, kSizeTol);
  EXPECT_GT(by_shaft["input"]->evidence_value("coincident_events"), 0);
}

// The overlap handling must not swallow a real further defect: the same pair plus a train every
// 3 input revolutions (no shaft of this gearbox has that period) still raises multiplicity.
TEST(PeriodMatcher, AThirdUnmatchedTrainBesideAnOverlappingPairStillRaisesMultiplicity) {
  const auto gb = overlap_gearbox(overlapping_pair());
  auto r = sim::simulate_kinematic(gb, rig());
  const double p = 3 * 2 * M_PI, h = deg_to_rad(0.1);
  for (std::size_t i = 0; i < r.output_angle_rad.size(); ++i) {
    const double y = std::fmod(r.input_angle_rad[i] + 2.0, p);
    if (y < 0.05)
      r.output_angle_rad[i] -= h * y / 0.05;
    else if (y < 0.1)
      r.output_angle_rad[i] -= h * (0.1 - y) / 0.05;
  }
  const auto a = detect::attribute_defects(r.input_angle_rad, r.output_angle_rad, gb, {});
  EXPECT_TRUE(a.multiplicity) << detect::format_table(a);
  EXPECT_GE(a.unexplained.size(), 5u) << detect::format_table(a);
  EXPECT_EQ(a.status, detect::AttributionStatus::kMultiplicity);
}

TEST(PeriodMatcher, RefusesARecordTooShortSayingHowLongIsNeeded) {
  std::vector<double> in(1000), out(1000);
  for (std::size_t i = 0; i < in.size(); ++i) {
    in[i] = i * 0.01;
    out[i] = in[i] / 4;
  }
  try {
    detect::attribute_defects(in, out, seed_gearbox(json::array()), {});
    FAIL();
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at least 20 are needed"), std::string::npos) << e.what();
  }
}

TEST(PeriodMatcher, RefusesAnglesThatDoNotIncrease) {
  std::vector<double> in(20000), out(20000);
  for (std::size_t i = 0; i < in.size(); ++i) {
    in[i] = i * 0.01;
    out[i] = in[i] / 4;
  }
  in[500] = 0;
  try {
    detect::attribute_defects(in, out, seed_gearbox(json::array()), {});
    FAIL();
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not increasing: sample 500"), std::string::npos);
  }
}

TEST(PeriodMatcher, RefusesARecordingWhoseRatioContradictsTheGearbox) {
  std::vector<double> in(20000), out(20000);
  for (std::size_t i = 0; i < in.size(); ++i) {
    in[i] = i * 0.01;
    out[i] = in[i] / 3;
  }
  EXPECT_THROW(detect::attribute_defects(in, out, seed_gearbox(json::array()), {}),
               diag::InputError);
}

}  // namespace
