// The recording read path (diag/io/hdf5_inflate.hpp): channels decoded by geardiag from their
// chunks' stored bytes (libdeflate or zlib, its own unshuffle) must give the same bits as HDF5's
// own filter pipeline and as the values h5py wrote, for every block a reader may ask for; a
// damaged deflate chunk stays an InputError naming file and dataset (exit 2 from the CLI).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/hdf5_inflate.hpp"
#include "diag/io/recording.hpp"

namespace fs = std::filesystem;

namespace {

class Hdf5Read : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("hdf5_read"); }
  void TearDown() override {
    diag::hdf5_set_read_path({});
    fs::remove_all(dir_);
  }

  fs::path dir_;
};

// The ways a channel can be decoded: by the survey child (copied by the parent) or by the parent
// itself, with geardiag's direct read and libdeflate (when built in) or zlib, or with HDF5's own
// pipeline (H5Dread).
struct ReadPath {
  const char* name;
  diag::Hdf5ReadPath path;
};
const ReadPath kReadPaths[] = {
    {"direct, libdeflate when built in, survey reused", {true, false, true}},
    {"direct, libdeflate when built in", {true, false, false}},
    {"direct, zlib", {true, true, false}},
    {"HDF5 H5Dread", {false, false, false}},
};

int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string shell_quoted(const fs::path& p) { return "'" + p.string() + "'"; }

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// Samples that exercise every byte of a float64: signs, zeros of both signs, subnormals, the
// largest and smallest normal numbers, and a noisy sine (incompressible low bytes).
std::vector<double> test_samples(std::size_t n, int seed) {
  std::vector<double> x(n);
  unsigned state = 12345u + static_cast<unsigned>(seed);
  for (std::size_t i = 0; i < n; ++i) {
    state = state * 1664525u + 1013904223u;
    x[i] = std::sin(0.01 * static_cast<double>(i) * (seed + 1)) + 1e-3 * (state >> 8) / 16777216.0;
  }
  const double special[] = {0.0,
                            -0.0,
                            std::numeric_limits<double>::denorm_min(),
                            -std::numeric_limits<double>::denorm_min(),
                            std::numeric_limits<double>::max(),
                            std::numeric_limits<double>::lowest(),
                            std::numeric_limits<double>::min(),
                            1e300,
                            -1e-300};
  for (std::size_t k = 0; k < std::size(special) && 3 * k + 5 < n; ++k) x[3 * k + 5] = special[k];
  return x;
}

diag::Recording test_recording(std::size_t n) {
  diag::Recording rec;
  for (int c = 0; c < 3; ++c) {
    diag::Signal s;
    s.name = "ch" + std::to_string(c);
    s.fs_hz = 1000.0;
    s.unit = "m/s^2";
    s.samples = test_samples(n, c);
    rec.signals.push_back(std::move(s));
  }
  return rec;
}

}  // namespace

TEST_F(Hdf5Read, ReportsTheInflateCodec) {
  const bool libdeflate = diag::hdf5_set_read_path({});
  const std::string codec = diag::hdf5_inflate_codec();
  EXPECT_EQ(codec.rfind(libdeflate ? "libdeflate " : "zlib ", 0), 0u) << codec;
  diag::hdf5_set_read_path({.direct = true, .zlib = true});
  EXPECT_EQ(diag::hdf5_inflate_codec().rfind("zlib ", 0), 0u);
  RecordProperty("codec", codec);
}

// Every block a reader may ask for (inside one chunk, across chunk boundaries, the last partial
// chunk, lengths that are not multiples of the 8-sample unshuffle) gives the written bits on all
// read paths, with shuffle + deflate (geardiag's files) and without filters.
TEST_F(Hdf5Read, DirectDecodeEqualsTheWrittenSamplesOnEveryPath) {
  constexpr std::size_t n = 12345;
  const diag::Recording rec = test_recording(n);
  for (const int level : {4, 0}) {
    const fs::path path = dir_ / ("level" + std::to_string(level) + ".h5");
    diag::Hdf5WriteOptions options;
    options.chunk_samples = 1000;
    options.deflate_level = level;
    diag::write_recording(path, rec, options);
    for (const ReadPath& p : kReadPaths) {
      SCOPED_TRACE(std::string(p.name) + ", deflate level " + std::to_string(level));
      diag::hdf5_set_read_path(p.path);
      const diag::Recording back = diag::read_recording(path);
      ASSERT_EQ(back.signals.size(), rec.signals.size());
      for (std::size_t c = 0; c < rec.signals.size(); ++c) {
        EXPECT_TRUE(same_bits(back.signals[c].samples, rec.signals[c].samples)) << c;
      }
      const diag::RecordingReader reader(path);
      const std::pair<std::size_t, std::size_t> blocks[] = {
          {0, 1}, {999, 2}, {1000, 1000}, {7, 8}, {12344, 1}, {3, 12340}, {4095, 4097}, {0, n}};
      for (const auto& [offset, count] : blocks) {
        std::vector<double> got(count);
        reader.read_block("ch1", offset, got);
        const std::vector<double> want(rec.signals[1].samples.begin() + offset,
                                       rec.signals[1].samples.begin() + offset + count);
        EXPECT_TRUE(same_bits(got, want)) << "block " << offset << " + " << count;
      }
      // A stream of short blocks (each chunk decoded once, kept for the next block).
      std::vector<double> streamed;
      for (std::size_t offset = 0; offset < n; offset += 333) {
        std::vector<double> got(std::min<std::size_t>(333, n - offset));
        reader.read_block("ch2", offset, got);
        streamed.insert(streamed.end(), got.begin(), got.end());
      }
      EXPECT_TRUE(same_bits(streamed, rec.signals[2].samples));
    }
  }
}

