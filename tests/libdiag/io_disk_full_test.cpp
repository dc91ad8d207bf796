// Output on a full disk (docs/limits.md), for every kind of output file: a recording, named
// arrays (wear histories), curves and plain bytes (JSON, HTML, SVG, CSV). The disk is made full
// for one child process by a file size limit (RLIMIT_FSIZE, with SIGXFSZ ignored, writes past it
// fail with EFBIG as they fail with ENOSPC on a full disk): this needs no mount and no privilege,
// so it runs wherever the tests run. /dev/full gives ENOSPC itself for the stream path. Each case
// must end with an InputError naming the file (exit 2 from the CLI), the previous file intact,
// no temporary file left, and no crash (before, HDF5's failed close left the file open and its
// library shutdown crashed at exit).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/data_groups.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/hdf5_arrays.hpp"
#include "diag/io/output_file.hpp"
#include "diag/io/recording.hpp"

namespace fs = std::filesystem;

namespace {

constexpr rlim_t kLimitBytes = 64 * 1024;  // the "disk": far below every output written here

class IoDiskFull : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("io_disk_full"); }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs `write` in a child whose files may not grow past kLimitBytes. Returns the child's exit
  // code (2: InputError, 3: another exception, 0: no error; 128 + n: signal n) and its message.
  std::pair<int, std::string> run_limited(const std::function<void()>& write) const {
    const fs::path message = dir_ / "message.txt";
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::signal(SIGXFSZ, SIG_IGN);
      const rlimit limit{kLimitBytes, kLimitBytes};
      ::setrlimit(RLIMIT_FSIZE, &limit);
      int code = 0;
      std::string text;
      try {
        write();
      } catch (const diag::InputError& e) {
        code = 2;
        text = e.what();
      } catch (const std::exception& e) {
        code = 3;
        text = e.what();
      }
      // Short enough to pass the limit.
      if (FILE* f = std::fopen(message.c_str(), "w")) {
        std::fputs(text.substr(0, 4000).c_str(), f);
        std::fclose(f);
      }
      // A normal exit runs the libraries' shutdown (HDF5's included), where the crash was.
      std::exit(code);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    std::ifstream in(message);
    std::stringstream text;
    text << in.rdbuf();
    fs::remove(message);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return {code, text.str()};
  }

  // The output names no other file in the directory than `keep`.
  void expect_only(const std::vector<std::string>& keep) const {
    for (const auto& entry : fs::directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      EXPECT_NE(std::find(keep.begin(), keep.end(), name), keep.end()) << "left behind: " << name;
    }
  }

  void expect_disk_full_keeps_previous(const std::string& name,
                                       const std::function<void(const fs::path&)>& write) const {
    const fs::path path = dir_ / name;
    const std::string previous = "the previous output, which must survive\n";
    {
      std::ofstream out(path, std::ios::binary);
      out << previous;
    }
    const auto [code, message] = run_limited([&] { write(path); });
    EXPECT_EQ(code, 2) << message;
    EXPECT_NE(message.find(name), std::string::npos) << message;
    EXPECT_NE(message.find("write failed"), std::string::npos) << message;
    std::ifstream in(path, std::ios::binary);
    std::stringstream now;
    now << in.rdbuf();
    EXPECT_EQ(now.str(), previous);
    expect_only({name});
  }

  fs::path dir_;
};

diag::Recording large_recording() {
  diag::Recording rec;
  diag::Signal s;
  s.name = "acc";
  s.fs_hz = 1000.0;
  // Noise-like values: deflate cannot bring them under the limit.
  std::uint64_t x = 12345;
  for (int i = 0; i < 100000; ++i) {
    x = x * 6364136223846793005ULL + 1442695040888963407ULL;
    s.samples.push_back(static_cast<double>(x >> 11) / 9007199254740992.0 - 0.5);
  }
  rec.signals.push_back(s);
  return rec;
}

}  // namespace

TEST_F(IoDiskFull, RecordingKeepsThePreviousFile) {
  const diag::Recording rec = large_recording();
  expect_disk_full_keeps_previous("rec.h5",
                                  [&](const fs::path& p) { diag::write_recording(p, rec); });
}

TEST_F(IoDiskFull, ArraysKeepThePreviousFile) {
  const diag::Recording rec = large_recording();
  expect_disk_full_keeps_previous("wear.h5", [&](const fs::path& p) {
    diag::write_hdf5_arrays(p, {{"/history/depth_m", {}, rec.signals[0].samples, "m"}});
  });
}

TEST_F(IoDiskFull, CurvesKeepThePreviousFile) {
  const diag::Recording rec = large_recording();
  expect_disk_full_keeps_previous("curves.h5", [&](const fs::path& p) {
    const std::vector<diag::DataGroup> groups = {
        {"channels/acc/psd", "noise", {{"frequency_hz", "Hz", rec.signals[0].samples}}, {}, {}}};
    diag::write_data_groups(p, groups, {}, "--curves");
  });
}

TEST_F(IoDiskFull, BytesKeepThePreviousFile) {
  const std::string bytes(200000, 'x');
  expect_disk_full_keeps_previous("report.json",
                                  [&](const fs::path& p) { diag::write_output_file(p, bytes); });
}

// A stream (here /dev/full: every write fails with ENOSPC) gets nothing and a clear error; no
// temporary file is made for it, so a missing temporary directory does not matter.
TEST_F(IoDiskFull, StreamOutputFailsCleanly) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  const diag::Recording rec = large_recording();
  for (const auto& write : std::vector<std::function<void()>>{
           [&] { diag::write_recording("/dev/full", rec); },
           [&] {
             diag::write_hdf5_arrays("/dev/full", {{"/a", {}, {1.0, 2.0}, ""}});
           },
           [&] { diag::write_output_file("/dev/full", "{}\n"); }}) {
    const auto [code, message] = run_limited([&] {
      ::setenv("TMPDIR", (dir_ / "missing").c_str(), 1);
      write();
    });
    EXPECT_EQ(code, 2) << message;
    EXPECT_NE(message.find("/dev/full"), std::string::npos) << message;
    EXPECT_NE(message.find("No space left"), std::string::npos) << message;
  }
  expect_only({});
}

// The same curves written twice, more than a second apart, give the same bytes: no object
// timestamps (HDF5 stores them with one-second resolution).
TEST_F(IoDiskFull, CurvesAreByteDeterministic) {
  const std::vector<diag::DataGroup> groups = {
      {"channels/acc/psd", "d", {{"f", "Hz", {1, 2, 3}}, {"p", "W", {4, 5, 6}}}, {{"n", 1}}, {}},
      {"channels/acc/env/deep", "e", {{"f", "Hz", {1}}}, {}, {}}};
  auto bytes_of = [&](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  diag::write_data_groups(dir_ / "a.h5", groups);
  ::sleep(2);
  diag::write_data_groups(dir_ / "b.h5", groups);
  EXPECT_EQ(bytes_of(dir_ / "a.h5"), bytes_of(dir_ / "b.h5"));
}
