// `analyze` on a run-up in the order domain (docs/cli/analyze.md, "Varying speed"): the two-stage
// box (testdata/gearbox/three_shaft.json, two_stage_case.hpp) accelerated linearly from 500 to 3000
// rpm at the input in 9 s, with and without its tacho. At varying speed the spectra, sidebands and
// envelope spectra are order spectra (the channel resampled at uniform input-shaft angles, read at
// the mean speed); without a tacho the speed comes from the vibration (the estimator's run-up mode,
// followed from mid-record where the ramp passes the description's nominal 1750 rpm). A chipped
// counter-shaft gear must be put on the counter shaft either way; a healthy run-up, with or without
// ISO grade-6 pitch errors and runout, must give no gear finding.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>

#include "detect/analysis/analyze.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "report/report.hpp"
#include "sim/dynamics/simulate.hpp"
#include "two_stage_case.hpp"

namespace {

constexpr double kFromRpm = 500.0;
constexpr double kToRpm = 3000.0;
constexpr double kDurationS = 9.0;  // the output shaft turns 32.8 times (run_up_test.cpp)

diag::Gearbox two_stage() { return two_stage_case::gearbox(0.5 * (kFromRpm + kToRpm)); }

struct Case {
  std::string fault_gear;  // empty: healthy
  two_stage_case::Errors errors;
  bool tacho = true;
};

// One analysis per case, kept for the tests that read it (a 9 s dynamic simulation is the cost).
const detect::AnalysisResult& analysed(const Case& c) {
  static std::map<std::string, detect::AnalysisResult> cache;
  const std::string key = c.fault_gear + "/" + std::to_string(c.errors.accuracy_grade) + "/" +
                          std::to_string(c.errors.runout_m) + "/" + (c.tacho ? "t" : "v");
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  const diag::Gearbox gb = two_stage();
  std::optional<sim::GearFault> fault;
  if (!c.fault_gear.empty()) fault = two_stage_case::chip(c.fault_gear);
  diag::Recording rec = two_stage_case::simulate(
      gb, sim::SpeedProfile::ramp(kFromRpm, kToRpm, 0.0, kDurationS), kDurationS, fault, c.errors);
  if (!c.tacho) rec.tachos.clear();
  detect::AnalysisResult r = detect::analyze_recording(rec, &gb);
  std::cout << key << ": speed from " << r.speed.source << " " << r.speed.min_rpm << " - "
            << r.speed.max_rpm << " rpm, domain " << r.speed.spectra_domain << "\n";
  if (r.gear_damage) {
    for (const auto& s : r.gear_damage->shafts) {
      std::cout << "  " << s.shaft << ": score " << s.score << " snr " << s.snr << " level "
                << s.level << (s.damaged ? " DAMAGED" : "") << "\n";
    }
  }
  for (const auto& f : r.findings) std::cout << "  finding " << f.kind << " " << f.shaft << "\n";
  for (const auto& n : r.notes) std::cout << "  note: " << n << "\n";
  return cache.emplace(key, std::move(r)).first->second;
}

using two_stage_case::of_kind;

// The speed trace follows the ramp. Tolerance: the first and last points are means over 1/200 of
// the record (45 ms, 12.5 rpm of ramp) and the tacho's per-revolution speeds are interval means,
// so the ends read within 60 rpm of the ramp's ends.
void expect_ramp_followed(const detect::AnalysisResult& r, const std::string& source) {
  EXPECT_EQ(r.speed.source, source);
  EXPECT_FALSE(r.speed.stationary);
  EXPECT_EQ(r.speed.spectra_domain, "order");
  const nlohmann::json j = report::to_json(r)["speed"];
  ASSERT_TRUE(j.contains("time_s") && j.contains("rpm")) << j.dump();
  const auto& rpm = j["rpm"];
  ASSERT_GE(rpm.size(), 20u);
  EXPECT_LE(rpm.size(), 200u);  // bounded, whatever the record's length
  const double t0 = j["time_s"].front(), t1 = j["time_s"].back();
  auto ramp = [](double t) { return kFromRpm + (kToRpm - kFromRpm) * t / kDurationS; };
  EXPECT_NEAR(rpm.front().get<double>(), ramp(t0), 60.0);
  EXPECT_NEAR(rpm.back().get<double>(), ramp(t1), 60.0);
  // Rising throughout: each point at least the previous one less 1 % (neighbouring points of the
  // tacho's per-revolution speeds can be equal or swap by the pulse times' jitter: one sample in
  // the 200 of a revolution at 3000 rpm is 0.5 %).
  for (std::size_t k = 1; k < rpm.size(); ++k) {
    EXPECT_GE(rpm[k].get<double>(), 0.99 * rpm[k - 1].get<double>()) << "point " << k;
  }
  std::cout << "  trace " << t0 << " s " << rpm.front() << " rpm .. " << t1 << " s " << rpm.back()
            << " rpm, " << rpm.size() << " points\n";
}

// In the order domain a mesh line stays a line through the run-up: each accelerometer's largest
// spectral line sits on a mesh harmonic (input orders h x 18 of z1_z2 or h x 9 of z3_z4) at the
// mean speed. Tolerance 0.02 orders: the order spectrum of 262 revolutions has a line spacing of
// 0.004 orders and the peak is the largest bin. In the time domain a 6:1 run-up smears each line
// over 6x its frequency, and the largest bin lands anywhere in that band.
void expect_lines_on_mesh_orders(const detect::AnalysisResult& r) {
  const double input_hz = r.shafts.front().speed_hz;
  int checked = 0;
  for (const auto& c : r.channels) {
    if (!c.sensor || c.spectrum_peaks.empty()) continue;
    const double order = c.spectrum_peaks.front().frequency_hz / input_hz;
    const double nearest = 9.0 * std::round(order / 9.0);
    EXPECT_GT(nearest, 0.0) << c.name;
    EXPECT_NEAR(order, nearest, 0.02) << c.name;
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

TEST(AnalyzeRunUp, AChippedCounterGearWithTheTachoIsOnTheCounterShaft) {
  const auto& r = analysed({"z3", {}, true});
  expect_ramp_followed(r, "tacho");
  expect_lines_on_mesh_orders(r);
  const auto found = of_kind(r, "gear_damage");
  ASSERT_EQ(found.size(), 1u) << report::to_json(r)["gear_damage"].dump(1);
  EXPECT_EQ(found[0].shaft, "counter");
}

TEST(AnalyzeRunUp, AChippedCounterGearWithoutTheTachoIsOnTheCounterShaft) {
  const auto& r = analysed({"z3", {}, false});
  expect_ramp_followed(r, "vibration");
  expect_lines_on_mesh_orders(r);
  const auto found = of_kind(r, "gear_damage");
  ASSERT_EQ(found.size(), 1u) << report::to_json(r)["gear_damage"].dump(1);
  EXPECT_EQ(found[0].shaft, "counter");
}

// The sideband votes that passed their quorum (notes "sidebands of mesh M (...) point at S in K
// of N channels ...": never findings, findings.cpp), as (mesh, shaft pointed at).
std::set<std::pair<std::string, std::string>> sideband_votes(const detect::AnalysisResult& r) {
  std::set<std::pair<std::string, std::string>> out;
  const std::string head = "sidebands of mesh ", at = ") point at ";
  for (const auto& n : r.notes) {
    const auto p = n.find(at);
    if (n.rfind(head, 0) != 0 || p == std::string::npos) continue;
    const std::string mesh = n.substr(head.size(), n.find(' ', head.size()) - head.size());
    const auto s0 = p + at.size();
    out.insert({mesh, n.substr(s0, n.find(' ', s0) - s0)});
  }
  for (const auto& f : r.findings) EXPECT_NE(f.kind, "gear_sidebands") << f.note;
  return out;
}

// No gear finding on a healthy run-up (ideal gears: no sideband vote passes either).
void expect_no_gear_finding(const detect::AnalysisResult& r) {
  EXPECT_TRUE(of_kind(r, "gear_damage").empty()) << report::to_json(r)["gear_damage"].dump(1);
  EXPECT_TRUE(sideband_votes(r).empty()) << report::to_json(r)["notes"].dump(1);
}

TEST(AnalyzeRunUp, AHealthyRunUpWithTheTachoHasNoGearFinding) {
  const auto& r = analysed({"", {}, true});
  expect_ramp_followed(r, "tacho");
  expect_no_gear_finding(r);
}

TEST(AnalyzeRunUp, AHealthyRunUpWithoutTheTachoHasNoGearFinding) {
  const auto& r = analysed({"", {}, false});
  expect_ramp_followed(r, "vibration");
  expect_no_gear_finding(r);
}

// ISO 1328 grade 6 pitch errors on every gear (10 um of runout too where said). Their cumulative
// pitch error modulates each mesh once per revolution of its gears: real shaft-rate sidebands,
// which the steady analysis reports too (at 1750 rpm, seed 3: mesh z1_z2 pointed at the input in
// 26 of 28 channels, z3_z4 at the counter in 17 of 28). The damaged-shaft locator flags a healthy
// grade-6 box no more (its tooth score, gear_damage.hpp: the kurtosis score it replaced flagged
// the input at steady speed, 5.2, and the counter in the run-up, 5.5): the sideband vote is
// modulation, reported as a note (never a finding), a gear_damage finding would be a claim of
// damage. What the order domain must do: read the run-up as the steady record reads (the same
// sideband votes), and the speed from
// the vibration must follow the ramp through the errors.
constexpr two_stage_case::Errors kGrade6{6, 0.0};
constexpr two_stage_case::Errors kGrade6Runout{6, 10e-6};

TEST(AnalyzeRunUp, AGrade6RunUpReadsTheSidebandsOfTheSteadyRecord) {
  const auto& run_up = analysed({"", kGrade6, true});
  const diag::Gearbox gb = two_stage();
  const detect::AnalysisResult steady = detect::analyze_recording(
      two_stage_case::simulate(gb, sim::SpeedProfile{}, kDurationS, std::nullopt, kGrade6), &gb);
  EXPECT_TRUE(steady.speed.stationary);
  const auto expected = sideband_votes(steady);
  EXPECT_FALSE(expected.empty());  // the pitch errors' modulation is there to be read
  EXPECT_EQ(sideband_votes(run_up), expected) << report::to_json(run_up)["notes"].dump(1);
  // Healthy gears with ordinary manufacturing errors: no damage claimed, steady or run-up.
  EXPECT_TRUE(of_kind(steady, "gear_damage").empty()) << report::to_json(steady)["gear_damage"];
  EXPECT_TRUE(of_kind(run_up, "gear_damage").empty()) << report::to_json(run_up)["gear_damage"];
}

TEST(AnalyzeRunUp, TheSpeedFromTheVibrationFollowsAGrade6RunUpWithRunout) {
  const auto& r = analysed({"", kGrade6Runout, false});
  expect_ramp_followed(r, "vibration");
  expect_lines_on_mesh_orders(r);
  EXPECT_TRUE(of_kind(r, "gear_damage").empty()) << report::to_json(r)["gear_damage"];
}

}  // namespace
