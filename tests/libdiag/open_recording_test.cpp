// diag::open_recording: one door, a table of formats. Each format's file is read by its row and
// gives the same samples as its reader called directly; the row is chosen from the content (HDF5
// signature) and the name's ending, never from anything else; errors name the file.
#include "diag/io/open_recording.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/import.hpp"

namespace {

namespace fs = std::filesystem;

class OpenRecording : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("open_recording"); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write_text(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

  // A 16-bit PCM mono WAV file of `samples` at `fs` [Hz].
  fs::path write_wav(const std::string& name, const std::vector<std::int16_t>& samples,
                     std::uint32_t fs) const {
    const fs::path p = dir_ / name;
    std::ofstream o(p, std::ios::binary);
    auto u32 = [&](std::uint32_t v) { o.write(reinterpret_cast<const char*>(&v), 4); };
    auto u16 = [&](std::uint16_t v) { o.write(reinterpret_cast<const char*>(&v), 2); };
    const auto bytes = static_cast<std::uint32_t>(2 * samples.size());
    o << "RIFF";
    u32(36 + bytes);
    o << "WAVEfmt ";
    u32(16);
    u16(1);  // PCM
    u16(1);  // mono
    u32(fs);
    u32(2 * fs);
    u16(2);
    u16(16);
    o << "data";
    u32(bytes);
    o.write(reinterpret_cast<const char*>(samples.data()), bytes);
    return p;
  }

  fs::path dir_;
};

TEST_F(OpenRecording, EachFormatIsReadByItsRowAsItsReaderReadsIt) {
  // CSV with a time column (rate 1 kHz).
  std::string csv = "time,a1\n";
  for (int i = 0; i < 64; ++i)
    csv += std::to_string(i / 1000.0) + "," + std::to_string(i % 7) + "\n";
  const fs::path table = write_text("log.csv", csv);
  const diag::OpenedRecording c = diag::open_recording_as(table);
  EXPECT_EQ(c.format, "csv");
  EXPECT_FALSE(c.cut);
  const diag::Recording ci = diag::import_recording(table);
  ASSERT_EQ(c.recording.signals.size(), 1u);
  EXPECT_EQ(c.recording.signals[0].samples, ci.signals[0].samples);
  EXPECT_NEAR(c.recording.signals[0].fs_hz, 1000.0, 1e-9);

  // WAV (libsndfile): 16-bit samples scaled to [-1, 1).
  const fs::path wav = write_wav("tone.wav", {0, 16384, -16384, 32767, -32768, 1}, 8000);
  const diag::OpenedRecording w = diag::open_recording_as(wav);
  EXPECT_EQ(w.format, "sound");
  ASSERT_EQ(w.recording.signals.size(), 1u);
  EXPECT_DOUBLE_EQ(w.recording.signals[0].fs_hz, 8000.0);
  EXPECT_DOUBLE_EQ(w.recording.signals[0].samples[1], 0.5);
  EXPECT_EQ(w.recording.signals[0].samples, diag::import_recording(wav).signals[0].samples);

  // A geardiag HDF5 recording, whatever its name: by content.
  diag::Recording rec;
  diag::Signal& s = rec.signals.emplace_back();
  s.name = "acc";
  s.fs_hz = 2000;
  s.unit = "m/s^2";
  for (int i = 0; i < 5000; ++i) s.samples.push_back(std::sin(0.01 * i));
  const fs::path h5 = dir_ / "run.data";
  diag::write_recording(h5, rec);
  const diag::OpenedRecording h = diag::open_recording_as(h5);
  EXPECT_EQ(h.format, "hdf5");
  ASSERT_EQ(h.recording.signals.size(), 1u);
  EXPECT_EQ(h.recording.signals[0].samples, s.samples);

  // The limits cut an HDF5 recording only, and say so.
  diag::OpenOptions o;
  o.limits.max_samples = 1000;
  o.limits.max_channel_samples = 1000;
  const diag::OpenedRecording hc = diag::open_recording_as(h5, o);
  EXPECT_TRUE(hc.cut);
  EXPECT_EQ(hc.recording.signals[0].samples.size(), 1000u);
  EXPECT_FALSE(diag::open_recording_as(table, o).cut);
}

TEST_F(OpenRecording, MatFilesGoToTheMatReaderEvenWhenHdf5Inside) {
  // A MAT 7.3 file is HDF5 inside: the .mat row comes first, so it is read as MATLAB variables,
  // never as a geardiag recording (here a geardiag recording named .mat is no MAT file: the MAT
  // reader refuses it, naming the file).
  diag::Recording rec;
  diag::Signal& s = rec.signals.emplace_back();
  s.name = "acc";
  s.fs_hz = 1000;
  s.samples.assign(100, 1.0);
  const fs::path p = dir_ / "fake.mat";
  diag::write_recording(p, rec);
  diag::OpenOptions o;
  o.fs_hz = 1000;
  try {
    diag::open_recording_as(p, o);
    FAIL() << "an HDF5 file named .mat was read as a recording";
  } catch (const diag::InputError& e) {
    // The MAT reader's refusal, naming the file: not a MATLAB file.
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(p.string() + ": ", 0), 0u) << what;
    EXPECT_NE(what.find("MAT"), std::string::npos) << what;
  }
  EXPECT_EQ(diag::recording_formats(), (std::vector<std::string>{"mat", "hdf5", "csv", "sound"}));
}

TEST_F(OpenRecording, ErrorsNameTheFile) {
  const fs::path missing = dir_ / "none.h5";
  try {
    diag::open_recording(missing);
    FAIL() << "a missing file was read";
  } catch (const diag::InputError& e) {
    EXPECT_EQ(std::string(e.what()), missing.string() + ": no such file");
  }
  // Bytes no reader takes: the last row (libsndfile) refuses, and the message names the file.
  const fs::path junk = write_text("junk.bin", "not a recording at all\n");
  try {
    diag::open_recording(junk);
    FAIL() << "junk was read";
  } catch (const diag::InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(junk.string(), 0), 0u) << e.what();
  }
  // A sampling rate that contradicts an HDF5 recording's own is refused, not ignored.
  diag::Recording rec;
  diag::Signal& s = rec.signals.emplace_back();
  s.name = "acc";
  s.fs_hz = 2000;
  s.samples.assign(100, 1.0);
  const fs::path h5 = dir_ / "r.h5";
  diag::write_recording(h5, rec);
  diag::OpenOptions o;
  o.fs_hz = 1000;
  try {
    diag::open_recording(h5, o);
    FAIL() << "a contradicting rate passed";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fs_hz"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("2000 Hz"), std::string::npos) << e.what();
  }
  o.fs_hz = 2000;  // the same rate: accepted
  EXPECT_EQ(diag::open_recording(h5, o).signals[0].samples.size(), 100u);
  o.fs_hz = -1;
  EXPECT_THROW(diag::open_recording(h5, o), diag::InputError);
}

}  // namespace
