// analyze_file on a long log: every sample examined frame by frame, findings placed in time, the
// frames that cannot be analysed said so, the same bytes for any thread count. The log is
// measured data: the CWRU bearing set's healthy drive-end record (48 kHz, decimated to 12 kHz
// with diag::Decimator) twice, then its inner-race fault record (12 kHz), joined. Skips when the
// data is absent.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "detect/analysis/analyze_file.hpp"
#include "diag/dsp/fir.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/import.hpp"
#include "report/report.hpp"

namespace {

namespace fs = std::filesystem;

fs::path data_dir() { return fs::path(GEARDIAG_SHARED_DATA_DIR) / "cwru-bearing"; }

diag::Recording import_mat(const std::string& file, double fs_hz) {
  diag::ImportOptions opt;
  opt.fs_hz = fs_hz;
  return diag::import_recording(data_dir() / file, opt);
}

std::vector<double> channel(const diag::Recording& rec, const std::string& suffix) {
  for (const diag::Signal& s : rec.signals) {
    if (s.name.ends_with(suffix)) return s.samples;
  }
  ADD_FAILURE() << "no channel *" << suffix;
  return {};
}

struct Log {
  std::shared_ptr<diag::Recording> rec;
  double fault_from_s = 0;  // where the inner-race record starts
};

// Healthy (decimated 48 -> 12 kHz) twice, then the inner-race fault: DE and FE channels at the
// drive end and fan end, the speed the files record (1797 rpm, both).
Log joined_log() {
  const diag::Recording healthy = import_mat("normal_0.mat", 48000.0);
  const diag::Recording faulty = import_mat("IR007_0.mat", 12000.0);
  auto rec = std::make_shared<diag::Recording>();
  Log log;
  for (const auto& [suffix, location] :
       {std::pair{"_DE_time", "drive_end"}, {"_FE_time", "fan_end"}}) {
    diag::Decimator d(4);
    std::vector<double> h;
    d.push(channel(healthy, suffix), h);
    d.finish(h);
    diag::Signal s;
    s.name = std::string(suffix).substr(1, 2);
    s.fs_hz = 12000.0;
    s.location = location;
    s.samples = h;
    s.samples.insert(s.samples.end(), h.begin(), h.end());
    log.fault_from_s = static_cast<double>(s.samples.size()) / s.fs_hz;
    const std::vector<double> f = channel(faulty, suffix);
    s.samples.insert(s.samples.end(), f.begin(), f.end());
    rec->signals.push_back(std::move(s));
  }
  rec->roles_stated = false;
  rec->speed_rpm = 1797;
  log.rec = rec;
  return log;
}

diag::Gearbox cwru_box() {
  return diag::load_gearbox(fs::path(GEARDIAG_TESTDATA_DIR) / "reference" / "cwru_6205.json");
}

detect::AnalyzeRequest framed(const Log& log) {
  detect::AnalyzeRequest q;
  q.recording = detect::RecordingInput(log.rec, "joined");
  q.gearbox = cwru_box();
  q.frame_s = 5;  // 20.27 s: 5 frames of 4.054 s
  q.options.traces = false;
  q.options.threads = 1;
  return q;
}

class AnalyzeFrames : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::is_directory(data_dir())) GTEST_SKIP() << "real data not present: " << data_dir();
  }
};

