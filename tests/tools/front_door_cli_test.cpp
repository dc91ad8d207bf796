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

// A three-shaft recording: healthy (noise seed 11) or with a chip on z3 (noise seed 12).
fs::path simulated(const std::string& name, bool chipped) {
  const fs::path sc = scratch(name + ".json");
  std::ofstream(sc)
      << R"({"accuracy_grade": 6, "runout_um": 8, "seed": 4, "sensors": )"
      << (chipped
              ? R"({"noise_m_per_s2": 3, "noise_seed": 12}, "faults": [{"gear": "z3", "tooth": 5, "type": "chip", "size_mm": 1.2}]})"
              : R"({"noise_m_per_s2": 3, "noise_seed": 11}})");
  const fs::path h5 = scratch(name + ".h5");
  const auto r = run("simulate --gearbox " + gearbox().string() + " --scenario " + sc.string() +
                     " --rpm 2000 --duration 1 --fs 8000 -o " + h5.string());
  EXPECT_EQ(r.code, 0) << r.out;
  return h5;
}

TEST(FrontDoor, AnalyzeCliWritesTheLibrarysResult) {
  const fs::path healthy = simulated("healthy", false);
  const fs::path chipped = simulated("chipped", true);
  const fs::path js = scratch("cli.json");
  const auto r =
      run("analyze " + chipped.string() + " --gear-baseline " + healthy.string() + " --baseline " +
          healthy.string() + " --max-samples 4000 --threads 1" + " --json " + js.string());
  ASSERT_EQ(r.code, 0) << r.out;

  detect::AnalyzeRequest q;
  q.recording = chipped;
  q.gear_baseline = detect::RecordingInput(healthy);
  q.baseline = {detect::RecordingInput(healthy)};
  q.max_samples = 4000;
  q.options.threads = 1;
  q.options.traces = false;  // the CLI computes the plot curves only for --html / --curves
  const detect::FileAnalysis a = detect::analyze_file(q);
  EXPECT_TRUE(a.cut);
  EXPECT_EQ(slurp(js), report::to_json(a.result).dump(2) + "\n");
  // The gear baseline and the anomaly score went through: the door dropped nothing.
  const auto j = nlohmann::json::parse(slurp(js));
  EXPECT_TRUE(j.contains("anomaly_score") && j.contains("baseline"));
  EXPECT_TRUE(j.contains("gear_damage"));
}

TEST(FrontDoor, BatchRowIsTheAnalysisOfAnalyze) {
  const fs::path healthy = simulated("healthy_b", false);
  const fs::path chipped = simulated("chipped_b", true);
  const fs::path table = scratch("table.csv");
  const auto b = run("batch " + chipped.string() + " --baseline " + healthy.string() + " -o " +
                     table.string() + " -j 1");
  ASSERT_EQ(b.code, 0) << b.out;
  const fs::path js = scratch("one.json");
  const auto a = run("analyze " + chipped.string() + " --baseline " + healthy.string() +
                     " --max-samples 0 --json " + js.string());
  ASSERT_EQ(a.code, 0) << a.out;
  const auto j = nlohmann::json::parse(slurp(js));
  // The table's anomaly score is the analysis's, printed with the same digits JSON uses.
  const std::string csv = slurp(table);
  ASSERT_TRUE(j.contains("anomaly_score"));
  const std::string score = j["anomaly_score"].dump();
  EXPECT_NE(csv.find("," + score + ","), std::string::npos) << score << "\n" << csv.substr(0, 600);
}

}  // namespace
