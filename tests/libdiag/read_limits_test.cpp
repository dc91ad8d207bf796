// read_recording(path, ReadLimits) (diag/io/hdf5.hpp): a long recording's first part within the
// limits, every channel cut at the same time, the samples those of the whole record; a recording
// within the limits read whole, equal to read_recording(path).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "diag/io/hdf5.hpp"
#include "diag/io/recording.hpp"

namespace fs = std::filesystem;

namespace {

class ReadLimits : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* env = std::getenv("GEARDIAG_TMP");
    const fs::path base =
        env != nullptr && *env != '\0' ? fs::path(env) : fs::temp_directory_path();
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = base / ("read_limits_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // 10 s: two vibration channels at 1000 and 500 Hz and a tacho at 1000 Hz (25000 samples).
    diag::Recording rec;
    for (const auto& [name, fs_hz] : {std::pair<std::string, double>{"a", 1000.0}, {"b", 500.0}}) {
      diag::Signal s;
      s.name = name;
      s.fs_hz = fs_hz;
      s.unit = "m/s^2";
      s.samples.resize(static_cast<std::size_t>(10 * fs_hz));
      for (std::size_t i = 0; i < s.samples.size(); ++i) s.samples[i] = std::sin(0.1 * i) + i;
      rec.signals.push_back(s);
    }
    diag::Signal t;
    t.name = "input";
    t.fs_hz = 1000;
    t.role = diag::Role::kTacho;
    t.shaft = "input";
    t.ppr = 1;
    t.samples.resize(10000);
    for (std::size_t i = 0; i < t.samples.size(); ++i) t.samples[i] = i % 50 < 5 ? 1.0 : 0.0;
    rec.tachos.push_back(t);
    path_ = dir_ / "rec.h5";
    diag::write_recording(path_, rec);
    whole_ = diag::read_recording(path_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Every channel of `part` is the first part of the whole record's, with n_c samples.
  void expect_prefix(const diag::Recording& part, std::size_t na, std::size_t nb) const {
    ASSERT_EQ(part.signals.size(), whole_.signals.size());
    ASSERT_EQ(part.tachos.size(), whole_.tachos.size());
    auto check = [&](const diag::Signal& p, const diag::Signal& w, std::size_t n) {
      ASSERT_EQ(p.samples.size(), n) << p.name;
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(p.samples[i], w.samples[i]);
      EXPECT_EQ(p.role, w.role);
      EXPECT_EQ(p.ppr, w.ppr);
      EXPECT_EQ(p.fs_hz, w.fs_hz);
    };
    check(part.signals[0], whole_.signals[0], na);
    check(part.signals[1], whole_.signals[1], nb);
    check(part.tachos[0], whole_.tachos[0], na);  // the tacho: same rate as a, same time
  }

  fs::path dir_, path_;
  diag::Recording whole_;
};

TEST_F(ReadLimits, WithinTheLimitsTheWholeRecordAndNoNote) {
  diag::ReadLimits l;
  l.max_samples = 25000;  // exactly the record
  const diag::Recording r = diag::read_recording(path_, l);
  expect_prefix(r, 10000, 5000);
  EXPECT_EQ(r.notes, whole_.notes);
  // Many short channels: over max_samples but none over kept_channel_samples: whole.
  l.max_samples = 100;
  l.kept_channel_samples = 10000;
  expect_prefix(diag::read_recording(path_, l), 10000, 5000);
}

TEST_F(ReadLimits, TotalLimitCutsEveryChannelAtTheSameTime) {
  diag::ReadLimits l;
  l.max_samples = 6000;  // 2500 samples per second in all: 2.4 s
  const diag::Recording r = diag::read_recording(path_, l);
  // Cut at one time T (floor(T fs) samples each): 2.4 s, where the 2500 samples per second in
  // all reach the limit exactly (T is found by bisection, then every channel keeps floor(T fs)).
  expect_prefix(r, 2400, 1200);
  ASSERT_FALSE(r.notes.empty());
  EXPECT_NE(r.notes.back().find("the first 2.4 s of 10 s analysed"), std::string::npos)
      << r.notes.back();
}

TEST_F(ReadLimits, ChannelLimitHoldsWhateverTheOthers) {
  diag::ReadLimits l;
  l.max_channel_samples = 1500;   // the 1000 Hz channels: 1.5 s, though 3750 samples in all
  l.kept_channel_samples = 1500;  // are within max_samples (unlimited) anyway
  const diag::Recording r = diag::read_recording(path_, l);
  expect_prefix(r, 1500, 750);
}

}  // namespace
