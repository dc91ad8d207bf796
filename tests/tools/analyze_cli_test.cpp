// geardiag analyze end to end through the binary: simulate -> analyze (JSON and HTML), a CSV
// input through the import path, exit codes for bad input, and an HTML render check in headless
// Chromium (skipped when /usr/bin/chromium is absent; Debian package "chromium").
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;

using cli_test::run;

std::filesystem::path scratch(const std::string& name) {
  return cli_test::scratch("analyze_cli", name);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const fs::path& simulated() {
  static const fs::path h5 = [] {
    const fs::path p = scratch("sim.h5");
    const auto s = run("simulate --gearbox " +
                       (fs::path(GEARDIAG_TESTDATA_DIR) / "gearbox/three_shaft.json").string() +
                       " --duration 0.5 --fs 20000 -o " + p.string());
    EXPECT_EQ(s.code, 0) << s.out;
    return p;
  }();
  return h5;
}

// --max-samples is an opt-in limit: with 4000 samples per channel at most, the 0.5 s record at
// 20 kHz is examined up to 0.2 s for every channel and the rest is said to be not examined;
// without it every sample is, frame by frame when --frame-seconds asks for short frames.
TEST(AnalyzeCli, MaxSamplesLimitsWhatIsExaminedAndSaysSo) {
  const fs::path js = scratch("excerpt.json");
  auto a = run("analyze " + simulated().string() + " --max-samples 4000 --json " + js.string());
  ASSERT_EQ(a.code, 0) << a.out;
  EXPECT_NE(a.out.find("NOT EVERY SAMPLE EXAMINED"), std::string::npos) << a.out;
  auto j = nlohmann::json::parse(std::ifstream(js));
  EXPECT_DOUBLE_EQ(j["duration_s"].get<double>(), 0.5);  // the recording's
  // Up to the first sample not examined (within one sample of 0.2 s).
  EXPECT_NEAR(j["analysed_s"].get<double>(), 0.2, 1 / 20000.0);
  for (const auto& c : j["channels"]) EXPECT_EQ(c["samples"].get<int>(), 4000) << c["name"];
  EXPECT_EQ(j["examined"]["complete"], false);
  ASSERT_EQ(j["examined"]["not_examined"].size(), 1u);
  EXPECT_NE(j["examined"]["not_examined"][0].get<std::string>().find("max_samples 4000"),
            std::string::npos);
  a = run("analyze " + simulated().string() + " --frame-seconds 0.1 --json " + js.string());
  ASSERT_EQ(a.code, 0) << a.out;
  j = nlohmann::json::parse(std::ifstream(js));
  EXPECT_EQ(j["examined"]["complete"], true);
  EXPECT_EQ(j["examined"]["frames"], 5);
  ASSERT_EQ(j["segments"].size(), 5u);
  EXPECT_DOUBLE_EQ(j["segments"][4]["end_s"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["analysed_s"].get<double>(), 0.5);
  bool framed = false;
  for (const auto& n : j["notes"]) {
    framed |= n.get<std::string>().starts_with("long recording analysed in 5 frames of 0.1 s");
  }
  EXPECT_TRUE(framed) << j["notes"].dump(1);
}

TEST(AnalyzeCli, SimulatedRecordingGivesJsonAndHtmlReports) {
  const fs::path js = scratch("a.json"), html = scratch("a.html");
  const auto a = run("analyze " + simulated().string() + " --json " + js.string() + " --html " +
                     html.string());
  ASSERT_EQ(a.code, 0) << a.out;
  EXPECT_NE(a.out.find("findings:"), std::string::npos) << a.out;
  const auto j = nlohmann::json::parse(std::ifstream(js));
  EXPECT_EQ(j["format"], "geardiag-analysis");
  EXPECT_EQ(j["gearbox"], "three-shaft");  // found in the recording's /gearbox
  ASSERT_EQ(j["meshes"].size(), 2u);
  // 30 rpm input, 18 teeth: mesh z1-z2 at 9 Hz (nominal: the 0.5 s record holds no full
  // revolution for a tacho speed).
  EXPECT_NEAR(j["meshes"][0]["frequency_hz"].get<double>(), 9.0, 1e-9);
  EXPECT_TRUE(j["findings"].is_array());
  EXPECT_TRUE(j["two_direction"].is_array());
  EXPECT_FALSE(j["two_direction"].empty());  // the simulator records along and normal channels
  bool vibration = false;
  for (const auto& c : j["channels"]) {
    if (!c["vibration"].get<bool>()) continue;
    vibration = true;
    for (const char* k : {"indicators", "spectrum", "psd", "meshes", "tsa"}) {
      EXPECT_TRUE(c.contains(k)) << k;
    }
    // The envelope analysis (kurtogram band, envelope spectrum) is for vibration sensors only:
    // the simulator's mesh force, friction and transmission-error channels have none.
    EXPECT_EQ(c.contains("envelope"), c["sensor"].get<bool>()) << c["name"];
  }
  EXPECT_TRUE(vibration);
  const std::string h = slurp(html);
  EXPECT_EQ(h.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(h.find("</html>"), std::string::npos);
  // No temporary files left beside the outputs.
  for (const auto& e : fs::directory_iterator(js.parent_path())) {
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
  }
}

TEST(AnalyzeCli, CsvWithoutTimeColumnNeedsFsAndIsAnalysed) {
  const fs::path csv = scratch("tone.csv"), js = scratch("csv.json");
  {
    std::ofstream o(csv);
    o << std::setprecision(17) << "acc\n";  // exact text round trip
    for (int i = 0; i < 4096; ++i) o << std::sin(2 * M_PI * 100.0 * i / 2048.0) << "\n";
  }
  const auto missing = run("analyze " + csv.string());
  EXPECT_EQ(missing.code, 2) << missing.out;
  const auto a = run("analyze " + csv.string() + " --fs 2048 --json " + js.string());
  ASSERT_EQ(a.code, 0) << a.out;
  const auto j = nlohmann::json::parse(std::ifstream(js));
  EXPECT_TRUE(j["gearbox"].is_null());
  ASSERT_EQ(j["channels"].size(), 1u);
  const auto& c = j["channels"][0];
  EXPECT_EQ(c["name"], "acc");
  // A unit sine: RMS 1/sqrt(2) over whole periods (2048 samples hold 100 of them).
  // 17-digit text round trip, two-pass sums over 4096 samples: 1e-12.
  EXPECT_NEAR(c["indicators"]["rms"].get<double>(), 1 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(c["spectrum"]["peaks"][0]["frequency_hz"].get<double>(), 100.0, 1e-9);
}

TEST(AnalyzeCli, BadInputExitsWithCodeTwoNamingTheProblem) {
  const auto missing = run("analyze " + scratch("nope.h5").string());
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.out.find("nope.h5"), std::string::npos) << missing.out;
  const auto bad_fs = run("analyze " + simulated().string() + " --fs -5");
  EXPECT_EQ(bad_fs.code, 2);
  EXPECT_NE(bad_fs.out.find("--fs"), std::string::npos) << bad_fs.out;
  const auto bad_time = run("analyze " + simulated().string() + " --rpm-at nan");
  EXPECT_EQ(bad_time.code, 2);
  EXPECT_NE(bad_time.out.find("nominal_time_s"), std::string::npos) << bad_time.out;
  const fs::path js = scratch("never.json");
  const auto no_rec = run("analyze " + scratch("nope.h5").string() + " --json " + js.string());
  EXPECT_EQ(no_rec.code, 2);
  EXPECT_FALSE(fs::exists(js));  // nothing written on failure
}

// A simulated healthy baseline at 28 and 32 rpm around the recording's 30 rpm.
fs::path simulated_baseline(int rpm) {
  const fs::path p = scratch("base" + std::to_string(rpm) + ".h5");
  if (!fs::exists(p)) {
    const auto s =
        run("simulate --gearbox " +
            (fs::path(GEARDIAG_TESTDATA_DIR) / "gearbox/three_shaft.json").string() +
            " --duration 1 --fs 20000 --rpm " + std::to_string(rpm) + " -o " + p.string());
    EXPECT_EQ(s.code, 0) << s.out;
  }
  return p;
}

TEST(AnalyzeCli, BaselineGivesAnomalyScoreAndAlarmAtTheJsonTopLevel) {
  const fs::path js = scratch("base.json"), html = scratch("base.html");
  const auto a = run("analyze " + simulated().string() + " --baseline " +
                     simulated_baseline(28).string() + " " + simulated_baseline(32).string() +
                     " --json " + js.string() + " --html " + html.string());
  ASSERT_EQ(a.code, 0) << a.out;
  EXPECT_NE(a.out.find("anomaly score"), std::string::npos) << a.out;
  const auto j = nlohmann::json::parse(std::ifstream(js));
  ASSERT_TRUE(j.contains("anomaly_score"));
  ASSERT_TRUE(j.contains("alarm"));
  EXPECT_TRUE(j["anomaly_score"].is_number());
  EXPECT_TRUE(j["alarm"].is_boolean());
  EXPECT_EQ(j["anomaly_threshold"].get<double>(), 25.0);
  EXPECT_EQ(j["alarm"].get<bool>(),
            j["anomaly_score"].get<double>() > j["anomaly_threshold"].get<double>());
  // 1 s at 20 kHz: 4 parts of >= 4096 samples per baseline recording, a note says so.
  EXPECT_EQ(j["baseline"]["samples"], 8);
  EXPECT_EQ(j["baseline"]["recordings"].size(), 2u);
  EXPECT_EQ(j["baseline"]["notes"].size(), 2u);
  // The accelerometers are compared; the simulator's mesh forces, DTE and contact channels (no
  // direction) and the angles are not.
  std::set<std::string> compared;
  for (const auto& c : j["baseline"]["channels"]) compared.insert(c.get<std::string>());
  std::size_t accelerometers = 0;
  for (const auto& c : j["channels"]) {
    const std::string dir = c["direction"], name = c["name"];
    const bool sensor =
        dir == "along_loa" || dir == "normal_loa" || dir == "horizontal" || dir == "vertical";
    accelerometers += sensor;
    EXPECT_EQ(compared.count(name), sensor ? 1u : 0u) << name;
  }
  EXPECT_GT(accelerometers, 0u);
  // 11 features per compared channel, each with its deviation, largest |z| first.
  const auto& d = j["baseline_deviations"];
  ASSERT_EQ(d.size(), 11 * compared.size());
  for (std::size_t k = 1; k < d.size(); ++k)
    EXPECT_GE(std::abs(d[k - 1]["z"].get<double>()), std::abs(d[k]["z"].get<double>()));
  EXPECT_NE(slurp(html).find("Against the baseline"), std::string::npos);
}

TEST(AnalyzeCli, BadBaselineFileExitsWithCodeTwoNamingItAndWritesNothing) {
  const fs::path js = scratch("bad_base.json"), html = scratch("bad_base.html");
  const fs::path corrupt = scratch("corrupt_base.csv"), missing = scratch("missing_base.h5");
  {
    std::ofstream o(corrupt);
    o << "a1,a2\n1,2\n3\n";  // ragged row
  }
  for (const fs::path& bad : {corrupt, missing}) {
    SCOPED_TRACE(bad.string());
    // --fs: the CSV's fault is its ragged row, not a missing rate
    const auto a = run("analyze " + simulated().string() + " --fs 20000 --baseline " +
                       simulated_baseline(28).string() + " " + bad.string() + " --json " +
                       js.string() + " --html " + html.string());
    EXPECT_EQ(a.code, 2) << a.out;
    EXPECT_NE(a.out.find(bad.filename().string()), std::string::npos) << a.out;
    EXPECT_NE(a.out.find("--baseline"), std::string::npos) << a.out;
    EXPECT_FALSE(fs::exists(js));
    EXPECT_FALSE(fs::exists(html));
  }
  // A readable baseline that shares no channel with the recording: exit 2, named, nothing written.
  const fs::path other = scratch("other_base.csv");
  {
    std::ofstream o(other);
    o << "x\n";
    for (int i = 0; i < 40000; ++i) o << std::sin(0.1 * i) + 0.01 * (i % 7) << "\n";
  }
  const auto a =
      run("analyze " + simulated().string() + " --fs 20000 --baseline " +
          simulated_baseline(28).string() + " " + other.string() + " --json " + js.string());
  EXPECT_EQ(a.code, 2) << a.out;
  EXPECT_NE(a.out.find("other_base.csv"), std::string::npos) << a.out;
  EXPECT_NE(a.out.find("no channel in common"), std::string::npos) << a.out;
  EXPECT_FALSE(fs::exists(js));
}

// The baseline's validation through the whole command line (import with --fs, features, fit, score,
// JSON): SpectraQuest gearbox, leave one load out. For each load L in 0..80 %, the baseline is the
// healthy files of the four other loads; h30hzL must not alarm and b30hzL must. The threshold is
// the default 25, not tuned here (baseline.hpp). The set publishes no sampling rate: --fs 1 (the
// features depend on f / fs only). Skips when ../shared/data is absent.
TEST(AnalyzeCli, SpectraQuestLeaveOneLoadOutAlarmsOnEveryBrokenToothAndNoHealthyGear) {
  const fs::path dir = fs::path(GEARDIAG_SHARED_DATA_DIR) / "spectraquest-gearbox";
  if (!fs::is_directory(dir)) GTEST_SKIP() << "real data not present: " << dir;
  const int loads[] = {0, 20, 40, 60, 80};
  double worst_healthy = 0, weakest_broken = 1e300;
  for (const int held_out : loads) {
    std::string base;
    for (const int l : loads)
      if (l != held_out) base += " " + (dir / ("h30hz" + std::to_string(l) + ".csv.gz")).string();
    for (const char kind : {'h', 'b'}) {
      const std::string file = std::string(1, kind) + "30hz" + std::to_string(held_out);
      SCOPED_TRACE(file);
      const fs::path js = scratch("sq_" + file + ".json");
      const auto a = run("analyze " + (dir / (file + ".csv.gz")).string() + " --fs 1 --baseline" +
                         base + " --json " + js.string());
      ASSERT_EQ(a.code, 0) << a.out;
      const auto j = nlohmann::json::parse(std::ifstream(js));
      const double score = j["anomaly_score"].get<double>();
      EXPECT_EQ(j["alarm"].get<bool>(), kind == 'b') << "score " << score;
      EXPECT_EQ(j["baseline"]["samples"], 32);  // 4 files x 8 parts, as in the validation
      EXPECT_EQ(j["baseline"]["channels"].size(), 4u);
      if (kind == 'h') worst_healthy = std::max(worst_healthy, score);
      if (kind == 'b') weakest_broken = std::min(weakest_broken, score);
    }
  }
  std::cout << "[ margins ] worst healthy " << worst_healthy << ", weakest broken "
            << weakest_broken << ", threshold 25\n";
}

// --curves: checked before the analysis like the other outputs; one report at most on stdout.
// (The file's contents are read with h5py and compared with the Python module's curves in
// python/tests/test_recording_analysis.py.)
TEST(AnalyzeCli, CurvesOutputIsCheckedBeforeTheAnalysis) {
  const fs::path js = scratch("curves_before.json");
  const auto a = run("analyze " + simulated().string() + " --json " + js.string() + " --curves " +
                     (scratch("no_such_folder") / "c.h5").string());
  EXPECT_EQ(a.code, 2) << a.out;
  EXPECT_NE(a.out.find("--curves"), std::string::npos) << a.out;
  EXPECT_EQ(a.out.find("findings:"), std::string::npos) << a.out;  // no analysis was run
  EXPECT_FALSE(fs::exists(js));
  const auto b = run("analyze " + simulated().string() + " --json - --curves -");
  EXPECT_EQ(b.code, 2) << b.out;
  EXPECT_NE(b.out.find("only one report can go to stdout"), std::string::npos) << b.out;
  const fs::path h5 = scratch("curves.h5");
  const auto c = run("analyze " + simulated().string() + " --curves " + h5.string());
  EXPECT_EQ(c.code, 0) << c.out;
  std::ifstream in(h5, std::ios::binary);
  char sig[8] = {};
  in.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "HDF");
}

TEST(AnalyzeCli, HtmlReportRendersInHeadlessChromium) {
  const char* chromium = "/usr/bin/chromium";
  if (!fs::exists(chromium)) {
    GTEST_SKIP() << "/usr/bin/chromium is absent (Debian package 'chromium'): render check skipped";
  }
  const fs::path html = scratch("render.html"), png = scratch("render.png");
  ASSERT_EQ(run("analyze " + simulated().string() + " --html " + html.string()).code, 0);
  // timeout: a hung browser fails the test instead of stalling the suite.
  const std::string cmd = "timeout 120 " + std::string(chromium) +
                          " --headless --disable-gpu --no-sandbox --dump-dom file://" +
                          html.string() + " 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  std::string dom;
  char buf[4096];
  while (std::size_t n = fread(buf, 1, sizeof buf, p)) dom.append(buf, n);
  ASSERT_EQ(pclose(p), 0);
  EXPECT_NE(dom.find("<svg"), std::string::npos);
  EXPECT_NE(dom.find("Findings"), std::string::npos);
  // The spectrograms: SVG <image> elements holding inline PNGs, parsed into the DOM.
  EXPECT_NE(dom.find("<image"), std::string::npos);
  EXPECT_NE(dom.find("data:image/png;base64,iVBORw0KGgo"), std::string::npos);
  const std::string shot = "timeout 120 " + std::string(chromium) +
                           " --headless --disable-gpu --no-sandbox --screenshot=" + png.string() +
                           " --window-size=1200,2000 file://" + html.string() + " >/dev/null 2>&1";
  ASSERT_EQ(std::system(shot.c_str()), 0);
  EXPECT_GT(fs::file_size(png), 10000u);  // a rendered page, not an empty image
}

}  // namespace
