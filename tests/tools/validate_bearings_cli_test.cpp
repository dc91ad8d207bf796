// geardiag validate --bearings end to end through the binary: the table is printed, a bad list is
// an input error (exit 2).
#include <gtest/gtest.h>

#include <string>

#include "cli_run.hpp"

namespace {

using cli_test::run;

TEST(ValidateBearingsCli, PrintsRightSilentWrongByClassAndSnr) {
  auto v = run("validate --bearings --speeds 30 --sizes 1 --snr -5 --cases 1");
  EXPECT_EQ(v.code, 0) << v.out;
  for (const char* row : {"| healthy |", "| outer_race |", "| inner_race |", "| rolling_element |",
                          "| cage |", "-5 dB"})
    EXPECT_NE(v.out.find(row), std::string::npos) << row << "\n" << v.out;
}

TEST(ValidateBearingsCli, RejectsANonNumericListWithExitTwo) {
  auto v = run("validate --bearings --snr -5,x");
  EXPECT_EQ(v.code, 2) << v.out;
  EXPECT_NE(v.out.find("--snr"), std::string::npos) << v.out;
}

}  // namespace
