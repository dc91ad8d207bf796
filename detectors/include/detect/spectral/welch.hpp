// Welch power spectral density, computed exactly as scipy.signal.welch (scipy 1.10,
// _spectral_helper with mode 'psd', boundary None, padded False, average 'mean').
//
// The record is cut into K = floor((N - noverlap) / (nperseg - noverlap)) segments starting at
// s_m = m (nperseg - noverlap); samples after the last whole segment are not used. Each
// segment is detrended (constant: its mean removed; linear: its least-squares line removed),
// multiplied by the periodic window w, and transformed with an nfft-point DFT (zero-padded when
// nfft > nperseg). Then
//   P_k = c_k S / K  sum_m |X_{m,k}|^2,       k = 0..nfft/2,  f_k = k fs / nfft,
//   S = 1 / (fs sum w^2)   for density  [x-units^2 / Hz]  (Welch 1967, eq. 3; scipy 'density')
//   S = 1 / (sum w)^2      for spectrum [x-units^2]       (a sine of amplitude A reads A^2/2 at
//                                                          its bin when bin-centred)
//   c_k = 2 for 0 < k < nfft/2 (one-sided: negative frequencies folded in), else 1
//   (the last bin is doubled too when nfft is odd, as in scipy).
// Parseval: with density scaling, sum_k P_k fs/nfft = mean over segments of
// sum_j (w_j y_j)^2 / sum_j w_j^2, the window-weighted mean square of the detrended record.
//
// welch() is WelchAccumulator fed with the whole record at once: both give the same bytes.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "detect/spectral/fft.hpp"
#include "detect/spectral/window.hpp"

namespace detect {

enum class Detrend {
  kNone,      // segment used as is
  kConstant,  // segment mean removed (scipy default)
  kLinear,    // least-squares straight line removed
};

enum class PsdScaling {
  kDensity,   // x-units^2 / Hz (scipy 'density', the default)
  kSpectrum,  // x-units^2 (scipy 'spectrum': a bin-centred sine of amplitude A reads A^2/2)
};

struct WelchOptions {
  double fs_hz = 1.0;                     // sampling rate [Hz], finite, > 0
  std::size_t nperseg = 256;              // segment length [samples], [8, 2^24]
  long long noverlap = -1;                // samples shared by consecutive segments,
                                          // [0, nperseg); -1: nperseg / 2 (scipy default)
  std::size_t nfft = 0;                   // DFT length, 0: nperseg; else [nperseg, 2^26]
  WindowType window = WindowType::kHann;  // periodic form (scipy get_window default)
  Detrend detrend = Detrend::kConstant;
  PsdScaling scaling = PsdScaling::kDensity;

  void validate() const;  // throws diag::InputError "welch: <field>: <value> is not in <range>"
  std::size_t overlap() const { return noverlap < 0 ? nperseg / 2 : std::size_t(noverlap); }
  std::size_t step() const { return nperseg - overlap(); }
  std::size_t fft_length() const { return nfft == 0 ? nperseg : nfft; }
  // The segments welch() averages over a record of n samples: those starting at 0, step(),
  // 2 step(), ... that end within it.
  std::size_t segments(std::size_t n) const { return n < nperseg ? 0 : (n - nperseg) / step() + 1; }
};

struct Psd {
  std::vector<double> frequency_hz;  // k fs / nfft, k = 0..nfft/2
  std::vector<double> value;         // density [x^2/Hz] or spectrum [x^2], see scaling
  PsdScaling scaling = PsdScaling::kDensity;
  std::size_t segments = 0;  // K, the segments averaged
  double resolution_hz = 0;  // fs / nfft
  double enbw_hz = 0;        // window ENBW: enbw_bins fs / nperseg
};

// One-shot Welch PSD. x must hold at least nperseg samples, all finite (diag::InputError
// otherwise; scipy would silently shorten nperseg, this library asks for it explicitly).
Psd welch(std::span<const double> x, const WelchOptions& options);

// Streaming Welch: push chunks of any size (a 4 GB recording read piecewise); memory is
// O(nperseg + nfft) whatever the record length. Segments that span chunk boundaries are
// assembled in an internal buffer. result() after pushing x in any chunking equals welch(x)
// bit for bit (same segments, same arithmetic, same order). One object per thread.
class WelchAccumulator {
 public:
  explicit WelchAccumulator(const WelchOptions& options);  // validates options

  void push(std::span<const double> chunk);  // throws diag::InputError on a non-finite sample
  Psd result() const;  // throws diag::InputError when no whole segment has been pushed yet
  void reset();        // forget every sample and segment, keep the plans

  std::size_t segments() const { return segments_; }
  std::size_t samples() const { return samples_; }  // samples pushed so far

 private:
  void process(const double* segment);  // detrend, window, DFT, accumulate |X|^2

  WelchOptions options_;
  std::size_t nperseg_, step_, nfft_;
  std::vector<double> window_;
  double window_sum_ = 0, window_sum_sq_ = 0;
  RealFft fft_;
  std::vector<double> work_;     // nperseg: a segment assembled across two chunks
  std::vector<double> power_;    // sum over segments of |X_k|^2
  std::vector<double> pending_;  // samples not yet consumed, < nperseg of them
  std::size_t pending_size_ = 0;
  std::size_t segments_ = 0;
  std::size_t samples_ = 0;
};

// Detrends x in place (used per segment by Welch and the spectrogram).
void detrend(std::span<double> x, Detrend type);

}  // namespace detect
