#include "detect/spectral/fft.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cstring>
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

}  // namespace

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
