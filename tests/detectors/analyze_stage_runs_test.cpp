// What ran and what did not (AnalysisResult::stages, the JSON's `stages`): every stage of the
// analysis table once, in order, with the channels it ran on and why not on the others.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "detect/analysis/analyze.hpp"
#include "report/report.hpp"

namespace {

diag::Recording two_channels() {
  diag::Recording rec;
  for (const auto& [name, role] :
       {std::pair{"accel", diag::Role::kVibration}, std::pair{"angle", diag::Role::kAngle}}) {
    diag::Signal s;
    s.name = name;
    s.role = role;
    s.fs_hz = 5000;
    for (int i = 0; i < 10000; ++i) {
      s.samples.push_back(std::sin(2 * std::numbers::pi * 300 * i / 5000.0) + 1e-3 * (i % 7));
    }
    rec.signals.push_back(std::move(s));
  }
  return rec;
}

// Without a description: the recording stages that need one skipped for that reason, the time
// indicators on both channels, the spectra on the accelerometer only (the angle is no vibration
// channel), the TSA on none; the plot-only spectrogram not listed (the report is the same with
// plots asked for or not).
TEST(AnalyzeStageRuns, EachStageSaysWhereItRanAndWhyNotElsewhere) {
  detect::AnalyzeOptions opt;
  opt.traces = false;
  const detect::AnalysisResult r = detect::analyze_recording(two_channels(), nullptr, opt);
  std::map<std::string, detect::StageRun> by;
  for (const detect::StageRun& s : r.stages) {
    EXPECT_TRUE(by.emplace(s.stage, s).second) << "twice: " << s.stage;
  }
  ASSERT_EQ(r.stages.front().stage, "kinematics");
  EXPECT_EQ(by["kinematics"].ran, 0u);
  EXPECT_EQ(by["kinematics"].why, "no gearbox description");
  EXPECT_EQ(by["angle_plans"].ran, 1u);
  EXPECT_EQ(by["channel.time"].ran, 2u);
  EXPECT_EQ(by["channel.time"].skipped, 0u);
  EXPECT_TRUE(by["channel.time"].why.empty());
  EXPECT_EQ(by["channel.spectra"].ran, 1u);
  EXPECT_EQ(by["channel.spectra"].why, "not a vibration, force or displacement channel");
  EXPECT_EQ(by.count("channel.spectrogram"), 0u);
  EXPECT_EQ(by["channel.tsa"].ran, 0u);
  EXPECT_NE(by["channel.tsa"].why.find("no gearbox description"), std::string::npos);
  EXPECT_EQ(by["findings"].why, "no gearbox description");
  // The JSON carries the same rows.
  const auto j = report::to_json(r);
  ASSERT_EQ(j["stages"].size(), r.stages.size());
  EXPECT_EQ(j["stages"][0]["stage"], "kinematics");
  EXPECT_EQ(j["stages"][0]["skipped"], 1);
  EXPECT_EQ(j["stages"][0]["why"], "no gearbox description");
}

}  // namespace
