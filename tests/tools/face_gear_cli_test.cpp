// The face-gear pair (seed 002) through the CLI: simulate writes the DTE, mesh torque, contact
// state and both angles with the DLF in the truth; bifurcation writes speeds_rpm, points and class
// and half_gmf_ratio and does not depend on the thread count, runs on all cores and shows its
// progress on a terminal; a stiffness table from HDF5; the commands that need shafts/gears/meshes
// refuse the description with exit 2; bad input names the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "cli_run.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/hdf5_arrays.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kFaceGear =
    std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/seed002_face_gear.json";

fs::path scratch(const std::string& name) { return cli_test::scratch("face_gear_cli", name); }

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(FaceGearCli, SimulateWritesDteTorqueContactAnglesAndDlf) {
  const fs::path out = scratch("fg.h5");
  const cli_test::Run r =
      cli_test::run("simulate --gearbox " + kFaceGear + " --duration 0.05 -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const diag::Recording rec = diag::read_recording(out);
  bool dte = false;
  for (const char* name : {"mesh_torque", "contact_state", "pinion_angle", "face_gear_angle"}) {
    EXPECT_NE(rec.find(name), nullptr) << name;
  }
  for (const diag::Signal& s : rec.signals) dte |= s.name.find("dte") != std::string::npos;
  EXPECT_TRUE(dte);
  // The phase portrait's second axis: dte_rate is the time derivative of dte. Against the central
  // difference of the recorded dte: the difference's own error at the mesh harmonics
  // ((2 pi f / fs)^2 / 6: 1.6 % at the GMF, 6.6 % at 2 GMF for 1 kHz at 20 kHz) stays under 10 %
  // of the rate's RMS; a wrong sign or scale gives >= 100 %.
  const diag::Signal* d = rec.find("dte");
  const diag::Signal* v = rec.find("dte_rate");
  ASSERT_NE(d, nullptr);
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->unit, "rad/s");
  double err2 = 0, rate2 = 0;
  for (std::size_t i = 1; i + 1 < d->samples.size(); ++i) {
    const double diff = (d->samples[i + 1] - d->samples[i - 1]) * d->fs_hz / 2.0;
    err2 += (diff - v->samples[i]) * (diff - v->samples[i]);
    rate2 += v->samples[i] * v->samples[i];
  }
  ASSERT_GT(rate2, 0.0);
  EXPECT_LT(std::sqrt(err2 / rate2), 0.10);
  const nlohmann::json truth = nlohmann::json::parse(rec.truth_json);
  EXPECT_GT(truth.at("dlf").get<double>(), 1.0);
  EXPECT_EQ(truth.at("period"), "period-1");
  EXPECT_EQ(truth.at("impact"), "no impact");
  // The mesh torque's mean is the static torque (300 N m less the pinion bearing's drag).
  const diag::Signal& t = *rec.find("mesh_torque");
  double mean = 0;
  for (double v : t.samples) mean += v;
  mean /= t.samples.size();
  EXPECT_NEAR(mean, truth.at("static_mesh_torque_nm").get<double>(), 3.0);
  // The truth reports the mean mesh torque (what the mesh carries, not the input torque).
  EXPECT_NEAR(truth.at("mean_mesh_torque_nm").get<double>(), mean, 3.0);
  EXPECT_LT(truth.at("mean_mesh_torque_nm").get<double>(), truth.at("input_torque_nm"));

  // info on the recording works; analyze says it does not apply (exit 2, not a crash).
  EXPECT_EQ(cli_test::run("info " + out.string()).code, 0);
  const cli_test::Run a = cli_test::run("analyze " + out.string());
  EXPECT_EQ(a.code, 2) << a.out;
  EXPECT_NE(a.out.find("face_gear_pair"), std::string::npos) << a.out;
}

