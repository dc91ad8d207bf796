// Linear-phase FIR low-pass design (windowed sinc) and a streaming decimator. Shared by the
// simulator (anti-alias filtering of the integrator's output before it is sampled at the user's
// rate) and the detectors (anti-alias filtering before resampling).
//
// Design: h[n] = 2 fc sinc(2 fc (n - M)) w[n], n = 0..2M, with a Blackman window w (stopband
// attenuation about 74 dB, transition width about 5.5 / (2M + 1) of the sampling rate), scaled
// to unit gain at DC. Group delay: exactly M samples.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace diag {

// Taps of a low-pass filter with cutoff fc (half-amplitude point) as a fraction of the sampling
// rate, 0 < fc < 0.5, and half-length M >= 1 (2M + 1 taps). Throws InputError otherwise.
std::vector<double> lowpass_taps(double cutoff_fraction, int half_length);

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