// The fault starts part-way: found, placed in the frames from its start to the end of the log,
// and the frames wholly before it are healthy.
TEST_F(AnalyzeFrames, AFaultFromPartWayIsFoundAndPlacedInTime) {
  const Log log = joined_log();
  const detect::FileAnalysis a = detect::analyze_file(framed(log));
  const detect::AnalysisResult& r = a.result;
  ASSERT_TRUE(r.coverage);
  EXPECT_TRUE(r.coverage->complete());
  EXPECT_EQ(r.coverage->frames, 5u);
  EXPECT_EQ(r.coverage->frames_examined, 5u);
  EXPECT_NEAR(r.coverage->analysed_s, r.duration_s, 1e-9);
  ASSERT_EQ(r.findings.size(), 1u) << report::to_json(r)["findings"].dump(1);
  const detect::Finding& f = r.findings[0];
  EXPECT_EQ(f.kind, "bearing");
  EXPECT_EQ(diag::to_string(f.fault), "inner_race");
  ASSERT_EQ(r.segments.size(), 5u) << report::to_json(r)["segments"].dump(1);
  // Placed to within a frame: from the frame holding the fault's start (half of it healthy) or
  // the next, to the end of the log.
  EXPECT_GT(f.first_s, log.fault_from_s - r.coverage->frame_s);
  EXPECT_LE(f.first_s, log.fault_from_s + r.coverage->frame_s);
  EXPECT_DOUBLE_EQ(f.last_s, r.segments.back().end_s);
  ASSERT_EQ(r.segments.size(), 5u);
  for (const detect::AnalysisSegment& s : r.segments) {
    if (s.end_s <= log.fault_from_s) {
      EXPECT_EQ(s.verdict, "no finding") << s.start_s;
    }
    if (s.start_s >= log.fault_from_s) {
      EXPECT_EQ(s.verdict, "finding") << s.start_s;
    }
    // The file's 1797 rpm, or the speed measured from the shaft's lines (within 0.2 %: the
    // motor's speed to a few rpm).
    EXPECT_NEAR(s.speed_rpm / 1797, 1.0, 2e-3) << s.start_s;
  }
  EXPECT_NE(f.note.find("to the end of the log"), std::string::npos) << f.note;
  // The JSON places it too.
  const auto j = report::to_json(r);
  EXPECT_EQ(j["findings"][0]["time_s"][0].get<double>(), f.first_s);
  EXPECT_EQ(j["examined"]["complete"], true);
  EXPECT_EQ(j["segments"].size(), 5u);
}

// Threads split the channels of each frame: the result does not depend on them.
TEST_F(AnalyzeFrames, SameBytesForOneAndTwoThreads) {
  const Log log = joined_log();
  detect::AnalyzeRequest q = framed(log);
  const std::string one = report::to_json(detect::analyze_file(q).result).dump();
  q.options.threads = 2;
  EXPECT_EQ(report::to_json(detect::analyze_file(q).result).dump(), one);
}

// A given speed 5 % off the one recorded with the file: a warning naming both, the recorded
// speed used, the same finding.
TEST_F(AnalyzeFrames, AGivenSpeedThatContradictsTheRecordedOneIsAWarningAndNotUsed) {
  const Log log = joined_log();
  detect::AnalyzeRequest q = framed(log);
  const detect::FileAnalysis right = detect::analyze_file(q);
  q.channels.rpm = 1797 * 0.95;
  const detect::FileAnalysis off = detect::analyze_file(q);
  bool warned = false;
  for (const std::string& n : off.result.notes) {
    warned =
        warned || (n.starts_with("warning: --rpm 1707") && n.find("1797") != std::string::npos);
  }
  EXPECT_TRUE(warned);
  ASSERT_EQ(off.result.findings.size(), right.result.findings.size());
  EXPECT_EQ(off.result.findings[0].fault, right.result.findings[0].fault);
  EXPECT_EQ(off.result.findings[0].first_s, right.result.findings[0].first_s);
}

// A NaN stretch: its frame is not examined (the reason said), the others are, and the fault
// is still found; the analysis is never "complete".
TEST_F(AnalyzeFrames, AFrameWithNaNSamplesIsNotExaminedAndTheRestIs) {
  Log log = joined_log();
  for (diag::Signal& s : log.rec->signals) {
    for (std::size_t i = 60000; i < 61000; ++i) {  // 5.0-5.08 s: the second frame
      s.samples[i] = std::numeric_limits<double>::quiet_NaN();
    }
  }
  const detect::FileAnalysis a = detect::analyze_file(framed(log));
  const detect::AnalysisResult& r = a.result;
  ASSERT_TRUE(r.coverage);
  EXPECT_FALSE(r.coverage->complete());
  EXPECT_EQ(r.coverage->frames_examined, 4u);
  EXPECT_EQ(r.segments[1].verdict, "not examined");
  EXPECT_NE(r.segments[1].reason.find("NaN"), std::string::npos) << r.segments[1].reason;
  ASSERT_EQ(r.coverage->not_examined.size(), 1u);
  ASSERT_EQ(r.findings.size(), 1u);
  EXPECT_EQ(r.findings[0].frames_examined, 4);
}

// A clipped stretch (the converter saturated at +-0.1 through the second frame, 4.05-8.1 s; the
// healthy signal's RMS is 0.07): that frame is not examined and said so, the others are.
TEST_F(AnalyzeFrames, AClippedFrameIsNotExamined) {
  Log log = joined_log();
  for (std::size_t i = 48000; i < 98000; ++i) {  // the frame is samples 48647-97293
    double& x = log.rec->signals[0].samples[i];
    x = std::clamp(x, -0.1, 0.1);
  }
  const detect::FileAnalysis a = detect::analyze_file(framed(log));
  const detect::AnalysisResult& r = a.result;
  EXPECT_EQ(r.segments[1].verdict, "not examined");
  EXPECT_NE(r.segments[1].reason.find("channel 'DE': clipped at"), std::string::npos)
      << r.segments[1].reason;
  EXPECT_EQ(r.coverage->frames_examined, 4u);
  ASSERT_EQ(r.findings.size(), 1u);
}

