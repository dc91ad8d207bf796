#include "detect/spectral/fft.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
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

}  // namespace
