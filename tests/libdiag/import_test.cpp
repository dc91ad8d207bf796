// Import of measured data (diag/io/import.hpp): CSV (plain and gzip), WAV, MAT, HDF5, with the
// sampling-rate rules and the errors that name the file, line and column; then the real CWRU and
// SpectraQuest files from ../shared/data when present.
#include "diag/io/import.hpp"

#include <gtest/gtest.h>
#include <matio.h>
#include <sndfile.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"

namespace fs = std::filesystem;

namespace {

class Import : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("import"); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write_text(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  fs::path dir_;
};

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

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

diag::ImportOptions with_fs(double fs_hz) {
  diag::ImportOptions options;
  options.fs_hz = fs_hz;
  return options;
}

// "time,a,b" with time stamps printed to the microsecond, as data loggers often do.
std::string csv_with_time(int rows, double fs_hz) {
  std::string text = "time,a,b\n";
  char line[128];
  for (int i = 0; i < rows; ++i) {
    std::snprintf(line, sizeof line, "%.6f,%.17g,%d\n", i / fs_hz, std::sin(0.1 * i), i);
    text += line;
  }
  return text;
}

}  // namespace

TEST_F(Import, CsvTimeColumnGivesTheSamplingRateAndIsNotAChannel) {
  // Time stamps (period 333.3 us) rounded to 1 us over a 0.33 s span: the rate derived from
  // the first and last stamps is exact to ~3e-6 relative.
  constexpr double kRateRelTol = 1e-5;
  const fs::path path = write_text("log.csv", csv_with_time(1000, 3000.0));
  const diag::Recording rec = diag::import_recording(path);
  ASSERT_EQ(rec.signals.size(), 2u);
  EXPECT_EQ(rec.signals[0].name, "a");
  EXPECT_EQ(rec.signals[1].name, "b");
  EXPECT_NEAR(rec.signals[0].fs_hz, 3000.0, 3000.0 * kRateRelTol);
  ASSERT_EQ(rec.signals[0].samples.size(), 1000u);
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ(rec.signals[0].samples[i], std::sin(0.1 * i)) << i;  // %.17g reads back exactly
    ASSERT_EQ(rec.signals[1].samples[i], i);
  }
  EXPECT_EQ(rec.metadata.at("source"), "log.csv");

  // An explicit rate that agrees within 0.1 % is accepted and used.
  EXPECT_EQ(diag::import_recording(path, with_fs(3001.0)).signals[0].fs_hz, 3001.0);
}

