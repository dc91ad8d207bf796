// `analyze` with a gearbox runs the damaged-shaft locator (detect/gear/gear_damage) and turns its
// answer into "gear_damage" findings: closed-loop checks with the dynamic simulator on the
// two-stage box (testdata/gearbox/three_shaft.json), with the tacho and, for an imported
// measurement without tacho or sensor directions, with the shaft angles from the nominal speed.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "detect/analysis/analyze_file.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "report/report.hpp"
#include "sim/dynamics/simulate.hpp"
#include "two_stage_case.hpp"

namespace {

constexpr double kRpm = 2000.0;

using two_stage_case::of_kind;

diag::Gearbox two_stage(double rpm = kRpm) { return two_stage_case::gearbox(rpm); }

// 11 output revolutions at constant speed, optionally a chipped tooth (0.8 module) on `gear`.
diag::Recording simulate(const diag::Gearbox& gb, const std::string& gear) {
  return two_stage_case::simulate(
      gb, sim::SpeedProfile::constant(kRpm), 11.0 / (kRpm / 60.0 / 4.0),
      gear.empty() ? std::nullopt : std::optional(two_stage_case::chip(gear)));
}

// What a measurement imported from CSV looks like: no tacho, no directions, no locations.
diag::Recording as_imported(diag::Recording rec) {
  rec.tachos.clear();
  std::vector<diag::Signal> kept;
  for (auto& s : rec.signals) {
    if (s.direction == diag::Direction::kAngle) continue;
    s.direction = diag::Direction::kUnspecified;
    s.location.clear();
    kept.push_back(std::move(s));
  }
  rec.signals = std::move(kept);
  return rec;
}

TEST(AnalyzeGearDamage, AChippedCounterGearIsAFindingOnTheCounterShaft) {
  const diag::Gearbox gb = two_stage();
  const detect::AnalysisResult r = detect::analyze_recording(simulate(gb, "z3"), &gb);
  ASSERT_TRUE(r.gear_damage.has_value());
  EXPECT_EQ(r.gear_damage_angles, "tacho");
  EXPECT_EQ(r.gear_damage->status, "damaged");
  const auto found = of_kind(r, "gear_damage");
  ASSERT_EQ(found.size(), 1u) << report::to_json(r)["gear_damage"].dump(1);
  EXPECT_EQ(found[0].shaft, "counter");
  EXPECT_EQ(found[0].gears, (std::vector<std::string>{"z2", "z3"}));
  EXPECT_GT(found[0].confidence, 0.0);
  // The JSON carries the locator's per-shaft table and the finding in the common shape.
  const nlohmann::json j = report::to_json(r);
  EXPECT_EQ(j["gear_damage"]["status"], "damaged");
  EXPECT_EQ(j["gear_damage"]["angles"], "tacho");
  EXPECT_EQ(j["gear_damage"]["shafts"].size(), 3u);
  bool in_json = false;
  for (const auto& f : j["findings"])
    in_json |= f["kind"] == "gear_damage" && f["shaft"] == "counter";
  EXPECT_TRUE(in_json);
  EXPECT_TRUE(detect::features(r).count("gear_damage/counter/score"));
}

TEST(AnalyzeGearDamage, AHealthyGearboxHasNoGearDamageFinding) {
  const diag::Gearbox gb = two_stage();
  const detect::AnalysisResult r = detect::analyze_recording(simulate(gb, ""), &gb);
  ASSERT_TRUE(r.gear_damage.has_value());
  EXPECT_EQ(r.gear_damage->status, "healthy") << report::to_json(r)["gear_damage"].dump(1);
  EXPECT_TRUE(of_kind(r, "gear_damage").empty());
}

// Without a tacho the shaft angles come from the vibration's mesh line (speed_estimate.hpp) or,
// when that is switched off, from the nominal speed; every channel without a direction is a
// casing sensor. The chip on the output gear is put on the output shaft either way.
TEST(AnalyzeGearDamage, WithoutTachoTheVibrationOrTheNominalSpeedServesASteadyRig) {
  const diag::Gearbox gb = two_stage();
  const diag::Recording rec = as_imported(simulate(gb, "z4"));
  for (const bool from_vibration : {true, false}) {
    detect::AnalyzeOptions opt;
    opt.speed_from_vibration = from_vibration;
    const detect::AnalysisResult r = detect::analyze_recording(rec, &gb, opt);
    ASSERT_TRUE(r.gear_damage.has_value());
    EXPECT_EQ(r.gear_damage_angles, from_vibration ? "vibration" : "nominal");
    EXPECT_EQ(r.speed.source, r.gear_damage_angles);
    const auto found = of_kind(r, "gear_damage");
    ASSERT_FALSE(found.empty()) << report::to_json(r)["gear_damage"].dump(1);
    EXPECT_EQ(found[0].shaft, "output");
    EXPECT_NE(found[0].note.find(from_vibration ? "mesh line" : "nominal speed"),
              std::string::npos);
  }
}

// A nominal speed off the true one moves a pulse of the last revolutions by more than half a
// period of the mesh lines (0.5 % over 44 revolutions: 0.1 revolution); the locator's pulse
// correction is for small errors and declines, the averages smear, and there is no finding at
// all, on a chipped output gear or a healthy box, rather than a wrong one. (Correcting each
// shaft on its own, an earlier version put this output gear's fault on the input shaft: the
// fast shaft was corrected, the slow ones stayed smeared.)
//
// With the speed from the vibration (the default) the same wrong nominal speed gives the same
// findings as the right one: the output gear's chip on the output shaft, nothing on the healthy
// box (a nominal speed 3 % off must give the same findings).
TEST(AnalyzeGearDamage, AWrongNominalSpeedGivesNoFindingRatherThanAWrongOne) {
  const diag::Gearbox gb = two_stage();
  const diag::Recording faulty = as_imported(simulate(gb, "z4"));
  const diag::Recording healthy = as_imported(simulate(gb, ""));
  detect::AnalyzeOptions nominal_only;
  nominal_only.speed_from_vibration = false;
  for (const double off : {1.005, 1.03}) {
    const diag::Gearbox nominal = two_stage(kRpm * off);
    for (const diag::Recording* rec : {&faulty, &healthy}) {
      const auto v = detect::analyze_recording(*rec, &nominal);
      EXPECT_EQ(v.speed.source, "vibration");
      const auto found = of_kind(v, "gear_damage");
      if (rec == &faulty) {
        ASSERT_EQ(found.size(), 1u) << "x " << off << report::to_json(v)["gear_damage"].dump(1);
        EXPECT_EQ(found[0].shaft, "output");
      } else {
        EXPECT_TRUE(found.empty()) << "x " << off << report::to_json(v)["gear_damage"].dump(1);
      }
      const auto r = detect::analyze_recording(*rec, &nominal, nominal_only);
      ASSERT_TRUE(r.gear_damage.has_value());
      EXPECT_TRUE(of_kind(r, "gear_damage").empty())
          << "speed x " << off << ": " << report::to_json(r)["gear_damage"].dump(1);
      // Smeared: the averages hold less than noise alone would leave (SNR 0.01-0.4 here).
      for (const auto& s : r.gear_damage->shafts) EXPECT_LT(s.snr, 1.0) << s.shaft << " x " << off;
    }
  }
}

// With a healthy baseline of the same gears (ISO 1328 grade 7 pitch errors, 10 um runout; the
// baseline recorded with other sensor noise), analyze's locator subtracts the baseline's averages
// and fuses that answer with the recording's own (gear_damage.hpp step 7): the chipped counter
// gear is put on the counter shaft, every scored shaft carries both scores, and the healthy
// recording against the baseline gives no finding.
TEST(AnalyzeGearDamage, AHealthyBaselineOfTheSameGearsIsComparedAndFused) {
  const diag::Gearbox gb = two_stage();
  const two_stage_case::Errors errors{7, 10e-6};
  const double duration = 11.0 / (kRpm / 60.0 / 4.0);
  const auto speed = sim::SpeedProfile::constant(kRpm);
  // The same gears (seed 3: pitch errors, runout phases) in every record, each with its own noise.
  auto record = [&](const std::optional<sim::GearFault>& fault, std::uint64_t noise_seed) {
    return two_stage_case::simulate(gb, speed, duration, fault, errors, 3, noise_seed);
  };
  detect::AnalyzeOptions opt;
  opt.gear_damage.baseline = std::make_shared<const detect::GearDamageBaseline>(
      detect::gear_damage_baseline(record(std::nullopt, 17), gb, opt.gear_damage));

  const detect::AnalysisResult faulty =
      detect::analyze_recording(record(two_stage_case::chip("z3"), 5), &gb, opt);
  ASSERT_TRUE(faulty.gear_damage.has_value());
  const auto found = of_kind(faulty, "gear_damage");
  ASSERT_FALSE(found.empty()) << report::to_json(faulty)["gear_damage"].dump(1);
  EXPECT_EQ(found[0].shaft, "counter") << report::to_json(faulty)["gear_damage"].dump(1);
  for (const auto& s : faulty.gear_damage->shafts) {
    EXPECT_TRUE(s.compared) << s.shaft;
    EXPECT_TRUE(std::isfinite(s.score_alone)) << s.shaft;
  }

  const detect::AnalysisResult healthy =
      detect::analyze_recording(record(std::nullopt, 5), &gb, opt);
  ASSERT_TRUE(healthy.gear_damage.has_value());
  EXPECT_EQ(healthy.gear_damage->status, "healthy")
      << report::to_json(healthy)["gear_damage"].dump(1);
  EXPECT_TRUE(of_kind(healthy, "gear_damage").empty());
}

// Several healthy baselines (GearDamageOptions::more_baselines, a history's reference): each
// shaft is kept against the one that leaves the least in the difference. Two baselines of the
// same gears, one at the recording's torque (50 N m, other sensor noise) and one at 65 N m: the
// gears' response to their pitch errors moves with the load, so the second leaves more energy in
// every shaft's difference (checked: the premise). Given both, in either order, every shaft's
// comparison is exactly the one against the nearer baseline alone; a chipped counter gear is
// still put on the counter shaft; more baselines without a first are refused, naming the field.
TEST(AnalyzeGearDamage, OfSeveralBaselinesTheNearestExplainsTheRecording) {
  const diag::Gearbox gb = two_stage();
  const two_stage_case::Errors errors{7, 10e-6};
  const double duration = 11.0 / (kRpm / 60.0 / 4.0);
  const auto speed = sim::SpeedProfile::constant(kRpm);
  auto record = [&](const std::optional<sim::GearFault>& fault, std::uint64_t noise_seed,
                    double torque_nm) {
    return two_stage_case::simulate(gb, speed, duration, fault, errors, 3, noise_seed, torque_nm);
  };
  const detect::GearDamageOptions base;
  const auto near = std::make_shared<const detect::GearDamageBaseline>(
      detect::gear_damage_baseline(record(std::nullopt, 17, 50.0), gb, base));
  const auto far = std::make_shared<const detect::GearDamageBaseline>(
      detect::gear_damage_baseline(record(std::nullopt, 19, 65.0), gb, base));
  const diag::Recording healthy = record(std::nullopt, 5, 50.0);
  auto locate = [&](const diag::Recording& rec, std::shared_ptr<const detect::GearDamageBaseline> b,
                    std::vector<std::shared_ptr<const detect::GearDamageBaseline>> more) {
    detect::AnalyzeOptions opt;
    opt.gear_damage.baseline = std::move(b);
    opt.gear_damage.more_baselines = std::move(more);
    const detect::AnalysisResult r = detect::analyze_recording(rec, &gb, opt);
    EXPECT_TRUE(r.gear_damage.has_value());
    return r;
  };
  const detect::AnalysisResult against_near = locate(healthy, near, {});
  const detect::AnalysisResult against_far = locate(healthy, far, {});
  ASSERT_EQ(against_near.gear_damage->shafts.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_GT(against_far.gear_damage->shafts[i].level, against_near.gear_damage->shafts[i].level)
        << against_near.gear_damage->shafts[i].shaft;
  }
  for (const auto& [first, more] : {std::pair{far, near}, std::pair{near, far}}) {
    const detect::AnalysisResult both = locate(healthy, first, {more});
    for (std::size_t i = 0; i < 3; ++i) {
      const detect::ShaftDamage& a = both.gear_damage->shafts[i];
      const detect::ShaftDamage& n = against_near.gear_damage->shafts[i];
      EXPECT_EQ(a.score, n.score) << a.shaft;
      EXPECT_EQ(a.level, n.level) << a.shaft;
      EXPECT_EQ(a.channel, n.channel) << a.shaft;
    }
    EXPECT_TRUE(of_kind(both, "gear_damage").empty())
        << report::to_json(both)["gear_damage"].dump(1);
  }
  const detect::AnalysisResult chipped =
      locate(record(two_stage_case::chip("z3"), 5, 50.0), far, {near});
  const auto found = of_kind(chipped, "gear_damage");
  ASSERT_FALSE(found.empty()) << report::to_json(chipped)["gear_damage"].dump(1);
  EXPECT_EQ(found[0].shaft, "counter");
  detect::AnalyzeOptions bad;
  bad.gear_damage.more_baselines = {near};
  try {
    detect::analyze_recording(healthy, &gb, bad);
    ADD_FAILURE() << "more baselines without a baseline were accepted";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more_baselines"), std::string::npos) << e.what();
  }
}

// A caller comparing many recordings with the same healthy ones (a history's reference) takes
// their revolution averages once (gear_damage_baseline_of) and gives them to every analysis as
// the locator's options: the analysis is the same, byte for byte, as when each request takes its
// own from gear_baseline and more_gear_baselines, with the tacho and without it (the averages
// then on the angles found in each baseline's vibration). A baseline that cannot be averaged is
// refused with the same message either way.
TEST(AnalyzeGearDamage, GearBaselinesTakenOnceGiveWhatEachAnalysisTakes) {
  const diag::Gearbox gb = two_stage();
  const two_stage_case::Errors errors{7, 10e-6};
  const double duration = 11.0 / (kRpm / 60.0 / 4.0);
  auto record = [&](const std::optional<sim::GearFault>& fault, std::uint64_t noise_seed,
                    double torque_nm, bool tacho) {
    diag::Recording r = two_stage_case::simulate(gb, sim::SpeedProfile::constant(kRpm), duration,
                                                 fault, errors, 3, noise_seed, torque_nm);
    if (!tacho) r.tachos.clear();
    return std::make_shared<const diag::Recording>(std::move(r));
  };
  for (const bool tacho : {true, false}) {
    SCOPED_TRACE(tacho ? "with the tacho" : "without a tacho");
    detect::AnalyzeRequest each;
    each.recording =
        detect::RecordingInput(record(two_stage_case::chip("z3"), 5, 50.0, tacho), "r");
    each.gearbox = gb;
    each.gear_baseline = detect::RecordingInput(record(std::nullopt, 17, 50.0, tacho), "h1");
    each.more_gear_baselines = {
        detect::RecordingInput(record(std::nullopt, 19, 65.0, tacho), "h2")};
    detect::AnalyzeRequest shared = each;
    shared.options.gear_damage.baseline =
        detect::gear_damage_baseline_of(each, *each.gear_baseline, gb);
    shared.options.gear_damage.more_baselines = {
        detect::gear_damage_baseline_of(each, each.more_gear_baselines[0], gb)};
    shared.gear_baseline.reset();
    shared.more_gear_baselines.clear();
    const detect::FileAnalysis a = detect::analyze_file(each);
    const detect::FileAnalysis b = detect::analyze_file(shared);
    ASSERT_TRUE(a.result.gear_damage.has_value());
    EXPECT_TRUE(a.result.gear_damage->shafts[0].compared);
    EXPECT_EQ(report::to_json(a.result).dump(), report::to_json(b.result).dump());
    const auto found = of_kind(a.result, "gear_damage");
    ASSERT_FALSE(found.empty()) << report::to_json(a.result)["gear_damage"].dump(1);
    EXPECT_EQ(found[0].shaft, "counter");
  }
  // Too short to average a revolution of the output shaft.
  diag::Recording cut = *record(std::nullopt, 17, 50.0, true);
  for (diag::Signal& s : cut.signals) s.samples.resize(200);
  for (diag::Signal& s : cut.tachos) s.samples.resize(200);
  detect::AnalyzeRequest q;
  q.recording = detect::RecordingInput(record(std::nullopt, 5, 50.0, true), "r");
  q.gearbox = gb;
  q.gear_baseline =
      detect::RecordingInput(std::make_shared<const diag::Recording>(std::move(cut)), "short");
  std::string alone, taken;
  try {
    detect::analyze_file(q);
  } catch (const diag::InputError& e) {
    alone = e.what();
  }
  try {
    detect::gear_damage_baseline_of(q, *q.gear_baseline, gb);
  } catch (const diag::InputError& e) {
    taken = e.what();
  }
  EXPECT_TRUE(alone.starts_with("--gear-baseline short: ")) << alone;
  EXPECT_EQ(alone, taken);
}

}  // namespace
