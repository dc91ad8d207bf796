// Internals of the angular resampler shared by its source files (resample.hpp is the interface):
// the SIMD vector types, the cubic Hermite angle interpolation (shaft_angle.cpp), the Kaiser
// kernel table (resample_kernel.cpp), the half-band decimation's constants (half_band.cpp) and
// the instruction-set choice (resample.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

namespace detect::resample_internal {

// The inner loops, written once for 2- and 4-wide vectors (SSE2, the x86-64 baseline, and AVX2
// where the CPU has it, chosen at run time). Each vector lane does what the scalar code would
// do for its elements, and no fused multiply-add is enabled for either, so both give the same
// bytes.
using V2 = double __attribute__((vector_size(16)));
using V4 = double __attribute__((vector_size(32)));

// Cubic Hermite basis on [0, 1]: p(s) = H01(s) + m0 H10(s) + m1 H11(s) goes from 0 to 1 with
// slopes m0, m1 (slopes normalised by the secant).
inline double hermite(double s, double m0, double m1) {
  const double s2 = s * s, s3 = s2 * s;
  return (-2 * s3 + 3 * s2) + m0 * (s3 - 2 * s2 + s) + m1 * (s3 - s2);
}
inline double hermite_slope(double s, double m0, double m1) {
  const double s2 = s * s;
  return (-6 * s2 + 6 * s) + m0 * (3 * s2 - 4 * s + 1) + m1 * (3 * s2 - 2 * s);
}

// Kaiser beta for 80 dB stopband (Kaiser's formula 0.1102 (A - 8.7)), and the matching
// transition width relative to the cutoff for Z zero crossings: (A - 8) / (2.285 * 2 pi * Z).
inline constexpr double kKaiserBeta = 0.1102 * (80.0 - 8.7);
inline double transition_rel(int zero_crossings) {
  return (80.0 - 8.0) / (2.285 * 2 * std::numbers::pi * zero_crossings);
}

// The kernel h(v) = sinc(v) w(v / Z), v = g (u - n) in zero crossings, w the Kaiser window
// I0(beta sqrt(1 - r^2)) / I0(beta), as a piecewise cubic Hermite table: cell i covers
// [i, i + 1) / kCellsPerZeroCrossing and holds c0..c3 of h = c0 + f (c1 + f (c2 + f c3)), f the
// position in the cell. Value and slope are exact at the cell ends, so the error is at most
// max|h''''| d^4 / 384, d = 1 / 64: 4.5e-9 of the peak at Z = 4, 3.1e-9 at Z = 16 (resample.hpp
// gives h''''(0), the maximum). One extra cell of zeros after v = Z takes v == Z (and v a few
// ulps above it) without a branch.
inline constexpr int kCellsPerZeroCrossing = 64;

// The kernel table of Z zero crossings, built once per process (it does not depend on the plan);
// z in [4, 64]. resample_kernel.cpp.
const std::vector<double>& shared_kernel_table(int z);

inline double table_kernel(const double* table, int z, double v) {
  const double p = std::abs(v) * kCellsPerZeroCrossing;
  const auto i =
      std::min(static_cast<std::size_t>(p), static_cast<std::size_t>(z) * kCellsPerZeroCrossing);
  const double f = p - static_cast<double>(i);
  const double* c = table + 4 * i;
  return c[0] + f * (c[1] + f * (c[2] + f * c[3]));
}

// The half-band filter of resample.hpp: h[0] = 1/2, h[+-n] for odd n = 1 .. kHalfBandReach
// (kHalfBandPairs of them), every other even tap 0 (half_band.cpp).
inline constexpr int kHalfBandReach = 55;
inline constexpr int kHalfBandPairs = (kHalfBandReach + 1) / 2;
inline constexpr double kHalfBandEdge = 0.22;  // passband edge / the stage's input rate
inline constexpr int kMaxStages = 4;
inline std::size_t decimated_length(std::size_t n, int stages) {
  for (int s = 0; s < stages; ++s) n = (n + 1) / 2;
  return n;
}
// Samples at each end of a record decimated `stages` times that the zeros beyond the record
// reach (an upper bound: a sample k of stage s is exact when 2k -+ kHalfBandReach lies inside
// the exact part of stage s - 1).
inline long decimated_edge(int stages) {
  long edge = 0;
  for (int s = 0; s < stages; ++s) edge = (edge + kHalfBandReach + 1) / 2 + 1;
  return edge;
}

// Whether the AVX2 forms of the inner loops run (set_resample_simd; by default where the CPU has
// AVX2). resample.cpp.
bool use_avx2();

}  // namespace detect::resample_internal
