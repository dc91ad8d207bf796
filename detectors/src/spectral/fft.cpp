#include "detect/spectral/fft.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cstring>
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define DETECT_FFT_X86 1
#endif
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>

namespace detect {
namespace {

std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}

// Plans live for the process (a few hundred bytes each) and are destroyed at exit; they are made
// on fftw_malloc'ed arrays and executed with the new-array interface on equally aligned scratch
// buffers. Keyed by (length, inverse?).
struct PlanCache {
  std::map<std::pair<std::size_t, bool>, fftw_plan> plans;
  ~PlanCache() {
    for (auto& [key, p] : plans) fftw_destroy_plan(p);
    fftw_cleanup();
  }
};

fftw_plan plan_for(std::size_t n, bool inverse) {
  static PlanCache store;
  auto& cache = store.plans;
  std::lock_guard<std::mutex> lock(planner_mutex());
  auto it = cache.find({n, inverse});
  if (it != cache.end()) return it->second;
  double* r = fftw_alloc_real(n);
  fftw_complex* c = fftw_alloc_complex(n / 2 + 1);
  const int len = static_cast<int>(n);
  fftw_plan p = inverse ? fftw_plan_dft_c2r_1d(len, c, r, FFTW_ESTIMATE)
                        : fftw_plan_dft_r2c_1d(len, r, c, FFTW_ESTIMATE);
  fftw_free(r);
  fftw_free(c);
  if (!p) throw std::runtime_error("FFTW could not make a plan");
  cache.emplace(std::pair{n, inverse}, p);
  return p;
}

// The even 7-smooth number nearest n on the side `up` (>= n) or down (<= n): every 2^a 3^b 5^c
// 7^d (a >= 1) near n is visited once, O(log^3 n) candidates.
std::size_t fast_length(std::size_t n, bool up) {
  std::size_t best = up ? std::numeric_limits<std::size_t>::max() : 0;
  const std::size_t limit = up ? 2 * std::max<std::size_t>(n, 1) : n;  // a power of 2 below it
  for (std::size_t p7 = 2; p7 <= limit; p7 *= 7)
    for (std::size_t p5 = p7; p5 <= limit; p5 *= 5)
      for (std::size_t p3 = p5; p3 <= limit; p3 *= 3) {
        std::size_t m = p3;  // the power of 2 that brings m to n's side
        if (up) {
          while (m < n) m *= 2;
          best = std::min(best, m);
        } else {
          while (m * 2 <= n) m *= 2;
          best = std::max(best, m);
        }
      }
  return best;
}

// Bins [from, to) of scaled_magnitudes, one at a time.
void magnitudes_scalar(const std::complex<double>* X, double scale, double* out, std::size_t from,
                       std::size_t to) {
  for (std::size_t k = from; k < to; ++k) out[k] = magnitude(X[k]) * scale;
}

#ifdef DETECT_FFT_X86
// |z|^2 of two bins: [r0 r1]^2 + [i0 i1]^2 (r * r + i * i as magnitude(): one rounding each).
// Returns the first bin not done (a bin outside magnitude()'s range: its pair is left to the
// scalar loop, which takes std::abs there).
std::size_t magnitudes_sse2(const std::complex<double>* X, double scale, double* out,
                            std::size_t n) {
  const double* z = reinterpret_cast<const double*>(X);
  const __m128d lo = _mm_set1_pd(DBL_MIN), hi = _mm_set1_pd(DBL_MAX), s = _mm_set1_pd(scale);
  std::size_t k = 0;
  for (; k + 2 <= n; k += 2) {
    const __m128d a = _mm_loadu_pd(z + 2 * k), b = _mm_loadu_pd(z + 2 * k + 2);
    const __m128d a2 = _mm_mul_pd(a, a), b2 = _mm_mul_pd(b, b);
    const __m128d n2 = _mm_add_pd(_mm_unpacklo_pd(a2, b2), _mm_unpackhi_pd(a2, b2));
    const __m128d ok = _mm_and_pd(_mm_cmpge_pd(n2, lo), _mm_cmple_pd(n2, hi));
    if (_mm_movemask_pd(ok) != 3) break;
    _mm_storeu_pd(out + k, _mm_mul_pd(_mm_sqrt_pd(n2), s));
  }
  return k;
}

// The same, four bins at a time.
[[gnu::target("avx2")]] std::size_t magnitudes_avx2(const std::complex<double>* X, double scale,
                                                    double* out, std::size_t n) {
  const double* z = reinterpret_cast<const double*>(X);
  const __m256d lo = _mm256_set1_pd(DBL_MIN), hi = _mm256_set1_pd(DBL_MAX);
  const __m256d s = _mm256_set1_pd(scale);
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4) {
    const __m256d a = _mm256_loadu_pd(z + 2 * k), b = _mm256_loadu_pd(z + 2 * k + 4);
    const __m256d a2 = _mm256_mul_pd(a, a), b2 = _mm256_mul_pd(b, b);
    // Within 128-bit halves: [r0 r2 | r1 r3] + [i0 i2 | i1 i3], then bins in order.
    const __m256d sum = _mm256_add_pd(_mm256_unpacklo_pd(a2, b2), _mm256_unpackhi_pd(a2, b2));
    const __m256d n2 = _mm256_permute4x64_pd(sum, 0xD8);
    const __m256d ok =
        _mm256_and_pd(_mm256_cmp_pd(n2, lo, _CMP_GE_OQ), _mm256_cmp_pd(n2, hi, _CMP_LE_OQ));
    if (_mm256_movemask_pd(ok) != 15) break;
    _mm256_storeu_pd(out + k, _mm256_mul_pd(_mm256_sqrt_pd(n2), s));
  }
  return k;
}
#endif

}  // namespace

