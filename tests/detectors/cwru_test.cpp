// Bearing diagnosis on measured data: the Case Western Reserve University bearing set (drive end,
// 0 hp, faults of 0.007 in; the data set's README). Skips when the data folder is absent.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "detect/bearing/bearing_diagnosis.hpp"
#include "diag/gearbox/bearing_rates.hpp"
#include "diag/io/import.hpp"

namespace {

namespace fs = std::filesystem;

fs::path data_dir() { return fs::path(GEARDIAG_SHARED_DATA_DIR) / "cwru-bearing"; }

diag::BearingSpec skf6205() { return diag::skf6205("drive_end", "motor"); }

struct CwruRun {
  detect::BearingDiagnosis diagnosis;
  double shaft_hz = 0;
};

// Imports `file` at fs_hz, takes the drive-end channel X<nnn>_DE_time and the speed X<nnn>RPM.
CwruRun diagnose(const std::string& file, double fs_hz) {
  diag::ImportOptions opt;
  opt.fs_hz = fs_hz;
  const diag::Recording rec = diag::import_recording(data_dir() / file, opt);
  const diag::Signal* de = nullptr;
  for (const diag::Signal& s : rec.signals)
    if (s.name.size() > 8 && s.name.ends_with("_DE_time")) de = &s;
  EXPECT_NE(de, nullptr) << file;
  if (de == nullptr) return {};
  const std::string prefix = de->name.substr(0, de->name.size() - 8);
  const double rpm = std::stod(rec.metadata.at(prefix + "RPM"));
  CwruRun r;
  r.shaft_hz = rpm / 60.0;
  const diag::BearingSpec b = skf6205();
  r.diagnosis = detect::diagnose_bearings_from_signal(*de, r.shaft_hz, std::span(&b, 1));
  std::cout << "[ " << file << " ] " << detect::to_json(r.diagnosis).dump() << "\n";
  return r;
}

class Cwru : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::is_directory(data_dir())) GTEST_SKIP() << "real data not present: " << data_dir();
  }
};

// The data centre's fault-frequency table (multiples of the shaft speed) for this bearing:
// BPFI 5.4152, BPFO 3.5848, FTF 0.39828, "BSF" 4.7135 (= 2 BSF, the ball-fault line). Printed
// to 5 significant digits: agreement to 1e-4 relative.
TEST_F(Cwru, BearingGeometryGivesTheDataCentresFaultFrequencies) {
  constexpr double kTableRelTol = 1e-4;
  const auto f = detect::bearing_frequencies(skf6205(), 1.0);
  EXPECT_NEAR(f.bpfi_hz, 5.4152, 5.4152 * kTableRelTol);
  EXPECT_NEAR(f.bpfo_hz, 3.5848, 3.5848 * kTableRelTol);
  EXPECT_NEAR(f.ftf_hz, 0.39828, 0.39828 * kTableRelTol);
  EXPECT_NEAR(f.ball_fault_hz, 4.7135, 4.7135 * kTableRelTol);
}

void expect_single_finding(const CwruRun& r, const std::string& fault, double multiple) {
  ASSERT_EQ(r.diagnosis.findings.size(), 1u) << detect::to_json(r.diagnosis).dump(1);
  const detect::Finding& f = r.diagnosis.findings[0];
  EXPECT_EQ(diag::to_string(f.fault), fault);
  EXPECT_EQ(f.bearing, "drive_end");
  EXPECT_EQ(f.channel, r.diagnosis.channel);
  // The reported frequency is the family's nominal fundamental at the file's speed.
  constexpr double kRelTol = 1e-4;
  EXPECT_NEAR(f.frequency_hz, multiple * r.shaft_hz, multiple * r.shaft_hz * kRelTol);
  const auto j = detect::to_json(r.diagnosis);
  EXPECT_EQ(j["findings"][0]["fault"], fault);
  EXPECT_EQ(j["findings"][0]["bearing"], "drive_end");
}

TEST_F(Cwru, InnerRaceFaultIsDiagnosedAsInnerRace) {
  expect_single_finding(diagnose("IR007_0.mat", 12000.0), "inner_race", 5.4152);
}

TEST_F(Cwru, OuterRaceFaultIsDiagnosedAsOuterRace) {
  expect_single_finding(diagnose("OR007@6_0.mat", 12000.0), "outer_race", 3.5848);
}

TEST_F(Cwru, HealthyBearingGivesNoFinding) {
  const CwruRun r = diagnose("normal_0.mat", 48000.0);
  EXPECT_TRUE(r.diagnosis.findings.empty()) << detect::to_json(r.diagnosis).dump(1);
}

// Ball faults are the hard case of this set (Smith & Randall 2015 diagnose few of them): a
// finding is allowed only when it names the right fault.
TEST_F(Cwru, BallFaultIsEitherRollingElementOrNothingNeverAnotherFault) {
  const CwruRun r = diagnose("B007_0.mat", 12000.0);
  for (const auto& f : r.diagnosis.findings) EXPECT_EQ(diag::to_string(f.fault), "rolling_element");
}

}  // namespace
