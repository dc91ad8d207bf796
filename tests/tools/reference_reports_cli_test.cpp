// The analysis's behaviour pinned: `geardiag analyze` on reference inputs must give the very
// bytes recorded in testdata/reference/analyze_sha256.txt (JSON and HTML reports). The inputs
// are shipped (a format-1 recording), simulated here (the three-shaft box at 1500 rpm, and a
// run-up), or the measured files (CWRU, SpectraQuest; skipped when absent). A digest that moves
// is a change of what users get: it fails here until it is renewed on purpose.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;

using cli_test::run;

fs::path scratch(const std::string& name) { return cli_test::scratch("reference_reports", name); }

// "<case> <output>" -> sha256, from the digest file.
std::map<std::string, std::string> expected_digests() {
  std::ifstream in(fs::path(GEARDIAG_TESTDATA_DIR) / "reference" / "analyze_sha256.txt");
  std::map<std::string, std::string> d;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string name, output, sha;
    s >> name >> output >> sha;
    d[name + " " + output] = sha;
  }
  return d;
}

std::string sha256(const fs::path& file) {
  const auto r = cli_test::run_command("sha256sum '" + file.string() + "'");
  return r.code == 0 ? r.out.substr(0, 64) : "sha256sum failed: " + r.out;
}

// Runs `analyze INPUT ARGS --json J [--html H]` (in folder `cwd` when given: the report names the
// baseline files as they were given) and compares the digests of the case.
void check(const std::string& name, const std::string& input_and_args, bool html,
           const fs::path& cwd = {}) {
  const auto digests = expected_digests();
  ASSERT_FALSE(digests.empty()) << "no digest file under " << GEARDIAG_TESTDATA_DIR;
  const fs::path js = scratch(name + ".json");
  const fs::path page = scratch(name + ".html");
  const std::string cmd = std::string(GEARDIAG_BINARY) + " analyze " + input_and_args + " --json " +
                          js.string() + (html ? " --html " + page.string() : "") + " 2>&1";
  const auto r = cli_test::run_command(cwd.empty() ? cmd : "cd '" + cwd.string() + "' && " + cmd);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(sha256(js), digests.at(name + " json")) << name << ": the JSON report changed";
  if (html) {
    EXPECT_EQ(sha256(page), digests.at(name + " html")) << name << ": the HTML report changed";
  }
}

fs::path testdata(const std::string& rel) { return fs::path(GEARDIAG_TESTDATA_DIR) / rel; }

TEST(ReferenceReports, ShippedFormat1Recording) {
  check("format1", testdata("recordings/format1_three_shaft.h5").string(), true);
}

TEST(ReferenceReports, SimulatedSteadyAndRunUp) {
  const fs::path gb = testdata("gearbox/three_shaft.json");
  const fs::path steady = scratch("run.h5");
  auto s =
      run("simulate --gearbox " + gb.string() + " --rpm 1500 --duration 2 -o " + steady.string());
  ASSERT_EQ(s.code, 0) << s.out;
  check("run", steady.string(), false);
  const fs::path ramp = scratch("runup.json");
  std::ofstream(ramp)
      << R"({"speed": {"ramp": {"from_rpm": 500, "to_rpm": 3000, "start_s": 0, "duration_s": 3}}})";
  const fs::path runup = scratch("runup.h5");
  s = run("simulate --gearbox " + gb.string() + " --scenario " + ramp.string() +
          " --duration 3 -o " + runup.string());
  ASSERT_EQ(s.code, 0) << s.out;
  check("runup", runup.string(), false);
}

TEST(ReferenceReports, MeasuredFiles) {
  const fs::path data(GEARDIAG_SHARED_DATA_DIR);
  const fs::path cwru = data / "cwru-bearing";
  const fs::path sq = data / "spectraquest-gearbox";
  if (!fs::exists(cwru / "IR007_0.mat") || !fs::exists(sq / "b30hz40.csv.gz")) {
    GTEST_SKIP() << "the measured data are not under " << data;
  }
  const std::string gb = " --gearbox " + testdata("reference/cwru_6205.json").string();
  check("ir007", (cwru / "IR007_0.mat").string() + " --fs 12000" + gb, true);
  check("or007", (cwru / "OR007@6_0.mat").string() + " --fs 12000" + gb, false);
  check("normal", (cwru / "normal_0.mat").string() + " --fs 48000", false);
  check("sq_base",
        "b30hz40.csv.gz --fs 2560 --baseline h30hz0.csv.gz h30hz20.csv.gz h30hz60.csv.gz", false,
        sq);
}

}  // namespace
