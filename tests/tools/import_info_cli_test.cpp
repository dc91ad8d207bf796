// `geardiag import` and `geardiag info` as a user runs them: exit codes (0 ok, 2 bad input with a
// message naming the file, and no output left behind), what they print, and the file they write.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "diag/io/hdf5.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs geardiag with the given (already quoted) arguments.
Result geardiag(const std::string& args) {
  const std::string command = std::string("'") + GEARDIAG_BINARY + "' " + args + " 2>&1";
  Result result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer;
  std::size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

class ImportInfoCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("import_info_cli"); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write_text(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  fs::path dir_;
};

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

const char kCsv[] =
    "time,drive_end,fan_end\n"
    "0.000,0.5,1\n"
    "0.001,0.25,2\n"
    "0.002,-0.5,3\n"
    "0.003,0.125,4\n";

}  // namespace

TEST_F(ImportInfoCli, ImportWritesTheRecordingAndPrintsOneLinePerChannel) {
  const fs::path csv = write_text("rig.csv", kCsv);
  const fs::path out = dir_ / "rig.h5";
  const Result r = geardiag("import " + q(csv) + " -o " + q(out));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_CONTAINS(r.output, "drive_end");
  EXPECT_CONTAINS(r.output, "fan_end");
  EXPECT_CONTAINS(r.output, "1000 Hz");

  const diag::Recording rec = diag::read_recording(out);
  ASSERT_EQ(rec.signals.size(), 2u);
  EXPECT_EQ(rec.signals[0].samples, (std::vector<double>{0.5, 0.25, -0.5, 0.125}));
  EXPECT_NEAR(rec.signals[0].fs_hz, 1000.0, 1e-9);  // exact up to decimal-to-binary round-off
  EXPECT_EQ(rec.metadata.at("source"), "rig.csv");
}

