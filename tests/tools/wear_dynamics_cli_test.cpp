// Worn flanks in the dynamic simulator from the command line: `geardiag wear --record-every`
// (recordings along a pair's life, the wear state as truth), the scenario's worn-profile fault
// kind in `geardiag simulate`, and a `geardiag dataset` class of worn pairs.
//
// The physical check is the mesh harmonic. Worn flanks open a gap g(s) between the pairs near the
// start and end of contact (wear is zero at the pitch point and deepest at the roots), so the
// load leaves the double-contact zones: the loaded transmission error's mesh-periodic part and
// with it the bearing vibration along the line of action at the mesh frequency grow with wear.
// Measured on this pair (18/36 teeth, m 3 mm, 50 N m, 1000 rpm, noise off; docs/wear.md, "Worn
// profiles in the dynamic simulator"), the mesh-frequency amplitude along the LOA: new 0.434,
// Archard wear of 2.5e6 cycles 0.622, 5e6 0.678, 7.5e6 0.734, 1e7 0.789 m/s^2; a 20 um worn fault
// 0.644 (x 1.48). Tolerances below are margins under those figures, not fits.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>

#include "cli_run.hpp"
#include "diag/io/hdf5.hpp"

namespace {

namespace fs = std::filesystem;
using cli_test::run;

fs::path scratch(const std::string& name) { return cli_test::scratch("wear_dynamics", name); }

std::string gearbox_file() {
  const fs::path p = scratch("gb.json");
  std::ofstream(p) << R"({"shafts": [{"name": "in"}, {"name": "out"}],
 "gears": [{"name": "pinion", "shaft": "in", "teeth": 18, "module_mm": 3.0, "face_width_mm": 20},
           {"name": "wheel", "shaft": "out", "teeth": 36, "module_mm": 3.0, "face_width_mm": 20}],
 "meshes": [{"driver": "pinion", "driven": "wheel"}],
 "input": {"shaft": "in", "speed_rpm": 1000.0, "torque_nm": 50.0}})";
  return p.string();
}

std::string write(const std::string& name, const std::string& text) {
  const fs::path p = scratch(name);
  std::ofstream(p) << text;
  return p.string();
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

constexpr double kMeshHz = 300.0;  // 18 teeth at 1000 rpm
const char* const kRun = " --duration 0.2 --fs 10000";

// RMS over the vibration channels along the line of action (by role and direction, not name) of the
// Hann-windowed amplitude at the mesh frequency; 0.2 s holds 60 mesh periods, so the frequency
// falls on a bin.
double mesh_amplitude(const fs::path& h5) {
  const diag::Recording rec = diag::read_recording(h5);
  double sum = 0;
  int n = 0;
  for (const diag::Signal& s : rec.signals) {
    if (s.role != diag::Role::kVibration || s.direction != diag::Direction::kAlongLoa) continue;
    double re = 0, im = 0, wsum = 0;
    const std::size_t N = s.samples.size();
    for (std::size_t i = 0; i < N; ++i) {
      const double w = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * i / N);
      const double a = 2 * std::numbers::pi * kMeshHz * i / s.fs_hz;
      re += w * s.samples[i] * std::cos(a);
      im += w * s.samples[i] * std::sin(a);
      wsum += w;
    }
    const double amp = 2 * std::hypot(re, im) / wsum;
    sum += amp * amp;
    ++n;
  }
  return n ? std::sqrt(sum / n) : 0.0;
}

nlohmann::json truth(const fs::path& h5) {
  return nlohmann::json::parse(diag::read_recording(h5).truth_json);
}

