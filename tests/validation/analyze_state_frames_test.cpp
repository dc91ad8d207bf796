// Frames that follow the operating state: a long log's frame is cut where the tacho shows a
// splice (two recordings joined) or a speed step, and each part analysed as a segment of its own.
// The two-stage box (two_stage_case.hpp), a tacho on the input shaft:
//  - a healthy recording and a recording of the same gears with a chip on the counter shaft's z3,
//    joined: the join falls inside a frame, which is cut there; the chip is found from the join
//    on and not before, at the nominal speed and with the nominal speed 5 % off; without the
//    tacho the frames stay whole (no splice is seen) and the chip is found after the join;
//  - a speed step (1500 -> 1800 rpm in 0.2 s) inside a frame: cut at the step, each side at its
//    own speed; without the tacho (1500 -> 1620 rpm) from the speed the vibration shows, and a
//    step beyond the band searched (1500 -> 1850 rpm) by halving the frame.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>

#include "detect/analysis/analyze_file.hpp"
#include "diag/error.hpp"
#include "report/report.hpp"
#include "two_stage_case.hpp"

namespace {

constexpr double kRpm = 1750.0;
constexpr double kPartS = 4.5;  // each recording of the joined log

// Each channel of `b` after the same channel of `a`.
std::shared_ptr<const diag::Recording> joined(diag::Recording a, const diag::Recording& b) {
  for (auto [to, from] : {std::pair{&a.signals, &b.signals}, std::pair{&a.tachos, &b.tachos}}) {
    EXPECT_EQ(to->size(), from->size());
    for (std::size_t i = 0; i < to->size(); ++i) {
      auto& s = (*to)[i].samples;
      s.insert(s.end(), (*from)[i].samples.begin(), (*from)[i].samples.end());
    }
  }
  return std::make_shared<const diag::Recording>(std::move(a));
}

detect::AnalysisResult analysed(const std::shared_ptr<const diag::Recording>& rec, double rpm,
                                double frame_s) {
  detect::AnalyzeRequest q;
  q.recording = detect::RecordingInput(rec, "joined");
  q.gearbox = two_stage_case::gearbox(rpm);
  q.frame_s = frame_s;
  q.options.traces = false;
  return detect::analyze_file(q).result;
}

// The healthy gears, then the same gears (the same manufacturing seed, another noise seed) with
// the chip: 9 s in frames of 3 s, the join at 4.5 s in the middle of the second frame.
TEST(AnalyzeStateFrames, AChipFromAJoinIsFoundFromTheJoinOn) {
  const diag::Gearbox gb = two_stage_case::gearbox(kRpm);
  const auto speed = sim::SpeedProfile::constant(kRpm);
  const auto rec =
      joined(two_stage_case::simulate(gb, speed, kPartS, std::nullopt),
             two_stage_case::simulate(gb, speed, kPartS, two_stage_case::chip("z3"), {}, 3, 4));
  for (const double off : {1.0, 1.05}) {
    const detect::AnalysisResult r = analysed(rec, off * kRpm, 3.0);
    ASSERT_TRUE(r.coverage);
    EXPECT_TRUE(r.coverage->complete()) << off;
    // 3 frames, the second cut at the join: 4 segments, the third starting there (to within a
    // revolution, 34 ms).
    ASSERT_EQ(r.segments.size(), 4u) << off << ": " << report::to_json(r)["segments"].dump(1);
    const detect::AnalysisSegment& from_join = r.segments[2];
    EXPECT_NEAR(from_join.start_s, kPartS, 60 / kRpm) << off;
    EXPECT_NE(from_join.cut.find("splice"), std::string::npos) << from_join.cut;
    EXPECT_TRUE(r.segments[1].cut.empty());
    const auto found = two_stage_case::of_kind(r, "gear_damage");
    ASSERT_EQ(found.size(), 1u) << off << ": " << report::to_json(r)["findings"].dump(1);
    EXPECT_EQ(found[0].shaft, "counter") << off;
    // Placed from the join (or the next frame) to the end; nothing before the join.
    EXPECT_GE(found[0].first_s, from_join.start_s) << off;
    EXPECT_LE(found[0].first_s, 2 * 3.0) << off;
    EXPECT_DOUBLE_EQ(found[0].last_s, r.segments.back().end_s) << off;
    for (std::size_t k = 0; k < 2; ++k) {
      EXPECT_EQ(r.segments[k].verdict, "no finding") << off << " segment " << k;
    }
  }
}

// The same log without its tacho: no splice is seen (the frames stay as they are), the speed and
// angles come from the vibration; the chip is found in the frames after the join's, and not in
// the first (healthy) frame.
TEST(AnalyzeStateFrames, WithoutTachoAChipFromAJoinIsFoundAfterIt) {
  const diag::Gearbox gb = two_stage_case::gearbox(kRpm);
  const auto speed = sim::SpeedProfile::constant(kRpm);
  diag::Recording healthy = two_stage_case::simulate(gb, speed, kPartS, std::nullopt);
  diag::Recording chipped =
      two_stage_case::simulate(gb, speed, kPartS, two_stage_case::chip("z3"), {}, 3, 4);
  healthy.tachos.clear();
  chipped.tachos.clear();
  const auto rec = joined(std::move(healthy), chipped);
  for (const double off : {1.0, 1.05}) {
    const detect::AnalysisResult r = analysed(rec, off * kRpm, 3.0);
    ASSERT_EQ(r.segments.size(), 3u) << off;
    EXPECT_EQ(r.segments[2].speed_source, "vibration") << off;
    const auto found = two_stage_case::of_kind(r, "gear_damage");
    ASSERT_EQ(found.size(), 1u) << off << ": " << report::to_json(r)["findings"].dump(1);
    EXPECT_EQ(found[0].shaft, "counter") << off;
    EXPECT_GE(found[0].first_s, 3.0) << off;
    EXPECT_EQ(r.segments[0].verdict, "no finding") << off;
    EXPECT_EQ(r.segments[2].verdict, "finding") << off;
  }
}

// A log of two 3 s frames whose speed steps from 1500 rpm to `to_rpm` in the ramp at 1.5-1.7 s:
// three segments, the second starting at the ramp to within `within_s`, each at its own speed
// (1 %: the steadiness rule; the ramp's end may fall in a part; the last, steady throughout, to
// `steady_tol`), no gear finding.
void expect_step_cut(const detect::AnalysisResult& r, double to_rpm, double within_s,
                     const std::string& source, double steady_tol) {
  ASSERT_EQ(r.segments.size(), 3u) << report::to_json(r)["segments"].dump(1);
  const detect::AnalysisSegment& after = r.segments[1];
  EXPECT_GE(after.start_s, 1.5 - within_s);
  EXPECT_LE(after.start_s, 1.7 + within_s);
  EXPECT_NE(after.cut.find("speed step"), std::string::npos) << after.cut;
  for (const detect::AnalysisSegment& seg : r.segments) EXPECT_EQ(seg.speed_source, source);
  EXPECT_NEAR(r.segments[0].speed_rpm / 1500, 1.0, 1e-2);
  EXPECT_NEAR(r.segments[1].speed_rpm / to_rpm, 1.0, 1e-2);
  EXPECT_NEAR(r.segments[2].speed_rpm / to_rpm, 1.0, steady_tol);
  EXPECT_TRUE(two_stage_case::of_kind(r, "gear_damage").empty())
      << report::to_json(r)["findings"].dump(1);
}

diag::Recording stepping(double to_rpm, double at_s = 1.5) {
  return two_stage_case::simulate(two_stage_case::gearbox(1500),
                                  sim::SpeedProfile::ramp(1500, to_rpm, at_s, 0.2), 6.0,
                                  std::nullopt);
}

// With the tacho, 1500 -> 1800 rpm: cut within 3 revolutions (0.12 s at 1500 rpm) of the ramp
// (the lines fitted over 8 revolutions on each side part most a little before or after it); the
// steady last frame's speed to 1e-3 (a tacho's).
TEST(AnalyzeStateFrames, ASpeedStepInsideAFrameCutsItThere) {
  const auto rec = std::make_shared<const diag::Recording>(stepping(1800));
  expect_step_cut(analysed(rec, 1500, 3.0), 1800, 0.12, "tacho", 1e-3);
}

// Without the tacho, 1500 -> 1620 rpm (the later frame's speed within the 12.5 % the speed is
// sought in around the nominal 1500): the speed measured from the vibration over the frame shows
// the step; cut within 0.3 s of it (the speed points are 0.05 s apart, fitted over 8 on each
// side), each part analysed at the speed measured in it (the last frame's to 1 %: a frame bin of
// the speed estimate's STFT is 0.3 %, and a ramp's tail may reach it).
TEST(AnalyzeStateFrames, WithoutTachoASpeedStepIsCutWhereTheVibrationShowsIt) {
  diag::Recording r0 = stepping(1620);
  r0.tachos.clear();
  const auto rec = std::make_shared<const diag::Recording>(std::move(r0));
  const detect::AnalysisResult r = analysed(rec, 1500, 3.0);
  expect_step_cut(r, 1620, 0.3, "vibration", 1e-2);
  ASSERT_EQ(r.segments.size(), 3u);
  EXPECT_NE(r.segments[1].cut.find("from the vibration"), std::string::npos) << r.segments[1].cut;
}

// Without the tacho, a step beyond the band the speed is sought in around the nominal 1500 rpm
// (12.5 %): 1500 -> 1850 rpm (+23 %) in the ramp at 1.1-1.3 s. The line followed over the frame
// is lost at the step (or none is found), so the frame's halves are measured, the halves not
// measured halved again down to pieces of 0.5-1 s: the parts wholly before the ramp at 1500 rpm,
// those after at 1850 rpm (1 %), the steady last frame too (the harmonic-set check finds 1850 rpm
// although it is outside the band), all from the vibration but the piece holding the ramp (at
// most 0.75 s here), whose speed is not measured: a part of its own at the nominal speed, said so
// ("nominal"); no gear finding.
TEST(AnalyzeStateFrames, WithoutTachoAStepBeyondTheSearchBandIsPlacedByHalvingTheFrame) {
  diag::Recording r0 = stepping(1850, 1.1);
  r0.tachos.clear();
  const auto rec = std::make_shared<const diag::Recording>(std::move(r0));
  const detect::AnalysisResult r = analysed(rec, 1500, 3.0);
  const std::string segments = report::to_json(r)["segments"].dump(1);
  ASSERT_GE(r.segments.size(), 3u) << segments;
  for (const detect::AnalysisSegment& seg : r.segments) {
    if (seg.start_s > 0 && seg.start_s < 3.0) {
      EXPECT_NE(seg.cut.find("from the vibration"), std::string::npos) << seg.cut;
    }
    if (seg.speed_source != "vibration") {
      EXPECT_EQ(seg.speed_source, "nominal") << segments;
      EXPECT_LE(seg.start_s, 1.1) << segments;  // the piece holds the ramp
      EXPECT_GE(seg.end_s, 1.3) << segments;
      EXPECT_LE(seg.end_s - seg.start_s, 0.75 + 1e-9) << segments;
      continue;
    }
    if (seg.end_s <= 1.1) {
      EXPECT_NEAR(seg.speed_rpm / 1500, 1.0, 1e-2) << segments;
    }
    if (seg.start_s >= 1.3) {
      EXPECT_NEAR(seg.speed_rpm / 1850, 1.0, 1e-2) << segments;
    }
  }
  EXPECT_NEAR(r.segments.back().speed_rpm / 1850, 1.0, 1e-3) << segments;
  EXPECT_TRUE(two_stage_case::of_kind(r, "gear_damage").empty())
      << report::to_json(r)["findings"].dump(1);
}

// A load channel (`--load`): the two-stage box at a steady 1500 rpm with a torque channel of
// 100 N m (5 % ripple at 50 Hz, noise) stepping to 150 N m at 4.2 s, in 3 s frames: the second
// frame is cut at the step (its RMS over 0.05 s windows: within two windows), with and without
// the tacho; the parts keep the frame's speed. A frame is not cut by the ripple (5 %: a level
// that steps by more than 5 % between the lines fitted on each side). A name the recording does
// not have is an error naming it, even for a recording of one frame.
TEST(AnalyzeStateFrames, ALoadStepCutsTheFrameWhereTheLoadChannelShowsIt) {
  const diag::Gearbox gb = two_stage_case::gearbox(1500);
  diag::Recording base =
      two_stage_case::simulate(gb, sim::SpeedProfile::constant(1500), 6.0, std::nullopt);
  diag::Signal torque;
  torque.name = "torque";
  torque.unit = "N m";
  torque.role = diag::Role::kOther;
  torque.fs_hz = base.signals.front().fs_hz;
  const std::size_t n = base.signals.front().samples.size();
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 2.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / torque.fs_hz;
    torque.samples.push_back((t < 4.2 ? 100.0 : 150.0) *
                                 (1 + 0.05 * std::sin(2 * std::numbers::pi * 50 * t)) +
                             noise(rng));
  }
  base.signals.push_back(std::move(torque));
  for (const bool tacho : {true, false}) {
    diag::Recording r0 = base;
    if (!tacho) r0.tachos.clear();
    const auto rec = std::make_shared<const diag::Recording>(std::move(r0));
    detect::AnalyzeRequest q;
    q.recording = detect::RecordingInput(rec, "loaded");
    q.gearbox = gb;
    q.frame_s = 3.0;
    q.load_channel = "torque";
    q.options.traces = false;
    const detect::AnalysisResult r = detect::analyze_file(q).result;
    const std::string segments = report::to_json(r)["segments"].dump(1);
    ASSERT_EQ(r.segments.size(), 3u) << tacho << segments;
    EXPECT_NEAR(r.segments[2].start_s, 4.2, 0.1) << segments;
    EXPECT_NE(r.segments[2].cut.find("a load step, "), std::string::npos) << segments;
    EXPECT_NE(r.segments[2].cut.find("N m RMS of channel 'torque'"), std::string::npos) << segments;
    for (const detect::AnalysisSegment& seg : r.segments) {
      EXPECT_NEAR(seg.speed_rpm / 1500, 1.0, 1e-3) << tacho << segments;
    }
  }
  detect::AnalyzeRequest q;
  q.recording = detect::RecordingInput(std::make_shared<const diag::Recording>(base), "loaded");
  q.gearbox = gb;
  q.load_channel = "torq";
  q.options.traces = false;
  try {
    detect::analyze_file(q);
    ADD_FAILURE() << "a load channel the recording has not must be refused";
  } catch (const diag::InputError& e) {
    // The option, the recording and the reason are named.
    EXPECT_NE(std::string(e.what()).find("--load torq: loaded: no such channel"), std::string::npos)
        << e.what();
  }
}

}  // namespace
