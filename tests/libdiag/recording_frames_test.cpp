// diag::open_recording_frames: a recording read frame by frame. A CSV file is read row by row
// (memory: one frame), an HDF5 recording by blocks, a sound file after a seek, any other in
// memory; the frames hold exactly
// the samples the whole reader gives, in any order they are asked for.
#include "diag/io/recording_frames.hpp"

#include <gtest/gtest.h>
#include <sndfile.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/import.hpp"

namespace {

namespace fs = std::filesystem;

class RecordingFrames : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("recording_frames"); }
  void TearDown() override { fs::remove_all(dir_); }

  // time,a,b at 1 kHz: `rows` rows, the values exact in text (%.17g round-trips).
  std::string table(std::size_t rows, bool header = true, bool time = true) const {
    std::string text = header ? (time ? "time,a,b\n" : "a,b\n") : "";
    char line[128];
    for (std::size_t i = 0; i < rows; ++i) {
      const double t = static_cast<double>(i) / 1000;
      const double a = std::sin(0.01 * static_cast<double>(i)), b = 0.5 * static_cast<double>(i);
      if (time) {
        std::snprintf(line, sizeof line, "%.6f,%.17g,%.17g\n", t, a, b);
      } else {
        std::snprintf(line, sizeof line, "%.17g,%.17g\n", a, b);
      }
      text += line;
    }
    return text;
  }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    if (name.ends_with(".gz")) {
      gzFile f = gzopen(p.c_str(), "wb");
      gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
      gzclose(f);
    } else {
      std::ofstream(p, std::ios::binary) << text;
    }
    return p;
  }

  fs::path dir_;
};

// Frames [0, 0.7), [0.7, 1.9), [1.9, end) of a CSV, asked for out of order, are the rows the
// whole import gives, once each.
void expect_frames_are_the_whole(const fs::path& file, const diag::OpenOptions& o,
                                 const std::string& format = "csv") {
  diag::ImportOptions io;
  io.fs_hz = o.fs_hz;
  const diag::Recording whole = diag::import_recording(file, io);
  const diag::OpenedFrames opened = diag::open_recording_frames(file, o);
  EXPECT_EQ(opened.format, format);
  const diag::RecordingFrames& f = *opened.frames;
  EXPECT_DOUBLE_EQ(f.duration_s(), whole.signals[0].duration_s());
  const double inf = std::numeric_limits<double>::infinity();
  const diag::Recording late = f.frame(1.9, inf), early = f.frame(0, 0.7), mid = f.frame(0.7, 1.9);
  ASSERT_EQ(early.signals.size(), whole.signals.size());
  for (std::size_t c = 0; c < whole.signals.size(); ++c) {
    EXPECT_EQ(early.signals[c].name, whole.signals[c].name);
    EXPECT_EQ(early.signals[c].fs_hz, whole.signals[c].fs_hz);
    EXPECT_EQ(early.signals[c].samples.size(), 700u);
    std::vector<double> joined = early.signals[c].samples;
    joined.insert(joined.end(), mid.signals[c].samples.begin(), mid.signals[c].samples.end());
    joined.insert(joined.end(), late.signals[c].samples.begin(), late.signals[c].samples.end());
    EXPECT_EQ(joined, whole.signals[c].samples) << whole.signals[c].name;
  }
  EXPECT_EQ(early.metadata, whole.metadata);
  EXPECT_FALSE(early.roles_stated);
}

TEST_F(RecordingFrames, ACsvFileIsReadFrameByFrameAsTheWholeImportReadsIt) {
  expect_frames_are_the_whole(write("log.csv", table(2500)), {});
  expect_frames_are_the_whole(write("log.csv.gz", table(2500)), {});
  diag::OpenOptions o;
  o.fs_hz = 1000;
  expect_frames_are_the_whole(write("bare.csv", table(2500, false, false)), o);
  expect_frames_are_the_whole(write("named.csv", table(2500, true, false)), o);
}

