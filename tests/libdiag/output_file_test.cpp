// diag/io/output_file.hpp: the checks before the work and the writers, on regular files, links,
// devices and failures (nothing half-written, no temporary file left).
#include "diag/io/output_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>

#include "diag/error.hpp"

namespace {

namespace fs = std::filesystem;

// A fresh folder per test, removed afterwards.
class OutputFile : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("output_file"); }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  int temporaries() const {
    int n = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir_)) {
      n += e.path().filename().string().find(".tmp-") != std::string::npos;
    }
    return n;
  }
  fs::path dir_;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const diag::InputError& e) {
    return e.what();
  }
  return "no InputError";
}

TEST_F(OutputFile, ReplacesARegularFileAndKeepsItsPermissions) {
  const fs::path p = dir_ / "a.txt";
  std::ofstream(p) << "old";
  fs::permissions(p, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  diag::write_output_file(p, "new bytes");
  EXPECT_EQ(slurp(p), "new bytes");
  EXPECT_EQ(fs::status(p).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  EXPECT_EQ(temporaries(), 0);
}

TEST_F(OutputFile, WritesThroughAChainOfLinksAndKeepsThem) {
  fs::create_directories(dir_ / "real");
  fs::create_symlink("real/t.txt", dir_ / "l1");
  fs::create_symlink(dir_ / "l1", dir_ / "l2");  // absolute, to a relative link
  const diag::OutputTarget t = diag::check_output_path(dir_ / "l2", "--x");
  EXPECT_EQ(t.kind, diag::OutputKind::kRegular);
  EXPECT_EQ(t.target, dir_ / "real/t.txt");
  diag::write_output_file(dir_ / "l2", "through");
  EXPECT_TRUE(fs::is_symlink(dir_ / "l1"));
  EXPECT_TRUE(fs::is_symlink(dir_ / "l2"));
  EXPECT_EQ(slurp(dir_ / "real/t.txt"), "through");
  EXPECT_EQ(temporaries(), 0);
}

TEST_F(OutputFile, ALinkLoopIsRefusedNamingIt) {
  fs::create_symlink("b", dir_ / "a");
  fs::create_symlink("a", dir_ / "b");
  const std::string m = message_of([&] { diag::check_output_path(dir_ / "a", "--json"); });
  EXPECT_NE(m.find("--json"), std::string::npos) << m;
  EXPECT_NE(m.find("symbolic links"), std::string::npos) << m;
}

TEST_F(OutputFile, BadPathsAreRefusedBeforeAnythingIsCreated) {
  const std::string absent =
      message_of([&] { diag::check_output_path(dir_ / "no/such/r.html", "--html"); });
  EXPECT_EQ(absent.rfind("--html: " + (dir_ / "no/such/r.html").string(), 0), 0u) << absent;
  EXPECT_NE(absent.find("does not exist"), std::string::npos) << absent;
  const std::string is_dir = message_of([&] { diag::write_output_file(dir_, "x", "--json"); });
  EXPECT_NE(is_dir.find("is a directory"), std::string::npos) << is_dir;
  std::ofstream(dir_ / "file") << "x";
  const std::string under_file =
      message_of([&] { diag::check_output_path(dir_ / "file" / "r.json", "-o"); });
  EXPECT_NE(under_file.find("is not a directory"), std::string::npos) << under_file;
  EXPECT_EQ(diag::check_output_path("-").kind, diag::OutputKind::kStdout);
  EXPECT_EQ(diag::check_output_path("/dev/stdout").kind, diag::OutputKind::kStdout);
  EXPECT_EQ(temporaries(), 0);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(OutputFile, AFailingWriterLeavesNeitherTheFileNorATemporary) {
  const fs::path p = dir_ / "r.h5";
  std::ofstream(p) << "previous";
  EXPECT_THROW(diag::write_output_file_via(p,
                                           [](const fs::path& file) {
                                             std::ofstream(file) << "half";
                                             throw std::runtime_error("writer failed");
                                           }),
               std::runtime_error);
  EXPECT_EQ(slurp(p), "previous");  // untouched
  EXPECT_EQ(temporaries(), 0);
}

TEST_F(OutputFile, ADeviceIsWrittenInPlaceThroughATemporaryElsewhere) {
  fs::path seen;
  diag::write_output_file_via("/dev/null", [&](const fs::path& file) {
    seen = file;
    std::ofstream(file) << "bytes";
  });
  EXPECT_NE(seen.parent_path(), fs::path("/dev"));  // never beside the device
  EXPECT_FALSE(fs::exists(seen));                   // and deleted
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  diag::write_output_file("/dev/null", "bytes");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

}  // namespace
