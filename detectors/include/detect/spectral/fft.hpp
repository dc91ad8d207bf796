// Real FFTs over FFTW3 with plans made once per length and reused.
//
// Plans are created under a process-wide lock (FFTW's planner is not thread-safe) and cached by
// length and direction; executing them is thread-safe. A plan is made on the first transform in
// its direction, not at construction (a user of inverse() only, like the kurtogram's band
// envelopes, never plans the forward transform: planning is a large part of the time of a small
// recording). A RealFft object owns scratch buffers, so use one object per thread. Plans use
// FFTW_ESTIMATE: the output is the same bytes on every run (FFTW_MEASURE may pick different
// algorithms from run to run); planning still computes the twiddle factors, O(n): measured
// 5-25 ms per plan at n ~ 10^5 (FFTW 3.3.10, EPYC).
//
// The length matters: a record whose length has a large prime factor (the CWRU files: 122571 =
// 3^2 x 13619, 121991 = 43 x 2837) takes FFTW 12-18 ms per transform against ~1 ms at a length of
// small factors (2^a 3^b 5^c); a Bluestein transform through such a length was measured no faster
// (two complex transforms of >= 2n - 1 points), so these lengths are kept as they are.
#pragma once

#include <cfloat>
#include <cmath>
#include <complex>
#include <cstddef>
#include <span>

namespace detect {

class RealFft {
 public:
  explicit RealFft(std::size_t n);  // n >= 1
  ~RealFft();
  RealFft(const RealFft&) = delete;
  RealFft& operator=(const RealFft&) = delete;
  RealFft(RealFft&&) noexcept;
  RealFft& operator=(RealFft&&) noexcept;

  std::size_t size() const { return n_; }
  std::size_t bins() const { return n_ / 2 + 1; }

  // Unnormalised forward transform: X_k = sum_j x_j exp(-2 pi i j k / n), k = 0..n/2.
  // in.size() == n, out.size() == n/2 + 1.
  void forward(std::span<const double> in, std::span<std::complex<double>> out);
  // Inverse of forward(), including the 1/n factor. in.size() == n/2 + 1, out.size() == n.
  void inverse(std::span<const std::complex<double>> in, std::span<double> out);

  // The same forward transform without the two copies: write the n input samples into input()
  // (its content is unspecified before), then forward_input() transforms them and returns the
  // n/2 + 1 bins, a view valid until the next transform by this object. input() is kept.
  std::span<double> input() { return {real_, n_}; }
  std::span<const std::complex<double>> forward_input();

 private:
  std::size_t n_ = 0;
  void* forward_plan_ = nullptr;  // fftw_plan, owned by the process-wide cache; made on first use
  void* inverse_plan_ = nullptr;
  double* real_ = nullptr;    // fftw_malloc'ed scratch, n doubles
  void* spectrum_ = nullptr;  // fftw_complex scratch, n/2 + 1
};

// Lengths FFTW transforms fast. A real transform of a length with a large prime factor is an
// order of magnitude slower than one of a nearby length of small factors (FFTW 3.3.10,
// FFTW_ESTIMATE, EPYC: r2c of 121265 = 5 x 79 x 307 takes 4.4 ms, of 121500 = 2^2 3^5 5^3
// 0.40 ms); odd lengths are 3-4x slower than even ones even when smooth (151875 = 3^5 5^4:
// 1.6 ms, 151200: 0.55 ms), and factors 11 and 13 make ESTIMATE planning slow (121680 =
// 2^4 3^2 5 13^2: 220 ms to plan). A fast length is therefore an even 7-smooth number,
// 2^a 3^b 5^c 7^d with a >= 1; consecutive ones differ by under 1 % above 10^4 (as
// scipy.fft.next_fast_len, but even and without 11).
// next_fast_length(n): the smallest fast length >= n (n <= 1 gives 2; zero-padding to it keeps all
// samples and changes the bin spacing from fs/n to fs/m). previous_fast_length(n): the largest
// fast length <= n (n >= 2; truncating to it drops n - m samples). Both exact (integer search).
std::size_t next_fast_length(std::size_t n);
std::size_t previous_fast_length(std::size_t n);

// |z| as sqrt(re^2 + im^2): several times faster than std::abs (hypot, which guards against
// overflow and underflow of the squares). The squares can only overflow or underflow when |z| is
// outside [sqrt(DBL_MIN), sqrt(DBL_MAX)] ~ [1.5e-154, 1.3e154]; then (norm not in [DBL_MIN,
// DBL_MAX]) the value is taken from std::abs. Either way |z| within about 1 ulp (sqrt of a sum of
// two rounded squares: relative error <= 1.5 eps, against hypot's ~1 ulp).
inline double magnitude(std::complex<double> z) {
  const double re = z.real(), im = z.imag();
  const double n2 = re * re + im * im;
  if (n2 >= DBL_MIN && n2 <= DBL_MAX) [[likely]]
    return std::sqrt(n2);
  return std::abs(z);  // 0, tiny, huge or not finite
}

// out[k] = magnitude(X[k]) * scale for every k (out.size() == X.size()): the same bytes as that
// loop, two or four bins at a time (SSE2, or AVX2 where the CPU has it: IEEE squares, one add,
// a correctly rounded sqrt and one multiply per bin in every path, no fused multiply-add), the
// rare bins outside magnitude()'s range from std::abs as there.
void scaled_magnitudes(std::span<const std::complex<double>> X, double scale,
                       std::span<double> out);
namespace detail {
// scaled_magnitudes through one path whatever the CPU (tests: every path gives the same bytes).
enum class MagnitudePath { kScalar, kSse2, kAvx2 };
bool magnitude_path_available(MagnitudePath path);
void scaled_magnitudes(std::span<const std::complex<double>> X, double scale, std::span<double> out,
                       MagnitudePath path);
}  // namespace detail

}  // namespace detect
