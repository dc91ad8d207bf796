// Filters: an FFT-domain (brick-wall) band-pass, and a windowed-sinc FIR low-pass applied with
// zero phase, with decimation built on it.
//
// fft_bandpass: X_k = DFT(x), keep the bins with low_hz <= k fs/N <= high_hz, zero the others,
// inverse DFT. Exact for a record holding whole periods of its content (circular); otherwise
// the edges ring (Gibbs): taper the record or discard the edges when that matters.
//
// design_lowpass_fir: h_j = w_j 2 (fc/fs) sinc(2 (fc/fs) (j - M)), j = 0..2M (an odd number of
// taps, symmetric window w), normalised to sum h = 1 (unit DC gain): diag::design_lowpass
// (diag/dsp/fir.hpp) with the window's values. Linear phase, delay M;
// applied centred (filter_zero_phase, decimate) the delay is removed, i.e. zero phase. The
// transition band is about enbw-of-the-window * fs / taps wide; with Blackman-Harris the
// stop band is below about -90 dB (Oppenheim & Schafer, Discrete-Time Signal Processing, 7.5).
// For anti-alias decimation by D choose cutoff_hz <= fs / (2 D) minus the transition band:
// design_decimation_lowpass does that.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "detect/spectral/window.hpp"

namespace detect {

struct BandOptions {
  double fs_hz = 1.0;    // sampling rate [Hz], finite, > 0
  double low_hz = 0.0;   // lower band edge [Hz], [0, high_hz)
  double high_hz = 0.0;  // upper band edge [Hz], (low_hz, fs/2]; 0: fs / 2

  void validate() const;  // throws diag::InputError "band: <field>: ..."
  double upper_hz() const { return high_hz == 0.0 ? 0.5 * fs_hz : high_hz; }
};

// Brick-wall band-pass by DFT; x: at least 2 finite samples.
std::vector<double> fft_bandpass(std::span<const double> x, const BandOptions& band);

struct FirLowpassOptions {
  double fs_hz = 1.0;                               // sampling rate [Hz], finite, > 0
  double cutoff_hz = 0.25;                          // -6 dB point [Hz], (0, fs/2)
  std::size_t taps = 101;                           // odd, [3, 2^16 + 1]
  WindowType window = WindowType::kBlackmanHarris;  // symmetric form is used

  void validate() const;  // throws diag::InputError "fir_lowpass: <field>: ..."
};

std::vector<double> design_lowpass_fir(const FirLowpassOptions& options);

// Low-pass for decimation by `factor` (>= 2): cutoff fs / (2 factor) less the transition band
// (4 fs / taps: half the Blackman-Harris main lobe), so that nothing above the new Nyquist
// frequency leaks through the transition band. With the default 64 factor + 1 taps the pass band
// (gain 1 within 1e-4) reaches 0.75 of the new Nyquist frequency. taps odd; throws
// diag::InputError when taps is too short for the factor.
std::vector<double> design_decimation_lowpass(double fs_hz, std::size_t factor,
                                              std::size_t taps = 0);  // 0: 64 factor + 1

// y_i = sum_j h_j x_{i + j - M}, M = (taps - 1)/2: centred (zero-phase for symmetric h), output
// as long as x; beyond the ends x is mirrored about its end samples (x_{-j} = x_j,
// x_{N-1+j} = x_{N-1-j}). taps odd; x.size() > M; x finite.
std::vector<double> filter_zero_phase(std::span<const double> x, std::span<const double> taps);

// filter_zero_phase(x, taps) evaluated at every factor-th sample only (i = 0, factor, ...):
// ceil(N / factor) samples at fs / factor.
std::vector<double> decimate(std::span<const double> x, std::size_t factor,
                             std::span<const double> taps);

}  // namespace detect
