// Gearbox description: derived speeds, frequencies and recurrence periods on the seed-003
// gearbox (numbers from the seed), and refusal of bad descriptions with the field named.
#include "diag/gearbox/gearbox.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "diag/error.hpp"

namespace {

using nlohmann::json;

json three_shaft() {
  return json::parse(R"({"name": "three-shaft",
   "shafts": [{"name": "input"}, {"name": "counter"}, {"name": "output"}],
   "gears": [{"name": "z1", "shaft": "input",   "teeth": 18, "module_mm": 3.0,
              "pressure_angle_deg": 20.0, "face_width_mm": 20.0},
             {"name": "z2", "shaft": "counter", "teeth": 36, "module_mm": 3.0,
              "pressure_angle_deg": 20.0, "face_width_mm": 20.0},
             {"name": "z3", "shaft": "counter", "teeth": 18, "module_mm": 3.0,
              "pressure_angle_deg": 20.0, "face_width_mm": 20.0},
             {"name": "z4", "shaft": "output",  "teeth": 36, "module_mm": 3.0,
              "pressure_angle_deg": 20.0, "face_width_mm": 20.0}],
   "meshes": [{"driver": "z1", "driven": "z2"}, {"driver": "z3", "driven": "z4"}],
   "input": {"shaft": "input", "speed_rpm": 30.0, "torque_nm": 50.0}})");
}