namespace detail {

bool magnitude_path_available(MagnitudePath path) {
#ifdef DETECT_FFT_X86
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return path != MagnitudePath::kAvx2 || avx2;
#else
  return path == MagnitudePath::kScalar;
#endif
}

void scaled_magnitudes(std::span<const std::complex<double>> X, double scale, std::span<double> out,
                       MagnitudePath path) {
  if (out.size() != X.size())
    throw std::invalid_argument("scaled_magnitudes: X and out differ in length");
  if (!magnitude_path_available(path))
    throw std::invalid_argument("scaled_magnitudes: path not available on this CPU");
  const std::size_t n = X.size();
  std::size_t k = 0;
  while (k < n) {
#ifdef DETECT_FFT_X86
    if (path == MagnitudePath::kAvx2)
      k += magnitudes_avx2(X.data() + k, scale, out.data() + k, n - k);
    else if (path == MagnitudePath::kSse2)
      k += magnitudes_sse2(X.data() + k, scale, out.data() + k, n - k);
#endif
    // The tail, or the group holding a bin outside magnitude()'s range (up to 4 bins).
    const std::size_t to = path == MagnitudePath::kScalar ? n : std::min(n, k + 4);
    magnitudes_scalar(X.data(), scale, out.data(), k, to);
    k = to;
  }
}

}  // namespace detail

void scaled_magnitudes(std::span<const std::complex<double>> X, double scale,
                       std::span<double> out) {
  using detail::MagnitudePath;
  static const MagnitudePath path =
      detail::magnitude_path_available(MagnitudePath::kAvx2)   ? MagnitudePath::kAvx2
      : detail::magnitude_path_available(MagnitudePath::kSse2) ? MagnitudePath::kSse2
                                                               : MagnitudePath::kScalar;
  detail::scaled_magnitudes(X, scale, out, path);
}

std::size_t next_fast_length(std::size_t n) { return fast_length(n, true); }

std::size_t previous_fast_length(std::size_t n) {
  if (n < 2) throw std::invalid_argument("previous_fast_length: n must be >= 2");
  return fast_length(n, false);
}

RealFft::RealFft(std::size_t n) : n_(n) {
  if (n == 0) throw std::invalid_argument("RealFft: length must be >= 1");
  real_ = fftw_alloc_real(n);
  spectrum_ = fftw_alloc_complex(n / 2 + 1);
}

RealFft::~RealFft() {
  fftw_free(real_);
  fftw_free(spectrum_);
}

RealFft::RealFft(RealFft&& o) noexcept
    : n_(std::exchange(o.n_, 0)),
      forward_plan_(std::exchange(o.forward_plan_, nullptr)),
      inverse_plan_(std::exchange(o.inverse_plan_, nullptr)),
      real_(std::exchange(o.real_, nullptr)),
      spectrum_(std::exchange(o.spectrum_, nullptr)) {}

RealFft& RealFft::operator=(RealFft&& o) noexcept {
  if (this != &o) {
    fftw_free(real_);
    fftw_free(spectrum_);
    n_ = std::exchange(o.n_, 0);
    forward_plan_ = std::exchange(o.forward_plan_, nullptr);
    inverse_plan_ = std::exchange(o.inverse_plan_, nullptr);
    real_ = std::exchange(o.real_, nullptr);
    spectrum_ = std::exchange(o.spectrum_, nullptr);
  }
  return *this;
}

void RealFft::forward(std::span<const double> in, std::span<std::complex<double>> out) {
  if (in.size() != n_ || out.size() != bins())
    throw std::invalid_argument("RealFft::forward: wrong buffer sizes");
  std::memcpy(real_, in.data(), n_ * sizeof(double));
  const std::span<const std::complex<double>> X = forward_input();
  std::memcpy(static_cast<void*>(out.data()), X.data(), bins() * sizeof(fftw_complex));
}

std::span<const std::complex<double>> RealFft::forward_input() {
  if (!forward_plan_) forward_plan_ = plan_for(n_, false);
  auto* c = static_cast<fftw_complex*>(spectrum_);
  // An out-of-place r2c transform keeps its input (FFTW_PRESERVE_INPUT is its default).
  fftw_execute_dft_r2c(static_cast<fftw_plan>(forward_plan_), real_, c);
  // fftw_complex is double[2], layout-compatible with std::complex<double> ([complex.numbers]/4).
  return {reinterpret_cast<const std::complex<double>*>(spectrum_), bins()};
}

void RealFft::inverse(std::span<const std::complex<double>> in, std::span<double> out) {
  if (in.size() != bins() || out.size() != n_)
    throw std::invalid_argument("RealFft::inverse: wrong buffer sizes");
  if (!inverse_plan_) inverse_plan_ = plan_for(n_, true);
  auto* c = static_cast<fftw_complex*>(spectrum_);
  std::memcpy(c, static_cast<const void*>(in.data()), bins() * sizeof(fftw_complex));
  fftw_execute_dft_c2r(static_cast<fftw_plan>(inverse_plan_), c, real_);  // destroys c
  const double scale = 1.0 / static_cast<double>(n_);
  for (std::size_t i = 0; i < n_; ++i) out[i] = real_[i] * scale;
}

}  // namespace detect
