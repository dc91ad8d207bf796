// Spectrogram: the short-time Fourier transform's power or amplitude, segment by segment.
//
// Segments, detrending and windowing as in welch.hpp (periodic window, segment m starts at
// m (nperseg - noverlap)); for each segment m and bin k:
//   kPsd:        S_{m,k} = c_k |X_{m,k}|^2 / (fs sum w^2)   [x^2/Hz]  (one Welch segment; scipy
//                spectrogram mode 'psd' with the same window and overlap)
//   kAmplitude:  S_{m,k} = c'_k |X_{m,k}| / sum w            [x]  (peak amplitude as in
//                spectrum.hpp: c'_k = 2 inside, 1 at DC and Nyquist)
// Times are the segment centres, t_m = (m step + nperseg / 2) / fs (as scipy).
// Defaults differ from scipy.signal.spectrogram (Tukey 0.25, noverlap nperseg/8): here the Hann
// window and 50 % overlap, as Welch.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "detect/spectral/welch.hpp"

namespace detect {

enum class SpectrogramMode {
  kPsd,        // one-sided power spectral density per segment [x^2/Hz]
  kAmplitude,  // one-sided peak amplitude per segment [x]
};

struct SpectrogramOptions {
  double fs_hz = 1.0;                     // sampling rate [Hz], finite, > 0
  std::size_t nperseg = 256;              // segment length [samples], [8, 2^24]
  long long noverlap = -1;                // [0, nperseg); -1: nperseg / 2
  std::size_t nfft = 0;                   // 0: nperseg; else [nperseg, 2^26]
  WindowType window = WindowType::kHann;  // periodic form
  Detrend detrend = Detrend::kConstant;
  SpectrogramMode mode = SpectrogramMode::kPsd;

  void validate() const;  // throws diag::InputError "spectrogram: <field>: ..."
};

struct Spectrogram {
  std::vector<double> frequency_hz;  // nfft/2 + 1 bins, k fs / nfft
  std::vector<double> time_s;        // segment centres
  std::vector<double> value;         // row-major: value[m * frequency_hz.size() + k]
  SpectrogramMode mode = SpectrogramMode::kPsd;

  double at(std::size_t segment, std::size_t bin) const {
    return value[segment * frequency_hz.size() + bin];
  }
};

// x: at least nperseg finite samples.
Spectrogram spectrogram(std::span<const double> x, const SpectrogramOptions& options);

}  // namespace detect
