// `geardiag analyze` on what a rig records rather than on the simulator's own files: a CSV with
// one accelerometer and a tacho column (named, or not), the speed from the vibration when the
// nominal one is off, --rpm, --tacho, a channel map, the speed stored in a CWRU file, and a
// format-1 recording. The gearbox is the two-stage box with a chipped counter-shaft gear (z3),
// simulated once; its answer is known: the counter shaft.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "../validation/two_stage_case.hpp"
#include "cli_run.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "sim/dynamics/simulate.hpp"

namespace {

namespace fs = std::filesystem;
using cli_test::run;

constexpr double kRpm = 2000.0;

fs::path scratch(const std::string& name) { return cli_test::scratch("measured_cli", name); }

fs::path gearbox_file(double rpm) {
  const fs::path p = scratch("gb_" + std::to_string(static_cast<int>(rpm)) + ".json");
  std::ofstream(p) << two_stage_case::description(rpm).dump(2);
  return p;
}

// The analyze_gear_damage_test case: 11 output revolutions, a 0.8-module chip on tooth 5 of z3.
const diag::Recording& chipped_counter() {
  static const diag::Recording rec =
      two_stage_case::simulate(two_stage_case::gearbox(kRpm), sim::SpeedProfile::constant(kRpm),
                               11.0 / (kRpm / 60.0 / 4.0), two_stage_case::chip("z3"));
  return rec;
}

// A CSV as a data logger writes it: time, one accelerometer on the counter shaft's bearing, and
// (when tacho_column is not empty) the input shaft's once-per-revolution pulse under that name.
fs::path measured_csv(const std::string& tacho_column) {
  const diag::Recording& rec = chipped_counter();
  const fs::path p = scratch("meas_" + (tacho_column.empty() ? "acc" : tacho_column) + ".csv");
  const diag::Signal& acc = rec.require("counter_bearing1_vertical", "test");
  const diag::Signal* key = nullptr;
  for (const auto& t : rec.tachos)
    if (t.shaft == "input") key = &t;
  std::ofstream out(p);
  out << "time,acc" << (tacho_column.empty() ? "" : "," + tacho_column) << "\n";
  out.precision(10);
  for (std::size_t i = 0; i < acc.samples.size(); ++i) {
    out << static_cast<double>(i) / acc.fs_hz << "," << acc.samples[i];
    if (!tacho_column.empty()) out << "," << 5.0 * key->samples[i];
    out << "\n";
  }
  return p;
}

nlohmann::json analyze(const std::string& args, int expected_code = 0) {
  const fs::path json = scratch("out.json");
  fs::remove(json);
  const auto r = run("analyze " + args + " --json " + json.string());
  EXPECT_EQ(r.code, expected_code) << r.out;
  if (!fs::exists(json)) return nullptr;
  std::ifstream in(json);
  return nlohmann::json::parse(in);
}

std::vector<std::string> damaged_shafts(const nlohmann::json& j) {
  std::vector<std::string> out;
  for (const auto& f : j["findings"])
    if (f["kind"] == "gear_damage") out.push_back(f["shaft"]);
  return out;
}

bool noted(const nlohmann::json& j, const std::string& text) {
  for (const auto& n : j["notes"])
    if (n.get<std::string>().find(text) != std::string::npos) return true;
  return false;
}

// The tacho column, whatever it is called, is taken as the input's tacho (name or two-level
// shape, at the input's rate), never analysed as vibration, and the chip is put on the counter.
TEST(MeasuredInput, ACsvWithATachoColumnIsAnalysedWithTheTacho) {
  const fs::path gb = gearbox_file(kRpm);
  for (const std::string column : {"input", "tacho", "input_tacho", "ch3"}) {
    const auto j = analyze(measured_csv(column).string() + " --gearbox " + gb.string());
    ASSERT_FALSE(j.is_null()) << column;
    EXPECT_EQ(j["speed"]["source"], "tacho") << column << "\n" << j["notes"].dump(1);
    EXPECT_NEAR(j["speed"]["mean_rpm"].get<double>(), kRpm, 1.0) << column;
    for (const auto& c : j["channels"]) EXPECT_NE(c["name"], column) << "analysed as vibration";
    EXPECT_EQ(damaged_shafts(j), std::vector<std::string>{"counter"}) << column << "\n"
                                                                      << j["gear_damage"].dump(1);
    EXPECT_TRUE(noted(j, "taken as the tacho of shaft input")) << j["notes"].dump(1);
  }
}

// --tacho says it outright; a wrong shaft name is refused before any work.
TEST(MeasuredInput, TachoOptionNamesTheColumnAndItsShaft) {
  const fs::path gb = gearbox_file(kRpm);
  const fs::path csv = measured_csv("sensor2");
  const auto j = analyze(csv.string() + " --gearbox " + gb.string() + " --tacho sensor2=input:1");
  ASSERT_FALSE(j.is_null());
  EXPECT_EQ(j["speed"]["source"], "tacho");
  EXPECT_EQ(damaged_shafts(j), std::vector<std::string>{"counter"});
  const auto bad =
      run("analyze " + csv.string() + " --gearbox " + gb.string() + " --tacho sensor2=spindle");
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("spindle"), std::string::npos) << bad.out;
  const auto missing =
      run("analyze " + csv.string() + " --gearbox " + gb.string() + " --tacho nosuch=input");
  EXPECT_EQ(missing.code, 2) << missing.out;
  EXPECT_NE(missing.out.find("nosuch"), std::string::npos) << missing.out;
}

