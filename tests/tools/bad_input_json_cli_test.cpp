// Bad descriptions, scenarios and options: a table of generated bad inputs, each of which
// must end with exit 2 (a diag::InputError), a message naming the file or option and the field,
// no output file, and within a time limit (no hang, no memory exhaustion): deep nesting, numbers
// beyond double range, tooth counts, speeds, rates, durations, sub-steps and settling times beyond
// the documented limits (docs/limits.md), names that cannot name channels, malformed JSON.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;

// 30 s: every case is refused before any simulation starts; the slowest legitimate step is
// reading the description. A hang or a run that starts anyway exceeds it by orders of magnitude.
constexpr double kTimeLimitS = 30.0;

fs::path scratch(const std::string& name) { return cli_test::scratch("bad_input_json", name); }

// The seed-003 description (tests/testdata), the base every case mutates.
const std::string& good_gearbox() {
  static const std::string text = [] {
    std::ifstream in(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  return text;
}

// The good description with `from` replaced by `to` (first occurrence).
std::string gearbox_with(const std::string& from, const std::string& to) {
  std::string s = good_gearbox();
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

std::string nested(int depth, const std::string& key) {
  std::string open, close;
  for (int i = 0; i < depth; ++i) {
    open += "[";
    close += "]";
  }
  return gearbox_with("\"name\": \"three-shaft\",",
                      "\"name\": \"three-shaft\", \"" + key + "\": " + open + close + ",");
}

struct Case {
  std::string name;
  std::string gearbox;     // description text ("" : the good one)
  std::string scenario;    // scenario text ("" : none)
  std::string command;     // {gb}, {sc}, {out}, {csv} are replaced by paths
  std::string expect;      // text the message must hold (the field or option)
  bool names_file = true;  // the message must name the description or scenario file
};

std::vector<Case> cases() {
  const std::string sim = "simulate --gearbox {gb} --duration 0.05 --fs 5000 -o {out}";
  const std::string sim_sc = "simulate --gearbox {gb} --scenario {sc} -o {out}";
  const std::string info = "info --gearbox {gb}";
  std::vector<Case> c = {
      {"comment nested 20000 deep", nested(20000, "comment"), "", info, "nested more than 64"},
      {"underscore key nested 20000 deep", nested(20000, "_notes"), "", sim, "nested"},
      {"sensors nested 5000 deep", nested(5000, "sensors"), "", info, "nested"},
      {"comment holding an object",
       gearbox_with("\"name\": \"three-shaft\",", "\"name\": \"b\", \"comment\": {\"a\": 1},"), "",
       info, "comment"},
      {"module beyond double range", gearbox_with("\"module_mm\": 3.0", "\"module_mm\": 1e400"), "",
       info, "not valid JSON"},
      {"teeth 1e9", gearbox_with("\"teeth\": 18", "\"teeth\": 1000000000"), "", sim,
       "gears[0].teeth"},
      {"teeth 1001", gearbox_with("\"teeth\": 36", "\"teeth\": 1001"), "",
       "simulate --mode kinematic --gearbox {gb} -o {out}", "gears[1].teeth"},
      {"teeth as text", gearbox_with("\"teeth\": 18", "\"teeth\": \"18\""), "", info,
       "gears[0].teeth"},
      {"speed 1e308 rpm", gearbox_with("\"speed_rpm\": 30.0", "\"speed_rpm\": 1e308"), "", sim,
       "input.speed_rpm"},
      {"speed 1e7 rpm", gearbox_with("\"speed_rpm\": 30.0", "\"speed_rpm\": 1e7"), "", sim,
       "input.speed_rpm"},
      {"torque 1e12", gearbox_with("\"torque_nm\": 50.0", "\"torque_nm\": 1e12"), "", sim,
       "input.torque_nm"},
      {"module 1e-6 mm", gearbox_with("\"module_mm\": 3.0", "\"module_mm\": 1e-6"), "", info,
       "gears[0].module_mm"},
      {"module 1000 mm", gearbox_with("\"module_mm\": 3.0", "\"module_mm\": 1000"), "", info,
       "gears[0].module_mm"},
      {"gear name with a slash", gearbox_with("\"name\": \"z1\"", "\"name\": \"z/1\""), "", sim,
       "gears[0].name"},
      {"gear name with a dot", gearbox_with("\"name\": \"z1\"", "\"name\": \"z.1\""), "", sim,
       "gears[0].name"},
      {"shaft name with NUL", gearbox_with("{\"name\": \"input\"}", "{\"name\": \"in\\u0000put\"}"),
       "", sim, "shafts[0].name"},
      {"pointed tooth", gearbox_with("\"teeth\": 18,", "\"teeth\": 18, \"profile_shift\": 1.6,"),
       "", info, "pointed"},
      {"truncated description", good_gearbox().substr(0, 120), "", info, "not valid JSON"},
      {"description that is an array", "[1, 2, 3]", "", info, "must be a JSON object"},
      {"empty description", " ", "", info, "not valid JSON"},
      {"300 shafts",
       gearbox_with(
           "\"shafts\": [", "\"shafts\": [" +
                                [] {
                                  std::string s;
                                  for (int i = 0; i < 300; ++i)
                                    s += "{\"name\": \"s" + std::to_string(i) + "\"}, ";
                                  return s;
                                }()),
       "", info, "shafts"},
      // Scenarios.
      {"scenario fs 1e12", "", R"({"fs_hz": 1e12})", sim_sc, "fs_hz"},
      {"scenario duration 1e9 s", "", R"({"duration_s": 1e9})", sim_sc, "duration_s"},
      {"scenario duration 1e4 s", "", R"({"duration_s": 1e4})", sim_sc, "duration_s"},
      {"scenario settle 1e9 s", "", R"({"settle_s": 1e9, "duration_s": 0.01})", sim_sc, "settle_s"},
      {"scenario contact_substeps 1e9", "",
       R"({"integrator": {"contact_substeps": 1000000000}, "duration_s": 0.01})", sim_sc,
       "contact_substeps"},
      {"scenario steps_per_mesh 1e6", "",
       R"({"integrator": {"steps_per_mesh": 1000000}, "duration_s": 0.01})", sim_sc,
       "steps_per_mesh"},
      {"scenario speed 1e9 rpm", "", R"({"speed": {"rpm": 1e9}, "duration_s": 0.01})", sim_sc,
       "rpm"},
      {"scenario speed 1e308 rpm", "", R"({"speed": {"rpm": 1e308}, "duration_s": 0.01})", sim_sc,
       "rpm"},
      {"scenario ramp to 1e7 rpm", "",
       R"({"speed": {"ramp": {"from_rpm": 100, "to_rpm": 1e7, "duration_s": 1}}})", sim_sc, "rpm"},
      {"scenario number beyond double range", "", R"({"duration_s": 1e400})", sim_sc,
       "not valid JSON"},
      {"scenario nested 20000 deep", "",
       "{\"comment\": " + std::string(20000, '[') + std::string(20000, ']') + "}", sim_sc,
       "nested"},
      {"scenario comment holding an object", "", R"({"comment": {"deep": [1, 2]}})", sim_sc,
       "comment"},
      // Options.
      {"--fs 1e12", "", "", "simulate --gearbox {gb} --fs 1e12 --duration 0.01 -o {out}", "fs_hz",
       false},
      {"--duration 1e9", "", "", "simulate --gearbox {gb} --duration 1e9 -o {out}", "duration_s",
       false},
      {"--duration 3000 at 1 MHz", "", "",
       "simulate --gearbox {gb} --duration 3000 --fs 1e6 -o {out}", "duration_s", false},
      {"--rpm 0", "", "", "simulate --gearbox {gb} --rpm 0 --duration 0.01 -o {out}", "--rpm",
       false},
      {"--rpm 1e9", "", "", "simulate --gearbox {gb} --rpm 1e9 --duration 0.01 -o {out}", "--rpm",
       false},
      {"sweep --steps 1e9", "", "",
       "sweep --gearbox {gb} --from-rpm 100 --to-rpm 200 --steps 1000000000 --json {out}", "steps",
       false},
      {"kinematic --revolutions 1e9", "", "",
       "simulate --mode kinematic --gearbox {gb} --revolutions 1e9 -o {out}", "revolutions", false},
      {"import --chunk-samples -1", "", "", "import {csv} --fs 100 --chunk-samples -1 -o {out}",
       "--chunk-samples", false},
      {"analyze --rpm 0", "", "", "analyze {csv} --fs 100 --gearbox {gb} --rpm 0", "--rpm", false},
  };
  return c;
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

TEST(BadInputJsonCli, EveryBadDescriptionScenarioOrOptionIsRefusedWithExit2NamingTheField) {
  const auto table = cases();
  ASSERT_GE(table.size(), 30u);
  const fs::path csv = scratch("signal.csv");
  {
    std::ofstream o(csv);
    o << "a\n";
    for (int i = 0; i < 64; ++i) o << (i % 7) * 0.1 << "\n";
  }
  int n = 0;
  for (const Case& c : table) {
    SCOPED_TRACE(c.name);
    const std::string tag = std::to_string(n++);
    const fs::path gb = scratch("gb" + tag + ".json"), sc = scratch("sc" + tag + ".json");
    const fs::path out = scratch("out" + tag + ".h5");
    std::ofstream(gb, std::ios::binary) << (c.gearbox.empty() ? good_gearbox() : c.gearbox);
    if (!c.scenario.empty()) std::ofstream(sc, std::ios::binary) << c.scenario;
    std::string cmd = replace_all(c.command, "{gb}", gb.string());
    cmd = replace_all(cmd, "{sc}", sc.string());
    cmd = replace_all(cmd, "{out}", out.string());
    cmd = replace_all(cmd, "{csv}", csv.string());
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = cli_test::run(cmd, 2 * static_cast<int>(kTimeLimitS));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.code, 2) << cmd << "\n" << r.out.substr(0, 2000);
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << cmd << "\n" << r.out.substr(0, 2000);
    if (c.names_file) {
      const std::string file = (c.scenario.empty() ? gb : sc).string();
      EXPECT_NE(r.out.find(file), std::string::npos) << cmd << "\n" << r.out.substr(0, 2000);
    }
    EXPECT_FALSE(fs::exists(out)) << cmd;
    EXPECT_LT(seconds, kTimeLimitS) << cmd;
  }
}

}  // namespace