TEST(FaceGearCli, BifurcationJsonIsDeterministicAcrossThreads) {
  const fs::path j1 = scratch("b1.json"), j2 = scratch("b2.json"), svg = scratch("b.svg");
  const std::string base = "bifurcation --gearbox " + kFaceGear +
                           " --from-rpm 2000 --to-rpm 3500 --steps 4 --transient 50 --periods 20";
  const cli_test::Run r1 =
      cli_test::run(base + " --threads 1 --json " + j1.string() + " --svg " + svg.string());
  ASSERT_EQ(r1.code, 0) << r1.out;
  ASSERT_EQ(cli_test::run(base + " --threads 2 --json " + j2.string()).code, 0);
  EXPECT_EQ(slurp(j1), slurp(j2));
  const nlohmann::json j = nlohmann::json::parse(slurp(j1));
  ASSERT_EQ(j.at("speeds_rpm").size(), 4u);
  ASSERT_EQ(j.at("points").size(), 4u);
  EXPECT_EQ(j.at("points")[0].size(), 20u);
  for (const auto& c : j.at("class")) EXPECT_EQ(c, "period-1");
  // Period-1: no GMF / 2 line (measured ratios below 1e-5; 1e-3 is the bound of the library
  // test FaceGear.PeriodTwoHasHalfGmfLinePeriodOneHasNone).
  ASSERT_EQ(j.at("half_gmf_ratio").size(), 4u);
  for (const auto& x : j.at("half_gmf_ratio")) EXPECT_LT(x.get<double>(), 1e-3);
  // The mesh torque per speed: the input torque (300 N m) less the pinion bearing's c_p Omega.
  ASSERT_EQ(j.at("mean_mesh_torque_nm").size(), 4u);
  for (const auto& x : j.at("mean_mesh_torque_nm")) {
    EXPECT_LT(x.get<double>(), 300.0);
    EXPECT_GT(x.get<double>(), 299.0);
  }
  EXPECT_NE(r1.out.find("on 1 threads"), std::string::npos) << r1.out;
  EXPECT_NE(slurp(svg).find("<svg"), std::string::npos);
}

TEST(FaceGearCli, RefusalsAndBadInputExit2) {
  // Commands that need a gearbox of shafts and meshes.
  const cli_test::Run v = cli_test::run("validate --attribution --gearbox " + kFaceGear);
  EXPECT_EQ(v.code, 2) << v.out;
  // Kinematic mode has no face-gear form.
  const cli_test::Run k = cli_test::run("simulate --mode kinematic --gearbox " + kFaceGear +
                                        " -o " + scratch("k.csv").string());
  EXPECT_EQ(k.code, 2) << k.out;
  EXPECT_NE(k.out.find("face_gear_pair"), std::string::npos) << k.out;
  // Negative backlash.
  std::string text = slurp(kFaceGear);
  text.replace(text.find("\"backlash_um\": 50"), 17, "\"backlash_um\": -5");
  const fs::path bad = scratch("bad.json");
  std::ofstream(bad) << text;
  const cli_test::Run b = cli_test::run("simulate --gearbox " + bad.string() +
                                        " --duration 0.01 -o " + scratch("x.h5").string());
  EXPECT_EQ(b.code, 2) << b.out;
  EXPECT_NE(b.out.find("face_gear_pair.backlash_um"), std::string::npos) << b.out;
  // A scenario field that does not exist.
  const fs::path sc = scratch("sc.json");
  std::ofstream(sc) << R"({"stiffness_scal": 10})";
  const cli_test::Run s = cli_test::run("bifurcation --gearbox " + kFaceGear + " --scenario " +
                                        sc.string() + " --from-rpm 100 --to-rpm 200 --steps 2 " +
                                        "--json " + scratch("s.json").string());
  EXPECT_EQ(s.code, 2) << s.out;
  EXPECT_NE(s.out.find("stiffness_scal"), std::string::npos) << s.out;
  // bifurcation on an ordinary gearbox.
  const cli_test::Run g =
      cli_test::run("bifurcation --gearbox " + std::string(GEARDIAG_TESTDATA_DIR) +
                    "/gearbox/three_shaft.json --from-rpm 100 --to-rpm 200 --steps 2 --json " +
                    scratch("g.json").string());
  EXPECT_EQ(g.code, 2) << g.out;
}