// No tacho and a nominal speed 3 % off: the speed comes from the vibration's mesh line and the
// answer is the same as with the tacho. --rpm overrides the description's speed.
TEST(MeasuredInput, WithoutTachoTheSpeedComesFromTheVibration) {
  const fs::path csv = measured_csv("");
  for (double nominal : {kRpm, kRpm * 1.03, kRpm * 0.97}) {
    const auto j = analyze(csv.string() + " --gearbox " + gearbox_file(nominal).string());
    ASSERT_FALSE(j.is_null());
    EXPECT_EQ(j["speed"]["source"], "vibration") << nominal << "\n" << j["notes"].dump(1);
    // The simulator turns at exactly kRpm; the line's phase gives the mean speed to far better
    // than the 3 % error (speed_estimate_test: 1e-6 on synthetic data): 1e-4 here.
    EXPECT_NEAR(j["speed"]["mean_rpm"].get<double>(), kRpm, 1e-4 * kRpm) << nominal;
    EXPECT_EQ(damaged_shafts(j), std::vector<std::string>{"counter"}) << nominal << "\n"
                                                                      << j["gear_damage"].dump(1);
  }
  const auto j = analyze(csv.string() + " --gearbox " + gearbox_file(1500).string() + " --rpm " +
                         std::to_string(kRpm * 1.02));
  ASSERT_FALSE(j.is_null());
  EXPECT_NEAR(j["speed"]["nominal_rpm"].get<double>(), kRpm * 1.02, 1e-6);
  EXPECT_TRUE(noted(j, "from --rpm")) << j["notes"].dump(1);
  EXPECT_EQ(damaged_shafts(j), std::vector<std::string>{"counter"});
  EXPECT_EQ(run("analyze " + csv.string() + " --rpm 2000").code, 2);  // no gearbox
  EXPECT_EQ(
      run("analyze " + csv.string() + " --gearbox " + gearbox_file(kRpm).string() + " --rpm -5")
          .code,
      2);
}

// A channel map gives roles, units and locations; a bad map is refused naming the file.
TEST(MeasuredInput, AChannelMapDescribesTheColumns) {
  const fs::path gb = gearbox_file(kRpm);
  const fs::path csv = measured_csv("k");
  const fs::path map = scratch("map.json");
  std::ofstream(map) << R"({"channels": [
      {"name": "acc", "role": "vibration", "unit": "m/s^2", "direction": "vertical",
       "shaft": "counter"},
      {"name": "k", "role": "tacho", "shaft": "input", "ppr": 1}]})";
  const auto j =
      analyze(csv.string() + " --gearbox " + gb.string() + " --channels " + map.string());
  ASSERT_FALSE(j.is_null());
  EXPECT_EQ(j["speed"]["source"], "tacho");
  ASSERT_EQ(j["channels"].size(), 1u);
  EXPECT_EQ(j["channels"][0]["unit"], "m/s^2");
  EXPECT_EQ(j["channels"][0]["shaft"], "counter");
  EXPECT_EQ(damaged_shafts(j), std::vector<std::string>{"counter"});
  std::ofstream(map) << R"({"channels": [{"name": "acc", "rol": "vibration"}]})";
  const auto bad =
      run("analyze " + csv.string() + " --gearbox " + gb.string() + " --channels " + map.string());
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("map.json"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("rol"), std::string::npos) << bad.out;
}

