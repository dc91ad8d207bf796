// Where the tests find their input files, overridable at run time:
//   GEARDIAG_TESTDATA      the repository's testdata/ folder (gearboxes, scenarios, recordings)
//   GEARDIAG_SHARED_DATA   the measured data (cwru-bearing/, spectraquest-gearbox/); the tests
//                          that need it skip with a message when it is absent
// An unset or empty variable means the folder the build was configured with
// (tests/CMakeLists.txt). tests/CMakeLists.txt includes this header in every test source and
// defines GEARDIAG_TESTDATA_DIR and GEARDIAG_SHARED_DATA_DIR as calls of the functions below, so
// that a test names the folder by macro or by function alike.
//
// Scratch files go to scratch_dir(prefix): a fresh folder under GEARDIAG_TMP (CTest sets it to the
// build's tests/ folder) or, unset, the system's temporary folder.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace geardiag_test {

// The folder named by the environment variable `variable` when set and not empty, else
// `configured`.
inline const char* data_dir(const char* variable, const char* configured) {
  const char* value = std::getenv(variable);
  return value != nullptr && *value != '\0' ? value : configured;
}

inline const char* testdata_dir() {
  return data_dir("GEARDIAG_TESTDATA", GEARDIAG_CONFIGURED_TESTDATA_DIR);
}

inline const char* shared_data_dir() {
  return data_dir("GEARDIAG_SHARED_DATA", GEARDIAG_CONFIGURED_SHARED_DATA_DIR);
}

// A fresh, empty folder <base>/<prefix>_<test name>_<pid> for the running test's files (base:
// GEARDIAG_TMP when set and not empty, else the system's temporary folder). The test removes it.
inline std::filesystem::path scratch_dir(const std::string& prefix) {
  const char* env = std::getenv("GEARDIAG_TMP");
  const std::filesystem::path base = env != nullptr && *env != '\0'
                                         ? std::filesystem::path(env)
                                         : std::filesystem::temp_directory_path();
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      base / (prefix + "_" + (info != nullptr ? std::string(info->name()) + "_" : std::string()) +
              std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace geardiag_test