TEST_F(ImportInfoCli, ImportOfBadInputExitsTwoNamingTheFileAndLeavesNoOutput) {
  const fs::path ragged = write_text("ragged.csv", "a,b\n1,2\n3\n");
  const fs::path out = dir_ / "out.h5";
  Result r = geardiag("import " + q(ragged) + " --fs 100 -o " + q(out));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_CONTAINS(r.output, ragged.string());
  EXPECT_CONTAINS(r.output, "line 3");

  const fs::path no_rate = write_text("no_rate.csv", "a,b\n1,2\n3,4\n");
  r = geardiag("import " + q(no_rate) + " -o " + q(out));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_CONTAINS(r.output, no_rate.string());

  const fs::path missing = dir_ / "missing.csv";
  r = geardiag("import " + q(missing) + " -o " + q(out));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_CONTAINS(r.output, missing.string());

  const fs::path nan = write_text("nan.csv", "a\n1\nnan\n");
  r = geardiag("import " + q(nan) + " --fs 10 -o " + q(out));
  EXPECT_EQ(r.exit_code, 2) << r.output;

  // Writing into a directory that does not exist.
  const fs::path good = write_text("good.csv", kCsv);
  r = geardiag("import " + q(good) + " -o " + q(dir_ / "nowhere" / "out.h5"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_CONTAINS(r.output, "nowhere");

  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_NE(entry.path().extension(), ".h5") << entry.path();
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  }
}

TEST_F(ImportInfoCli, BadUsageExitsTwo) {
  const fs::path csv = write_text("rig.csv", kCsv);
  EXPECT_EQ(geardiag("import " + q(csv)).exit_code, 2);               // no -o
  EXPECT_EQ(geardiag("import -o " + q(dir_ / "x.h5")).exit_code, 2);  // no input
  EXPECT_EQ(geardiag("import " + q(csv) + " --fs abc -o " + q(dir_ / "x.h5")).exit_code, 2);
  EXPECT_EQ(geardiag("import " + q(csv) + " --fs -5 -o " + q(dir_ / "x.h5")).exit_code, 2);
  EXPECT_EQ(geardiag("info").exit_code, 2);
  const Result help = geardiag("import --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_CONTAINS(help.output, "[Hz]");
  EXPECT_EQ(geardiag("info --help").exit_code, 0);
}

TEST_F(ImportInfoCli, InfoDescribesTheImportedRecording) {
  const fs::path csv = write_text("rig.csv", kCsv);
  const fs::path out = dir_ / "rig.h5";
  ASSERT_EQ(geardiag("import " + q(csv) + " -o " + q(out)).exit_code, 0);

  const Result text = geardiag("info " + q(out));
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_CONTAINS(text.output, "drive_end");
  EXPECT_CONTAINS(text.output, "fan_end");
  EXPECT_CONTAINS(text.output, "signals");
  EXPECT_CONTAINS(text.output, "geardiag-recording");
  EXPECT_CONTAINS(text.output, "source: rig.csv");

  const Result json = geardiag("info --json " + q(out));
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const auto j = nlohmann::json::parse(json.output);
  ASSERT_EQ(j["channels"].size(), 2u);
  EXPECT_EQ(j["channels"][0]["name"], "drive_end");
  EXPECT_EQ(j["channels"][0]["samples"], 4);
  EXPECT_NEAR(j["channels"][0]["fs_hz"].get<double>(), 1000.0, 1e-9);
  EXPECT_EQ(j["metadata"]["source"], "rig.csv");

  // info reads the CSV itself too, and refuses a file that is not a recording.
  const Result direct = geardiag("info " + q(csv));
  EXPECT_EQ(direct.exit_code, 0) << direct.output;
  EXPECT_CONTAINS(direct.output, "drive_end");
  const fs::path junk = write_text("junk.h5", "not hdf5");
  const Result bad = geardiag("info " + q(junk));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_CONTAINS(bad.output, junk.string());
}

TEST_F(ImportInfoCli, InfoPrintsTheGearboxSummaryAndTheTruth) {
  const fs::path gearbox = fs::path(GEARDIAG_TESTDATA_DIR) / "gearbox" / "three_shaft.json";
  if (!fs::exists(gearbox)) GTEST_SKIP() << "no gearbox description at " << gearbox;
  std::ifstream in(gearbox);
  const std::string description((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
  diag::Recording rec;
  diag::Signal s;
  s.name = "te";
  s.fs_hz = 100.0;
  s.samples = {0.0, 1.0};
  rec.signals = {s};
  rec.gearbox_json = description;
  rec.truth_json = R"({"defects":[{"gear":"z1","size_rad":1e-05}]})";
  const fs::path path = dir_ / "sim.h5";
  diag::write_recording(path, rec);

  const Result r = geardiag("info " + q(path));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_CONTAINS(r.output, "gearbox:");
  EXPECT_CONTAINS(r.output, "truth:");
  EXPECT_CONTAINS(r.output, "\"size_rad\": 1e-05");  // pretty-printed

  const Result summary = geardiag("info --gearbox " + q(gearbox));
  EXPECT_EQ(summary.exit_code, 0) << summary.output;
  EXPECT_FALSE(summary.output.empty());
  const Result json = geardiag("info --json " + q(path));
  ASSERT_EQ(json.exit_code, 0) << json.output;
  EXPECT_TRUE(nlohmann::json::parse(json.output).contains("gearbox"));
}

TEST(ImportInfoCliRealData, CwruMatImportsAt48kHz) {
  const fs::path mat = fs::path(GEARDIAG_SHARED_DATA_DIR) / "cwru-bearing" / "normal_0.mat";
  if (!fs::exists(mat)) GTEST_SKIP() << "real data not present: " << mat;
  const fs::path dir = geardiag_test::scratch_dir("import_info_cli");
  const fs::path out = dir / "cwru_normal_0.h5";
  const Result r = geardiag("import " + q(mat) + " --fs 48000 -o " + q(out));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_CONTAINS(r.output, "X097_DE_time");
  EXPECT_CONTAINS(r.output, "243938");  // samples per channel, see libdiag/import_test.cpp
  const Result info = geardiag("info " + q(out));
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_CONTAINS(info.output, "X097RPM: 1796");
  fs::remove_all(dir);
}
