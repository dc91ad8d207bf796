// HDF5 recordings (diag/io/hdf5.hpp): exact round trips, byte-identical output, streaming reads,
// refusal of bad files and samples, atomic writes, readability by h5py without geardiag, and
// reading a long recording's first part within limits (ReadLimits).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/hdf5_inflate.hpp"
#include "diag/io/recording.hpp"

namespace fs = std::filesystem;

namespace {

// A fresh directory per test (tests run in parallel under ctest -j).
class RecordingIo : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("recording_io"); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
};

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// Runs a shell command, returns its exit status (-1 when it did not exit normally).
int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string shell_quoted(const fs::path& p) { return "'" + p.string() + "'"; }

// Every kind of value a float64 dataset must carry unchanged.
std::vector<double> awkward_samples(std::size_t n) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = std::sin(0.37 * static_cast<double>(i)) * 1e-3;
  if (n >= 6) {
    v[0] = -0.0;
    v[1] = std::numeric_limits<double>::denorm_min();
    v[2] = std::numeric_limits<double>::max();
    v[3] = -std::numeric_limits<double>::lowest() / 3;
    v[4] = 0.1;
    v[5] = 1.0 / 3.0;
  }
  return v;
}

diag::Recording example_recording() {
  diag::Recording rec;
  diag::Signal a;
  a.name = "accel_x";
  a.fs_hz = 25600.0;
  a.unit = "m/s^2";
  a.direction = diag::Direction::kAlongLoa;
  a.location = "bearing_1";
  a.samples = awkward_samples(1001);
  diag::Signal b;
  b.name = "te";
  b.fs_hz = 1000.5;
  b.unit = "rad";
  b.direction = diag::Direction::kAngle;
  b.location = "output";
  b.samples = {1.0, 2.0, 3.0};
  diag::Signal empty_strings;  // empty unit and location, unspecified direction
  empty_strings.name = "ch0";
  empty_strings.fs_hz = 48000.0;
  empty_strings.samples = {42.0};
  rec.signals = {a, b, empty_strings};
  diag::Signal tacho;
  tacho.name = "input";
  tacho.fs_hz = 25600.0;
  tacho.direction = diag::Direction::kTacho;
  tacho.location = "input";
  tacho.samples = {0, 0, 1, 1, 0, 0, 1, 1};
  rec.tachos = {tacho};
  rec.gearbox_json = R"({"name": "unit-test", "note": "äöü \" quoted"})";
  rec.truth_json = R"({"defects": [{"gear": "z1", "size_rad": 1e-05}]})";
  rec.metadata = {{"source", "unit test"}, {"speed_rpm", "1796.5"}, {"utf8", "µm · °C"}};
  return rec;
}

void expect_same_signal(const diag::Signal& expected, const diag::Signal& actual) {
  EXPECT_EQ(expected.name, actual.name);
  EXPECT_EQ(expected.fs_hz, actual.fs_hz);
  EXPECT_EQ(expected.unit, actual.unit);
  EXPECT_EQ(expected.direction, actual.direction);
  EXPECT_EQ(expected.location, actual.location);
  ASSERT_EQ(expected.samples.size(), actual.samples.size());
  for (std::size_t i = 0; i < expected.samples.size(); ++i) {
    // Bit-exact, so that -0.0 and denormals count too.
    EXPECT_EQ(std::signbit(expected.samples[i]), std::signbit(actual.samples[i])) << i;
    EXPECT_EQ(expected.samples[i], actual.samples[i]) << expected.name << " sample " << i;
  }
}

void expect_same_recording(const diag::Recording& expected, const diag::Recording& actual) {
  ASSERT_EQ(expected.signals.size(), actual.signals.size());
  for (std::size_t i = 0; i < expected.signals.size(); ++i) {
    expect_same_signal(expected.signals[i], actual.signals[i]);
  }
  ASSERT_EQ(expected.tachos.size(), actual.tachos.size());
  for (std::size_t i = 0; i < expected.tachos.size(); ++i) {
    expect_same_signal(expected.tachos[i], actual.tachos[i]);
  }
  EXPECT_EQ(expected.gearbox_json, actual.gearbox_json);
  EXPECT_EQ(expected.truth_json, actual.truth_json);
  EXPECT_EQ(expected.metadata, actual.metadata);
}

template <typename F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const diag::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected diag::InputError";
  return "";
}

}  // namespace

