// Spectral kurtosis (STFT estimator) and the fast kurtogram.
//
// Spectral kurtosis (Antoni 2006, "The spectral kurtosis: a useful tool for characterising
// non-stationary signals", MSSP 20, eq. 10 with the STFT estimator of sec. 4):
//   SK(f_k) = <|X_m(f_k)|^4>_m / <|X_m(f_k)|^2>_m^2 - 2,
// X_m the windowed DFT of segment m. 0 for stationary Gaussian noise (a complex circular
// Gaussian has E|X|^4 = 2 (E|X|^2)^2), -1 for a steady tone, large and positive where impulsive
// (transient) energy lives. At DC and Nyquist X is real and Gaussian noise reads 1 there.
//
// Fast kurtogram (Antoni 2007, "Fast computation of the kurtogram for the detection of
// transient faults", MSSP 21, sec. 3-4): the band [0, fs/2] is split on the 1/3-binary tree of
// levels l = 0, 1, log2 3, 2, 1 + log2 3, 3, ..., max_level; level l has 2^l bands of width
// B_l = fs / 2^(l+1), band i covering [i B_l, (i + 1) B_l) (centre (i + 1/2) B_l; half-open: the
// DFT bin at fs/2 of an even-length record is in no band). For each band
// the kurtosis of its complex envelope c_n (the analytic band signal shifted to baseband),
//   K = <|c|^4> / <|c|^2>^2 - 2,
// is computed, and the band with the largest K is selected (the band to demodulate for an
// envelope spectrum).
// IMPLEMENTATION NOTE (differs from the paper's filter bank): Antoni builds the tree from
// quasi-analytic FIR filters (a low-pass h and its 1/4-band-shifted copies, decimating by 2 and
// 3 at each step). Here every band is cut from one DFT of the whole record with brick-wall
// edges: c is the inverse DFT of the band's bins, zero-padded to at least twice their number (the
// paper's complex decimated signals are oversampled by 2; the padded length is the next even
// 2^a 3^b 5^c above twice the level's widest band, one fast FFT length per level, which leaves K
// unchanged: |c|^4 of m bins is a trigonometric polynomial of degree 2(m - 1), whose mean any
// >= 2m - 1 equispaced samples give exactly). Same bands, same statistic; sharper band edges and
// no leakage between neighbours; cost O(N log N) per level (about one complex inverse FFT of the
// record), the cost of the paper's filter-bank tree too. Being circular, it needs the record's ends
// tapered (taper_fraction) so that a steady tone cut mid-period does not appear as one impulse per
// record in the bands beside it.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "detect/spectral/window.hpp"

namespace detect {

struct SpectralKurtosisOptions {
  double fs_hz = 1.0;                     // sampling rate [Hz], finite, > 0
  std::size_t nperseg = 256;              // segment length [samples], [8, 2^24]
  long long noverlap = -1;                // [0, nperseg); -1: 3 nperseg / 4
  WindowType window = WindowType::kHann;  // periodic form

  void validate() const;  // throws diag::InputError "spectral_kurtosis: <field>: ..."
};

struct SpectralKurtosis {
  std::vector<double> frequency_hz;  // k fs / nperseg, k = 0..nperseg/2
  std::vector<double> kurtosis;      // SK(f_k), dimensionless (0 for Gaussian noise)
  std::size_t segments = 0;
};

// x: at least 4 segments' worth of finite samples (fewer give no usable 4th moment).
SpectralKurtosis spectral_kurtosis(std::span<const double> x,
                                   const SpectralKurtosisOptions& options);

struct KurtogramOptions {
  double fs_hz = 1.0;  // sampling rate [Hz], finite, > 0
  int max_level = 6;   // deepest level, [1, 20]; x needs >= 2^(max_level + 7) samples (Antoni's
                       // rule nlevel <= log2(N) - 7: at least 64 bins in the narrowest band)
  double taper_fraction = 0.01;  // half-cosine ramp at each end of the record, as a fraction of
                                 // its length, [0, 0.25]: removes the wrap-around jump the DFT
                                 // filter bank would otherwise read as an impulse
  // The bands a caller can use (diagnose_bearings_from_signal: wide enough for the fault lines,
  // above them): a level whose bandwidth is below min_bandwidth_hz is not computed (not in
  // `levels`), and a band whose low edge i B_l is below min_low_hz is not computed (its kurtosis
  // NaN, never selected). Every computed band's kurtosis is the same as without them. 0: all.
  double min_bandwidth_hz = 0;  // [Hz], finite, >= 0
  double min_low_hz = 0;        // [Hz], finite, >= 0

  void validate() const;  // throws diag::InputError "kurtogram: <field>: ..."
};

struct KurtogramLevel {
  double level = 0;              // l: 0, 1, log2 3 = 1.585, 2, 2.585, ...
  double bandwidth_hz = 0;       // fs / 2^(l+1)
  std::vector<double> kurtosis;  // one per band, band i centred at (i + 1/2) bandwidth (NaN:
                                 // not computed, below min_low_hz)
};

struct Kurtogram {
  std::vector<KurtogramLevel> levels;  // in increasing l (those computed, see min_bandwidth_hz)
  double centre_hz = 0;                // the selected (largest-kurtosis) band
  double bandwidth_hz = 0;
  double level = 0;
  double kurtosis = 0;

  double low_hz() const { return centre_hz - 0.5 * bandwidth_hz; }
  double high_hz() const { return centre_hz + 0.5 * bandwidth_hz; }
};

// x: at least 2^(max_level + 7) finite samples. The record's mean is removed first.
Kurtogram fast_kurtogram(std::span<const double> x, const KurtogramOptions& options);

}  // namespace detect
