// decimate_half_band (resample.hpp): half-band low-pass and decimation by 2, in stages.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <vector>

#include "detect/angular/resample.hpp"
#include "diag/dsp/fir.hpp"
#include "diag/error.hpp"
#include "resample_internal.hpp"

namespace detect {

namespace {

using namespace resample_internal;

// The half-band filter's taps h[+-n] for odd n = 1 .. kHalfBandReach. Built once per process.
const std::array<double, kHalfBandPairs>& half_band_taps() {
  static const std::array<double, kHalfBandPairs> taps = [] {
    // fc = fs / 4 with a Kaiser window for 100 dB; not scaled, so that h[0] is exactly 1/2 and
    // the even taps are zeros (dropped here: they are sin(k pi) ~ 1e-16, not 0).
    diag::LowpassDesign design;
    design.cutoff_fraction = 0.25;
    design.half_length = kHalfBandReach;
    design.window = diag::FirWindow::kKaiser;
    design.kaiser_beta = 0.1102 * (100.0 - 8.7);
    design.unit_dc_gain = false;
    const std::vector<double> h = diag::design_lowpass(design);
    std::array<double, kHalfBandPairs> odd{};
    for (int j = 0; j < kHalfBandPairs; ++j)
      odd[static_cast<std::size_t>(j)] = h[static_cast<std::size_t>(kHalfBandReach + 2 * j + 1)];
    return odd;
  }();
  return taps;
}

// The half-band stage (half_band_stage) for outputs k0 .. k1: y[k] = x[2k] / 2 + sum_j h_j
// (o[k - 1 - j] + o[k + j]), o the odd samples with zeros around them; kHalfBandBlock outputs at
// a time in independent accumulators (the sum of each output in the order j = 0, 1, ..., the
// same in every lane and in half_band_one: the same bytes at either width).
constexpr std::size_t kHalfBandBlock = 16;
using HalfBand = void (*)(const double* x, const double* o, double* y, std::size_t k0,
                          std::size_t k1);
void half_band_one(const double* x, const double* o, double* y, std::size_t k0, std::size_t k1) {
  const auto& h = half_band_taps();
  for (std::size_t k = k0; k < k1; ++k) {
    double acc = 0.5 * x[2 * k];
    for (std::size_t j = 0; j < h.size(); ++j) acc += h[j] * (o[k - 1 - j] + o[k + j]);
    y[k] = acc;
  }
}
template <class V>
[[gnu::always_inline]] inline void half_band_block(const double* x, const double* o, double* y,
                                                   std::size_t k0, std::size_t k1) {
  constexpr std::size_t kW = sizeof(V) / sizeof(double), kRegs = kHalfBandBlock / kW;
  const auto& h = half_band_taps();
  for (std::size_t k = k0; k < k1; k += kHalfBandBlock) {
    V acc[kRegs];
    for (std::size_t r = 0; r < kRegs; ++r) {
      for (std::size_t l = 0; l < kW; ++l) acc[r][l] = 0.5 * x[2 * (k + r * kW + l)];
    }
    for (std::size_t j = 0; j < h.size(); ++j) {
      V hj;
      for (std::size_t l = 0; l < kW; ++l) hj[l] = h[j];
#pragma GCC unroll 8
      for (std::size_t r = 0; r < kRegs; ++r) {
        V a, b;
        std::memcpy(&a, o + k + r * kW - 1 - j, sizeof(V));
        std::memcpy(&b, o + k + r * kW + j, sizeof(V));
        acc[r] += hj * (a + b);
      }
    }
    for (std::size_t r = 0; r < kRegs; ++r) std::memcpy(y + k + r * kW, &acc[r], sizeof(V));
  }
}
void half_band_sse2(const double* x, const double* o, double* y, std::size_t k0, std::size_t k1) {
  half_band_block<V2>(x, o, y, k0, k1);
}
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
[[gnu::target("avx2")]] void half_band_avx2(const double* x, const double* o, double* y,
                                            std::size_t k0, std::size_t k1) {
  half_band_block<V4>(x, o, y, k0, k1);
}
#endif
HalfBand half_band_kernel() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (use_avx2()) return half_band_avx2;
#endif
  return half_band_sse2;
}

// One half-band stage: y[k] = x[2k] / 2 + sum_j h_j (x[2k - 1 - 2j] + x[2k + 1 + 2j]), zeros
// beyond x. The odd samples are copied with kHalfBandPairs zeros on each side, so that the sum
// over j reads two contiguous rows of them.
std::vector<double> half_band_stage(std::span<const double> x, HalfBand block) {
  const std::size_t n = x.size(), ny = (n + 1) / 2, no = n / 2;
  constexpr std::size_t kPad = kHalfBandPairs;
  std::vector<double> odd(no + 2 * kPad + 8, 0.0);
  for (std::size_t i = 0; i < no; ++i) odd[kPad + i] = x[2 * i + 1];
  std::vector<double> y(ny);
  // Whole blocks where x[2k] exists for every k of the block; the rest one by one.
  const std::size_t whole = std::min(ny, n / 2) / kHalfBandBlock * kHalfBandBlock;
  block(x.data(), odd.data() + kPad, y.data(), 0, whole);
  half_band_one(x.data(), odd.data() + kPad, y.data(), whole, ny);
  return y;
}

}  // namespace

std::vector<double> decimate_half_band(std::span<const double> x, int stages) {
  diag::require(stages >= 0 && stages <= kMaxStages, "decimate_half_band", "stages",
                std::to_string(stages) + " is not in [0, " + std::to_string(kMaxStages) + "]");
  if (stages == 0) return {x.begin(), x.end()};
  const HalfBand block = half_band_kernel();
  std::vector<double> y = half_band_stage(x, block);
  for (int s = 1; s < stages; ++s) y = half_band_stage(y, block);
  return y;
}

}  // namespace detect
