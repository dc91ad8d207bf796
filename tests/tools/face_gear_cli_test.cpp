// The face-gear pair (seed 002) through the CLI: simulate writes the DTE, mesh torque, contact
// state and both angles with the DLF in the truth; bifurcation writes speeds_rpm, points and class
// and does not depend on the thread count; the commands that need shafts/gears/meshes refuse the
// description with exit 2; bad input names the field.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.hpp"
#include "diag/io/hdf5.hpp"

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

  // info on the recording works; analyze says it does not apply (exit 2, not a crash).
  EXPECT_EQ(cli_test::run("info " + out.string()).code, 0);
  const cli_test::Run a = cli_test::run("analyze " + out.string());
  EXPECT_EQ(a.code, 2) << a.out;
  EXPECT_NE(a.out.find("face_gear_pair"), std::string::npos) << a.out;
}

TEST(FaceGearCli, BifurcationJsonIsDeterministicAcrossThreads) {
  const fs::path j1 = scratch("b1.json"), j2 = scratch("b2.json"), svg = scratch("b.svg");
  const std::string base = "bifurcation --gearbox " + kFaceGear +
                           " --from-rpm 2000 --to-rpm 6000 --steps 4 --transient 50 --periods 20";
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
