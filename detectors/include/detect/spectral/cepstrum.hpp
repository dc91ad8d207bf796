// Real cepstrum: the inverse DFT of the log magnitude spectrum (Bogert, Healy & Tukey 1963;
// Randall 2011, "Vibration-based condition monitoring", sec. 3.7; MATLAB rceps):
//   c_q = (1/nfft) sum_k log|X_k| exp(2 pi i k q / nfft),   quefrency tau_q = q / fs  [s].
// log|X| is real and even, so c is real and even: c_{nfft-q} = c_q; only q = 0..nfft/2 is
// returned. A spectrum with a periodic comb of spacing Df (an echo of delay tau = 1/Df, the
// harmonics of a shaft or the sidebands of a mesh) puts rahmonics at tau, 2 tau, ...: for
// x_j = s_j + a s_{j-d} (circular, |a| < 1), log|1 + a e^{-i w d}| = sum_m (-1)^{m+1} a^m/m cos(m w
// d) adds (-1)^{m+1} a^m / (2 m) at q = m d.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "detect/spectral/window.hpp"

namespace detect {

struct CepstrumOptions {
  double fs_hz = 1.0;    // sampling rate [Hz], finite, > 0
  std::size_t nfft = 0;  // 0: record length; else >= it, <= 2^28
  WindowType window = WindowType::kRectangular;
  double floor_relative = 1e-12;  // |X_k| below floor_relative max|X| is raised to
                                  // it before the log (log 0 guard), (0, 1)

  void validate() const;  // throws diag::InputError "cepstrum: <field>: ..."
};

struct Cepstrum {
  std::vector<double> quefrency_s;  // q / fs, q = 0..nfft/2
  std::vector<double> value;        // c_q (dimensionless: log of x-units, offset in c_0)
};

// x: at least 2 finite samples, not all zero.
Cepstrum real_cepstrum(std::span<const double> x, const CepstrumOptions& options);

}  // namespace detect
