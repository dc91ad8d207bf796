// MAT files at their limits (docs/limits.md): level-4 dimensions whose byte count would wrap, a
// valid level-5 file with a large sparse matrix beside a vector (read, the matrix skipped with a
// note), and level 7.3 files (HDF5), read through the checks every HDF5 file passes: external
// storage and chunks never written refused, a numeric vector read as MATLAB wrote it.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/import.hpp"
#include "diag/io/open_recording.hpp"
#include "diag/io/recording.hpp"
#include "diag/io/recording_frames.hpp"

namespace fs = std::filesystem;

namespace {

class ImportMatLimits : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = geardiag_test::scratch_dir("import_mat");
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

void put32(std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }
void put_i32(std::string& out, std::int32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

// A level-5 data element (mat-file-format.pdf): tag, data, padding to 8 bytes.
std::string element(std::uint32_t type, const std::string& data) {
  std::string out;
  put32(out, type);
  put32(out, static_cast<std::uint32_t>(data.size()));
  out += data;
  out.append((8 - data.size() % 8) % 8, '\0');
  return out;
}

std::string matrix(std::uint32_t cls, std::vector<std::int32_t> dims, const std::string& name,
                   const std::vector<std::string>& parts) {
  std::string flags, d;
  put32(flags, cls);
  put32(flags, 0);
  for (std::int32_t x : dims) put_i32(d, x);
  std::string body = element(6, flags) + element(5, d) + element(1, name);
  for (const std::string& p : parts) body += p;
  return element(14, body);
}

std::string doubles(const std::vector<double>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
}

std::string level5_header() {
  std::string h = "MATLAB 5.0 MAT-file, written by a test";
  h.resize(124, ' ');
  h += std::string("\x00\x01", 2);
  h += "IM";
  return h;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const diag::InputError& e) {
    return e.what();
  }
  return "";
}

// A MAT 7.3 file: HDF5 with a 512-byte user block holding MATLAB's header; `fill(file)` adds
// the variables.
void write_mat73(const fs::path& path, const std::function<void(hid_t)>& fill) {
  const hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
  H5Pset_userblock(fcpl, 512);
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  fill(file);
  H5Fclose(file);
  H5Pclose(fcpl);
  std::string header = "MATLAB 7.3 MAT-file, written by a test";
  header.resize(124, ' ');
  header += std::string("\x00\x02", 2);
  header += "IM";
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.write(header.data(), static_cast<std::streamsize>(header.size()));
}

void matlab_class(hid_t obj, const char* cls) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, std::strlen(cls));
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(obj, "MATLAB_class", type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, type, cls);
  H5Aclose(attr);
  H5Sclose(space);
  H5Tclose(type);
}

// `bad` (10 s at 1 kHz) has a NaN at sample 7000 of its first channel, variable x: the whole read
// refuses the file naming the variable and the sample; read frame by frame, only the frame that
// holds it is refused, with the same message, and the frames before it are read.
void expect_nan_refuses_only_its_frame(const fs::path& bad, const diag::OpenOptions& o) {
  const std::string e = error_of([&] { diag::open_recording(bad, o); });
  EXPECT_NE(e.find("variable x, sample 7000"), std::string::npos) << e;
  const diag::OpenedFrames frames = diag::open_recording_frames(bad, o);
  EXPECT_EQ(frames.frames->frame(0, 6.0).signals[0].samples.size(), 6000u);
  const std::string fe = error_of([&] { frames.frames->frame(6.0, 9.0); });
  EXPECT_NE(fe.find(bad.filename().string()), std::string::npos) << fe;
  EXPECT_NE(fe.find("variable x, sample 7000"), std::string::npos) << fe;
}

}  // namespace

// rows x columns x 8 bytes x 2 (complex) = 2^64 wrapped to 0 bytes needed: refused by the
// dimensions themselves (before: an internal error, exit 3).
TEST_F(ImportMatLimits, Level4DimensionsThatWrapAreRefused) {
  std::string bytes;
  for (std::int32_t v : {0, 1 << 30, 1 << 30, 1, 2}) put_i32(bytes, v);  // MOPT, rows, cols, imag
  bytes += std::string("x\0", 2);
  bytes += std::string(64, '\0');
  const fs::path path = dir_ / "wrap.mat";
  std::ofstream(path, std::ios::binary) << bytes;
  const std::string e = error_of([&] { diag::import_recording(path, {.fs_hz = 100.0}); });
  EXPECT_NE(e.find("wrap.mat"), std::string::npos) << e;
  EXPECT_NE(e.find("1073741824 x 1073741824"), std::string::npos) << e;
}

