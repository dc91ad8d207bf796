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
// band holding fc +- fm reads A m at fm. By default (max_frequency_hz 0) the envelope is taken at
// the record's own samples, as defined.
// With max_frequency_hz = f_max > 0 (a caller that reads the spectrum only up to f_max), |z| is
// taken at fewer instants: the band's analytic signal moved to baseband (|z| unchanged) at
// len = the smallest 2^a 3^b 5^c >= 2 k_max + 32 m + 2 equispaced instants spanning the record
// (k_max = ceil(f_max / df), m the band's bins, df = fs / n), i.e. at fs' >= 2 f_max + 32 B for a
// band B Hz wide. The spectrum is on the record's grid k df (the instants span the same period),
// k = 0..len/2 (to fs'/2 >= f_max + 16 B, not to fs/2). This is NOT exact: |z| is not
// band-limited (a square root; for Gaussian band noise its spectrum's tail falls off as a power
// of B / f), and its tail beyond fs'/2 folds back onto the kept bins, as the definition's own tail
// beyond fs/2 does. Measured against the definition (the record's samples) on the reference
// recordings, over [0, f_max]: the largest difference is 0.9 % of the spectrum's median there
// (ts10, 156 Hz band, f_max 1 kHz, len = 0.35 n), 0.4 % and 0.3 % on CWRU channels (125 and 500 Hz
// bands); at fs' = 2 f_max + 16 B it was 3 %, at 2 f_max + 4 B 23 %: hence 32 B. A band so wide
// that len >= n uses the record's samples (the definition). Cost: one DFT of n and two of len
// instead of four of n.
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

// The smallest even 2^a 3^b 5^c >= n (a >= 1): a length FFTW transforms at full speed (the band
// signals here and in kurtogram.hpp are padded to it; a prime-length band took FFTW's slow path,
// and an odd one is 10-20 times slower in FFTW's real transforms: c2r of 5625 = 3^2 5^4 took
// 0.27 ms against 0.028 ms for 5760 = 2^7 3^2 5, 10935 = 3^7 5 0.53 ms against 0.027 ms for
// 11520). Belongs with fft.hpp.
std::size_t smooth_length_at_least(std::size_t n);
// The largest 2^a 3^b 5^c 7^d <= n (n >= 1): the record length the analysis stages and
// diagnose_bearings_from_signal cut a record to (its middle), so that its whole-record DFTs run at
// FFTW's full speed: a length with a large prime factor (CWRU's 121265 = 5 x 79 x 307) took 4.4 ms
// per real DFT against 0.37 ms at 120960 = 2^7 3^3 5 7. At most 1/64 of the samples is dropped for
// n >= 2^16, 1/50 for n >= 2^14, 1/25 for n >= 2^10 (the largest gap between such numbers,
// computed up to 2^33). Belongs with fft.hpp.
std::size_t fast_length_at_most(std::size_t n);
// The middle fast_length_at_most(x.size()) samples of x (x itself when its length is one).
std::span<const double> fast_length_middle(std::span<const double> x);

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
  double max_frequency_hz = 0;  // > 0: the spectrum is read only up to this
                                // [Hz]; |z| at fewer instants (see above); 0:
                                // the definition, to fs / 2

  void validate() const;  // throws diag::InputError "envelope_spectrum: <field>: ..."
};

// The decimation of the envelope for max_frequency_hz > 0: |z| at fs' >= 2 f_max + this many
// band widths (see above).
inline constexpr std::size_t kEnvelopeAliasBands = 32;

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
