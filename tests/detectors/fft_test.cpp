#include "detect/spectral/fft.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

// A sine of k cycles in the frame lands in bin k with magnitude n/2 (unnormalised DFT), and the
// inverse returns the input (round-off: 1e-12 relative for n <= 4096).
TEST(RealFft, SineLandsInItsBinAndRoundTrips) {
  for (std::size_t n : {7u, 64u, 1000u, 4096u}) {
    detect::RealFft fft(n);
    std::vector<double> x(n), back(n);
    const std::size_t k = 3;
    for (std::size_t j = 0; j < n; ++j)
      x[j] = 2.0 * std::sin(2 * std::numbers::pi * k * j / n) + 0.5;
    std::vector<std::complex<double>> X(fft.bins());
    fft.forward(x, X);
    EXPECT_NEAR(X[0].real(), 0.5 * n, 1e-9 * n);
    EXPECT_NEAR(std::abs(X[k]), 1.0 * n, 1e-9 * n);
    for (std::size_t b = 1; b < fft.bins(); ++b) {
      if (b != k) {
        EXPECT_LT(std::abs(X[b]), 1e-9 * n) << "n=" << n << " bin " << b;
      }
    }
    fft.inverse(X, back);
    for (std::size_t j = 0; j < n; ++j) EXPECT_NEAR(back[j], x[j], 1e-12 * 4);
  }
}

TEST(RealFft, RejectsWrongSizes) {
  detect::RealFft fft(16);
  std::vector<double> x(15);
  std::vector<std::complex<double>> X(9);
  EXPECT_THROW(fft.forward(x, X), std::invalid_argument);
}

// The zero-copy path (input() then forward_input()) gives the same bytes as forward() (the same
// plan on the same aligned buffer), keeps its input (so a zero padding written once stays), and
// an object used only for inverse transforms works without a forward plan.
TEST(RealFft, InPlaceInputMatchesForwardAndIsKept) {
  for (std::size_t n : {9u, 256u, 1000u}) {
    std::mt19937 rng(7);
    std::normal_distribution<double> g;
    std::vector<double> x(n);
    for (double& v : x) v = g(rng);
    detect::RealFft a(n), b(n);
    std::vector<std::complex<double>> X(a.bins());
    a.forward(x, X);
    std::copy(x.begin(), x.end(), b.input().begin());
    const std::span<const std::complex<double>> Y = b.forward_input();
    ASSERT_EQ(Y.size(), X.size());
    for (std::size_t k = 0; k < X.size(); ++k) {
      EXPECT_EQ(Y[k], X[k]) << "n=" << n << " bin " << k;
    }
    for (std::size_t j = 0; j < n; ++j) EXPECT_EQ(b.input()[j], x[j]);
    detect::RealFft inv(n);  // inverse only
    std::vector<double> back(n);
    inv.inverse(X, back);
    for (std::size_t j = 0; j < n; ++j) EXPECT_NEAR(back[j], x[j], 1e-12 * 8);
  }
}

// magnitude() against std::abs (hypot): within 2 ulp (sqrt of a sum of two rounded squares:
// relative error <= 1.5 eps, hypot's own <= 1 ulp) over magnitudes from 1e-300 to 1e300,
// through the fallback below sqrt(DBL_MIN) and above sqrt(DBL_MAX); exact at 0, NaN stays NaN.
TEST(Magnitude, MatchesHypotEverywhere) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> expo(-300, 300), ang(0, 2 * std::numbers::pi);
  for (int i = 0; i < 20000; ++i) {
    const double r = std::pow(10.0, expo(rng)), t = ang(rng);
    const std::complex<double> z(r * std::cos(t), r * std::sin(t));
    const double want = std::abs(z);
    EXPECT_NEAR(detect::magnitude(z), want, 2 * DBL_EPSILON * want) << z;
  }
  EXPECT_EQ(detect::magnitude({0.0, 0.0}), 0.0);
  EXPECT_EQ(detect::magnitude({3.0, -4.0}), 5.0);
  EXPECT_EQ(detect::magnitude({1e200, 1e200}), std::abs(std::complex<double>(1e200, 1e200)));
  EXPECT_EQ(detect::magnitude({1e-200, 0.0}), 1e-200);
  EXPECT_TRUE(std::isnan(detect::magnitude({std::numeric_limits<double>::quiet_NaN(), 1.0})));
}

}  // namespace

