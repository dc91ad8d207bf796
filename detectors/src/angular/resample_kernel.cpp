// The interpolation kernel of the angular resampler as a cubic table (resample_internal.hpp).
#include <array>
#include <cmath>
#include <mutex>
#include <numbers>
#include <vector>

#include "resample_internal.hpp"

namespace detect::resample_internal {
namespace {

std::vector<double> kernel_table(int z, double beta) {
  const int cells = kCellsPerZeroCrossing * z;
  const double i0_beta = std::cyl_bessel_i(0.0, beta);
  const double pi = std::numbers::pi;
  std::vector<double> h(static_cast<std::size_t>(cells) + 1), dh(h.size());
  for (int i = 0; i <= cells; ++i) {
    const double v = static_cast<double>(i) / kCellsPerZeroCrossing;
    const double r = v / z;
    const double sinc = i == 0 ? 1.0 : std::sin(pi * v) / (pi * v);
    const double dsinc = i == 0 ? 0.0 : (std::cos(pi * v) - sinc) / v;
    const double arg = beta * std::sqrt(std::max(0.0, 1 - r * r));
    const double w = std::cyl_bessel_i(0.0, arg) / i0_beta;
    // dw/dr = -beta^2 r (I1(arg) / arg) / I0(beta); I1(a) / a -> 1/2 as a -> 0 (r = 1).
    const double i1_over = arg > 1e-8 ? std::cyl_bessel_i(1.0, arg) / arg : 0.5;
    const double dw = -beta * beta * r * i1_over / i0_beta;
    h[static_cast<std::size_t>(i)] = sinc * w;
    dh[static_cast<std::size_t>(i)] = dsinc * w + sinc * dw / z;
  }
  const double d = 1.0 / kCellsPerZeroCrossing;
  std::vector<double> table(4 * (static_cast<std::size_t>(cells) + 1), 0.0);
  for (std::size_t i = 0; i < static_cast<std::size_t>(cells); ++i) {
    const double h0 = h[i], h1 = h[i + 1], s0 = d * dh[i], s1 = d * dh[i + 1];
    table[4 * i] = h0;
    table[4 * i + 1] = s0;
    table[4 * i + 2] = 3 * (h1 - h0) - 2 * s0 - s1;
    table[4 * i + 3] = 2 * (h0 - h1) + s0 + s1;
  }
  return table;
}

}  // namespace

const std::vector<double>& shared_kernel_table(int z) {
  static std::array<std::once_flag, 65> once;
  static std::array<std::vector<double>, 65> tables;
  const auto i = static_cast<std::size_t>(z);
  std::call_once(once[i], [&] { tables[i] = kernel_table(z, kKaiserBeta); });
  return tables[i];
}

}  // namespace detect::resample_internal