// A sound file (WAV, FLAC), 2 channels at 1 kHz, 2500 frames written by libsndfile: kept open
// and read after a seek per frame, the same samples as the whole import; a NaN of a float WAV is
// kept in its frame, where the import refuses the file.
TEST_F(RecordingFrames, ASoundFileIsReadFrameByFrameAsTheWholeImportReadsIt) {
  const auto sound = [&](const std::string& name, int format, double nan_at = -1) {
    const fs::path path = dir_ / name;
    SF_INFO info{};
    info.samplerate = 1000;
    info.channels = 2;
    info.format = format;
    SNDFILE* file = sf_open(path.c_str(), SFM_WRITE, &info);
    EXPECT_NE(file, nullptr) << sf_strerror(nullptr);
    std::vector<double> frames;
    for (int i = 0; i < 2500; ++i) {
      frames.push_back(std::sin(0.01 * i) * 0.5);
      frames.push_back(i == nan_at ? std::numeric_limits<double>::quiet_NaN() : (i % 100) / 128.0);
    }
    EXPECT_EQ(sf_writef_double(file, frames.data(), 2500), 2500);
    sf_close(file);
    return path;
  };
  expect_frames_are_the_whole(sound("pcm.wav", SF_FORMAT_WAV | SF_FORMAT_PCM_16), {}, "sound");
  expect_frames_are_the_whole(sound("float.wav", SF_FORMAT_WAV | SF_FORMAT_FLOAT), {}, "sound");
  expect_frames_are_the_whole(sound("log.flac", SF_FORMAT_FLAC | SF_FORMAT_PCM_16), {}, "sound");

  const fs::path gap = sound("gap.wav", SF_FORMAT_WAV | SF_FORMAT_FLOAT, 1200);
  EXPECT_THROW(diag::import_recording(gap), diag::InputError);
  const diag::OpenedFrames opened = diag::open_recording_frames(gap);
  EXPECT_TRUE(std::isnan(opened.frames->frame(1.0, 2.0).signals[1].samples[200]));
  EXPECT_TRUE(std::isfinite(opened.frames->frame(0, 1.0).signals[1].samples[999]));
}

// A NaN the logger wrote is kept in its frame (the caller says the frame was not examined), where
// the whole import refuses the file; a ragged row is an error of the frame that holds it, naming
// its line; a time column whose steps are uneven is refused when the file is opened, as the
// import refuses it.
TEST_F(RecordingFrames, ABadRowIsTheErrorOfItsFrameAndAnUnevenClockOfTheFile) {
  std::string text = table(2000);
  const std::size_t at = text.find("\n1.500000,");
  ASSERT_NE(at, std::string::npos);
  const std::size_t end = text.find('\n', at + 1);
  std::string nan_text = text;
  nan_text.replace(at + 1, end - at - 1, "1.500000,nan,1");
  const fs::path nan_file = write("nan.csv", nan_text);
  EXPECT_THROW(diag::import_recording(nan_file), diag::InputError);
  const auto frames = diag::open_recording_frames(nan_file).frames;
  const diag::Recording late = frames->frame(1.0, 2.0);
  EXPECT_TRUE(std::isnan(late.signals[0].samples[500]));
  EXPECT_TRUE(std::isfinite(frames->frame(0, 1.0).signals[0].samples[999]));

  std::string ragged = text;
  ragged.replace(at + 1, end - at - 1, "1.500000,1");
  const auto r = diag::open_recording_frames(write("ragged.csv", ragged)).frames;
  EXPECT_NO_THROW(r->frame(0, 1.0));
  try {
    r->frame(1.0, 2.0);
    ADD_FAILURE() << "a ragged row read";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 1502"), std::string::npos) << e.what();
  }

  // One time stamp off the clock (an uneven step, then back): the file is refused when opened,
  // as the import refuses it.
  std::string uneven = text;
  uneven.replace(at + 1, 8, "1.500300");
  EXPECT_THROW(diag::open_recording_frames(write("uneven.csv", uneven)), diag::InputError);
  EXPECT_THROW(diag::import_recording(write("uneven2.csv", uneven)), diag::InputError);
}