TEST(Direction, NamesRoundTripAndUnknownNamesAreRefused) {
  for (auto d : {diag::Direction::kUnspecified, diag::Direction::kAlongLoa,
                 diag::Direction::kNormalLoa, diag::Direction::kHorizontal,
                 diag::Direction::kVertical, diag::Direction::kAngle, diag::Direction::kTacho}) {
    EXPECT_EQ(diag::direction_from_string(diag::to_string(d)), d);
  }
  EXPECT_EQ(diag::to_string(diag::Direction::kAlongLoa), "along_loa");
  EXPECT_THROW(diag::direction_from_string("sideways"), diag::InputError);
}

TEST(Recording, RequireNamesTheMissingChannelAndListsTheOthers) {
  const diag::Recording rec = example_recording();
  EXPECT_EQ(rec.find("te"), &rec.signals[1]);
  EXPECT_EQ(rec.find("input"), &rec.tachos[0]);
  EXPECT_EQ(rec.find("nope"), nullptr);
  const std::string message = input_error_of([&] { rec.require("nope", "analyze"); });
  EXPECT_NE(message.find("analyze"), std::string::npos) << message;
  EXPECT_NE(message.find("nope"), std::string::npos) << message;
  EXPECT_NE(message.find("accel_x"), std::string::npos) << message;
}

TEST(Recording, ValidateRefusesBadNamesRatesEmptyAndNonFiniteSamples) {
  diag::Signal s;
  s.name = "x";
  s.fs_hz = 100;
  s.samples = {1, 2, 3};
  EXPECT_NO_THROW(diag::validate(s, "here"));
  auto bad = s;
  bad.name = "";
  EXPECT_THROW(diag::validate(bad, "here"), diag::InputError);
  bad = s;
  bad.name = "a/b";
  EXPECT_THROW(diag::validate(bad, "here"), diag::InputError);
  bad = s;
  bad.fs_hz = 0;
  EXPECT_THROW(diag::validate(bad, "here"), diag::InputError);
  bad = s;
  bad.samples.clear();
  EXPECT_THROW(diag::validate(bad, "here"), diag::InputError);
  bad = s;
  bad.samples[2] = std::numeric_limits<double>::infinity();
  const std::string message = input_error_of([&] { diag::validate(bad, "here"); });
  EXPECT_NE(message.find("here"), std::string::npos) << message;
  EXPECT_NE(message.find("sample 2"), std::string::npos) << message;
}

TEST_F(RecordingIo, RoundTripKeepsSamplesAttributesAndStringsExactly) {
  const diag::Recording rec = example_recording();
  const fs::path path = dir_ / "rec.h5";
  diag::Hdf5WriteOptions options;
  options.chunk_samples = 64;  // several chunks, the last one partial
  diag::write_recording(path, rec, options);
  ASSERT_TRUE(diag::is_hdf5_file(path));
  expect_same_recording(rec, diag::read_recording(path));

  const diag::RecordingReader reader(path);
  const auto format = reader.format_attributes();
  EXPECT_EQ(format.at("format"), "geardiag-recording");
  EXPECT_EQ(format.at("format_version"), "2");
  EXPECT_EQ(format.at("creator").rfind("geardiag ", 0), 0u) << format.at("creator");
  EXPECT_FALSE(format.at("git_revision").empty());
}

TEST_F(RecordingIo, RoundTripWorksWithoutCompressionAndWithoutOptionalParts) {
  diag::Recording rec;
  diag::Signal s;
  s.name = "only";
  s.fs_hz = 1.0;
  s.samples = {3.5};
  rec.signals = {s};
  diag::Hdf5WriteOptions options;
  options.deflate_level = 0;
  const fs::path path = dir_ / "minimal.h5";
  diag::write_recording(path, rec, options);
  expect_same_recording(rec, diag::read_recording(path));
}

TEST_F(RecordingIo, SameRecordingGivesIdenticalBytes) {
  const diag::Recording rec = example_recording();
  diag::write_recording(dir_ / "first.h5", rec);
  // More than a second apart, so that any stored timestamp would show.
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  diag::write_recording(dir_ / "second.h5", rec);
  const std::string first = read_bytes(dir_ / "first.h5");
  EXPECT_FALSE(first.empty());
  EXPECT_TRUE(first == read_bytes(dir_ / "second.h5"));
}

