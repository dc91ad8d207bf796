// geardiag profile and geardiag wear from the command line: outputs and bad input (exit 2).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "cli_run.hpp"

namespace {

std::string gearbox_file() {
  const auto p = cli_test::scratch("profile_wear", "gb.json");
  std::ofstream(p) << R"({"shafts": [{"name": "in"}, {"name": "out"}],
   "gears": [{"name": "pinion", "shaft": "in", "teeth": 20, "module_mm": 2.0, "face_width_mm": 20},
             {"name": "wheel", "shaft": "out", "teeth": 50, "module_mm": 2.0, "face_width_mm": 20},
             {"name": "small", "shaft": "out", "teeth": 15, "module_mm": 2.0, "face_width_mm": 20}],
   "meshes": [{"driver": "pinion", "driven": "wheel"}],
   "input": {"shaft": "in", "speed_rpm": 1500.0, "torque_nm": 20.0}})";
  return p.string();
}

TEST(ProfileCli, WritesAnUndercutGearAsCsvAndSvg) {
  const std::string gb = gearbox_file();
  const auto csv = cli_test::scratch("profile_wear", "p.csv");
  const auto svg = cli_test::scratch("profile_wear", "p.svg");
  auto r = cli_test::run("profile --gearbox " + gb + " --gear small --tooth 2 -o " + csv.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("undercut"), std::string::npos);
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "tooth,x_mm,y_mm,radius_mm");
  r = cli_test::run("profile --gearbox " + gb + " --gear small -o " + svg.string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::stringstream s;
  s << std::ifstream(svg).rdbuf();
  EXPECT_EQ(s.str().rfind("<svg", 0), 0u);
}

TEST(ProfileCli, BadGearOrToothExitsTwoNamingIt) {
  const std::string gb = gearbox_file();
  const auto out = cli_test::scratch("profile_wear", "bad.csv").string();
  auto r = cli_test::run("profile --gearbox " + gb + " --gear gear9 -o " + out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("unknown gear 'gear9'"), std::string::npos) << r.out;
  r = cli_test::run("profile --gearbox " + gb + " --gear small --tooth 15 -o " + out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--tooth"), std::string::npos) << r.out;
}

TEST(WearCli, WritesTheHistoryAndRefusesBadInput) {
  const std::string gb = gearbox_file();
  const auto h5 = cli_test::scratch("profile_wear", "w.h5").string();
  auto r =
      cli_test::run("wear --gearbox " + gb +
                    " --mesh pinion_wheel --cycles 1e6 --steps 3 --profile-points 21 -o " + h5);
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string py =
      std::string(GEARDIAG_PYTHON) +
      " -c \"import h5py,sys; f=h5py.File(sys.argv[1]); "
      "print(f['wear/cycles'].shape, f['wear/pinion/depth_um'].shape, "
      "f['wear/wheel/radius_mm'].shape, f['wear/te_peak_to_peak_rad'].shape)\" " +
      h5;
  FILE* p = popen(py.c_str(), "r");
  char buf[256] = {};
  const std::size_t n = fread(buf, 1, sizeof buf - 1, p);
  const int status = pclose(p);
  if (status != 0) GTEST_SKIP() << "python3 with h5py not available";
  EXPECT_EQ(std::string(buf, n), "(3,) (3, 21) (21,) (3,)\n");
  for (const std::string bad :
       {"--mesh wheel_pinion --cycles 1e6 --steps 3", "--mesh pinion_wheel --cycles 0 --steps 3",
        "--mesh pinion_wheel --cycles 1e6 --steps 0",
        "--mesh pinion_wheel --cycles 1e6 --steps 3 --law linear"}) {
    r = cli_test::run("wear --gearbox " + gb + " " + bad + " -o " + h5 + ".bad");
    EXPECT_EQ(r.code, 2) << bad << ": " << r.out;
  }
}

// Closed check from the output file alone (tests/tools/wear_contact_check.py): at every step the
// loaded contact ratio and mesh stiffness recomputed in Python from the file's worn profiles, pair
// stiffness and normal force (its own sharing solver) agree with what the tool wrote (within one
// sample angle and 1 %), for both laws, on the seed pair of docs/wear.md over 1e7 cycles.
TEST(WearCli, LoadedContactRatioAgreesWithTheFilesProfiles) {
  for (const std::string law : {"archard", "seed004"}) {
    const auto h5 = cli_test::scratch("profile_wear", "check_" + law + ".h5").string();
    const auto r = cli_test::run("wear --gearbox " + std::string(GEARDIAG_TESTDATA_DIR) +
                                 "/gearbox/three_shaft.json --mesh z1_z2 --cycles 1e7 --steps 5 "
                                 "--law " +
                                 law + " -o " + h5);
    ASSERT_EQ(r.code, 0) << r.out;
    const std::string py = std::string(GEARDIAG_PYTHON) + " -c \"import h5py\" 2>/dev/null";
    if (std::system(py.c_str()) != 0) GTEST_SKIP() << "python3 with h5py not available";
    const std::string check = std::string(GEARDIAG_PYTHON) + " " + std::string(GEARDIAG_TESTS_DIR) +
                              "/tools/wear_contact_check.py " + h5 + " 2>&1";
    FILE* p = popen(check.c_str(), "r");
    std::string out;
    char buf[512];
    for (std::size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    EXPECT_EQ(pclose(p), 0) << out;
    EXPECT_NE(out.find(": ok"), std::string::npos) << out;
  }
}

}  // namespace