// A 100000 x 100000 sparse matrix holding 3 values beside a 10-sample vector: a valid file. The
// vector is the channel; the matrix is skipped, with a note.
TEST_F(ImportMatLimits, SparseMatrixBesideAVectorIsSkippedWithANote) {
  std::string ir, jc;
  for (std::int32_t v : {0, 5, 99999}) put_i32(ir, v);
  std::vector<std::int32_t> cols(100001, 3);
  cols[0] = 0;
  for (std::int32_t v : cols) put_i32(jc, v);
  const std::string sparse = matrix(
      5, {100000, 100000}, "S", {element(5, ir), element(5, jc), element(9, doubles({1, 2, 3}))});
  std::vector<double> x;
  for (int i = 0; i < 10; ++i) x.push_back(0.5 * i);
  const std::string vector = matrix(6, {1, 10}, "x", {element(9, doubles(x))});
  const fs::path path = dir_ / "sparse.mat";
  std::ofstream(path, std::ios::binary) << level5_header() + sparse + vector;
  const diag::Recording rec = diag::import_recording(path, {.fs_hz = 100.0});
  ASSERT_EQ(rec.signals.size(), 1u);
  EXPECT_EQ(rec.signals[0].name, "x");
  EXPECT_EQ(rec.signals[0].samples, x);
  bool noted = false;
  for (const std::string& n : rec.notes)
    noted |= n.find("variable S skipped: a sparse matrix") == 0;
  EXPECT_TRUE(noted);
}

