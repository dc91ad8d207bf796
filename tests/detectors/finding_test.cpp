// The one finding type (detect/finding.hpp) and its JSON.
#include "detect/finding.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

namespace {

TEST(Finding, JsonHasTheCommonKeysTheEvidenceAndLeavesOutWhatDoesNotApply) {
  detect::Finding f;
  f.kind = "attribution";
  f.fault = diag::FaultKind::kToothDamage;
  f.shaft = "counter";
  f.gears = {"z2", "z3"};
  f.confidence = 0.9;
  f.size = 0.02;
  f.size_unit = "rad";
  f.evidence = {{"period_input_rev", 2.0}, {"events", 12}, {"size_output_rad", 0.01}};
  const nlohmann::json j = detect::to_json(f);
  EXPECT_EQ(j["kind"], "attribution");
  EXPECT_EQ(j["fault"], "tooth_damage");
  EXPECT_EQ(j["gears"], (std::vector<std::string>{"z2", "z3"}));
  EXPECT_EQ(j["size_unit"], "rad");
  // The evidence as an object and at the top level (the keys attribute --json had).
  EXPECT_EQ(j["evidence"]["size_output_rad"], 0.01);
  EXPECT_EQ(j["size_output_rad"], 0.01);
  EXPECT_TRUE(j["events"].is_number_integer());  // a count stays an integer
  EXPECT_TRUE(j["evidence"]["period_input_rev"].is_number_integer());
  for (const char* absent : {"bearing", "channel", "frequency_hz"}) {
    EXPECT_FALSE(j.contains(absent)) << absent;
  }
}

TEST(Finding, EvidenceIsReadAndReplacedByName) {
  detect::Finding f;
  f.set_evidence("score", 30.0);
  f.set_evidence("score", 31.0);
  EXPECT_EQ(f.evidence.size(), 1u);
  EXPECT_EQ(f.evidence_value("score"), 31.0);
  EXPECT_TRUE(std::isnan(f.evidence_value("snr")));
  EXPECT_FALSE(detect::to_json(f).contains("size"));  // no size estimate: left out
}

}  // namespace
