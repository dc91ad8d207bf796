// docs/cli/analyze.md's example, the healthy two-stage box
// (testdata/gearbox/three_shaft.json) simulated at 1500 rpm for 2 s WITHOUT sensor noise, gave
// gear_sidebands findings "230 dB over the local floor". Its spectrum holds the mesh harmonics
// (multiples of 225 Hz: both meshes) and, 55-130 dB below them, lines at every input-shaft order
// from the integrator (the contact jumps fall at a position within the RK4 step that repeats once
// per input revolution, RunOptions::contact_substeps); the local floor between them is FFT
// round-off. Closed loop: no sideband finding on the healthy box, every prominence within the
// dynamic range (detect::kDefaultDynamicRangeDb), and a chipped counter-shaft gear with sensor
// noise still named by its sidebands.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "detect/analysis/analyze.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "report/report.hpp"
#include "sim/dynamics/simulate.hpp"

namespace {

constexpr double kRpm = 1500.0;

diag::Gearbox two_stage() {
  std::ifstream in(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["input"]["speed_rpm"] = kRpm;
  return diag::parse_gearbox(j, "three_shaft.json at 1500 rpm");
}

// As `geardiag simulate --rpm 1500 --duration 2` (20 kHz, 50 N m): noise 0 unless given.
diag::Recording simulate(const diag::Gearbox& gb, double noise_m_per_s2, bool chipped_z3) {
  sim::DynamicsOptions dyn;
  dyn.speed = sim::SpeedProfile::constant(kRpm);
  dyn.input_torque_nm = 50.0;
  if (chipped_z3) {
    sim::GearFault f;
    f.gear = "z3";  // on the counter shaft, meshing with z4
    f.fault.kind = sim::ToothFault::Kind::kChip;
    f.fault.tooth = 5;
    f.fault.size_m = 0.8 * 3e-3;  // 0.8 module, as analyze_gear_damage_test
    dyn.faults.push_back(f);
  }
  sim::RunOptions run;
  run.duration_s = 2.0;
  run.fs_hz = 20000.0;
  run.accel_noise_m_per_s2 = noise_m_per_s2;
  run.seed = 5;
  return sim::to_recording(gb, sim::simulate_dynamic(gb, dyn, run));
}

void expect_within_dynamic_range(const detect::LineMeasurement& l, const std::string& what) {
  if (!l.valid) return;
  EXPECT_TRUE(std::isfinite(l.prominence_db)) << what;
  EXPECT_LE(l.prominence_db, detect::kDefaultDynamicRangeDb) << what;
}

TEST(HealthyNoiseFree, AHealthyBoxWithoutNoiseHasNoSidebandFindingAndNoProminenceBeyondTheRange) {
  const diag::Gearbox gb = two_stage();
  const detect::AnalysisResult r = detect::analyze_recording(simulate(gb, 0.0, false), &gb);
  // No vote passes its quorum (the vote is never a finding: findings.cpp), and no finding.
  EXPECT_TRUE(r.findings.empty()) << report::to_json(r)["findings"].dump(1);
  for (const auto& n : r.notes) {
    const bool passed = n.rfind("sidebands of mesh", 0) == 0 && n.find(" in only ") == n.npos;
    EXPECT_FALSE(passed) << n;
  }
  int lines = 0;
  for (const auto& c : r.channels) {
    for (const auto& m : c.meshes) {
      const std::string where = c.name + " " + m.name;
      for (const auto& l : m.sidebands.mesh) expect_within_dynamic_range(l, where + " mesh");
      for (const auto& s : m.sidebands.shafts) {
        EXPECT_LE(s.score_db, s.lines.size() * detect::kDefaultDynamicRangeDb) << where;
        for (const auto& l : s.lines) {
          expect_within_dynamic_range(l.line, where + " " + s.name);
          lines += l.line.valid;
        }
      }
    }
    for (const auto& b : c.bearings) {
      for (const auto* d : {&b.diagnosis.band_decision, &b.diagnosis.whole_decision}) {
        for (const auto& fam : d->families) {
          EXPECT_TRUE(std::isfinite(fam.score_db)) << c.name;
          EXPECT_LE(fam.score_db, detect::kDefaultDynamicRangeDb) << c.name;
          for (const auto& l : fam.lines) expect_within_dynamic_range(l, c.name + " " + b.bearing);
        }
      }
    }
  }
  EXPECT_GT(lines, 0);  // the checks above ran
}

// A chipped z3 (counter shaft) with 1 m/s^2 sensor noise (the demo's): the z3_z4 mesh's sidebands
// at the counter's rotation (-40..-12 dB of the mesh's strongest harmonic on the counter and
// output bearings) are found and name the counter shaft. KNOWN LIMIT, not asserted: mesh z1_z2's
// family points at the input shaft, because the input turns at exactly twice the counter's rate
// and the chip's even-order counter sidebands are the input's first-order ones (a rule that
// lines at a faster shaft's orders are no evidence for a slower shaft would need every shaft's
// speed in SidebandContext).
TEST(HealthyNoiseFree, AChippedCounterGearWithSensorNoiseStillDrawsTheSidebandVoteToTheCounter) {
  const diag::Gearbox gb = two_stage();
  const detect::AnalysisResult r = detect::analyze_recording(simulate(gb, 1.0, true), &gb);
  bool counter = false;
  for (const auto& f : r.findings) EXPECT_NE(f.kind, "gear_sidebands") << f.note;
  for (const auto& n : r.notes) {
    if (n.rfind("sidebands of mesh z3_z4 (", 0) != 0) continue;
    EXPECT_NE(n.find(") point at counter in "), std::string::npos) << n;
    counter |= n.find(") point at counter in ") != std::string::npos;
  }
  EXPECT_TRUE(counter);
}

}  // namespace