// "All cores, progress on a terminal": under a pseudo-terminal (util-linux script) the default
// --threads 0 runs min(cores, speeds) workers and stderr shows "\rbifurcation: i/N speeds"; through
// a pipe no progress is written (the JSON and the summary only).
TEST(FaceGearCli, BifurcationUsesAllCoresAndShowsProgressOnATerminal) {
  if (!fs::exists("/usr/bin/script")) GTEST_SKIP() << "no /usr/bin/script for a pseudo-terminal";
  const std::string args = std::string(GEARDIAG_BINARY) + " bifurcation --gearbox " + kFaceGear +
                           " --from-rpm 2000 --to-rpm 6000 --steps 4 --transient 50 --periods 20" +
                           " --json " + scratch("tty.json").string();
  const cli_test::Run tty =
      cli_test::run_command("/usr/bin/script -qec '" + args + "' /dev/null < /dev/null");
  ASSERT_EQ(tty.code, 0) << tty.out;
  EXPECT_NE(tty.out.find("\rbifurcation: 1/4 speeds"), std::string::npos) << tty.out;
  EXPECT_NE(tty.out.find("\rbifurcation: 4/4 speeds"), std::string::npos) << tty.out;
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  EXPECT_NE(tty.out.find("on " + std::to_string(std::min(cores, 4u)) + " threads"),
            std::string::npos)
      << tty.out;
  const cli_test::Run pipe = cli_test::run_command(args + " 2>&1");
  ASSERT_EQ(pipe.code, 0) << pipe.out;
  EXPECT_EQ(pipe.out.find("speeds\r"), std::string::npos) << pipe.out;
  EXPECT_EQ(pipe.out.find('\r'), std::string::npos) << pipe.out;
}

// A stiffness table from HDF5 through simulate (a recording shorter than the 18 mesh periods the
// period class needs still gets one), and a bad HDF5 table: exit 2 naming the dataset.
TEST(FaceGearCli, SimulateWithHdf5TableAndBadTableExit2) {
  std::vector<double> angle, e0, k, k_bad;
  for (int i = 0; i < 24; ++i) {
    angle.push_back(i);  // deg, one mesh period of 15 teeth
    e0.push_back(2.0 * std::cos(2 * 3.141592653589793 * i / 24));
    for (int j = 0; j < 2; ++j) k.push_back(9e5 * (1 + 0.05 * std::cos(0.26 * i)));
  }
  k_bad = k;
  k_bad[7] = -1.0;
  auto table = [&](const std::string& name, const std::vector<double>& drive_k) {
    diag::write_hdf5_arrays(scratch(name), {{"/angle_deg", {}, angle, "deg"},
                                            {"/load_nm", {}, {10.0, 300.0}, "N m"},
                                            {"/drive/stiffness_nm_per_rad", {24, 2}, drive_k, ""},
                                            {"/drive/e0_urad", {}, e0, "urad"},
                                            {"/coast/stiffness_nm_per_rad", {24, 2}, k, ""},
                                            {"/coast/e0_urad", {}, e0, "urad"}});
    const fs::path json = scratch(name + ".json");
    std::ofstream(json)
        << nlohmann::json{{"face_gear_pair",
                           {{"pinion_teeth", 15}, {"gear_teeth", 121}, {"stiffness_table", name}}}}
               .dump();
    return json.string();
  };
  const fs::path out = scratch("h5table.h5");
  const cli_test::Run ok = cli_test::run("simulate --gearbox " + table("t.h5", k) +
                                         " --duration 0.005 -o " + out.string());
  ASSERT_EQ(ok.code, 0) << ok.out;
  const nlohmann::json truth = nlohmann::json::parse(diag::read_recording(out).truth_json);
  EXPECT_EQ(truth.at("stiffness_table"), "t.h5");
  EXPECT_EQ(truth.at("period"), "period-1");
  EXPECT_LT(truth.at("half_gmf_ratio").get<double>(), 1e-3);
  const cli_test::Run bad = cli_test::run("simulate --gearbox " + table("bad.h5", k_bad) +
                                          " --duration 0.005 -o " + scratch("x.h5").string());
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("bad.h5: /drive/stiffness_nm_per_rad: stiffness must be > 0"),
            std::string::npos)
      << bad.out;
}
