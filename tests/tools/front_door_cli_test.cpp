// One front door: `geardiag analyze` and `geardiag batch` are thin callers of
// detect::analyze_file. The CLI's JSON must be the bytes of the library's result for the same
// request (with a baseline, a gear baseline, a cut recording), and batch's row the same analysis.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_run.hpp"
#include "detect/analysis/analyze_file.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "report/report.hpp"

namespace {

namespace fs = std::filesystem;

using cli_test::run;

fs::path scratch(const std::string& name) { return cli_test::scratch("front_door", name); }

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path gearbox() { return fs::path(GEARDIAG_TESTDATA_DIR) / "gearbox/three_shaft.json"; }

// A three-shaft recording, 2 s at 8 kHz: healthy (sensor noise seed `noise`) or with a chip on
// z3. Made once per name.
fs::path simulated(const std::string& name, bool chipped, int noise) {
  const fs::path h5 = scratch(name + ".h5");
  if (fs::exists(h5)) return h5;
  const fs::path sc = scratch(name + ".json");
  std::ofstream(sc)
      << R"({"accuracy_grade": 6, "runout_um": 8, "seed": 4, "sensors": {"noise_m_per_s2": 3, "noise_seed": )"
      << noise << "}"
      << (chipped ? R"(, "faults": [{"gear": "z3", "tooth": 5, "type": "chip", "size_mm": 1.2}]})"
                  : "}");
  const auto r = run("simulate --gearbox " + gearbox().string() + " --scenario " + sc.string() +
                     " --rpm 2000 --duration 2 --fs 8000 -o " + h5.string());
  EXPECT_EQ(r.code, 0) << r.out;
  return h5;
}

// A recording cut by --max-samples (its first second), with a gear baseline.
TEST(FrontDoor, AnalyzeCliWritesTheLibrarysResultOfACutRecording) {
  const fs::path healthy = simulated("healthy", false, 11);
  const fs::path chipped = simulated("chipped", true, 12);
  const fs::path js = scratch("cut.json");
  const auto r = run("analyze " + chipped.string() + " --gear-baseline " + healthy.string() +
                     " --max-samples 8000 --threads 1 --json " + js.string());
  ASSERT_EQ(r.code, 0) << r.out;

  detect::AnalyzeRequest q;
  q.recording = chipped;
  q.gear_baseline = detect::RecordingInput(healthy);
  q.max_samples = 8000;
  q.options.threads = 1;
  q.options.traces = false;  // the CLI computes the plot curves only for --html / --curves
  const detect::FileAnalysis a = detect::analyze_file(q);
  EXPECT_TRUE(a.cut);
  EXPECT_EQ(slurp(js), report::to_json(a.result).dump(2) + "\n");
  const auto j = nlohmann::json::parse(slurp(js));
  EXPECT_TRUE(j.contains("gear_damage"));                // the gear baseline went through the door
  EXPECT_DOUBLE_EQ(j["duration_s"].get<double>(), 2.0);  // the recording's
  // What was examined: up to the first sample not examined (within one sample of 1 s).
  EXPECT_NEAR(j["analysed_s"].get<double>(), 1.0, 1 / 8000.0);
  EXPECT_EQ(j["examined"]["complete"], false);
}

// Silence about what was not examined is not a pass: --fail-on exits 4 when nothing was found
// in the part examined, 0 when every sample was examined and nothing found.
TEST(FrontDoor, FailOnSaysWhenNotEverySampleWasExamined) {
  const fs::path healthy = simulated("healthy", false, 11);
  const auto cut = run("analyze " + healthy.string() + " --max-samples 8000 --fail-on finding");
  EXPECT_EQ(cut.code, 4) << cut.out;
  EXPECT_NE(cut.out.find("NOT EVERY SAMPLE EXAMINED"), std::string::npos) << cut.out;
  const auto whole = run("analyze " + healthy.string() + " --fail-on finding");
  EXPECT_EQ(whole.code, 0) << whole.out;
  EXPECT_NE(whole.out.find("(every sample)"), std::string::npos) << whole.out;
}

// Healthy baselines: the anomaly score and the wear per mesh, in analyze and in batch's row.
TEST(FrontDoor, AnalyzeAndBatchGiveTheLibrarysBaselineComparison) {
  const fs::path healthy = simulated("healthy", false, 11);
  const fs::path other = simulated("other", false, 13);
  const fs::path chipped = simulated("chipped", true, 12);
  const fs::path js = scratch("base.json");
  const auto a = run("analyze " + chipped.string() + " --baseline " + healthy.string() + " " +
                     other.string() + " --threads 1 --json " + js.string());
  ASSERT_EQ(a.code, 0) << a.out;
  detect::AnalyzeRequest q;
  q.recording = chipped;
  q.baseline = {detect::RecordingInput(healthy), detect::RecordingInput(other)};
  q.options.threads = 1;
  q.options.traces = false;
  const detect::FileAnalysis lib = detect::analyze_file(q);
  EXPECT_EQ(slurp(js), report::to_json(lib.result).dump(2) + "\n");
  ASSERT_TRUE(lib.result.baseline.has_value());
  EXPECT_FALSE(lib.result.baseline->wear.empty());  // the wear indicator per mesh ran

  const fs::path table = scratch("table.csv");
  const auto b = run("batch " + chipped.string() + " --baseline " + healthy.string() + " " +
                     other.string() + " -o " + table.string() + " -j 1");
  ASSERT_EQ(b.code, 0) << b.out;
  // The table's anomaly score is the analysis's, printed with the digits JSON uses.
  const std::string score = nlohmann::json(lib.result.baseline->anomaly_score).dump();
  const std::string csv = slurp(table);
  EXPECT_NE(csv.find("," + score + ","), std::string::npos) << score << "\n" << csv.substr(0, 600);
}

}  // namespace
