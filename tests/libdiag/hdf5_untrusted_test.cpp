// Untrusted HDF5 files (docs/limits.md): what a file may point at outside itself, what it may
// declare without holding, and the crash guard that reads it first. Every rule is checked in one
// place (libdiag/src/io/hdf5_file.hpp) for every HDF5 open: recordings, read_hdf5_arrays (the
// face-gear tables) and MAT 7.3 files; each test here builds a file that breaks one rule with
// HDF5's own API and expects the refusal, naming the file, the object and the reason.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "../../libdiag/src/io/crash_guard.hpp"
#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/hdf5_arrays.hpp"
#include "diag/io/import.hpp"
#include "diag/io/recording.hpp"

namespace fs = std::filesystem;

namespace {

class Hdf5Untrusted : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = geardiag_test::scratch_dir("hdf5_untrusted");
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  void TearDown() override {
    diag::hdf5_detail::set_guard_test_hooks(nullptr, nullptr);
    fs::remove_all(dir_);
  }
  fs::path dir_;
};

diag::Recording small_recording(double scale = 1.0) {
  diag::Recording rec;
  diag::Signal s;
  s.name = "acc";
  s.fs_hz = 1000.0;
  s.unit = "m/s^2";
  for (int i = 0; i < 4000; ++i) s.samples.push_back(scale * std::sin(0.01 * i));
  rec.signals.push_back(s);
  return rec;
}

// Writes the geardiag recording attributes on channel `ds` and the root, so that only the rule
// under test can refuse the file.
void recording_attributes(hid_t file, hid_t ds) {
  auto text = [](hid_t obj, const char* name, const char* value) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, std::strlen(value) + 1);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attr, type, value);
    H5Aclose(attr);
    H5Sclose(space);
    H5Tclose(type);
  };
  const hid_t space = H5Screate(H5S_SCALAR);
  const double fs = 1000.0;
  const hid_t attr = H5Acreate2(ds, "fs_hz", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, H5T_NATIVE_DOUBLE, &fs);
  H5Aclose(attr);
  H5Sclose(space);
  text(ds, "unit", "m/s^2");
  text(file, "format", "geardiag-recording");
}

// A recording whose one channel /signals/acc is made by `make(group)` (which returns the dataset).
void write_crafted(const fs::path& path, const std::function<hid_t(hid_t group)>& make) {
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t group = H5Gcreate2(file, "/signals", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const hid_t ds = make(group);
  ASSERT_GE(ds, 0);
  recording_attributes(file, ds);
  H5Dclose(ds);
  H5Gclose(group);
  ASSERT_GE(H5Fclose(file), 0);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const diag::InputError& e) {
    return e.what();
  }
  return "";
}

void expect_refused(const std::string& error, const std::vector<std::string>& parts) {
  EXPECT_FALSE(error.empty()) << "not refused";
  for (const std::string& p : parts) EXPECT_NE(error.find(p), std::string::npos) << error;
}

}  // namespace