// A logger that paused: the clock jumps by 3 s after row 1500 and runs on. The whole import
// refuses the file; frame by frame it is read at the rate of its steps, times counted in samples,
// and only the frame that holds the jump is refused, naming the line and the times.
TEST_F(RecordingFrames, AClockThatJumpsMakesItsFrameAnErrorAndTheOthersAreRead) {
  std::string text = "time,a,b\n";
  char line[96];
  for (std::size_t i = 0; i < 3000; ++i) {
    const double t = static_cast<double>(i) / 1000 + (i >= 1500 ? 3.0 : 0.0);
    std::snprintf(line, sizeof line, "%.6f,%zu,%zu\n", t, i, 2 * i);
    text += line;
  }
  const fs::path file = write("paused.csv", text);
  EXPECT_THROW(diag::import_recording(file), diag::InputError);
  const auto frames = diag::open_recording_frames(file).frames;
  // 3000 samples at 1 kHz (the median step's rate, 1e-12 from 1 kHz: printed time stamps); the
  // frames' edges half a sample off the rows.
  EXPECT_NEAR(frames->duration_s(), 3.0, 1e-9);
  const double inf = std::numeric_limits<double>::infinity();
  const diag::Recording head = frames->frame(0, 1.0005), tail = frames->frame(2.0005, inf);
  EXPECT_EQ(head.signals[0].samples.back(), 999);
  EXPECT_EQ(tail.signals[0].samples.front(), 2000);
  ASSERT_FALSE(head.notes.empty());
  EXPECT_NE(head.notes[0].find("jumps 1 time"), std::string::npos) << head.notes[0];
  try {
    frames->frame(1.0005, 2.0005);
    ADD_FAILURE() << "the frame holding the jump read";
  } catch (const diag::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("line 1502"), std::string::npos) << m;
    EXPECT_NE(m.find("jumps from 1.499 to 4.5 s"), std::string::npos) << m;
  }
  // A frame that ends where the jump is, and one that starts there, hold none.
  EXPECT_NO_THROW(frames->frame(1.0005, 1.5005));
  EXPECT_NO_THROW(frames->frame(1.5005, 2.0005));
}

// An HDF5 recording and one in memory give the same frames.
TEST_F(RecordingFrames, AnHdf5RecordingAndOneInMemoryGiveTheSameFrames) {
  auto rec = std::make_shared<diag::Recording>(diag::import_recording(write("h.csv", table(3000))));
  rec->roles_stated = true;
  const fs::path h5 = dir_ / "h.h5";
  diag::write_recording(h5, *rec);
  const auto opened = diag::open_recording_frames(h5);
  EXPECT_EQ(opened.format, "hdf5");
  const diag::RecordingFrames memory(std::shared_ptr<const diag::Recording>{rec});
  for (const auto& [t0, t1] : {std::pair{0.0, 1.25}, {1.25, 2.5}, {2.5, 3.0}}) {
    const diag::Recording a = opened.frames->frame(t0, t1), b = memory.frame(t0, t1);
    ASSERT_EQ(a.signals.size(), b.signals.size());
    for (std::size_t c = 0; c < a.signals.size(); ++c) {
      EXPECT_EQ(a.signals[c].samples, b.signals[c].samples) << t0;
    }
  }
  diag::ReadLimits l;
  l.max_samples = 2000;  // 1000 per channel: 1 s
  l.kept_channel_samples = 0;
  EXPECT_DOUBLE_EQ(memory.frame_seconds(l), opened.frames->frame_seconds(l));
  EXPECT_NEAR(memory.frame_seconds(l), 1.0, 1e-3);
}

}  // namespace
