// Baseline comparison on measured data: the SpectraQuest gearbox set (healthy vs broken tooth at
// 0-80 % load; the data set's README). Skips when the data folder is absent.
//
// The set publishes no sampling rate. Every baseline feature depends on frequency only through
// f / fs (band edges are fractions of fs), so a nominal rate is enough: kNominalFsHz = 1 Hz,
// i.e. frequencies below read as fractions of the (unknown) sampling rate.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "detect/baseline/baseline.hpp"
#include "detect/indicators/indicators.hpp"
#include "diag/io/import.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kNominalFsHz = 1.0;
constexpr int kLoads[] = {0, 20, 40, 60, 80};
// Healthy files are cut into this many segments, each one baseline sample: 4 loads x 8 = 32
// samples per fit, enough for a median/MAD (each segment still holds > 10 Welch segments of
// 1024 samples: 88 000-115 000 rows / 8).
constexpr std::size_t kSegmentsPerFile = 8;
const char* const kChannels[] = {"a1", "a2", "a3", "a4"};

fs::path data_dir() { return fs::path(GEARDIAG_SHARED_DATA_DIR) / "spectraquest-gearbox"; }

// All four channels' features of rows [begin, end) of a recording, named "a1.kurtosis_log", ...
detect::FeatureSet features(const diag::Recording& rec, std::size_t begin, std::size_t end) {
  detect::FeatureSet all;
  for (const char* name : kChannels) {
    const diag::Signal& s = rec.require(name, "spectraquest_test");
    diag::Signal part = s;
    part.samples.assign(s.samples.begin() + static_cast<std::ptrdiff_t>(begin),
                        s.samples.begin() + static_cast<std::ptrdiff_t>(end));
    all.merge(detect::prefixed(name, detect::baseline_features(part)));
  }
  return all;
}

class SpectraQuest : public ::testing::Test {
 protected:
  struct File {
    diag::Recording rec;
    std::vector<detect::FeatureSet> segments;  // kSegmentsPerFile feature sets
    detect::FeatureSet whole;                  // features of the whole record
  };
  // Imported once for the suite: "h0", "b0", "h20", ...
  static std::map<std::string, File>* files_;

  static void SetUpTestSuite() {
    if (!fs::is_directory(data_dir())) return;
    files_ = new std::map<std::string, File>;
    diag::ImportOptions opt;
    opt.fs_hz = kNominalFsHz;
    for (const char kind : {'h', 'b'})
      for (const int load : kLoads) {
        File f;
        const std::string stem = std::string(1, kind) + "30hz" + std::to_string(load);
        f.rec = diag::import_recording(data_dir() / (stem + ".csv.gz"), opt);
        const std::size_t n = f.rec.signals.at(0).samples.size();
        for (std::size_t k = 0; k < kSegmentsPerFile; ++k)
          f.segments.push_back(
              features(f.rec, k * n / kSegmentsPerFile, (k + 1) * n / kSegmentsPerFile));
        f.whole = features(f.rec, 0, n);
        (*files_)[std::string(1, kind) + std::to_string(load)] = std::move(f);
      }
  }
  static void TearDownTestSuite() {
    delete files_;
    files_ = nullptr;
  }
  void SetUp() override {
    if (files_ == nullptr) GTEST_SKIP() << "real data not present: " << data_dir();
  }
};

std::map<std::string, SpectraQuest::File>* SpectraQuest::files_ = nullptr;

// The data README's warning, checked: at 0 % load the broken tooth's a1 is LESS impulsive than
// the healthy gear's, so kurtosis alone would call the healthy one faulty.
TEST_F(SpectraQuest, KurtosisAloneRanksTheZeroLoadPairTheWrongWayOnA1) {
  const double k_healthy = detect::kurtosis(files_->at("h0").rec.require("a1", "t").samples);
  const double k_broken = detect::kurtosis(files_->at("b0").rec.require("a1", "t").samples);
  EXPECT_LT(k_broken, k_healthy);
}