// max_samples is an opt-in limit: the part beyond it is not examined, and said so.
TEST_F(AnalyzeFrames, AMaxSamplesLimitLeavesTheRestNotExamined) {
  const Log log = joined_log();
  detect::AnalyzeRequest q = framed(log);
  // No channel over 60 000 samples: each keeps its first 5 s, all healthy.
  q.max_samples = 60000;
  const detect::FileAnalysis a = detect::analyze_file(q);
  EXPECT_TRUE(a.cut);
  ASSERT_TRUE(a.result.coverage);
  EXPECT_FALSE(a.result.coverage->complete());
  // Up to the first sample not examined (within one sample of 5 s).
  EXPECT_NEAR(a.result.coverage->analysed_s, 5.0, 1 / 12000.0);
  EXPECT_TRUE(a.result.findings.empty());
  ASSERT_EQ(a.result.coverage->not_examined.size(), 1u);
  EXPECT_NE(a.result.coverage->not_examined[0].find("max_samples"), std::string::npos);
  EXPECT_NE(report::format_summary(a.result).find("NOT EVERY SAMPLE EXAMINED"), std::string::npos);
}

// The joined log as a CSV file (time, DE, FE; every value printed to round-trip): read row by row,
// frame by frame, it gives the analysis of the same file read whole into memory, byte for byte.
TEST_F(AnalyzeFrames, ACsvLogReadRowByRowGivesTheAnalysisOfTheWholeFile) {
  const Log log = joined_log();
  const fs::path dir = geardiag_test::scratch_dir("analyze_frames");
  const fs::path csv = dir / "joined.csv";
  {
    std::ofstream out(csv);
    out << "time,DE,FE\n";
    char line[96];
    const auto& de = log.rec->signals[0].samples;
    const auto& fe = log.rec->signals[1].samples;
    for (std::size_t i = 0; i < de.size(); ++i) {
      std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", static_cast<double>(i) / 12000.0,
                    de[i], fe[i]);
      out << line;
    }
  }
  detect::AnalyzeRequest q;
  q.recording = csv;
  q.gearbox = cwru_box();
  q.frame_s = 5;
  q.options.traces = false;
  q.options.threads = 2;
  const detect::FileAnalysis rows = detect::analyze_file(q);
  EXPECT_EQ(rows.format, "csv");
  q.recording = detect::RecordingInput(
      std::make_shared<const diag::Recording>(diag::import_recording(csv)), csv);
  const detect::FileAnalysis whole = detect::analyze_file(q);
  EXPECT_EQ(report::to_json(rows.result).dump(), report::to_json(whole.result).dump());
  ASSERT_EQ(rows.result.findings.size(), 1u);
  EXPECT_EQ(diag::to_string(rows.result.findings[0].fault), "inner_race");
  fs::remove_all(dir);
}

// A recording of one frame: analyze_recording's findings, placed over the whole record.
TEST_F(AnalyzeFrames, ARecordOfOneFrameIsOneSegment) {
  detect::AnalyzeRequest q;
  q.recording = data_dir() / "IR007_0.mat";
  q.fs_hz = 12000.0;
  q.gearbox = cwru_box();
  q.options.traces = false;
  const detect::FileAnalysis a = detect::analyze_file(q);
  const detect::AnalysisResult& r = a.result;
  ASSERT_EQ(r.segments.size(), 1u);
  EXPECT_EQ(r.segments[0].verdict, "finding");
  ASSERT_EQ(r.findings.size(), 1u);
  EXPECT_EQ(r.findings[0].first_s, 0);
  EXPECT_DOUBLE_EQ(r.findings[0].last_s, r.duration_s);
  EXPECT_EQ(r.findings[0].frames_seen, 1);
  EXPECT_TRUE(r.coverage->complete());
  // Every sample: OR007's 121 991 samples, whose duration times the rate rounds below 121 991.
  q.recording = data_dir() / "OR007@6_0.mat";
  const detect::FileAnalysis o = detect::analyze_file(q);
  for (const detect::ChannelAnalysis& c : o.result.channels) EXPECT_EQ(c.samples, 121991u);
}

}  // namespace