TEST_F(ImportMatLimits, Mat73VectorIsRead) {
  std::vector<double> x;
  for (int i = 0; i < 50; ++i) x.push_back(0.25 * i - 3);
  const fs::path path = dir_ / "v73.mat";
  write_mat73(path, [&](hid_t file) {
    const hsize_t dims[2] = {50, 1};  // MATLAB's 1 x 50, reversed
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t ds =
        H5Dcreate2(file, "x", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x.data());
    matlab_class(ds, "double");
    H5Dclose(ds);
    H5Sclose(space);
    const hid_t group = H5Gcreate2(file, "S", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    matlab_class(group, "double");
    const hid_t scalar = H5Screate(H5S_SCALAR);
    const hid_t attr =
        H5Acreate2(group, "MATLAB_sparse", H5T_STD_U64LE, scalar, H5P_DEFAULT, H5P_DEFAULT);
    const std::uint64_t rows = 100000;
    H5Awrite(attr, H5T_NATIVE_UINT64, &rows);
    H5Aclose(attr);
    H5Sclose(scalar);
    H5Gclose(group);
  });
  const diag::Recording rec = diag::import_recording(path, {.fs_hz = 10.0});
  ASSERT_EQ(rec.signals.size(), 1u);
  EXPECT_EQ(rec.signals[0].samples, x);
  bool noted = false;
  for (const std::string& n : rec.notes)
    noted |= n.find("variable S skipped: a sparse matrix") == 0;
  EXPECT_TRUE(noted);
}

// A level 5 file is read frame by frame: a vector of doubles, one stored as int16 and one in a
// compressed element (each over the 64 KiB read whole), and a scalar speed. Every frame holds the
// samples the whole read gives for its span, also when an earlier frame is asked for again (the
// compressed stream starts over); a NaN refuses the frame that holds it, naming the variable and
// sample; a compressed element cut short refuses the frames past its end.
TEST_F(ImportMatLimits, Level5IsReadFrameByFrameLikeTheWholeFile) {
  constexpr int kN = 10000;
  std::vector<double> x(kN), z(kN);
  std::string y16;
  for (int i = 0; i < kN; ++i) {
    x[i] = std::sin(0.01 * i);
    z[i] = std::sin(1e3 * i) * std::exp(std::cos(7.1 * i));  // hardly compressible: > 64 KiB
    const std::int16_t v = static_cast<std::int16_t>(i % 3000 - 1500);
    y16.append(reinterpret_cast<const char*>(&v), 2);
  }
  auto compressed = [](const std::string& element_bytes, std::size_t cut) {
    uLongf size = compressBound(element_bytes.size());
    std::string out(size, '\0');
    compress2(reinterpret_cast<Bytef*>(out.data()), &size,
              reinterpret_cast<const Bytef*>(element_bytes.data()), element_bytes.size(), 6);
    out.resize(size - cut);
    std::string tagged;
    put32(tagged, 15);
    put32(tagged, static_cast<std::uint32_t>(out.size()));
    return tagged + out;  // a top-level element is not padded
  };
  auto write = [&](const fs::path& path, const std::vector<double>& xs, std::size_t cut) {
    std::ofstream(path, std::ios::binary)
        << level5_header() + matrix(6, {1, kN}, "x", {element(9, doubles(xs))}) +
               matrix(6, {kN, 1}, "y", {element(3, y16)}) +
               compressed(matrix(6, {kN, 1}, "z", {element(9, doubles(z))}), cut) +
               matrix(6, {1, 1}, "X100RPM", {element(9, doubles({1797.0}))});
  };
  diag::OpenOptions o;
  o.fs_hz = 1000.0;
  const fs::path path = dir_ / "long5.mat";
  write(path, x, 0);
  const diag::Recording whole = diag::open_recording(path, o);
  ASSERT_EQ(whole.signals.size(), 3u);
  const diag::OpenedFrames opened = diag::open_recording_frames(path, o);
  ASSERT_NE(opened.frames, nullptr);
  EXPECT_DOUBLE_EQ(opened.frames->duration_s(), 10.0);
  auto expect_span = [&](double t0, double t1) {
    const diag::Recording f = opened.frames->frame(t0, t1);
    ASSERT_EQ(f.signals.size(), 3u);
    const auto first = static_cast<std::ptrdiff_t>(std::lround(t0 * 1000));
    for (std::size_t c = 0; c < 3; ++c) {
      const std::vector<double>& all = whole.signals[c].samples;
      EXPECT_EQ(f.signals[c].name, whole.signals[c].name);
      EXPECT_EQ(f.signals[c].samples,
                std::vector<double>(
                    all.begin() + first,
                    all.begin() + first + static_cast<std::ptrdiff_t>(f.signals[c].samples.size())))
          << f.signals[c].name << " from " << t0 << " s";
      EXPECT_EQ(static_cast<double>(f.signals[c].samples.size()),
                std::min(t1, 10.0) * 1000 - static_cast<double>(first));
    }
    EXPECT_EQ(f.metadata, whole.metadata);
    EXPECT_EQ(f.speed_rpm, 1797.0);
  };
  expect_span(0, 3);
  expect_span(3, 6);
  expect_span(6, 9);
  expect_span(9, 12);
  expect_span(1.5, 4.5);  // back: the compressed stream again from its start

  std::vector<double> with_nan = x;
  with_nan[7000] = std::nan("");
  const fs::path bad = dir_ / "nan5.mat";
  write(bad, with_nan, 0);
  expect_nan_refuses_only_its_frame(bad, o);

  const fs::path cut = dir_ / "cut5.mat";
  write(cut, x, 2000);  // z's compressed stream loses its last 2000 bytes
  EXPECT_NE(error_of([&] { diag::open_recording(cut, o); }).find("compressed data"),
            std::string::npos);
  const diag::OpenedFrames cut_frames = diag::open_recording_frames(cut, o);
  EXPECT_EQ(cut_frames.frames->frame(0, 3.0).signals[2].samples.size(), 3000u);
  const std::string ce = error_of([&] { cut_frames.frames->frame(9.0, 10.0); });
  EXPECT_NE(ce.find("'z'"), std::string::npos) << ce;
  EXPECT_NE(ce.find("compressed data"), std::string::npos) << ce;
}

// A level 7.3 file is read frame by frame (diag::open_recording_frames), as an HDF5 recording
// is: every frame holds exactly the samples the whole read gives for its span, with the same
// channels, metadata and speed; a NaN refuses the frame that holds it, naming the variable and
// the sample, not the others. A row vector and a column vector (HDF5 n x 1 and 1 x n).
TEST_F(ImportMatLimits, Mat73IsReadFrameByFrameLikeTheWholeFile) {
  constexpr hsize_t kN = 10000;
  std::vector<double> x(kN), y(kN);
  for (hsize_t i = 0; i < kN; ++i) {
    x[i] = std::sin(0.01 * static_cast<double>(i));
    y[i] = 0.5 * static_cast<double>(i) - 7;
  }
  auto write = [&](const fs::path& path, const std::vector<double>& xs) {
    write_mat73(path, [&](hid_t file) {
      const auto vector = [&](const char* name, hsize_t d0, hsize_t d1, const double* data) {
        const hsize_t dims[2] = {d0, d1};
        const hid_t space = H5Screate_simple(2, dims, nullptr);
        const hid_t ds =
            H5Dcreate2(file, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
        matlab_class(ds, "double");
        H5Dclose(ds);
        H5Sclose(space);
      };
      vector("x", kN, 1, xs.data());  // MATLAB's 1 x n
      vector("y", 1, kN, y.data());   // MATLAB's n x 1
      const double rpm = 1797;
      vector("X100RPM", 1, 1, &rpm);
    });
  };
  const fs::path path = dir_ / "long73.mat";
  write(path, x);
  diag::OpenOptions o;
  o.fs_hz = 1000.0;
  const diag::Recording whole = diag::open_recording(path, o);
  const diag::OpenedFrames opened = diag::open_recording_frames(path, o);
  EXPECT_EQ(opened.format, "mat");
  ASSERT_NE(opened.frames, nullptr);
  EXPECT_DOUBLE_EQ(opened.frames->duration_s(), 10.0);
  std::size_t at = 0;
  for (double t0 = 0; t0 < 10.0; t0 += 3.0) {  // 3 s frames, the last one short
    const diag::Recording f = opened.frames->frame(t0, t0 + 3.0);
    ASSERT_EQ(f.signals.size(), whole.signals.size());
    for (std::size_t c = 0; c < f.signals.size(); ++c) {
      EXPECT_EQ(f.signals[c].name, whole.signals[c].name);
      EXPECT_EQ(f.signals[c].fs_hz, 1000.0);
      const std::vector<double>& all = whole.signals[c].samples;
      ASSERT_LE(at + f.signals[c].samples.size(), all.size());
      EXPECT_TRUE(std::equal(f.signals[c].samples.begin(), f.signals[c].samples.end(),
                             all.begin() + static_cast<std::ptrdiff_t>(at)))
          << f.signals[c].name << " from " << t0 << " s";
    }
    EXPECT_EQ(f.metadata, whole.metadata);
    EXPECT_EQ(f.speed_rpm, 1797.0);
    EXPECT_FALSE(f.roles_stated);
    at += f.signals[0].samples.size();
  }
  EXPECT_EQ(at, kN);  // every sample once

  std::vector<double> with_nan = x;
  with_nan[7000] = std::nan("");
  const fs::path bad = dir_ / "nan73.mat";
  write(bad, with_nan);
  expect_nan_refuses_only_its_frame(bad, o);
}

// 1e8 doubles declared, none written, in a 2 KB file: refused at once (before: 8 GB of zeros).
TEST_F(ImportMatLimits, Mat73UnwrittenVariableIsRefused) {
  const fs::path path = dir_ / "empty_chunks.mat";
  write_mat73(path, [&](hid_t file) {
    const hsize_t dims[2] = {100000000, 1}, chunk[2] = {65536, 1};
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 2, chunk);
    H5Pset_deflate(dcpl, 3);
    const hid_t ds = H5Dcreate2(file, "x", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    matlab_class(ds, "double");
    H5Dclose(ds);
    H5Pclose(dcpl);
    H5Sclose(space);
  });
  const std::string e = error_of([&] { diag::import_recording(path, {.fs_hz = 10.0}); });
  EXPECT_NE(e.find("empty_chunks.mat"), std::string::npos) << e;
  EXPECT_NE(e.find("/x"), std::string::npos) << e;
  EXPECT_NE(e.find("never written"), std::string::npos) << e;
}

TEST_F(ImportMatLimits, Mat73ExternalStorageIsRefused) {
  const fs::path secret = dir_ / "secret.txt";
  std::ofstream(secret) << std::string(400, 's');
  const fs::path path = dir_ / "external.mat";
  write_mat73(path, [&](hid_t file) {
    const hsize_t dims[2] = {50, 1};
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_external(dcpl, secret.c_str(), 0, 400);
    const hid_t ds = H5Dcreate2(file, "x", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    matlab_class(ds, "double");
    H5Dclose(ds);
    H5Pclose(dcpl);
    H5Sclose(space);
  });
  const std::string e = error_of([&] { diag::import_recording(path, {.fs_hz = 10.0}); });
  EXPECT_NE(e.find("external.mat"), std::string::npos) << e;
  EXPECT_NE(e.find("external files"), std::string::npos) << e;
}