// Leave one load out: the baseline holds the healthy files of the four OTHER loads (all four
// channels, 8 segments each); the held-out load's healthy file must not alarm and its broken-tooth
// file must. The threshold is BaselineOptions' default (25: see baseline.hpp for the argument),
// not tuned here. Each held-out file is scored on its whole record and on each of its eighths
// (a record as long as one baseline sample; the whole record's features scatter less).
// Margins measured (commit time): whole records, worst healthy 9.95 (0 % load, an extrapolation
// below the baseline's 20-80 %), weakest broken 50.6 (60 %), a factor 2.5 below and 2.0 above
// the threshold; eighths, 13.0 and 47.1.
TEST_F(SpectraQuest, LeaveOneLoadOutBaselineAlarmsOnEveryBrokenToothAndNoHealthyGear) {
  double worst_healthy = 0, weakest_broken = 1e300;
  double worst_healthy_segment = 0, weakest_broken_segment = 1e300;
  std::string worst_healthy_at, weakest_broken_at;
  for (const int held_out : kLoads) {
    std::vector<detect::FeatureSet> healthy;
    for (const int load : kLoads) {
      if (load == held_out) continue;
      const auto& segs = files_->at("h" + std::to_string(load)).segments;
      healthy.insert(healthy.end(), segs.begin(), segs.end());
    }
    const detect::Baseline baseline = detect::Baseline::fit(healthy);
    const std::string l = std::to_string(held_out);
    const auto h = baseline.score(files_->at("h" + l).whole);
    const auto b = baseline.score(files_->at("b" + l).whole);
    EXPECT_FALSE(h.alarm) << "h30hz" << l << ": score " << h.anomaly_score << " (largest "
                          << h.largest << " " << h.deviation.at(h.largest) << " sigma)";
    EXPECT_TRUE(b.alarm) << "b30hz" << l << ": score " << b.anomaly_score;
    std::cout << "[ load " << l << " % ] healthy " << h.anomaly_score << " (largest " << h.largest
              << " " << h.deviation.at(h.largest) << "), broken " << b.anomaly_score << " (largest "
              << b.largest << " " << b.deviation.at(b.largest) << "), threshold " << h.threshold
              << "\n";
    // The same decision from each eighth of the held-out records (as long as one baseline
    // sample): every one must come out right too.
    for (std::size_t k = 0; k < kSegmentsPerFile; ++k) {
      const auto hs = baseline.score(files_->at("h" + l).segments[k]);
      const auto bs = baseline.score(files_->at("b" + l).segments[k]);
      EXPECT_FALSE(hs.alarm) << "h30hz" << l << " segment " << k << ": " << hs.anomaly_score;
      EXPECT_TRUE(bs.alarm) << "b30hz" << l << " segment " << k << ": " << bs.anomaly_score;
      worst_healthy_segment = std::max(worst_healthy_segment, hs.anomaly_score);
      weakest_broken_segment = std::min(weakest_broken_segment, bs.anomaly_score);
    }
    if (h.anomaly_score > worst_healthy) {
      worst_healthy = h.anomaly_score;
      worst_healthy_at = l;
    }
    if (b.anomaly_score < weakest_broken) {
      weakest_broken = b.anomaly_score;
      weakest_broken_at = l;
    }
  }
  std::cout << "[ margins ] worst healthy " << worst_healthy << " at " << worst_healthy_at
            << " %, weakest broken " << weakest_broken << " at " << weakest_broken_at
            << " %; single segments: worst healthy " << worst_healthy_segment << ", weakest broken "
            << weakest_broken_segment << "\n";
  RecordProperty("worst_healthy_score", std::to_string(worst_healthy));
  RecordProperty("weakest_broken_score", std::to_string(weakest_broken));
}

// The baseline fitted on every healthy load (in-sample for the healthy segments): no healthy
// segment alarms and every broken one does.
TEST_F(SpectraQuest, AllLoadBaselineSeparatesEverySegment) {
  std::vector<detect::FeatureSet> healthy;
  for (const int load : kLoads) {
    const auto& segs = files_->at("h" + std::to_string(load)).segments;
    healthy.insert(healthy.end(), segs.begin(), segs.end());
  }
  const detect::Baseline baseline = detect::Baseline::fit(healthy);
  for (const int load : kLoads) {
    const std::string l = std::to_string(load);
    for (std::size_t k = 0; k < kSegmentsPerFile; ++k) {
      const auto h = baseline.score(files_->at("h" + l).segments[k]);
      const auto b = baseline.score(files_->at("b" + l).segments[k]);
      EXPECT_FALSE(h.alarm) << "h30hz" << l << " segment " << k << ": " << h.anomaly_score;
      EXPECT_TRUE(b.alarm) << "b30hz" << l << " segment " << k << ": " << b.anomaly_score;
    }
  }
}

}  // namespace