TEST_F(Import, CsvRateThatDisagreesWithTheTimeColumnIsRefused) {
  const fs::path path = write_text("log.csv", csv_with_time(100, 1000.0));
  const std::string message =
      input_error_of([&] { diag::import_recording(path, with_fs(1010.0)); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "disagrees");
}

TEST_F(Import, CsvWithoutTimeColumnNeedsTheSamplingRate) {
  const fs::path path = write_text("vib.csv", "a1;a2\n1;2\n3;4\n5;6\n");
  const std::string message = input_error_of([&] { diag::import_recording(path); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "fs_hz");
  const diag::Recording rec = diag::import_recording(path, with_fs(512.0));
  ASSERT_EQ(rec.signals.size(), 2u);
  EXPECT_EQ(rec.signals[1].name, "a2");
  EXPECT_EQ(rec.signals[1].fs_hz, 512.0);
  EXPECT_EQ(rec.signals[1].samples, (std::vector<double>{2, 4, 6}));
  EXPECT_THROW(diag::import_recording(path, with_fs(-1.0)), diag::InputError);
}

TEST_F(Import, CsvAcceptsCrLfQuotesBlankLinesAndHeaderlessFiles) {
  const fs::path quoted =
      write_text("q.csv", "\"t\", \"x (m/s^2)\"\r\n0,+1.5\r\n\r\n0.5,-2e-3\r\n");
  const diag::Recording rec = diag::import_recording(quoted);
  ASSERT_EQ(rec.signals.size(), 1u);
  EXPECT_EQ(rec.signals[0].name, "x (m_s^2)");  // '/' would split the HDF5 path
  EXPECT_EQ(rec.signals[0].fs_hz, 2.0);
  EXPECT_EQ(rec.signals[0].samples, (std::vector<double>{1.5, -2e-3}));

  const fs::path headerless = write_text("n.csv", "1,2\n3,4\n");
  const diag::Recording plain = diag::import_recording(headerless, with_fs(10.0));
  ASSERT_EQ(plain.signals.size(), 2u);
  EXPECT_EQ(plain.signals[0].name, "ch0");
  EXPECT_EQ(plain.signals[0].samples, (std::vector<double>{1, 3}));
}

TEST_F(Import, CsvRaggedRowIsRefusedNamingTheLine) {
  const fs::path path = write_text("ragged.csv", "a,b,c\n1,2,3\n4,5,6\n7,8\n");
  const std::string message = input_error_of([&] { diag::import_recording(path, with_fs(1.0)); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "line 4");
  EXPECT_CONTAINS(message, "ragged");
}

TEST_F(Import, CsvNonNumericFieldIsRefusedNamingLineAndColumn) {
  const fs::path path = write_text("text.csv", "a,b\n1,2\n3,oops\n");
  const std::string message = input_error_of([&] { diag::import_recording(path, with_fs(1.0)); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "line 3, column 2 ('b')");
  EXPECT_CONTAINS(message, "'oops' is not a number");
}

TEST_F(Import, CsvNaNAndInfinityAreRefusedNamingTheLine) {
  for (const char* bad : {"nan", "inf", "-Infinity"}) {
    const fs::path path = write_text("bad.csv", std::string("a\n1\n2\n") + bad + "\n");
    const std::string message = input_error_of([&] { diag::import_recording(path, with_fs(1.0)); });
    EXPECT_CONTAINS(message, "line 4");
    EXPECT_CONTAINS(message, "finite");
  }
}

TEST_F(Import, EmptyAndHeaderOnlyFilesAreRefused) {
  const fs::path empty = write_text("empty.csv", "");
  std::string message = input_error_of([&] { diag::import_recording(empty, with_fs(1.0)); });
  EXPECT_CONTAINS(message, empty.string());
  EXPECT_CONTAINS(message, "empty");
  const fs::path header_only = write_text("header.csv", "a,b\n");
  message = input_error_of([&] { diag::import_recording(header_only, with_fs(1.0)); });
  EXPECT_CONTAINS(message, "no data rows");
  const fs::path missing = dir_ / "missing.csv";
  message = input_error_of([&] { diag::import_recording(missing, with_fs(1.0)); });
  EXPECT_CONTAINS(message, missing.string());
}

TEST_F(Import, CsvUnevenTimeStampsAreRefused) {
  const fs::path path =
      write_text("uneven.csv", "time,a\n0,1\n0.001,2\n0.002,3\n0.004,4\n0.005,5\n");
  const std::string message = input_error_of([&] { diag::import_recording(path); });
  EXPECT_CONTAINS(message, "uniformly spaced");
}

TEST_F(Import, GzipCompressedCsvReadsLikeThePlainFile) {
  const std::string text = csv_with_time(500, 1000.0);
  const fs::path plain = write_text("log.csv", text);
  const fs::path packed = dir_ / "log.csv.gz";
  gzFile gz = gzopen(packed.c_str(), "wb");
  ASSERT_NE(gz, nullptr);
  ASSERT_EQ(gzwrite(gz, text.data(), static_cast<unsigned>(text.size())),
            static_cast<int>(text.size()));
  ASSERT_EQ(gzclose(gz), Z_OK);

  const diag::Recording a = diag::import_recording(plain);
  const diag::Recording b = diag::import_recording(packed);
  ASSERT_EQ(b.signals.size(), 2u);
  EXPECT_EQ(b.signals[0].fs_hz, a.signals[0].fs_hz);
  EXPECT_EQ(b.signals[0].samples, a.signals[0].samples);
  EXPECT_EQ(b.metadata.at("source"), "log.csv.gz");

  // A cut-off gzip stream is an error, not a silently shorter recording.
  std::ifstream in(packed, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path cut = write_text("cut.csv.gz", bytes.substr(0, bytes.size() / 2));
  const std::string message = input_error_of([&] { diag::import_recording(cut); });
  EXPECT_CONTAINS(message, cut.string());
}

TEST_F(Import, WavGivesOneChannelPerAudioChannelAndItsRate) {
  const fs::path path = dir_ / "two.wav";
  SF_INFO info{};
  info.samplerate = 8000;
  info.channels = 2;
  info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
  SNDFILE* file = sf_open(path.c_str(), SFM_WRITE, &info);
  ASSERT_NE(file, nullptr) << sf_strerror(nullptr);
  std::vector<double> frames;
  for (int i = 0; i < 400; ++i) {
    frames.push_back(i / 512.0);  // exactly representable in float32
    frames.push_back(-i / 1024.0);
  }
  ASSERT_EQ(sf_writef_double(file, frames.data(), 400), 400);
  sf_close(file);

  const diag::Recording rec = diag::import_recording(path);
  ASSERT_EQ(rec.signals.size(), 2u);
  EXPECT_EQ(rec.signals[0].name, "ch0");
  EXPECT_EQ(rec.signals[1].name, "ch1");
  EXPECT_EQ(rec.signals[0].fs_hz, 8000.0);
  ASSERT_EQ(rec.signals[1].samples.size(), 400u);
  EXPECT_EQ(rec.signals[0].samples[100], 100 / 512.0);
  EXPECT_EQ(rec.signals[1].samples[399], -399 / 1024.0);

  EXPECT_EQ(diag::import_recording(path, with_fs(8192.0)).signals[1].fs_hz, 8192.0);
}

TEST_F(Import, UnknownFormatIsRefusedNamingTheFile) {
  const fs::path path = write_text("data.bin", "this is not a sound file at all");
  const std::string message = input_error_of([&] { diag::import_recording(path); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "unrecognised format");
}

TEST_F(Import, MatVectorsBecomeChannelsAndScalarsMetadata) {
  const fs::path path = dir_ / "rig.mat";
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(mat, nullptr);
  std::vector<double> de = {0.25, -0.5, 1e-3, 4.0};
  std::vector<std::int16_t> counts = {1, -2, 3};
  double rpm = 1796.25;
  std::vector<double> matrix(6, 1.0);
  size_t column_dims[2] = {4, 1};
  size_t row_dims[2] = {1, 3};
  size_t scalar_dims[2] = {1, 1};
  size_t matrix_dims[2] = {2, 3};
  struct Var {
    const char* name;
    matio_classes cls;
    matio_types type;
    size_t* dims;
    void* data;
  };
  for (const Var& v : {Var{"X001_DE_time", MAT_C_DOUBLE, MAT_T_DOUBLE, column_dims, de.data()},
                       Var{"counts", MAT_C_INT16, MAT_T_INT16, row_dims, counts.data()},
                       Var{"X001RPM", MAT_C_DOUBLE, MAT_T_DOUBLE, scalar_dims, &rpm},
                       Var{"image", MAT_C_DOUBLE, MAT_T_DOUBLE, matrix_dims, matrix.data()}}) {
    matvar_t* var = Mat_VarCreate(v.name, v.cls, v.type, 2, v.dims, v.data, 0);
    ASSERT_NE(var, nullptr);
    ASSERT_EQ(Mat_VarWrite(mat, var, MAT_COMPRESSION_ZLIB), 0);
    Mat_VarFree(var);
  }
  Mat_Close(mat);

  const std::string message = input_error_of([&] { diag::import_recording(path); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "fs_hz");

  const diag::Recording rec = diag::import_recording(path, with_fs(12000.0));
  ASSERT_EQ(rec.signals.size(), 2u);  // the 2x3 matrix is not a channel
  EXPECT_EQ(rec.signals[0].name, "X001_DE_time");
  EXPECT_EQ(rec.signals[0].samples, de);
  EXPECT_EQ(rec.signals[0].fs_hz, 12000.0);
  EXPECT_EQ(rec.signals[1].name, "counts");
  EXPECT_EQ(rec.signals[1].samples, (std::vector<double>{1, -2, 3}));
  EXPECT_EQ(rec.metadata.at("X001RPM"), "1796.25");
  EXPECT_EQ(rec.metadata.count("image"), 0u);
  // CWRU's naming gives the location (a note says so); any other name gives none, and nothing
  // else (unit, role, direction) is read from a name.
  EXPECT_EQ(rec.signals[0].location, "drive_end");
  EXPECT_EQ(rec.signals[0].unit, "");
  EXPECT_EQ(rec.signals[0].role, diag::Role::kVibration);
  EXPECT_EQ(rec.signals[1].location, "");
  bool noted = false;
  for (const auto& n : rec.notes) noted = noted || n.find("X001_DE_time at drive_end") != n.npos;
  EXPECT_TRUE(noted);
}

// ---- damaged files (docs/limits.md): refused naming the file and the damage, never read as data
// ----

TEST_F(Import, CsvNulByteIsRefusedNotGluedToTheNextRow) {
  // A C-string reader stopped at the NUL and read "3" + "5,6" as a = 35.
  const fs::path path = write_text("nul.csv", std::string("a,b\n1,2\n3\0,4\n5,6\n", 17));
  const std::string message = input_error_of([&] { diag::import_recording(path, with_fs(10)); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "line 3");
  EXPECT_CONTAINS(message, "NUL byte");
}

TEST_F(Import, PlainTextNamedGzIsRefused) {
  const fs::path path = write_text("plain.csv.gz", csv_with_time(10, 100.0));
  EXPECT_CONTAINS(input_error_of([&] { diag::import_recording(path); }), "not gzip");
}

TEST_F(Import, WavShorterThanItsHeaderSaysIsRefused) {
  const fs::path path = dir_ / "cut.wav";
  SF_INFO info{};
  info.samplerate = 8000;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SNDFILE* file = sf_open(path.c_str(), SFM_WRITE, &info);
  ASSERT_NE(file, nullptr) << sf_strerror(nullptr);
  const std::vector<double> frames(4000, 0.25);
  ASSERT_EQ(sf_writef_double(file, frames.data(), 4000), 4000);
  sf_close(file);
  fs::resize_file(path, fs::file_size(path) - 3000);  // 1500 of 4000 frames cut off
  const std::string message = input_error_of([&] { diag::import_recording(path); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "truncated");
}

TEST_F(Import, MatTruncatedOrWithLyingDimensionsIsRefused) {
  const fs::path path = dir_ / "v.mat";
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(mat, nullptr);
  std::vector<double> x(1000, -0.757);
  size_t dims[2] = {1000, 1};
  for (const char* name : {"first", "second"}) {
    matvar_t* var = Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, x.data(), 0);
    ASSERT_EQ(Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE), 0);
    Mat_VarFree(var);
  }
  Mat_Close(mat);
  EXPECT_EQ(diag::import_recording(path, with_fs(100)).signals.size(), 2u);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  // The second variable cut short: refused, not dropped nor padded with zeros.
  const fs::path cut = write_text("cut.mat", bytes.substr(0, bytes.size() - 100));
  const std::string message = input_error_of([&] { diag::import_recording(cut, with_fs(100)); });
  EXPECT_CONTAINS(message, cut.string());
  EXPECT_CONTAINS(message, "variable 2");
  EXPECT_CONTAINS(message, "truncated");

  // The first variable's dimensions claim 10^8 rows (at byte 128 + 8 + 16 + 8).
  std::string lie = bytes;
  const std::int32_t rows = 100000000;
  std::memcpy(lie.data() + 160, &rows, sizeof rows);
  const fs::path lying = write_text("lie.mat", lie);
  EXPECT_CONTAINS(input_error_of([&] { diag::import_recording(lying, with_fs(100)); }), "'first'");
}

TEST_F(Import, FifoAndDeviceAreRefusedWithoutWaiting) {
  // Opening a FIFO without a writer would block forever; /dev/zero never ends.
  const fs::path fifo = dir_ / "pipe.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_CONTAINS(input_error_of([&] { diag::import_recording(fifo); }), "FIFO");
  const fs::path zero = dir_ / "zero.csv";
  fs::create_symlink("/dev/zero", zero);
  EXPECT_CONTAINS(input_error_of([&] { diag::import_recording(zero); }), "device");
  EXPECT_CONTAINS(input_error_of([&] { diag::read_recording(zero); }), "device");
}

TEST_F(Import, Hdf5RecordingImportsAsItIsAndRefusesAnotherRate) {
  diag::Recording rec;
  diag::Signal s;
  s.name = "x";
  s.fs_hz = 100.0;
  s.samples = {1, 2, 3};
  rec.signals = {s};
  rec.metadata["source"] = "original.csv";
  const fs::path path = dir_ / "rec.h5";
  diag::write_recording(path, rec);
  const diag::Recording back = diag::import_recording(path);
  EXPECT_EQ(back.signals[0].samples, s.samples);
  EXPECT_EQ(back.metadata.at("source"), "original.csv");  // kept, not replaced
  EXPECT_NO_THROW(diag::import_recording(path, with_fs(100.0)));
  EXPECT_THROW(diag::import_recording(path, with_fs(200.0)), diag::InputError);
}

// ---- real data: ../shared/data ------------------------------------------------------------

namespace {

struct CwruFile {
  const char* file;
  double fs_hz;         // from the data set's README
  const char* prefix;   // variable name prefix
  bool has_base;        // X<nnn>_BA_time present
  std::size_t samples;  // per channel
  const char* rpm;      // X<nnn>RPM
  double first_de;      // X<nnn>_DE_time[0]
};

// Sample counts, RPM and first drive-end sample obtained once, independently of geardiag, with
//   python3 -c "import scipy.io as s; m = s.loadmat('cwru-bearing/F');
//               print({k: (v.shape, repr(float(v.ravel()[0]))) for k, v in m.items()})"
// (scipy 1.10.1); the RPM variables are stored as uint16.
const CwruFile kCwruFiles[] = {
    {"normal_0.mat", 48000.0, "X097", false, 243938, "1796", 0.05319692307692307},
    {"IR007_0.mat", 12000.0, "X105", true, 121265, "1797", -0.08300435129740519},
    {"OR007@6_0.mat", 12000.0, "X130", true, 121991, "1796", 0.008527844311377245},
    {"B007_0.mat", 12000.0, "X118", true, 122571, "1796", -0.0027613972055888225},
};

}  // namespace

TEST(ImportRealData, CwruMatFilesGiveDriveFanAndBaseChannelsAndTheRpm) {
  const fs::path dir = fs::path(GEARDIAG_SHARED_DATA_DIR) / "cwru-bearing";
  if (!fs::is_directory(dir)) GTEST_SKIP() << "real data not present: " << dir;
  for (const CwruFile& f : kCwruFiles) {
    SCOPED_TRACE(f.file);
    const diag::Recording rec = diag::import_recording(dir / f.file, with_fs(f.fs_hz));
    const std::string p = f.prefix;
    std::vector<std::string> expected = {p + "_DE_time", p + "_FE_time"};
    if (f.has_base) expected.push_back(p + "_BA_time");
    std::vector<std::string> names;
    for (const auto& s : rec.signals) names.push_back(s.name);
    EXPECT_EQ(names, expected);
    for (const auto& s : rec.signals) {
      EXPECT_EQ(s.samples.size(), f.samples) << s.name;
      EXPECT_EQ(s.fs_hz, f.fs_hz);
    }
    ASSERT_FALSE(rec.signals.empty());
    EXPECT_EQ(rec.signals[0].samples[0], f.first_de);
    ASSERT_EQ(rec.metadata.count(p + "RPM"), 1u);
    EXPECT_EQ(rec.metadata.at(p + "RPM"), f.rpm);
    const double rpm = std::stod(rec.metadata.at(p + "RPM"));
    EXPECT_GE(rpm, 1796.0);
    EXPECT_LE(rpm, 1797.0);
    EXPECT_EQ(rec.metadata.at("source"), f.file);
  }
}

TEST(ImportRealData, SpectraQuestCsvGzGivesFourChannelsAndEveryRow) {
  const fs::path dir = fs::path(GEARDIAG_SHARED_DATA_DIR) / "spectraquest-gearbox";
  if (!fs::is_directory(dir)) GTEST_SKIP() << "real data not present: " << dir;
  // Row counts (without the header) and the first data row, obtained once with
  //   python3 -c "import gzip, csv; r = list(csv.reader(gzip.open('F', 'rt'))); print(len(r) - 1,
  //   r[1])"
  // and cross-checked with `zcat F | wc -l` (one more, the header).
  struct Expected {
    const char* file;
    std::size_t rows;
    double first[4];
  };
  const Expected files[] = {
      {"h30hz0.csv.gz", 88832, {4.63671, 0.516978, -3.20594, 1.82241}},
      {"b30hz0.csv.gz", 88320, {2.35039, 1.45487, -1.66708, -2.05561}},
  };
  // The set publishes no sampling rate and has no time column: the test gives one.
  constexpr double kAnyFsHz = 2560.0;
  for (const Expected& f : files) {
    SCOPED_TRACE(f.file);
    const diag::Recording rec = diag::import_recording(dir / f.file, with_fs(kAnyFsHz));
    ASSERT_EQ(rec.signals.size(), 4u);
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(rec.signals[c].name, "a" + std::to_string(c + 1));
      EXPECT_EQ(rec.signals[c].samples.size(), f.rows);
      EXPECT_EQ(rec.signals[c].samples[0], f.first[c]);
      EXPECT_EQ(rec.signals[c].fs_hz, kAnyFsHz);
    }
    EXPECT_EQ(rec.metadata.at("source"), f.file);
    EXPECT_THROW(diag::import_recording(dir / f.file), diag::InputError);  // no rate, no time
  }
}
