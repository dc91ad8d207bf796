// Linear-phase FIR low-pass design (windowed sinc) and a streaming decimator. The one low-pass
// designer of geardiag: the simulator's anti-alias filter before its output is sampled at the
// user's rate (Decimator, Blackman window), the detectors' filters and decimation
// (detect/spectral/filter.hpp, a window of detect/spectral/window.hpp) and the half-band stages
// before angular resampling (detect/angular/resample.hpp, Kaiser window).
//
// Design: h[n] = 2 fc sinc(2 fc (n - M)) w[n], n = 0..2M (Oppenheim & Schafer, Discrete-Time
// Signal Processing, 3rd ed., sec. 7.5), fc the cutoff as a fraction of the sampling rate (the
// half-amplitude point), w the window, optionally scaled to unit gain at DC. Group delay: exactly
// M samples. Windows:
//   Blackman  w[n] = 0.42 - 0.5 cos(2 pi n / 2M) + 0.08 cos(4 pi n / 2M): stopband attenuation
//             about 74 dB, transition width about 5.5 / (2M + 1) of the sampling rate;
//   Kaiser    w[n] = I0(beta sqrt(1 - ((n - M) / M)^2)) / I0(beta) (Kaiser 1974: beta =
//             0.1102 (A - 8.7) for A dB of stopband attenuation, A > 50);
//   given     the caller's 2M + 1 values (symmetric); w[n] for n <= M is used for both halves,
//             so the taps are exactly symmetric.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace diag {

enum class FirWindow {
  kBlackman,  // fixed shape, ~74 dB stopband
  kKaiser,    // LowpassDesign::kaiser_beta sets the stopband
  kGiven,     // LowpassDesign::window_values
};

struct LowpassDesign {
  double cutoff_fraction = 0.25;  // fc / fs, the half-amplitude point; (0, 0.5)
  int half_length = 16;           // M: 2M + 1 taps, delay M samples; >= 1
  FirWindow window = FirWindow::kBlackman;
  double kaiser_beta = 0.0;                // kKaiser only: beta >= 0
  std::vector<double> window_values = {};  // kGiven only: 2M + 1 finite values
  // true: the taps scaled to sum 1 (unit DC gain). false: the windowed ideal response as it is,
  // which keeps a half-band filter's (fc = 1/4) centre tap at exactly 1/2.
  bool unit_dc_gain = true;

  void validate() const;  // throws InputError "lowpass design: <field>: ..."
};

// The 2M + 1 taps of the design. Throws InputError for a design outside the ranges above.
std::vector<double> design_lowpass(const LowpassDesign& design);

// Low-pass filtering and decimation by an integer factor D, one channel, fed in blocks of any
// size. The taps are designed for a passband up to `passband_fraction` of the output Nyquist
// frequency and full stopband attenuation from the output Nyquist frequency up, so nothing above
// fs_out / 2 folds into the band below passband_fraction * fs_out / 2. Output sample k is the
// filtered input at input index k D (the filter's delay is compensated: push() withholds the
// first outputs until the filter is full, and finish() flushes the tail by holding the last
// input value).
class Decimator {
 public:
  Decimator(int factor, double passband_fraction = 0.8);
  int factor() const { return factor_; }
  int delay_out_samples() const { return half_ / factor_; }  // informative
  // Appends input samples; appends to `out` every output sample that became available.
  void push(std::span<const double> in, std::vector<double>& out);
  // Flushes the remaining outputs (the input is extended with its last value).
  void finish(std::vector<double>& out);

 private:
  void emit(std::vector<double>& out);
  int factor_ = 1;
  int half_ = 0;                  // M, a multiple of factor_
  std::vector<double> taps_;      // 2M + 1
  std::vector<double> history_;   // last 2M + 1 inputs, circular
  std::size_t pos_ = 0;           // next write position in history_
  long long received_ = 0;        // inputs pushed so far
  long long next_out_index_ = 0;  // input index of the next output sample
  double last_ = 0.0;
};

}  // namespace diag