namespace {

bool is_fast(std::size_t m) {  // even and 7-smooth: the definition in fft.hpp
  if (m < 2 || m % 2 != 0) return false;
  for (std::size_t p : {2u, 3u, 5u, 7u})
    while (m % p == 0) m /= p;
  return m == 1;
}

// The fast lengths against a plain scan of the definition, for every n up to 20 000 and around
// the CWRU lengths; and they are what fft.hpp says they are for the records we read.
TEST(FastLength, MatchesThePlainScan) {
  auto plain_next = [](std::size_t n) {
    std::size_t m = std::max<std::size_t>(n, 2);
    while (!is_fast(m)) ++m;
    return m;
  };
  auto plain_previous = [](std::size_t n) {
    std::size_t m = n;
    while (!is_fast(m)) --m;
    return m;
  };
  for (std::size_t n = 0; n <= 20000; ++n) {
    ASSERT_EQ(detect::next_fast_length(n), plain_next(n)) << n;
    if (n >= 2) {
      ASSERT_EQ(detect::previous_fast_length(n), plain_previous(n)) << n;
    }
  }
  for (std::size_t n = 121000; n <= 123000; ++n) {
    ASSERT_EQ(detect::next_fast_length(n), plain_next(n)) << n;
    ASSERT_EQ(detect::previous_fast_length(n), plain_previous(n)) << n;
  }
  EXPECT_EQ(detect::next_fast_length(121265), 121500u);  // CWRU IR007_0: 5 x 79 x 307
  EXPECT_EQ(detect::next_fast_length(200000), 200000u);  // already fast
  EXPECT_EQ(detect::next_fast_length(1u << 20), 1u << 20);
  EXPECT_THROW(detect::previous_fast_length(1), std::invalid_argument);
}

}  // namespace

namespace {

// scaled_magnitudes gives the bytes of the plain loop magnitude(X[k]) * scale through every path
// this CPU has, at every length up to 19 (all tails), with bins outside magnitude()'s range
// (0, tiny, huge, infinite, NaN) at every position of a SIMD group.
TEST(ScaledMagnitudes, SameBytesAsThePlainLoopOnEveryPath) {
  using detect::detail::MagnitudePath;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  const double odd[] = {0.0,
                        1e-170,
                        1e170,
                        std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::quiet_NaN(),
                        -1e-160};
  int paths = 0;
  for (MagnitudePath path : {MagnitudePath::kScalar, MagnitudePath::kSse2, MagnitudePath::kAvx2}) {
    if (!detect::detail::magnitude_path_available(path)) continue;
    ++paths;
    for (std::size_t n = 0; n <= 19; ++n) {
      for (std::size_t at = 0; at <= n; ++at) {  // at == n: no odd bin
        for (double v : odd) {
          std::vector<std::complex<double>> X(n);
          for (auto& z : X) z = {g(rng), g(rng)};
          if (at < n) X[at] = {v, 0.5 * v};
          std::vector<double> got(n, -1.0), want(n);
          for (std::size_t k = 0; k < n; ++k) want[k] = detect::magnitude(X[k]) * 0.37;
          detect::detail::scaled_magnitudes(X, 0.37, got, path);
          for (std::size_t k = 0; k < n; ++k) {
            if (std::isnan(want[k])) {
              EXPECT_TRUE(std::isnan(got[k]));
            } else {
              EXPECT_EQ(got[k], want[k])
                  << "path " << static_cast<int>(path) << " n " << n << " k " << k;
            }
          }
        }
      }
    }
  }
  EXPECT_GE(paths, 1);
}

}  // namespace