// A channel whose bytes live in another file (an external file list): the recording must not
// read that file, whatever it is (here a "secret" of the right size to pass any size check).
TEST_F(Hdf5Untrusted, ExternalStorageIsRefusedForRecordingsAndArrays) {
  const fs::path secret = dir_ / "secret.bin";
  {
    std::ofstream out(secret, std::ios::binary);
    const std::vector<double> values(1000, 42.0);
    out.write(reinterpret_cast<const char*>(values.data()), 8000);
  }
  const fs::path path = dir_ / "external.h5";
  write_crafted(path, [&](hid_t group) {
    const hsize_t n = 1000;
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_external(dcpl, secret.c_str(), 0, 8000);
    const hid_t ds =
        H5Dcreate2(group, "acc", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    H5Pclose(dcpl);
    H5Sclose(space);
    return ds;
  });
  expect_refused(error_of([&] { diag::read_recording(path); }),
                 {"external.h5", "/signals/acc", "external files"});
  expect_refused(error_of([&] { diag::RecordingReader reader(path); }), {"external files"});
  expect_refused(error_of([&] { diag::read_hdf5_arrays(path, {"/signals/acc"}); }),
                 {"external.h5", "/signals/acc", "external files"});
  expect_refused(error_of([&] { diag::import_recording(path); }), {"external files"});
}

TEST_F(Hdf5Untrusted, ExternalLinksAndVirtualDatasetsAreRefused) {
  diag::write_recording(dir_ / "other.h5", small_recording());
  const fs::path linked = dir_ / "linked.h5";
  write_crafted(linked, [&](hid_t group) {
    H5Lcreate_external((dir_ / "other.h5").c_str(), "/signals/acc", group, "elsewhere", H5P_DEFAULT,
                       H5P_DEFAULT);
    const hsize_t n = 10;
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t ds =
        H5Dcreate2(group, "acc", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const std::vector<double> v(10, 1.0);
    H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Sclose(space);
    return ds;
  });
  expect_refused(error_of([&] { diag::read_recording(linked); }),
                 {"linked.h5", "/signals/elsewhere", "external link"});
  // An external link anywhere in the file refuses it, also where the reader never looks.
  expect_refused(error_of([&] { diag::read_hdf5_arrays(linked, {"/signals/acc"}); }),
                 {"external link"});

  const fs::path virt = dir_ / "virtual.h5";
  write_crafted(virt, [&](hid_t group) {
    const hsize_t n = 4000;
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    const hid_t src_space = H5Screate_simple(1, &n, nullptr);
    H5Pset_virtual(dcpl, space, (dir_ / "other.h5").c_str(), "/signals/acc", src_space);
    const hid_t ds =
        H5Dcreate2(group, "acc", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    H5Sclose(src_space);
    H5Pclose(dcpl);
    H5Sclose(space);
    return ds;
  });
  expect_refused(error_of([&] { diag::read_recording(virt); }),
                 {"virtual.h5", "/signals/acc", "virtual dataset"});
}

// A channel declaring 200 000 samples of which 20 000 were written: HDF5 would read the rest as
// its fill value (zeros); refused, as the contiguous equivalent always was.
TEST_F(Hdf5Untrusted, ChunksNeverWrittenAreRefused) {
  for (const bool hole_in_middle : {false, true}) {
    const fs::path path = dir_ / (hole_in_middle ? "hole.h5" : "short.h5");
    write_crafted(path, [&](hid_t group) {
      const hsize_t n = 200000, chunk = 10000, part = 20000;
      const hid_t space = H5Screate_simple(1, &n, nullptr);
      const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
      H5Pset_chunk(dcpl, 1, &chunk);
      H5Pset_deflate(dcpl, 4);
      const hid_t ds =
          H5Dcreate2(group, "acc", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
      const std::vector<double> v(part, 0.5);
      const hid_t mem = H5Screate_simple(1, &part, nullptr);
      for (const hsize_t start :
           hole_in_middle ? std::vector<hsize_t>{0, 180000} : std::vector<hsize_t>{0}) {
        const hid_t file_space = H5Dget_space(ds);
        H5Sselect_hyperslab(file_space, H5S_SELECT_SET, &start, nullptr, &part, nullptr);
        H5Dwrite(ds, H5T_NATIVE_DOUBLE, mem, file_space, H5P_DEFAULT, v.data());
        H5Sclose(file_space);
      }
      H5Sclose(mem);
      H5Pclose(dcpl);
      H5Sclose(space);
      return ds;
    });
    expect_refused(error_of([&] { diag::read_recording(path); }),
                   {path.filename().string(), "/signals/acc",
                    hole_in_middle ? "16 of its 20 chunks were never written"
                                   : "18 of its 20 chunks were never written"});
  }
}

// A deflated chunk stored raw (its filter mask says deflate was skipped) 8 bytes short of the
// chunk: the decoder finds it and refuses it; it never hands it to H5Dread, which read the 8
// missing bytes from whatever memory followed.
TEST_F(Hdf5Untrusted, ShortRawChunkIsAnErrorNotAFallback) {
  const fs::path path = dir_ / "short_chunk.h5";
  write_crafted(path, [&](hid_t group) {
    const hsize_t n = 2048, chunk = 1024;
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 1, &chunk);
    H5Pset_shuffle(dcpl);
    H5Pset_deflate(dcpl, 4);
    const hid_t ds =
        H5Dcreate2(group, "acc", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    const std::vector<double> v(1024, 0.25);
    // Both filters skipped (mask bits 0 and 1): the stored bytes are the chunk itself, but short.
    for (const hsize_t offset : {hsize_t{0}, hsize_t{1024}}) {
      const std::size_t bytes = offset == 0 ? 8192 : 8192 - 8;
      H5Dwrite_chunk(ds, H5P_DEFAULT, 0x3, &offset, bytes, v.data());
    }
    H5Pclose(dcpl);
    H5Sclose(space);
    return ds;
  });
  expect_refused(error_of([&] { diag::read_recording(path); }),
                 {"short_chunk.h5", "/signals/acc", "chunk at sample 1024", "8184"});
}

// The guard's child and this process read one descriptor: a file renamed over the path after it
// was opened is not read by either (before, the child and the parent each opened the path: the
// parent then read another file than the one the child had checked).
TEST_F(Hdf5Untrusted, FileRenamedOverThePathIsNotRead) {
  const fs::path path = dir_ / "rec.h5";
  const fs::path other = dir_ / "other.h5";
  diag::write_recording(path, small_recording(1.0));
  diag::write_recording(other, small_recording(3.0));
  bool renamed = false;
  diag::hdf5_detail::set_guard_test_hooks(nullptr, [&] {
    if (!renamed) fs::rename(other, path);
    renamed = true;
  });
  const diag::Recording rec = diag::read_recording(path);
  EXPECT_TRUE(renamed);
  ASSERT_EQ(rec.signals.size(), 1u);
  EXPECT_EQ(rec.signals[0].samples, small_recording(1.0).signals[0].samples);
  diag::hdf5_detail::set_guard_test_hooks(nullptr, nullptr);
  // The path now names the other file, which a new read gives.
  EXPECT_EQ(diag::read_recording(path).signals[0].samples, small_recording(3.0).signals[0].samples);
}

// No child, no read: a file the guard cannot read first is refused, not read unguarded.
TEST_F(Hdf5Untrusted, FailedForkRefusesTheFile) {
  const fs::path path = dir_ / "rec.h5";
  diag::write_recording(path, small_recording());
  diag::hdf5_detail::set_guard_test_hooks(
      [] {
        errno = EAGAIN;
        return -1;
      },
      nullptr);
  expect_refused(error_of([&] { diag::read_recording(path); }), {"rec.h5", "fork", "refused"});
  expect_refused(error_of([&] { diag::read_hdf5_arrays(path, {"/signals/acc"}); }),
                 {"rec.h5", "fork"});
}

// Declared sizes beyond what any input may hold are refused before anything is allocated.
TEST_F(Hdf5Untrusted, HugeDeclaredExtentIsRefusedBeforeAllocation) {
  const fs::path path = dir_ / "huge.h5";
  write_crafted(path, [&](hid_t group) {
    const hsize_t n = hsize_t{1} << 50, chunk = 1024;
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 1, &chunk);
    const hid_t ds =
        H5Dcreate2(group, "acc", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    H5Pclose(dcpl);
    H5Sclose(space);
    return ds;
  });
  expect_refused(error_of([&] { diag::read_recording(path); }),
                 {"huge.h5", "/signals/acc", "more than the"});
}
