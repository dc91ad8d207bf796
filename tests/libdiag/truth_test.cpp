// The simulator's ground truth, typed (diag/io/truth.hpp): strict reading, the one layout written,
// older layouts read.
#include "diag/io/truth.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "diag/error.hpp"

namespace {

using json = nlohmann::json;

std::string error_of(const std::string& text) {
  try {
    diag::parse_truth(text, "rec.h5");
  } catch (const diag::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SimulationTruth, ReadsTheTypedFieldsAndKeepsTheRestAsExtra) {
  const json j = {{"kind", "kinematic"},
                  {"input_speed_rpm_min", 1500},
                  {"input_speed_rpm_max", 1500},
                  {"revolutions", 40.0},
                  {"defects",
                   {{{"type", "chip"},
                     {"gear", "z2"},
                     {"shaft", "counter"},
                     {"size_output_rad", 0.01},
                     {"period_input_rev", 2.0},
                     {"gears_on_shaft", {"z2", "z3"}},
                     {"on_power_path", true}}}}};
  const auto t = diag::parse_truth(j.dump(), "rec.h5");
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(t->kind, "kinematic");
  EXPECT_EQ(t->input_speed_rpm_min, 1500);
  ASSERT_EQ(t->defects.size(), 1u);
  const diag::TruthDefect& d = t->defects[0];
  EXPECT_EQ(d.kind, diag::FaultKind::kChip);
  EXPECT_EQ(d.shaft, "counter");
  EXPECT_EQ(d.period_input_rev, 2.0);
  EXPECT_TRUE(std::isnan(d.size_m));  // not given
  EXPECT_EQ(d.gears_on_shaft.size(), 2u);
  EXPECT_TRUE(d.on_power_path.value_or(false));
  EXPECT_EQ(t->extra.at("revolutions"), 40.0);
  EXPECT_EQ(t->to_json(), j);  // the one layout round-trips exactly
}

TEST(SimulationTruth, OlderLayoutsAndAliasesAreRead) {
  // A dynamic truth written before it was typed: "faults"; a bearing truth's "fault": "ball".
  const auto dyn = diag::parse_truth(
      R"({"kind": "dynamic", "faults": [{"gear": "z2", "shaft": "counter", "tooth": 7,
          "type": "crack", "size_m": 0.0015}]})",
      "old.h5");
  ASSERT_EQ(dyn->defects.size(), 1u);
  EXPECT_EQ(dyn->defects[0].kind, diag::FaultKind::kCrack);
  EXPECT_EQ(dyn->defects[0].tooth, 7);
  EXPECT_FALSE(dyn->to_json().contains("faults"));
  EXPECT_EQ(dyn->to_json()["defects"][0]["type"], "crack");
  const auto brg = diag::parse_truth(R"({"kind": "bearing", "fault": "ball"})", "old.h5");
  ASSERT_EQ(brg->defects.size(), 1u);
  EXPECT_EQ(brg->defects[0].kind, diag::FaultKind::kRollingElement);
  EXPECT_EQ(brg->to_json()["defects"][0]["type"], "rolling_element");
  EXPECT_TRUE(diag::parse_truth(R"({"kind": "bearing", "fault": "none"})", "h")->defects.empty());
}

TEST(SimulationTruth, NoTruthIsNoValue) {
  diag::Recording rec;
  EXPECT_FALSE(diag::parse_truth(rec, "measured.csv").has_value());
}

TEST(SimulationTruth, BadTruthIsAnInputErrorNamingTheField) {
  EXPECT_NE(error_of("[1, 2]").find("rec.h5: /truth"), std::string::npos);
  EXPECT_NE(error_of(R"({"defects": []})").find("kind"), std::string::npos);
  EXPECT_NE(error_of(R"({"kind": "dynamic", "input_torque_nm": "ten"})").find("input_torque_nm"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"kind": "k", "defects": [{"type": "scuffing"}]})").find("defects[0].type"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"kind": "k", "defects": [{"type": "chip", "colour": 1}]})")
                .find("defects[0].colour"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"kind": "k", "defects": [{"type": "chip", "size_m": "1"}]})")
                .find("defects[0].size_m"),
            std::string::npos);
  EXPECT_NE(error_of("{not json").find("rec.h5: /truth"), std::string::npos);
}

}  // namespace