// A life of 1e7 cycles in 4 steps, recorded at steps 0, 2, 4: each recording's mesh harmonic at
// least 7 % above the one before (measured +56 % and +16 %), the truth's wear entry matching the
// history's step, and the same bytes from a second run.
TEST(WearRecordCli, MeshHarmonicGrowsAlongTheLifeAndTruthIsTheWearState) {
  const std::string gb = gearbox_file();
  const std::string quiet = write("quiet.json", R"({"sensors": {"noise_m_per_s2": 0}})");
  const fs::path out = scratch("life.h5");
  const std::string args = "wear --gearbox " + gb +
                           " --mesh pinion_wheel --cycles 1e7 --steps 4 --record-every 2"
                           " --scenario " +
                           quiet + kRun + " -o " + out.string();
  const auto r = run(args);
  ASSERT_EQ(r.code, 0) << r.out;
  std::vector<double> amp;
  for (int k : {0, 2, 4}) {
    const fs::path rec = scratch("life_step" + std::to_string(k) + ".h5");
    ASSERT_TRUE(fs::exists(rec)) << rec << "\n" << r.out;
    EXPECT_NE(r.out.find(rec.filename().string()), std::string::npos) << r.out;
    amp.push_back(mesh_amplitude(rec));
    const nlohmann::json t = truth(rec);
    ASSERT_EQ(t["wear"].size(), 1u) << t.dump();
    const nlohmann::json& w = t["wear"][0];
    EXPECT_EQ(w["mesh"], "pinion_wheel");
    EXPECT_EQ(w["law"], "archard");
    EXPECT_DOUBLE_EQ(w["cycles"].get<double>(), 2.5e6 * k);  // 1e7 / 4 per step
    const double pinion = w["max_depth_um"]["pinion"], wheel = w["max_depth_um"]["wheel"];
    if (k == 0) {
      EXPECT_EQ(pinion, 0.0);
      EXPECT_EQ(wheel, 0.0);
    } else {
      EXPECT_GT(pinion, wheel);  // the driver's root wears most (lambda1 largest there)
    }
  }
  EXPECT_GT(amp[1], 1.07 * amp[0]);
  EXPECT_GT(amp[2], 1.07 * amp[1]);

  // The truth against the /wear datasets (h5py; skipped without it).
  const std::string py =
      std::string(GEARDIAG_PYTHON) +
      " -c \"import h5py,json,sys; f=h5py.File(sys.argv[1]); d=sys.argv[1][:-3]; "
      "print(list(f['wear/recorded_steps'][:]) == [0, 2, 4], "
      "f.attrs['recordings'] in ('life_step0.h5;life_step2.h5;life_step4.h5', "
      "b'life_step0.h5;life_step2.h5;life_step4.h5'), "
      "all(abs(json.loads(h5py.File(d + '_step%d.h5' % k)['truth'][()])['wear'][0][key] - v) "
      "<= 1e-12 * abs(v) for k in (2, 4) for key, v in ("
      "('cycles', f['wear/cycles'][k - 1]), "
      "('te_peak_to_peak_rad', f['wear/te_peak_to_peak_rad'][k - 1]))), "
      "all(abs(json.loads(h5py.File(d + '_step%d.h5' % k)['truth'][()])['wear'][0]"
      "['max_depth_um'][g] - f['wear/' + g + '/depth_um'][k - 1].max()) < 1e-9 "
      "for k in (2, 4) for g in ('pinion', 'wheel')))\" " +
      out.string();
  FILE* p = popen(py.c_str(), "r");
  char buf[256] = {};
  const std::size_t n = fread(buf, 1, sizeof buf - 1, p);
  if (pclose(p) == 0) {
    EXPECT_EQ(std::string(buf, n), "True True True True\n");
  } else {
    ADD_FAILURE() << "python3 with h5py could not read " << out;
  }

  // Determinism: the same command again gives the same bytes.
  const std::string first = slurp(scratch("life_step4.h5")), history = slurp(out);
  ASSERT_EQ(run(args).code, 0);
  EXPECT_EQ(slurp(scratch("life_step4.h5")), first);
  EXPECT_EQ(slurp(out), history);
}

TEST(WearRecordCli, BadOptionsExitTwoNamingThem) {
  const std::string gb = gearbox_file();
  const std::string base = "wear --gearbox " + gb + " --mesh pinion_wheel --cycles 1e6 --steps 2";
  for (const auto& [bad, field] : std::vector<std::pair<std::string, std::string>>{
           {" --record-every 0", "--record-every"},
           {" --duration 0.1", "--duration"},  // without --record-every
           {" --record-every 1 --fs -5", "--fs"},
           {" --record-every 1 --rpm 0", "--rpm"},
           {" --record-every 1 --torque -1", "--torque"}}) {
    const auto r = run(base + bad + " -o " + scratch("bad.h5").string());
    EXPECT_EQ(r.code, 2) << bad << ": " << r.out;
    EXPECT_NE(r.out.find(field), std::string::npos) << bad << ": " << r.out;
  }
  EXPECT_FALSE(fs::exists(scratch("bad.h5")));
}

