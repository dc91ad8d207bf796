// Analytic signal, envelope and envelope spectrum (the bearing/gear demodulation chain;
// Randall & Antoni 2011, "Rolling element bearing diagnostics - a tutorial", MSSP 25, sec. 3.2;
// MATLAB envspectrum, method 'hilbert').
//
// analytic_signal: z = x + i H{x} by DFT (Marple 1999, IEEE TSP 47(9); = scipy.signal.hilbert):
//   Z_k = X_k h_k,  h_0 = 1, h_k = 2 for 0 < k < N/2, h_{N/2} = 1 (N even), h_k = 0 above.
// Computed as two real inverse DFTs: Re z = IDFT(X h / 2 + conj-mirror) = x, Im z = IDFT(-i sgn X).
// envelope: |z|. For x = a(t) cos(2 pi fc t + phi) with a's spectrum inside (0, fc) and a
// record of whole periods, |z| = a(t) exactly.
//
// envelope_spectrum: x band-passed to [low_hz, high_hz] in the DFT domain (filter.hpp), its
// envelope, the envelope's mean removed, then the single-sided amplitude spectrum
// (spectrum.hpp, peak scaling). An AM signal A (1 + m cos(2 pi fm t)) cos(2 pi fc t) with the
// band holding fc +- fm reads A m at fm.
#pragma once

#include <complex>
#include <span>
#include <vector>

#include "detect/spectral/filter.hpp"
#include "detect/spectral/spectrum.hpp"

namespace detect {

// x: at least 2 finite samples.
std::vector<std::complex<double>> analytic_signal(std::span<const double> x);
std::vector<double> envelope(std::span<const double> x);
// Envelope of x band-passed to [band.low_hz, band.upper_hz()] (one forward DFT, two inverse).
std::vector<double> band_envelope(std::span<const double> x, const BandOptions& band);

struct EnvelopeSpectrumOptions {
  double fs_hz = 1.0;                            // sampling rate [Hz], finite, > 0
  double band_low_hz = 0.0;                      // demodulation band [Hz], [0, band_high_hz)
  double band_high_hz = 0.0;                     // (band_low_hz, fs/2]; 0: fs / 2
  WindowType window = WindowType::kRectangular;  // on the envelope (MATLAB: rectangular)
  AmplitudeScaling scaling = AmplitudeScaling::kPeak;

  void validate() const;  // throws diag::InputError "envelope_spectrum: <field>: ..."
};

Spectrum envelope_spectrum(std::span<const double> x, const EnvelopeSpectrumOptions& options);

}  // namespace detect
