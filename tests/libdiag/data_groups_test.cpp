// diag/io/data_groups.hpp: the curves file. Bad group or column names are refused before any
// file is made; a good set is written atomically (no temporary left) and an unwritable target is
// an InputError naming the option. Contents are read back with h5py in python/tests.
#include "diag/io/data_groups.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "diag/error.hpp"

namespace {

namespace fs = std::filesystem;

TEST(DataGroups, WritesAFileAndLeavesNoTemporary) {
  const fs::path dir = geardiag_test::scratch_dir("data_groups");
  std::vector<diag::DataGroup> g(2);
  g[0].path = "channels/a1/psd";
  g[0].columns = {{"frequency_hz", "Hz", {0, 1, 2}}, {"psd", "(m/s^2)^2/Hz", {1, 2, 3}}};
  g[0].numbers["resolution_hz"] = 1;
  g[1].path = "channels/a1/tsa/input";  // a sibling under an existing intermediate group
  g[1].columns = {{"angle_rev", "rev", {}}};
  diag::write_data_groups(dir / "c.h5", g, {{"source", "x.h5"}}, "--curves");
  EXPECT_GT(fs::file_size(dir / "c.h5"), 0u);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

TEST(DataGroups, RefusesBadNamesAndUnwritableTargets) {
  const fs::path dir = geardiag_test::scratch_dir("data_groups");
  std::vector<diag::DataGroup> g(1);
  for (const std::string bad : {"", "/abs", "a//b", "a/"}) {
    g[0].path = bad;
    EXPECT_THROW(diag::write_data_groups(dir / "c.h5", g), diag::InputError) << bad;
  }
  g[0].path = "a";
  g[0].columns = {{"x/y", "", {1}}};
  EXPECT_THROW(diag::write_data_groups(dir / "c.h5", g), diag::InputError);
  g[0].columns = {{"x", "", {1}}, {"x", "", {2}}};
  EXPECT_THROW(diag::write_data_groups(dir / "c.h5", g), diag::InputError);
  g[0].columns = {{"x", "", {1}}};
  g.push_back(g[0]);
  EXPECT_THROW(diag::write_data_groups(dir / "c.h5", g), diag::InputError);
  EXPECT_TRUE(fs::is_empty(dir));  // nothing written for refused input
  g.pop_back();
  try {
    diag::write_data_groups(dir / "missing" / "c.h5", g, {}, "--curves");
    FAIL() << "no error for a missing directory";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--curves"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

// A column with a shape is written (its dimensions are checked with h5py in
// python/tests/test_recording_analysis.py); a shape that does not hold the values is refused
// before any file is made.
TEST(DataGroups, TwoDimensionalColumnsKeepTheirShape) {
  const fs::path dir = geardiag_test::scratch_dir("data_groups");
  std::vector<diag::DataGroup> g(1);
  g[0].path = "channels/a1/spectrogram";
  g[0].columns = {{"time_s", "s", {0, 1, 2}},
                  {"frequency_hz", "Hz", {0, 10}},
                  {"psd_db", "dB", {1, 2, 3, 4, 5, 6}, {3, 2}}};
  diag::write_data_groups(dir / "c.h5", g);
  EXPECT_GT(fs::file_size(dir / "c.h5"), 0u);  // dimensions read back by h5py (python/tests)
  g[0].columns[2].shape = {4, 2};
  EXPECT_THROW(diag::write_data_groups(dir / "d.h5", g), diag::InputError);
  EXPECT_FALSE(fs::exists(dir / "d.h5"));
  fs::remove_all(dir);
}

}  // namespace