// simulate with faults[] {"type": "wear", "depth_um": 20}: the deepest flank point is 20 um (the
// history interpolated to it; tolerance round-off), the mesh harmonic above the healthy run's by
// at least 25 % (measured +48 %).
TEST(WornFaultCli, SimulateWithWornFlanksRaisesTheMeshHarmonic) {
  const std::string gb = gearbox_file();
  const std::string healthy = write("healthy.json", R"({"sensors": {"noise_m_per_s2": 0}})");
  const std::string worn = write("worn.json", R"({"sensors": {"noise_m_per_s2": 0},
    "faults": [{"type": "wear", "gear": "pinion", "depth_um": 20}]})");
  const fs::path h = scratch("healthy.h5"), w = scratch("worn.h5");
  auto r = run("simulate --gearbox " + gb + " --scenario " + healthy + kRun + " -o " + h.string());
  ASSERT_EQ(r.code, 0) << r.out;
  r = run("simulate --gearbox " + gb + " --scenario " + worn + kRun + " -o " + w.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json t = truth(w);
  ASSERT_EQ(t["wear"].size(), 1u);
  const double deepest = std::max(t["wear"][0]["max_depth_um"]["pinion"].get<double>(),
                                  t["wear"][0]["max_depth_um"]["wheel"].get<double>());
  EXPECT_NEAR(deepest, 20.0, 1e-9);
  EXPECT_GT(t["wear"][0]["cycles"].get<double>(), 0.0);
  EXPECT_GT(mesh_amplitude(w), 1.25 * mesh_amplitude(h));
  EXPECT_TRUE(truth(h)["wear"].empty());
}

TEST(WornFaultCli, BadWearFaultsExitTwoNamingTheField) {
  const std::string gb = gearbox_file();
  for (const auto& [fault, field] : std::vector<std::pair<std::string, std::string>>{
           {R"({"type": "wear", "gear": "pinion"})", "cycles"},
           {R"({"type": "wear", "gear": "pinion", "cycles": 1e6, "depth_um": 5})", "cycles"},
           {R"({"type": "wear", "gear": "pinion", "depth_um": -3})", "depth_um"},
           {R"({"type": "wear", "gear": "pinion", "depth_um": 5, "law": "linear"})", "law"},
           {R"({"type": "wear", "gear": "shaft", "depth_um": 5})", "gear"},
           {R"({"type": "wear", "mesh": "wheel_pinion", "depth_um": 5})", "mesh"},
           {R"({"type": "wear", "gear": "pinion", "depth_um": 5, "tooth": 2})", "tooth"},
           {R"({"type": "wear", "gear": "pinion", "cycles": 1e6, "steps": 0})", "steps"}}) {
    const std::string sc = write("bad_sc.json", R"({"faults": [)" + fault + "]}");
    const auto r = run("simulate --gearbox " + gb + " --scenario " + sc +
                       " --duration 0.05 --fs 10000 -o " + scratch("bad_sim.h5").string());
    EXPECT_EQ(r.code, 2) << fault << ": " << r.out;
    EXPECT_NE(r.out.find("faults[0]"), std::string::npos) << fault << ": " << r.out;
    EXPECT_NE(r.out.find(field), std::string::npos) << fault << ": " << r.out;
  }
}

// A dataset spec with a class of worn pairs: the scenario's wear fault per recording, the drawn
// depth in the manifest and in the recording's truth.
TEST(WornFaultCli, DatasetClassOfWornPairs) {
  gearbox_file();
  const fs::path spec = scratch("spec.json");
  std::ofstream(spec) << R"({"gearbox": "gb.json", "seed": 3, "recordings_per_class": 1,
 "duration_s": 0.1, "fs_hz": 10000, "operating_points": {"speed_rpm": 1000, "torque_nm": 50},
 "classes": [{"name": "worn", "faults": [{"type": "wear", "gear": "pinion", "depth_um": [10, 30]}]}]})";
  const fs::path dir = scratch("ds");
  const auto r = run("dataset --spec " + spec.string() + " -o " + dir.string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream rows(dir / "manifest.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(rows, line));
  const nlohmann::json row = nlohmann::json::parse(line);
  EXPECT_EQ(row["fault1_type"], "wear");
  EXPECT_TRUE(row["fault1_tooth"].is_null());
  const double depth = row["fault1_depth_um"];
  EXPECT_GE(depth, 10.0);
  EXPECT_LE(depth, 30.0);
  const nlohmann::json t = truth(dir / row["file"].get<std::string>());
  ASSERT_EQ(t["wear"].size(), 1u);
  EXPECT_NEAR(std::max(t["wear"][0]["max_depth_um"]["pinion"].get<double>(),
                       t["wear"][0]["max_depth_um"]["wheel"].get<double>()),
              depth, 1e-9);
}

}  // namespace
