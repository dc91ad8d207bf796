// A rolling-bearing defect in a dynamic run (RunOptions::bearing_faults, the scenario's faults[]
// type bearing): its impacts are the synthetic bearing model's fault component, added to the
// accelerometers at the bearing and nowhere else; the truth lists it; bad ones are refused before
// the run, naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "diag/error.hpp"
#include "diag/gearbox/bearing_rates.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/truth.hpp"
#include "sim/bearing/bearing_signal.hpp"
#include "sim/dynamics/scenario.hpp"
#include "sim/dynamics/simulate.hpp"

namespace {

diag::Gearbox bearing_box() {
  return diag::load_gearbox(std::string(GEARDIAG_TESTDATA_DIR) +
                            "/gearbox/two_stage_23_41_19_53_bearings.json");
}

sim::RunOptions run_of(double duration_s = 0.2) {
  sim::RunOptions r;
  r.duration_s = duration_s;
  r.fs_hz = 10000;
  r.settle_s = 0.05;
  r.seed = 7;
  return r;
}

sim::BearingFault outer_race(double amplitude) {
  sim::BearingFault f;
  f.bearing = "counter_bearing1";
  f.kind = sim::BearingFaultKind::kOuterRace;
  f.amplitude_m_per_s2 = amplitude;
  f.resonance_hz = 2800;
  return f;
}

std::string refusal(const diag::Gearbox& gb, const sim::DynamicsOptions& o,
                    const sim::RunOptions& r) {
  try {
    sim::simulate_dynamic(gb, o, r);
  } catch (const diag::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// The model is additive: a run with the defect minus the same run without it is, on every
// accelerometer at counter_bearing1, exactly the bearing model's fault component (to round-off of
// the addition), and zero on every other channel. The impacts come at the counter shaft's BPFO:
// (1 - slip) BPFO x duration of them, within one for where the first falls and the interval
// jitter (1 % RMS, a random walk: sqrt(N) 1 % of a period over N impacts, far under one).
TEST(BearingFaultDynamics, TheImpactsAreAddedAtTheBearingOnlyAndTheTruthListsThem) {
  const diag::Gearbox gb = bearing_box();
  sim::DynamicsOptions o;
  o.speed = sim::SpeedProfile::constant(1800);
  const sim::RunOptions healthy = run_of();
  sim::RunOptions faulty = healthy;
  faulty.bearing_faults.push_back(outer_race(40));
  const sim::DynamicResult a = sim::simulate_dynamic(gb, o, healthy);
  const sim::DynamicResult b = sim::simulate_dynamic(gb, o, faulty);
  ASSERT_EQ(a.channels.size(), b.channels.size());

  const double counter_hz = 1800.0 / 60 * 23.0 / 41.0;
  const diag::BearingSpec& spec = gb.bearings()[1];
  ASSERT_EQ(spec.name, "counter_bearing1");
  sim::BearingSignalOptions so;
  so.fs_hz = 10000;
  so.duration_s = static_cast<double>(a.channels[0].samples.size()) / so.fs_hz;
  so.shaft_hz = counter_hz;
  so.fault = sim::BearingFaultKind::kOuterRace;
  so.impact_amplitude = 40;
  so.resonance_hz = 2800;
  so.seed = (healthy.seed ^ 0x9E3779B97F4A7C15ULL) % 1000000007ULL;
  int impacts = 0;
  const std::vector<double> x = sim::bearing_fault_samples(spec, so, impacts);
  int at_bearing = 0;
  for (std::size_t c = 0; c < a.channels.size(); ++c) {
    const auto& ya = a.channels[c].samples;
    const auto& yb = b.channels[c].samples;
    ASSERT_EQ(ya.size(), yb.size());
    const bool at = a.channels[c].location == "counter_bearing1";
    at_bearing += at;
    double worst = 0;
    for (std::size_t j = 0; j < ya.size(); ++j) {
      const double expected = at ? x[j] : 0.0;
      worst = std::max(worst, std::abs((yb[j] - ya[j]) - expected));
    }
    // Round-off of adding x to samples of up to ~1e3 m/s^2: 1e-12 relative.
    EXPECT_LT(worst, 1e-9) << a.channels[c].name;
  }
  EXPECT_EQ(at_bearing, 6);  // along / normal to both meshes' LOA, horizontal, vertical

  const diag::BearingRates rates = diag::bearing_rates(spec, counter_hz);
  const double expected_impacts = 0.99 * rates.bpfo_hz * so.duration_s;
  EXPECT_NEAR(impacts, expected_impacts, 1.0);

  const diag::SimulationTruth truth = diag::SimulationTruth::from_json(b.truth, "truth");
  ASSERT_EQ(truth.defects.size(), 1u);
  EXPECT_EQ(truth.defects[0].kind, diag::FaultKind::kOuterRace);
  EXPECT_EQ(truth.defects[0].bearing, "counter_bearing1");
  EXPECT_EQ(truth.defects[0].shaft, "counter");
  EXPECT_NEAR(truth.defects[0].shaft_frequency_hz, counter_hz, 1e-9);
  const nlohmann::json& bf = b.truth.at("bearing_faults").at(0);
  EXPECT_EQ(bf.at("impacts").get<int>(), impacts);
  EXPECT_EQ(bf.at("amplitude_m_per_s2").get<double>(), 40.0);
  EXPECT_FALSE(a.truth.contains("bearing_faults"));

  // The same options, the same bytes.
  const sim::DynamicResult again = sim::simulate_dynamic(gb, o, faulty);
  for (std::size_t c = 0; c < b.channels.size(); ++c) {
    ASSERT_EQ(b.channels[c].samples, again.channels[c].samples) << b.channels[c].name;
  }
}

// A scenario's faults[] entry of type bearing is parsed into the run's options; its every field
// is checked, and the run refuses what it cannot place before it integrates anything.
TEST(BearingFaultDynamics, BadBearingFaultsAreRefusedNamingTheField) {
  const auto parse = [](const std::string& text) {
    return sim::parse_scenario(nlohmann::json::parse(text), "s.json");
  };
  const sim::Scenario sc = parse(
      R"({"faults": [{"type": "bearing", "bearing": "input_bearing1", "fault": "inner_race",
                      "amplitude_m_per_s2": 25, "resonance_hz": 3100, "jitter": 0.02}]})");
  ASSERT_EQ(sc.run.bearing_faults.size(), 1u);
  EXPECT_EQ(sc.run.bearing_faults[0].kind, sim::BearingFaultKind::kInnerRace);
  EXPECT_EQ(sc.run.bearing_faults[0].amplitude_m_per_s2, 25.0);
  EXPECT_EQ(sc.run.bearing_faults[0].resonance_hz, 3100.0);
  EXPECT_EQ(sc.run.bearing_faults[0].jitter, 0.02);
  // The fault vocabulary's aliases are read as their kind; "none" is no bearing fault.
  EXPECT_EQ(parse(R"({"faults": [{"type": "bearing", "bearing": "b", "fault": "ball",
                                  "amplitude_m_per_s2": 1}]})")
                .run.bearing_faults[0]
                .kind,
            sim::BearingFaultKind::kRollingElement);

  const auto refused = [&](const std::string& text) {
    try {
      parse(text);
    } catch (const diag::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refused(R"({"faults": [{"type": "bearing", "bearing": "b", "fault": "spall",
                                    "amplitude_m_per_s2": 1}]})")
                .find("faults[0].fault"),
            std::string::npos);
  EXPECT_NE(refused(R"({"faults": [{"type": "bearing", "bearing": "b", "fault": "none",
                                    "amplitude_m_per_s2": 1}]})")
                .find("faults[0].fault"),
            std::string::npos);
  EXPECT_NE(refused(R"({"faults": [{"type": "bearing", "bearing": "b", "fault": "cage"}]})")
                .find("amplitude_m_per_s2"),
            std::string::npos);
  EXPECT_NE(refused(R"({"faults": [{"type": "bearing", "bearing": "b", "fault": "cage",
                                    "amplitude_m_per_s2": 1, "tooth": 3}]})")
                .find("tooth"),
            std::string::npos);
  EXPECT_NE(refused(R"({"faults": [{"type": "bearing", "bearing": "b", "fault": "cage",
                                    "amplitude_m_per_s2": 1, "damping_ratio": 0.9}]})")
                .find("damping_ratio"),
            std::string::npos);

  const diag::Gearbox gb = bearing_box();
  sim::DynamicsOptions o;
  o.speed = sim::SpeedProfile::constant(1800);
  sim::RunOptions r = run_of(0.1);
  r.bearing_faults.push_back(outer_race(10));
  r.bearing_faults[0].bearing = "no_such_bearing";
  EXPECT_NE(refusal(gb, o, r).find("is not a bearing of the gearbox description"),
            std::string::npos);
  // From a scenario, the error names its file and entry.
  sim::Scenario from_file = parse(
      R"({"duration_s": 0.1, "fs_hz": 10000, "faults": [{"type": "crack", "gear": "p1",
          "tooth": 1, "depth_mm": 0.5}, {"type": "bearing", "bearing": "nowhere",
          "fault": "outer_race", "amplitude_m_per_s2": 5}]})");
  from_file.dynamics.speed = o.speed;
  EXPECT_NE(refusal(gb, from_file.dynamics, from_file.run)
                .find("s.json: faults[1]: bearing: 'nowhere' is not a bearing"),
            std::string::npos);
  // A bearing the description lists at a place where the simulator has no accelerometer.
  nlohmann::json j = nlohmann::json::parse(gb.description_json());
  j["bearings"][1]["name"] = "drive_end";
  const diag::Gearbox renamed = diag::parse_gearbox(j, "gb.json");
  r.bearing_faults[0].bearing = "drive_end";
  EXPECT_NE(refusal(renamed, o, r).find("no accelerometer at 'drive_end'"), std::string::npos);
  r.bearing_faults[0].bearing = "counter_bearing1";
  r.bearing_faults[0].resonance_hz = 4600;  // 0.45 fs = 4500 Hz
  EXPECT_NE(refusal(gb, o, r).find("bearing_faults[0]"), std::string::npos);
  r.bearing_faults[0].resonance_hz = 3000;
  sim::DynamicsOptions ramp = o;
  ramp.speed = sim::SpeedProfile::ramp(1000, 2000, 0, 0.1);
  EXPECT_NE(refusal(gb, ramp, r).find("needs a constant speed"), std::string::npos);
}
