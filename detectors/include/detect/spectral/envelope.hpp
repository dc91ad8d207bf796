// Analytic signal, envelope and envelope spectrum (the bearing/gear demodulation chain;
// Randall & Antoni 2011, "Rolling element bearing diagnostics - a tutorial", MSSP 25, sec. 3.2;
// MATLAB envspectrum, method 'hilbert').
//
// analytic_signal: z = x + i H{x} by DFT (Marple 1999, IEEE TSP 47(9); = scipy.signal.hilbert):
//   Z_k = X_k h_k,  h_0 = 1, h_k = 2 for 0 < k < N/2, h_{N/2} = 1 (N even), h_k = 0 above.
// Computed as two real inverse DFTs: Re z = IDFT(X h / 2 + conj-mirror) = x, Im z = IDFT(-i sgn X).
// envelope: |z| = sqrt(Re^2 + Im^2) (no hypot: |x| is far below DBL_MAX / n, so the squares
// cannot overflow). For x = a(t) cos(2 pi fc t + phi) with a's spectrum inside (0, fc) and a
// record of whole periods, |z| = a(t) exactly.
//
// envelope_spectrum: x band-passed to [low_hz, high_hz] in the DFT domain (filter.hpp), its
// envelope, the envelope's mean removed, then the single-sided amplitude spectrum
// (spectrum.hpp, peak scaling). An AM signal A (1 + m cos(2 pi fm t)) cos(2 pi fc t) with the
// band holding fc +- fm reads A m at fm. |z| is not band-limited (a square root), so the
// envelope is taken at the record's own samples, as defined.
//
// squared_envelope_spectrum (SES; Randall & Antoni 2011, sec. 3.2): the same with |z|^2, from the
// record's DFT (a caller that has it, e.g. a prewhitened spectrum, skips a forward DFT), on the
// record's grid k fs / n, k = 0..n/2. |z|^2 IS band-limited: for a band of m bins, z's baseband
// form c(t) = z(t) exp(-2 pi i f_lo t) (|c| = |z|) holds frequencies 0..m-1 bins, so |c|^2 holds
// -(m-1)..m-1 and, times a periodic window whose cosine sum has T terms (rectangular 0, Hann and
// Hamming 1), -(m-1+T)..m-1+T. Sampled at len > 2 (m - 1 + T) equispaced instants
// t_j = j n / len (one inverse DFT of the band's bins at length len), its windowed DFT has the
// same bins as at the record's n samples, times len / n, and so does the window's sum: the
// amplitude spectrum is the same, exactly (round-off aside), its mean too, and the bins above
// m - 1 + T are zero. len is the smallest 2^a 3^b 5^c >= 2 (m + T) + 1; when that is not below n
// (a wide band) or the window is longer (Blackman-Harris, flat-tops), the record's own samples.
// Cost O(n) + O(len log len) instead of three length-n DFTs.
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

// The smallest 2^a 3^b 5^c >= n: a length FFTW transforms at full speed (the band signals here
// and in kurtogram.hpp are padded to it; a prime-length band took FFTW's slow path). Belongs
// with fft.hpp.
std::size_t smooth_length_at_least(std::size_t n);

// The DFT bins k of a record of n samples with band.low_hz <= k fs / n <= band.upper_hz()
// (lo > hi: none). Validates band.
struct BandBins {
  std::size_t lo = 0, hi = 0;
};
BandBins band_bins(std::size_t n, const BandOptions& band);

struct EnvelopeSpectrumOptions {
  double fs_hz = 1.0;                            // sampling rate [Hz], finite, > 0
  double band_low_hz = 0.0;                      // demodulation band [Hz], [0, band_high_hz)
  double band_high_hz = 0.0;                     // (band_low_hz, fs/2]; 0: fs / 2
  WindowType window = WindowType::kRectangular;  // on the envelope (MATLAB: rectangular)
  AmplitudeScaling scaling = AmplitudeScaling::kPeak;

  void validate() const;  // throws diag::InputError "envelope_spectrum: <field>: ..."
};

Spectrum envelope_spectrum(std::span<const double> x, const EnvelopeSpectrumOptions& options);

// SES of the record of n samples whose DFT is X (RealFft(n).forward: n/2 + 1 bins; throws
// diag::InputError otherwise) in [band.low_hz, band.upper_hz()], the mean of |z|^2 removed,
// `window` on it, peak scaling (see the top of this header). record: empty, or the record x
// itself (n samples, the inverse DFT of X): with a band holding every bin, Re z = x, and one
// inverse DFT is saved.
Spectrum squared_envelope_spectrum(std::span<const std::complex<double>> X, std::size_t n,
                                   const BandOptions& band, WindowType window = WindowType::kHann,
                                   std::span<const double> record = {});

}  // namespace detect
