// geardiag analyze end to end through the binary: simulate -> analyze (JSON and HTML), a CSV
// input through the import path, exit codes for bad input, and an HTML render check in headless
// Chromium (skipped when /usr/bin/chromium is absent; Debian package "chromium").
#include <gtest/gtest.h>

#include "cli_run.hpp"
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

using cli_test::run;

std::filesystem::path scratch(const std::string& name) { return cli_test::scratch("analyze_cli", name); }

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
    for (const char* k : {"indicators", "spectrum", "psd", "envelope", "meshes", "tsa"}) {
      EXPECT_TRUE(c.contains(k)) << k;
    }
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
  const auto baseline =
      run("analyze " + simulated().string() + " --baseline " + simulated().string());
  EXPECT_EQ(baseline.code, 2);
  EXPECT_NE(baseline.out.find("not available"), std::string::npos) << baseline.out;
  const fs::path js = scratch("never.json");
  const auto no_rec = run("analyze " + scratch("nope.h5").string() + " --json " + js.string());
  EXPECT_EQ(no_rec.code, 2);
  EXPECT_FALSE(fs::exists(js));  // nothing written on failure
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
  const std::string shot = "timeout 120 " + std::string(chromium) +
                           " --headless --disable-gpu --no-sandbox --screenshot=" + png.string() +
                           " --window-size=1200,2000 file://" + html.string() + " >/dev/null 2>&1";
  ASSERT_EQ(std::system(shot.c_str()), 0);
  EXPECT_GT(fs::file_size(png), 10000u);  // a rendered page, not an empty image
}

}  // namespace