std::string error_of(const json& j) {
  try {
    diag::parse_gearbox(j, "gb.json");
  } catch (const diag::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Gearbox, TheMinimalDescriptionFileIsAccepted) {
  const auto gb =
      diag::load_gearbox(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
  EXPECT_EQ(gb.shafts().size(), 3u);
  EXPECT_EQ(gb.shafts()[gb.output_shaft()].name, "output");
}

// Seed 003: z1 = z3 = 18, z2 = z4 = 36, u_max = 4; a defect on z2 recurs every 720 deg of input,
// on z4 every 1440 deg; 1 deg on z2 shows as 0.5 deg at the output (u_2 = 2).
TEST(Gearbox, RecurrencePeriodsAndRatiosMatchTheSeedExample) {
  const auto gb = diag::parse_gearbox(three_shaft(), "gb");
  EXPECT_DOUBLE_EQ(gb.total_ratio(), 4.0);
  EXPECT_DOUBLE_EQ(gb.recurrence_period_input_rev(gb.gear_index("z1")), 1.0);
  EXPECT_DOUBLE_EQ(gb.recurrence_period_input_rev(gb.gear_index("z2")), 2.0);
  EXPECT_DOUBLE_EQ(gb.recurrence_period_input_rev(gb.gear_index("z3")), 2.0);
  EXPECT_DOUBLE_EQ(gb.recurrence_period_input_rev(gb.gear_index("z4")), 4.0);
  EXPECT_DOUBLE_EQ(gb.ratio_to_output(gb.gear_index("z2")), 2.0);
  EXPECT_DOUBLE_EQ(gb.ratio_to_output(gb.gear_index("z4")), 1.0);
  // T_i = 2 pi u_max / u_i (corrected eq. 5) for every gear.
  for (std::size_t g = 0; g < gb.gears().size(); ++g) {
    EXPECT_DOUBLE_EQ(gb.recurrence_period_input_rev(g) * gb.ratio_to_output(g), gb.total_ratio());
  }
  EXPECT_EQ(gb.gears_sharing_shaft(gb.gear_index("z2")).size(), 2u);
  ASSERT_EQ(gb.power_path().size(), 2u);
  EXPECT_EQ(gb.power_path()[0].up_gear, gb.gear_index("z1"));
  EXPECT_EQ(gb.power_path()[1].down_gear, gb.gear_index("z4"));
}

TEST(Gearbox, SpeedsMeshFrequenciesAndHuntingPeriodsFollowFromToothCounts) {
  json j = three_shaft();
  j["gears"][1]["teeth"] = 45;  // z1 = 18 -> z2 = 45: gcd 9
  const auto gb = diag::parse_gearbox(j, "gb");
  const int counter = gb.shaft_index("counter");
  EXPECT_DOUBLE_EQ(gb.shaft_speed_rpm(counter), 30.0 * 18 / 45);
  EXPECT_DOUBLE_EQ(gb.mesh_frequency_hz(0), 18 * 0.5);    // z1 f_input
  EXPECT_DOUBLE_EQ(gb.mesh_frequency_hz(1), 18 * 0.2);    // z3 f_counter, f_counter = 0.5*18/45
  EXPECT_DOUBLE_EQ(gb.hunting_period_input_rev(0), 5.0);  // 45 / gcd(18, 45) driver revs
  EXPECT_LT(gb.shafts()[counter].speed_ratio, 0.0);       // external mesh reverses
}

TEST(Gearbox, RefusesAnUnknownShaftNamingTheField) {
  json j = three_shaft();
  j["gears"][2]["shaft"] = "lay";
  const std::string e = error_of(j);
  EXPECT_NE(e.find("gb.json"), std::string::npos);
  EXPECT_NE(e.find("gears[2].shaft"), std::string::npos);
  EXPECT_NE(e.find("unknown shaft 'lay'"), std::string::npos);
}

TEST(Gearbox, RefusesAnUnknownGearInAMesh) {
  json j = three_shaft();
  j["meshes"][1]["driven"] = "z9";
  EXPECT_NE(error_of(j).find("meshes[1].driven: unknown gear 'z9'"), std::string::npos);
}

TEST(Gearbox, RefusesAMeshBetweenGearsOfOneShaft) {
  json j = three_shaft();
  j["meshes"][1] = {{"driver", "z2"}, {"driven", "z3"}};
  EXPECT_NE(error_of(j).find("same shaft"), std::string::npos);
}

TEST(Gearbox, RefusesMismatchedModules) {
  json j = three_shaft();
  j["gears"][3]["module_mm"] = 4.0;
  const std::string e = error_of(j);
  EXPECT_NE(e.find("meshes[1]"), std::string::npos);
  EXPECT_NE(e.find("module"), std::string::npos);
}

TEST(Gearbox, RefusesAShaftWithNoPathFromTheInput) {
  json j = three_shaft();
  j["shafts"].push_back({{"name", "idle"}});
  EXPECT_NE(error_of(j).find("shafts[3]: no gear train connects shaft 'idle'"), std::string::npos);
}

TEST(Gearbox, RefusesNonPositiveTeethAndModule) {
  json j = three_shaft();
  j["gears"][0]["teeth"] = -3;
  EXPECT_NE(error_of(j).find("gears[0].teeth: must be a positive integer"), std::string::npos);
  j = three_shaft();
  j["gears"][0]["module_mm"] = 0;
  EXPECT_NE(error_of(j).find("gears[0].module_mm: must be > 0"), std::string::npos);
}

// Undercut is a warning with its consequence, not a refusal: attribution and the
// kinematic simulator need only tooth counts.
TEST(Gearbox, AcceptsAnUndercutPinionWithAWarningNamingItsConsequence) {
  json j = three_shaft();
  j["gears"][0]["teeth"] = 15;
  j["gears"][1]["teeth"] = 39;  // the same centre distance as 18/36
  const auto gb = diag::parse_gearbox(j, "gb.json");
  ASSERT_FALSE(gb.warnings().empty());
  const std::string w = gb.warnings().front();
  EXPECT_NE(w.find("gb.json: gears[0]"), std::string::npos) << w;
  EXPECT_NE(w.find("undercut"), std::string::npos) << w;
  EXPECT_NE(w.find("stiffness"), std::string::npos) << w;
  bool contact_warned = false;
  for (const auto& s : gb.warnings())
    contact_warned |= s.find("contact ratio") != std::string::npos;
  EXPECT_TRUE(contact_warned);
  EXPECT_EQ(diag::summary_json(gb)["warnings"].size(), gb.warnings().size());
  EXPECT_TRUE(diag::parse_gearbox(three_shaft(), "gb.json").warnings().empty());
}

TEST(Gearbox, RefusesAPointedTooth) {
  json j = three_shaft();
  j["gears"][0]["profile_shift"] = 1.6;
  EXPECT_NE(error_of(j).find("pointed"), std::string::npos) << error_of(j);
}

TEST(Gearbox, RefusesAContactRatioBelowOne) {
  json j = three_shaft();
  for (auto& g : j["gears"]) g["addendum_coefficient"] = 0.5;  // short teeth
  EXPECT_NE(error_of(j).find("contact_ratio"), std::string::npos);
}

TEST(Gearbox, RefusesInconsistentLoopsAndUnknownFields) {
  json j = three_shaft();
  j["gears"].push_back({{"name", "z5"}, {"shaft", "output"}, {"teeth", 20}, {"module_mm", 3.0}});
  j["gears"].push_back({{"name", "z6"}, {"shaft", "input"}, {"teeth", 20}, {"module_mm", 3.0}});
  j["meshes"].push_back({{"driver", "z6"}, {"driven", "z5"}});
  EXPECT_NE(error_of(j).find("kinematically inconsistent loop"), std::string::npos);
  j = three_shaft();
  j["gears"][0]["modul_mm"] = 3.0;
  EXPECT_NE(error_of(j).find("gears[0].modul_mm: unknown field"), std::string::npos);
}

TEST(Gearbox, AOneShaftMotorOnBearingsIsValid) {
  const json j = json::parse(R"({"shafts": [{"name": "input"}],
    "input": {"shaft": "input", "speed_rpm": 1797},
    "bearings": [{"name": "drive_end", "shaft": "input", "rolling_elements": 9,
                  "pitch_diameter_mm": 39.04, "element_diameter_mm": 7.94,
                  "contact_angle_deg": 0.0}]})");
  const auto gb = diag::parse_gearbox(j, "motor");
  EXPECT_EQ(gb.output_shaft(), gb.input_shaft());
  EXPECT_TRUE(gb.power_path().empty());
  ASSERT_EQ(gb.bearings().size(), 1u);
  EXPECT_EQ(gb.bearings()[0].rolling_elements, 9);
}

TEST(Gearbox, DefectSizeInMicrometresIsTheSameLossAsTheAngleOnTheBaseCircle) {
  json j = three_shaft();
  // z2: r_b = 54 cos20 mm = 50.7434 mm; 1 deg of rotation = 885.64 um along the LOA.
  j["defects"] = {{{"gear", "z2"}, {"size_um", 885.64}, {"tooth", 1}}};
  const auto gb = diag::parse_gearbox(j, "gb");
  ASSERT_EQ(gb.defects().size(), 1u);
  EXPECT_NEAR(gb.defects()[0].size_rad, 3.14159265358979 / 180, 1e-6);
  EXPECT_NEAR(gb.defects()[0].phase_rad, 2 * 3.14159265358979 / 36, 1e-12);
  j["defects"] = {{{"gear", "z7"}, {"size_deg", 1.0}}};
  EXPECT_NE(error_of(j).find("defects[0].gear: unknown gear 'z7'"), std::string::npos);
}

// A defect's type is the fault vocabulary's (diag/faults/fault_kind.hpp): an alias is stored by
// the one name, a word outside it or a bearing kind is refused naming the field.
TEST(Gearbox, DefectTypeIsAGearKindOfTheFaultVocabulary) {
  json j = three_shaft();
  j["defects"] = {{{"gear", "z2"}, {"size_deg", 1.0}, {"type", "breakage"}}};
  EXPECT_EQ(diag::parse_gearbox(j, "gb").defects()[0].type, "missing");
  j["defects"][0]["type"] = "scuffing";
  EXPECT_NE(error_of(j).find("defects[0].type: 'scuffing' is not a gear fault kind"),
            std::string::npos)
      << error_of(j);
  j["defects"][0]["type"] = "outer_race";
  EXPECT_NE(error_of(j).find("defects[0].type"), std::string::npos);
}

}  // namespace