TEST_F(RecordingIo, WritingReplacesAnExistingFile) {
  diag::Recording rec = example_recording();
  const fs::path path = dir_ / "rec.h5";
  diag::write_recording(path, rec);
  rec.signals.resize(1);
  rec.metadata["run"] = "second";
  diag::write_recording(path, rec);
  expect_same_recording(rec, diag::read_recording(path));
}

TEST_F(RecordingIo, ChunkedReadBlockEqualsTheSlice) {
  diag::Recording rec = example_recording();
  const fs::path path = dir_ / "rec.h5";
  diag::Hdf5WriteOptions options;
  options.chunk_samples = 100;
  diag::write_recording(path, rec, options);

  const diag::RecordingReader reader(path);
  ASSERT_EQ(reader.channels().size(), 4u);
  const diag::ChannelInfo& info = reader.channel("accel_x");
  EXPECT_EQ(info.group, "signals");
  EXPECT_EQ(info.length, 1001u);
  EXPECT_EQ(info.fs_hz, 25600.0);
  EXPECT_EQ(info.unit, "m/s^2");
  EXPECT_EQ(info.direction, diag::Direction::kAlongLoa);
  EXPECT_EQ(info.location, "bearing_1");
  EXPECT_EQ(reader.channel("tacho/input").group, "tacho");
  EXPECT_EQ(reader.gearbox_json(), rec.gearbox_json);

  const std::vector<double>& all = rec.signals[0].samples;
  // Blocks inside one chunk, across chunk borders, at the start, and ending at the very end.
  const std::pair<std::uint64_t, std::size_t> blocks[] = {
      {0, 1}, {0, 100}, {95, 10}, {150, 333}, {900, 101}, {1000, 1}, {1001, 0}};
  for (const auto& [offset, size] : blocks) {
    std::vector<double> out(size, -1.0);
    reader.read_block("accel_x", offset, out);
    for (std::size_t i = 0; i < size; ++i) {
      ASSERT_EQ(out[i], all[offset + i]) << "offset " << offset << " index " << i;
    }
  }
  std::vector<double> too_long(2);
  const std::string message = input_error_of([&] { reader.read_block("accel_x", 1000, too_long); });
  EXPECT_NE(message.find("past the end"), std::string::npos) << message;
  EXPECT_THROW(reader.channel("nope"), diag::InputError);
}

// Several recordings read and written at once on several threads (as `geardiag batch`'s workers
// do): each reader forks its crash guard's child while the other threads are reading or writing,
// and every block read must be the file's own, every file written byte-identical to the one
// written alone. Blocks are read by HDF5's own pipeline, never from the guard child's copy, so
// that the library is entered from every thread the whole time. Under AddressSanitizer the
// readers are opened before the threads start: its allocator (GCC 12's) is not made safe for a
// fork while another thread allocates, so the child can hang in it; glibc's allocator is.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kForkOnThreads = false;
#else
constexpr bool kForkOnThreads = true;
#endif
TEST_F(RecordingIo, ManyFilesReadAndWrittenAtOnceOnThreadsKeepTheirSamples) {
  diag::Hdf5ReadPath read_path;
  read_path.direct = false;
  read_path.reuse_survey = false;
  diag::hdf5_set_read_path(read_path);
  constexpr int kFiles = 4;
  std::vector<diag::Recording> recordings;
  std::vector<std::string> written_alone;
  diag::Hdf5WriteOptions options;
  options.chunk_samples = 64;
  for (int k = 0; k < kFiles; ++k) {
    diag::Recording rec = example_recording();
    for (double& x : rec.signals[0].samples) x += k;  // each file its own samples
    const fs::path path = dir_ / ("r" + std::to_string(k) + ".h5");
    diag::write_recording(path, rec, options);
    written_alone.push_back(read_bytes(path));
    recordings.push_back(std::move(rec));
  }
  constexpr int kRounds = 3;
  std::vector<std::unique_ptr<diag::RecordingReader>> opened_ahead;
  for (int k = 0; k < kFiles && !kForkOnThreads; ++k) {
    for (int round = 0; round < kRounds; ++round) {
      opened_ahead.push_back(
          std::make_unique<diag::RecordingReader>(dir_ / ("r" + std::to_string(k) + ".h5")));
    }
  }
  std::vector<std::string> errors(kFiles);
  std::vector<std::thread> threads;
  for (int k = 0; k < kFiles; ++k) {
    threads.emplace_back([&, k] {
      try {
        const std::vector<double>& all = recordings[k].signals[0].samples;
        for (int round = 0; round < kRounds; ++round) {
          std::unique_ptr<diag::RecordingReader> own;
          if (kForkOnThreads) {
            own = std::make_unique<diag::RecordingReader>(dir_ / ("r" + std::to_string(k) + ".h5"));
          }
          const diag::RecordingReader& reader =
              kForkOnThreads ? *own : *opened_ahead[static_cast<std::size_t>(k * kRounds + round)];
          std::vector<double> block(37);
          for (std::uint64_t at = 0; at + block.size() <= all.size(); at += block.size()) {
            reader.read_block("accel_x", at, block);
            for (std::size_t i = 0; i < block.size(); ++i) {
              if (block[i] != all[at + i]) throw std::runtime_error("a sample of another file");
            }
          }
          const fs::path copy =
              dir_ / ("w" + std::to_string(k) + "_" + std::to_string(round) + ".h5");
          diag::write_recording(copy, recordings[k], options);
          if (read_bytes(copy) != written_alone[k]) throw std::runtime_error("other bytes");
        }
      } catch (const std::exception& e) {
        errors[k] = e.what();
      }
    });
  }
  for (std::thread& t : threads) t.join();
  diag::hdf5_set_read_path({});
  for (int k = 0; k < kFiles; ++k) EXPECT_EQ(errors[k], "") << "file " << k;
}

