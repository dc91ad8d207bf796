// Real FFTs over FFTW3 with plans made once per length and reused.
//
// Plans are created under a process-wide lock (FFTW's planner is not thread-safe) and cached by
// length; executing them is thread-safe. A RealFft object owns scratch buffers, so use one object
// per thread. Plans use FFTW_ESTIMATE: planning costs microseconds and the output is the same
// bytes on every run (FFTW_MEASURE may pick different algorithms from run to run).
#pragma once

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

 private:
  std::size_t n_ = 0;
  void* forward_plan_ = nullptr;  // fftw_plan, owned by the process-wide cache
  void* inverse_plan_ = nullptr;
  double* real_ = nullptr;    // fftw_malloc'ed scratch, n doubles
  void* spectrum_ = nullptr;  // fftw_complex scratch, n/2 + 1
};

}  // namespace detect
