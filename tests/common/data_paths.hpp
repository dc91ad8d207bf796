// Where the tests find their input files, overridable at run time:
//   GEARDIAG_TESTDATA      the repository's testdata/ folder (gearboxes, scenarios, recordings)
//   GEARDIAG_SHARED_DATA   the measured data (cwru-bearing/, spectraquest-gearbox/); the tests
//                          that need it skip with a message when it is absent
// An unset or empty variable means the folder the build was configured with
// (tests/CMakeLists.txt). tests/CMakeLists.txt includes this header in every test source and
// defines GEARDIAG_TESTDATA_DIR and GEARDIAG_SHARED_DATA_DIR as calls of the functions below, so
// that a test names the folder by macro or by function alike.
#pragma once

#include <cstdlib>

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

}  // namespace geardiag_test
