// A bearing log without tacho and without a recorded speed, the description's speed up to 10 %
// off: the speed is measured from the shaft's own lines (speed_estimate.hpp; a one-shaft box has
// no mesh line) and the findings are those of the right speed. Measured data: the CWRU drive-end
// records (inner race, outer race, healthy), their recorded speed removed, with the one-shaft
// SKF 6205 description told 0.9, 1 and 1.1 times the motor's 1797 rpm. Skips when the data is
// absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "detect/analysis/analyze_file.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/import.hpp"
#include "report/report.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kFileRpm = 1797;  // the data centre's figure for the 0 hp records

fs::path data_dir() { return fs::path(GEARDIAG_SHARED_DATA_DIR) / "cwru-bearing"; }

// The record as a logger without a speed channel would give it: the recorded speed dropped.
std::shared_ptr<const diag::Recording> without_speed(const std::string& file, double fs_hz) {
  diag::ImportOptions opt;
  opt.fs_hz = fs_hz;
  auto rec = std::make_shared<diag::Recording>(diag::import_recording(data_dir() / file, opt));
  rec->speed_rpm = 0;
  return rec;
}

diag::Gearbox box_at(double rpm) {
  return diag::parse_gearbox_text(
      R"({"name": "cwru", "shafts": [{"name": "input"}], "input": {"shaft": "input",
          "speed_rpm": )" +
          std::to_string(rpm) +
          R"(}, "bearings": [{"name": "drive_end", "shaft": "input", "rolling_elements": 9,
          "pitch_diameter_mm": 39.04, "element_diameter_mm": 7.94, "contact_angle_deg": 0.0}]})",
      "cwru");
}

detect::AnalysisResult analysed(const std::shared_ptr<const diag::Recording>& rec, double off) {
  detect::AnalyzeRequest q;
  q.recording = detect::RecordingInput(rec, "cwru");
  q.gearbox = box_at(off * kFileRpm);
  q.options.traces = false;
  return detect::analyze_file(q).result;
}

std::optional<detect::Finding> bearing_finding(const detect::AnalysisResult& r) {
  std::optional<detect::Finding> out;
  for (const detect::Finding& f : r.findings) {
    if (f.kind != "bearing") continue;
    EXPECT_FALSE(out) << report::to_json(r)["findings"].dump(1);
    out = f;
  }
  return out;
}

bool warned(const detect::AnalysisResult& r) {
  for (const std::string& n : r.notes) {
    if (n.starts_with("warning: the speed measured from the vibration")) return true;
  }
  return false;
}

class AnalyzeNominalOff : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::is_directory(data_dir())) GTEST_SKIP() << "real data not present: " << data_dir();
  }
};

// The fault records: the same fault at every nominal speed, the speed measured within 0.2 % of
// the file's whole-rpm figure (the motor's speed to a few rpm), a warning naming both speeds
// when the nominal one is 10 % off.
TEST_F(AnalyzeNominalOff, TheBearingFaultIsFoundWithTheNominalSpeedTenPercentOff) {
  for (const auto& [file, fault] :
       {std::pair<std::string, std::string>{"IR007_0.mat", "inner_race"},
        {"OR007@6_0.mat", "outer_race"}}) {
    const auto rec = without_speed(file, 12000);
    for (const double off : {0.9, 1.0, 1.1}) {
      const detect::AnalysisResult r = analysed(rec, off);
      EXPECT_EQ(r.speed.source, "vibration") << file << " " << off;
      EXPECT_NEAR(r.speed.mean_rpm / kFileRpm, 1.0, 2e-3) << file << " " << off;
      EXPECT_TRUE(r.speed.stationary) << file << " " << off;
      EXPECT_EQ(warned(r), off != 1.0) << file << " " << off;
      const auto f = bearing_finding(r);
      ASSERT_TRUE(f) << file << " " << off << ": " << report::to_json(r)["notes"].dump(1);
      EXPECT_EQ(diag::to_string(f->fault), fault) << file << " " << off;
      EXPECT_EQ(f->bearing, "drive_end");
    }
  }
}

// The healthy record: no bearing finding at any of the nominal speeds (where no line holds the
// phase well enough, the nominal speed is used, and said so).
TEST_F(AnalyzeNominalOff, TheHealthyBearingGivesNoFindingWithTheNominalSpeedTenPercentOff) {
  const auto rec = without_speed("normal_0.mat", 48000);
  for (const double off : {0.9, 1.0, 1.1}) {
    const detect::AnalysisResult r = analysed(rec, off);
    EXPECT_FALSE(bearing_finding(r)) << off;
    if (r.speed.source != "vibration") {
      bool said = false;
      for (const std::string& n : r.notes)
        said |= n.starts_with("speed from the vibration not used");
      EXPECT_TRUE(said) << off;
    }
  }
}

// Told a speed beyond the band searched around it (12.5 %), a quarter and a third off: the
// harmonic-set check on the shaft's own lines (orders 1, 2, 3 and their doubles 4 and 6) finds
// the motor's speed outside the band and the search is made again around it; the same fault,
// the speed within 0.2 %, a warning naming the speed the lines fit. Never a speed or a fault
// claimed wrongly: where no speed is measured, no bearing finding either.
TEST_F(AnalyzeNominalOff, AFarOffNominalSpeedIsFoundOutByTheShaftsLines) {
  for (const auto& [file, fault] :
       {std::pair<std::string, std::string>{"IR007_0.mat", "inner_race"},
        {"OR007@6_0.mat", "outer_race"}}) {
    const auto rec = without_speed(file, 12000);
    for (const double off : {0.75, 1.25, 4.0 / 3.0}) {
      const detect::AnalysisResult r = analysed(rec, off);
      std::printf("%s x%.3f: %s %.1f rpm\n", file.c_str(), off, r.speed.source.c_str(),
                  r.speed.mean_rpm);
      const auto f = bearing_finding(r);
      if (r.speed.source != "vibration") {
        EXPECT_FALSE(f) << file << " " << off;
        continue;
      }
      EXPECT_NEAR(r.speed.mean_rpm / kFileRpm, 1.0, 2e-3) << file << " " << off;
      ASSERT_TRUE(f) << file << " " << off << ": " << report::to_json(r)["notes"].dump(1);
      EXPECT_EQ(diag::to_string(f->fault), fault) << file << " " << off;
    }
  }
}

// The healthy record told as far off: no bearing finding (the healthy drive end's lines are weak:
// where no speed is measured the nominal one is used, and said so).
TEST_F(AnalyzeNominalOff, TheHealthyBearingGivesNoFindingWithAFarOffNominalSpeed) {
  const auto rec = without_speed("normal_0.mat", 48000);
  for (const double off : {0.75, 1.25, 4.0 / 3.0}) {
    const detect::AnalysisResult r = analysed(rec, off);
    std::printf("normal_0.mat x%.3f: %s %.1f rpm\n", off, r.speed.source.c_str(), r.speed.mean_rpm);
    EXPECT_FALSE(bearing_finding(r)) << off << ": " << report::to_json(r)["findings"].dump(1);
    if (r.speed.source == "vibration") {
      EXPECT_NEAR(r.speed.mean_rpm / kFileRpm, 1.0, 2e-3) << off;
    }
  }
}

}  // namespace