TEST_F(RecordingIo, NonHdf5FileIsRefusedNamingTheFile) {
  const fs::path path = dir_ / "notes.h5";
  write_bytes(path, "time,a\n0,1\n");
  EXPECT_FALSE(diag::is_hdf5_file(path));
  const std::string message = input_error_of([&] { diag::read_recording(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("not an HDF5 file"), std::string::npos) << message;
}

TEST_F(RecordingIo, TruncatedCopyIsRefusedNamingTheFile) {
  const fs::path good = dir_ / "good.h5";
  diag::write_recording(good, example_recording());
  const std::string bytes = read_bytes(good);
  for (const std::size_t keep : {bytes.size() / 2, bytes.size() - 1, std::size_t{100}}) {
    const fs::path cut = dir_ / ("cut_" + std::to_string(keep) + ".h5");
    write_bytes(cut, bytes.substr(0, keep));
    const std::string message = input_error_of([&] { diag::read_recording(cut); });
    EXPECT_NE(message.find(cut.string()), std::string::npos) << message;
    EXPECT_NE(message.find("truncated"), std::string::npos) << message;
  }
}

TEST_F(RecordingIo, EmptyAndMissingFilesAreRefusedNamingTheFile) {
  const fs::path empty = dir_ / "empty.h5";
  write_bytes(empty, "");
  std::string message = input_error_of([&] { diag::read_recording(empty); });
  EXPECT_NE(message.find(empty.string()), std::string::npos) << message;
  const fs::path missing = dir_ / "missing.h5";
  message = input_error_of([&] { diag::RecordingReader reader(missing); });
  EXPECT_NE(message.find(missing.string()), std::string::npos) << message;
}

TEST_F(RecordingIo, Hdf5FileWithoutSignalsIsNotARecording) {
  const fs::path path = dir_ / "other.h5";
  ASSERT_EQ(run(std::string(GEARDIAG_PYTHON) +
                " -c \"import h5py, sys; h5py.File(sys.argv[1], 'w').create_dataset('x', "
                "data=[1.0, 2.0])\" " +
                shell_quoted(path)),
            0)
      << "h5py is required (scripts/install-deps installs python3-h5py)";
  const std::string message = input_error_of([&] { diag::read_recording(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("not a geardiag recording"), std::string::npos) << message;
}

TEST_F(RecordingIo, NonFiniteSamplesInAFileAreRefusedWithChannelAndIndex) {
  const fs::path path = dir_ / "nan.h5";
  ASSERT_EQ(run(std::string(GEARDIAG_PYTHON) +
                " -c \"import h5py, sys; f = h5py.File(sys.argv[1], 'w'); "
                "d = f.create_dataset('signals/vib', data=[0.0, 1.0, 2.0, float('nan')]); "
                "d.attrs['fs_hz'] = 10.0\" " +
                shell_quoted(path)),
            0)
      << "h5py is required (scripts/install-deps installs python3-h5py)";
  // The metadata reads fine; the samples do not.
  const diag::RecordingReader reader(path);
  EXPECT_EQ(reader.channel("vib").length, 4u);
  std::vector<double> head(3);
  reader.read_block("vib", 0, head);
  EXPECT_EQ(head[2], 2.0);
  const std::string message = input_error_of([&] { diag::read_recording(path); });
  EXPECT_NE(message.find("vib"), std::string::npos) << message;
  EXPECT_NE(message.find("sample 3"), std::string::npos) << message;
  EXPECT_NE(message.find("NaN"), std::string::npos) << message;
}

TEST_F(RecordingIo, NaNSampleIsRefusedOnWriteAndLeavesNoFile) {
  diag::Recording rec = example_recording();
  rec.signals[1].samples[2] = std::nan("");
  const fs::path path = dir_ / "rec.h5";
  const std::string message = input_error_of([&] { diag::write_recording(path, rec); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("'te'"), std::string::npos) << message;
  EXPECT_NE(message.find("sample 2"), std::string::npos) << message;
  EXPECT_TRUE(fs::is_empty(dir_)) << "a failed write left a file behind";
}

TEST_F(RecordingIo, FailedWriteLeavesNeitherTargetNorTemporaryFile) {
  const fs::path path = dir_ / "no_such_dir" / "rec.h5";
  const std::string message =
      input_error_of([&] { diag::write_recording(path, example_recording()); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_TRUE(fs::is_empty(dir_));

  // The target is a directory: refused before anything is written, no temporary file.
  const fs::path occupied = dir_ / "occupied.h5";
  fs::create_directories(occupied / "inside");
  EXPECT_THROW(diag::write_recording(occupied, example_recording()), diag::InputError);
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++entries;
  EXPECT_EQ(entries, 1u) << "only the pre-existing directory may remain";
}

TEST_F(RecordingIo, BadOptionsDuplicateNamesAndReservedMetadataAreRefused) {
  const fs::path path = dir_ / "rec.h5";
  diag::Hdf5WriteOptions options;
  options.deflate_level = 10;
  std::string message =
      input_error_of([&] { diag::write_recording(path, example_recording(), options); });
  EXPECT_NE(message.find("deflate_level"), std::string::npos) << message;
  options = {};
  options.chunk_samples = 0;
  EXPECT_THROW(diag::write_recording(path, example_recording(), options), diag::InputError);

  diag::Recording twice = example_recording();
  twice.signals.push_back(twice.signals[0]);
  message = input_error_of([&] { diag::write_recording(path, twice); });
  EXPECT_NE(message.find("accel_x"), std::string::npos) << message;

  diag::Recording reserved = example_recording();
  reserved.metadata["creator"] = "someone else";
  message = input_error_of([&] { diag::write_recording(path, reserved); });
  EXPECT_NE(message.find("creator"), std::string::npos) << message;
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(RecordingIo, H5pyReadsTheRecordingWithoutGeardiag) {
  // read_with_h5py.py asserts exactly this content.
  diag::Recording rec;
  diag::Signal s;
  s.name = "accel";
  s.fs_hz = 1000.0;
  s.unit = "m/s^2";
  s.direction = diag::Direction::kAlongLoa;
  s.location = "bearing_1";
  for (int i = 0; i < 1000; ++i) s.samples.push_back(0.5 * i);
  rec.signals = {s};
  diag::Signal tacho;
  tacho.name = "input";
  tacho.fs_hz = 1000.0;
  tacho.direction = diag::Direction::kTacho;
  tacho.location = "input";
  tacho.samples = {0, 1, 0, 1};
  rec.tachos = {tacho};
  rec.gearbox_json = R"({"name": "h5py-check"})";
  rec.truth_json = R"({"defects": []})";
  rec.metadata["source"] = "h5py test";
  const fs::path path = dir_ / "for_h5py.h5";
  diag::Hdf5WriteOptions options;
  options.chunk_samples = 128;
  diag::write_recording(path, rec, options);

  const std::string script = std::string(GEARDIAG_TESTS_DIR) + "/libdiag/read_with_h5py.py";
  EXPECT_EQ(
      run(std::string(GEARDIAG_PYTHON) + " " + shell_quoted(script) + " " + shell_quoted(path)), 0)
      << "read_with_h5py.py failed (h5py is required: scripts/install-deps installs python3-h5py)";
}

namespace {

// read_recording(path, ReadLimits): a long recording's first part within the limits, every
// channel cut at the same time, the samples those of the whole record; a recording within the
// limits read whole, equal to read_recording(path).
class ReadLimits : public RecordingIo {
 protected:
  void SetUp() override {
    RecordingIo::SetUp();
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

  fs::path path_;
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