// import keeps what the options and inference said: the written file has the tacho in /tacho
// with its shaft, and analysing it needs no option.
TEST(MeasuredInput, ImportWritesTheRolesIntoTheRecording) {
  const fs::path gb = gearbox_file(kRpm);
  const fs::path h5 = scratch("imported.h5");
  const auto r = run("import " + measured_csv("tacho").string() + " --gearbox " + gb.string() +
                     " -o " + h5.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto info = run("info " + h5.string() + " --json");
  ASSERT_EQ(info.code, 0) << info.out;
  const auto j = nlohmann::json::parse(info.out.substr(info.out.find('{')));
  bool tacho = false;
  for (const auto& c : j["channels"]) {
    if (c["name"] == "tacho") {
      tacho = c["group"] == "tacho" && c["role"] == "tacho" && c["shaft"] == "input";
    }
  }
  EXPECT_TRUE(tacho) << j["channels"].dump(1);
  const auto a = analyze(h5.string());
  ASSERT_FALSE(a.is_null());
  EXPECT_EQ(a["speed"]["source"], "tacho");
  EXPECT_EQ(damaged_shafts(a), std::vector<std::string>{"counter"});
}

// Progress goes to a terminal only: piped, stderr carries no progress line; under a
// pseudo-terminal (util-linux `script`) the stage names appear.
TEST(MeasuredInput, AProgressLineOnATerminalOnly) {
  const fs::path gb = gearbox_file(kRpm);
  const fs::path csv = measured_csv("tacho");
  const auto piped = run("analyze " + csv.string() + " --gearbox " + gb.string());
  ASSERT_EQ(piped.code, 0) << piped.out;
  EXPECT_EQ(piped.out.find('\r'), std::string::npos);
  if (std::system("command -v script > /dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1)";
  const std::string cmd = std::string("script -qec '") + GEARDIAG_BINARY + " analyze " +
                          csv.string() + " --gearbox " + gb.string() + "' /dev/null 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[4096];
  while (std::size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  EXPECT_EQ(pclose(p), 0) << out;
  EXPECT_NE(out.find("\ranalyze meas_tacho.csv: channels"), std::string::npos) << out;
}

// A format-1 recording (before channel roles) still analyses, and says its roles were inferred.
TEST(MeasuredInput, AFormat1RecordingIsStillAnalysed) {
  const auto j = analyze(std::string(GEARDIAG_TESTDATA_DIR) + "/recordings/format1_three_shaft.h5");
  ASSERT_FALSE(j.is_null());
  EXPECT_TRUE(noted(j, "format-1")) << j["notes"].dump(1);
  for (const auto& c : j["channels"]) {
    if (c["name"] == "z1_z2_force") {
      EXPECT_EQ(c["role"], "force");
    }
    if (c["name"] == "input_bearing1_along_loa") {
      EXPECT_EQ(c["role"], "vibration");
    }
  }
}

// CWRU's files store the motor speed (X105RPM); it is used in place of a description's speed
// 2.6 % off, and said so. Skips without the shared data.
TEST(MeasuredInput, TheSpeedStoredInACwruFileIsUsed) {
  const fs::path mat = fs::path(GEARDIAG_SHARED_DATA_DIR) / "cwru-bearing" / "IR007_0.mat";
  if (!fs::exists(mat)) GTEST_SKIP() << "real data not present: " << mat;
  const fs::path gb = scratch("cwru.json");
  std::ofstream(gb) << R"({"name": "cwru", "shafts": [{"name": "input"}],
      "input": {"shaft": "input", "speed_rpm": 1750},
      "bearings": [{"name": "drive_end", "shaft": "input", "rolling_elements": 9,
                    "pitch_diameter_mm": 39.04, "element_diameter_mm": 7.94,
                    "contact_angle_deg": 0.0}]})";
  const auto j = analyze(mat.string() + " --fs 12000 --gearbox " + gb.string());
  ASSERT_FALSE(j.is_null());
  EXPECT_TRUE(noted(j, "recorded with the file")) << j["notes"].dump(1);
  EXPECT_NEAR(j["speed"]["nominal_rpm"].get<double>(), 1797, 1);
  bool inner = false;
  for (const auto& f : j["findings"]) inner |= f["kind"] == "bearing" && f["fault"] == "inner_race";
  EXPECT_TRUE(inner) << j["findings"].dump(1);
}

}  // namespace
