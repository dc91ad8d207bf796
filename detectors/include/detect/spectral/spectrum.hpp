// Single-sided amplitude spectrum of a whole record (one windowed DFT).
//
// With w the window (n samples), X_k = sum_j w_j x_j exp(-2 pi i j k / nfft), k = 0..nfft/2:
//   peak scaling:  A_k = 2 |X_k| / sum(w)   (0 < k < nfft/2),   A_0 = |X_0| / sum(w),
//                  A_{nfft/2} = |X_{nfft/2}| / sum(w) when nfft is even,
// so a sine  A sin(2 pi f t + phi)  reads A at its bin (the window's coherent gain sum(w)/n is
// divided out) when f is bin-centred; off-centre it reads A times the window's scalloping
// (< 0.051 % for the HFT95 flat-top, up to 15 % for Hann, 36 % for rectangular).
//   RMS scaling:   A_k / sqrt(2) for 0 < k < nfft/2 (a sine reads its RMS), DC and Nyquist as is.
// Frequencies f_k = k fs / nfft. nfft > n zero-pads (a finer grid, not a finer resolution).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "detect/spectral/window.hpp"

namespace detect {

enum class AmplitudeScaling {
  kPeak,  // a sine of amplitude A reads A
  kRms,   // a sine of amplitude A reads A / sqrt(2)
};

struct SpectrumOptions {
  double fs_hz = 1.0;                        // sampling rate [Hz], finite, > 0
  WindowType window = WindowType::kFlatTop;  // periodic form is used
  AmplitudeScaling scaling = AmplitudeScaling::kPeak;
  std::size_t nfft = 0;      // DFT length; 0: the record length; else >= it,
                             // <= 2^28 (zero padding)
  bool remove_mean = false;  // subtract the record's mean before windowing

  void validate() const;  // throws diag::InputError naming the field
};

struct Spectrum {
  std::vector<double> frequency_hz;  // k fs / nfft, k = 0..nfft/2
  std::vector<double> amplitude;     // same units as x (peak or RMS)
  double resolution_hz = 0;          // fs / nfft (bin spacing)
  double enbw_hz = 0;                // window's equivalent noise bandwidth, enbw_bins fs / n
};

// x: at least 2 finite samples (throws diag::InputError otherwise, naming the first non-finite
// sample's index).
Spectrum amplitude_spectrum(std::span<const double> x, const SpectrumOptions& options);

}  // namespace detect