// Files another program wrote: h5py's shuffle + gzip, gzip alone, shuffle alone (decoded by
// geardiag), and pipelines geardiag leaves to HDF5 (fletcher32, contiguous, float32): the values
// h5py wrote, to the bit, on every path.
TEST_F(Hdf5Read, H5pyWrittenPipelinesDecodeExactly) {
  const std::string script = std::string(GEARDIAG_TESTS_DIR) + "/libdiag/write_with_h5py.py";
  ASSERT_EQ(
      run(std::string(GEARDIAG_PYTHON) + " " + shell_quoted(script) + " " + shell_quoted(dir_)), 0)
      << "write_with_h5py.py failed (h5py is required: scripts/install-deps)";
  for (const ReadPath& p : kReadPaths) {
    SCOPED_TRACE(p.name);
    diag::hdf5_set_read_path(p.path);
    const diag::Recording rec = diag::read_recording(dir_ / "h5py.h5");
    ASSERT_EQ(rec.signals.size(), 6u);
    for (const diag::Signal& s : rec.signals) {
      std::ifstream in(dir_ / (s.name + ".f64"), std::ios::binary);
      std::vector<double> want(9999);
      in.read(reinterpret_cast<char*>(want.data()),
              static_cast<std::streamsize>(want.size() * sizeof(double)));
      ASSERT_TRUE(in) << s.name;
      EXPECT_TRUE(same_bits(s.samples, want)) << s.name;
    }
  }
}

// A deflate chunk damaged on disk: an InputError naming the file and the dataset on every path,
// never a crash or silently wrong samples (zlib and libdeflate both verify the stream's
// Adler-32), and exit 2 from `geardiag analyze`.
TEST_F(Hdf5Read, CorruptDeflateChunkIsAnInputErrorNamingFileAndDataset) {
  const fs::path path = dir_ / "damaged.h5";
  diag::Hdf5WriteOptions options;
  options.chunk_samples = 1000;
  diag::write_recording(path, test_recording(5000), options);
  // Where chunk 2 of /signals/ch1 lies in the file (h5py's chunk query).
  const fs::path where = dir_ / "chunk.txt";
  const std::string query = "import h5py,sys; c=h5py.File(sys.argv[1])[\"signals/ch1\"].id." +
                            std::string("get_chunk_info(2); print(c.byte_offset, c.size)");
  ASSERT_EQ(run(std::string(GEARDIAG_PYTHON) + " -c '" + query + "' " + shell_quoted(path) + " > " +
                shell_quoted(where)),
            0);
  std::uint64_t at = 0, size = 0;
  std::ifstream(where) >> at >> size;
  ASSERT_GT(size, 100u);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    for (std::uint64_t i = at + size / 2; i < at + size / 2 + 32; ++i) {
      f.seekg(static_cast<std::streamoff>(i));
      const char byte = static_cast<char>(f.get() ^ 0x5A);
      f.seekp(static_cast<std::streamoff>(i));
      f.put(byte);
    }
  }
  for (const ReadPath& p : kReadPaths) {
    SCOPED_TRACE(p.name);
    diag::hdf5_set_read_path(p.path);
    try {
      (void)diag::read_recording(path);
      ADD_FAILURE() << "a damaged chunk was read";
    } catch (const diag::InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path.string()), std::string::npos) << message;
      EXPECT_NE(message.find("/signals/ch1"), std::string::npos) << message;
      EXPECT_NE(message.find("corrupted"), std::string::npos) << message;
    }
  }
  const fs::path err = dir_ / "stderr.txt";
  EXPECT_EQ(run(std::string(GEARDIAG_BINARY) + " analyze " + shell_quoted(path) +
                " > /dev/null 2> " + shell_quoted(err)),
            2);
  std::ifstream in(err);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("/signals/ch1"), std::string::npos) << text;
}
