// The number formatters pinned: the exact text of each format, and each equal to the standard
// facility its header names (printf, an ostream with a precision, std::to_string, std::to_chars)
// over values that exercise rounding, exponents, signs and non-finite numbers.
#include "diag/util/number_format.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace {

using diag::format_fixed;
using diag::format_shortest;
using diag::format_significant;

const std::vector<double>& probes() {
  static const std::vector<double> v = {0.0,
                                        -0.0,
                                        1.0,
                                        -1.5,
                                        0.1,
                                        2.0 / 3.0,
                                        3.14159265358979,
                                        12345.678,
                                        1234567.0,
                                        9.9995,
                                        0.00012345,
                                        1e-300,
                                        6.02214076e23,
                                        std::numeric_limits<double>::max(),
                                        std::numeric_limits<double>::denorm_min(),
                                        std::numeric_limits<double>::infinity(),
                                        -std::numeric_limits<double>::infinity()};
  return v;
}

TEST(NumberFormat, SignificantDigitsPrintsThatManyDigitsAndDropsTrailingZeros) {
  EXPECT_EQ(format_significant(3.14159265, 4), "3.142");
  EXPECT_EQ(format_significant(2.5, 4), "2.5");
  EXPECT_EQ(format_significant(1234567.0, 6), "1.23457e+06");
  EXPECT_EQ(format_significant(0.00012345, 3), "0.000123");
  EXPECT_EQ(format_significant(-0.5, 1), "-0.5");
  EXPECT_EQ(format_significant(1500.0, 2), "1.5e+03");
  EXPECT_EQ(format_significant(0.1, 17), "0.10000000000000001");
  EXPECT_EQ(format_significant(7.0, 0), "7");  // 0 digits is 1, as in printf
  EXPECT_EQ(format_significant(std::numeric_limits<double>::infinity(), 6), "inf");
}

TEST(NumberFormat, FixedDecimalsPrintsThatManyDecimals) {
  EXPECT_EQ(format_fixed(2.0, 3), "2.000");
  EXPECT_EQ(format_fixed(2.25, 1), "2.2");  // 2.25 is exact: round half to even
  EXPECT_EQ(format_fixed(-0.04, 1), "-0.0");
  EXPECT_EQ(format_fixed(1234567.0, 0), "1234567");
  EXPECT_EQ(format_fixed(1.0 / 3.0, 6), "0.333333");
  EXPECT_EQ(format_fixed(-std::numeric_limits<double>::infinity(), 2), "-inf");
}

TEST(NumberFormat, ShortestReadsBackToTheSameDouble) {
  EXPECT_EQ(format_shortest(0.1), "0.1");
  EXPECT_EQ(format_shortest(2.0 / 3.0), "0.6666666666666666");
  EXPECT_EQ(format_shortest(1e21), "1e+21");
  EXPECT_EQ(format_shortest(-0.0), "-0");
  for (double v : probes()) {
    if (!std::isfinite(v)) continue;
    const std::string s = format_shortest(v);
    double back = 0;
    std::from_chars(s.data(), s.data() + s.size(), back);
    EXPECT_EQ(back, v) << s;
  }
}

TEST(NumberFormat, SignificantEqualsAnOstreamWithThatPrecision) {
  for (int digits : {1, 3, 4, 6, 12, 17}) {
    for (double v : probes()) {
      std::ostringstream o;
      o.precision(digits);
      o << v;
      EXPECT_EQ(format_significant(v, digits), o.str()) << v << " at " << digits;
    }
  }
  std::ostringstream o;  // an ostream's default precision is 6
  o << 2.0 / 3.0;
  EXPECT_EQ(format_significant(2.0 / 3.0, 6), o.str());
}

TEST(NumberFormat, FixedSixEqualsStdToString) {
  for (double v : probes()) EXPECT_EQ(format_fixed(v, 6), std::to_string(v)) << v;
}

TEST(NumberFormat, ShortestEqualsToChars) {
  for (double v : probes()) {
    char b[64];
    const auto r = std::to_chars(b, b + sizeof b, v);
    EXPECT_EQ(format_shortest(v), std::string(b, r.ptr)) << v;
  }
}

}  // namespace
