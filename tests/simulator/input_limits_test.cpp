// Simulator inputs at their limits (docs/limits.md): face-gear CSV stiffness tables read as
// untrusted files (a FIFO or device refused before it is opened, rows with extra fields refused,
// messages that name fields without echoing the file's text), wear runs that must end whatever
// the cycle count or torque, and the transmission-error harmonics of a scenario.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "diag/error.hpp"
#include "sim/dynamics/scenario.hpp"
#include "sim/facegear/description.hpp"
#include "sim/wear/wear.hpp"

namespace fs = std::filesystem;

namespace {

class FaceGearCsvTable : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("fg_csv_input"); }
  void TearDown() override { fs::remove_all(dir_); }

  std::string error_of(const std::string& table) const {
    try {
      sim::facegear::parse_description(
          nlohmann::json{{"face_gear_pair",
                          {{"pinion_teeth", 15}, {"gear_teeth", 121}, {"stiffness_table", table}}},
                         {"input", {{"speed_rpm", 9000}, {"torque_nm", 40}}}},
          (dir_ / "fg.json").string());
    } catch (const diag::InputError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

}  // namespace

TEST_F(FaceGearCsvTable, FifoIsRefusedBeforeItIsOpened) {
  const fs::path fifo = dir_ / "table.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto start = std::chrono::steady_clock::now();
  const std::string e = error_of("table.csv");  // would wait for a writer if opened
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  EXPECT_NE(e.find("table.csv"), std::string::npos) << e;
  EXPECT_NE(e.find("FIFO"), std::string::npos) << e;
}

TEST_F(FaceGearCsvTable, MessagesDoNotEchoTheFile) {
  std::ofstream(dir_ / "secret.csv") << "root:SECRET-TEXT:0:0\n";
  const std::string e = error_of("secret.csv");
  EXPECT_NE(e.find("secret.csv"), std::string::npos) << e;
  EXPECT_NE(e.find("header"), std::string::npos) << e;
  EXPECT_EQ(e.find("SECRET"), std::string::npos) << e;

  std::ofstream(dir_ / "flank.csv") << "flank,angle_deg,load_nm,stiffness_nm_per_rad,e0_urad\n"
                                    << "SECRET-FLANK,0,1,1e6,0\n";
  const std::string f = error_of("flank.csv");
  EXPECT_NE(f.find("line 2: flank"), std::string::npos) << f;
  EXPECT_EQ(f.find("SECRET"), std::string::npos) << f;
}

TEST_F(FaceGearCsvTable, RowsWithExtraFieldsAreRefused) {
  std::ofstream(dir_ / "extra.csv") << "flank,angle_deg,load_nm,stiffness_nm_per_rad,e0_urad\n"
                                    << "drive,0,1,1e6,0,7\n";
  const std::string e = error_of("extra.csv");
  EXPECT_NE(e.find("line 2"), std::string::npos) << e;
  EXPECT_NE(e.find("6 comma-separated fields; exactly 5"), std::string::npos) << e;
}

// The cycle count and torque are bounded up front, and the depth limit is checked inside every
// step: no wear run can go on without end.
TEST(WearLimits, HugeCyclesAndTorqueAreRefusedUpFront) {
  sim::WearOptions o;
  o.cycles = 1e300;
  EXPECT_THROW(o.validate(), diag::InputError);
  o.cycles = 1e6;
  EXPECT_NO_THROW(o.validate());
  o.input_torque_nm = 1e300;
  EXPECT_THROW(o.validate(), diag::InputError);
}

TEST(ScenarioLimits, TransmissionErrorHarmonicsAreBoundedAndPaired) {
  nlohmann::json many = {
      {"transmission_error", {{"amplitude_um", std::vector<double>(100000, 1.0)}}}};
  EXPECT_THROW(sim::parse_scenario(many, "sc.json"), diag::InputError);
  nlohmann::json unequal = {
      {"transmission_error", {{"amplitude_um", {1.0, 2.0, 3.0}}, {"phase_deg", {0.0, 10.0}}}}};
  try {
    sim::parse_scenario(unequal, "sc.json");
    ADD_FAILURE() << "unequal arrays accepted";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("phase_deg"), std::string::npos) << e.what();
  }
}
