// Condition indicators: time-domain statistics of a vibration signal and the gear metrics computed
// from a time-synchronous average (TSA) and the signals derived from it.
//
// Sources (each formula below names its own):
//  [Z93] Zakrajsek, Townsend, Decker, "An analysis of gear fault detection methods as applied to
//        pitting fatigue failure data", NASA TM-106032 (1993).
//  [D02] Decker, "Crack detection for aerospace quality spur gears", NASA TM-2002-211491 (2002).
//  [L00] Lebold, McClintic, Campbell, Byington, Maynard, "Review of vibration analysis methods for
//        gearbox diagnostics and prognostics", Proc. 54th MFPT (2000).
//  [ML]  MathWorks, Predictive Maintenance Toolbox, gearConditionMetrics (documentation).
//  [P08] Pebay, "Formulas for robust, one-pass parallel computation of covariances and
//        arbitrary-order statistical moments", Sandia SAND2008-6212 (2008).
//
// Notation: x_i, i = 1..N, a signal; x_bar its mean; d the difference signal, r the residual
// signal, y the regular signal (TSA minus everything but the shaft orders and the mesh harmonics);
// all moments are central and population-normalised (divided by N, not N - 1).
//
// Degenerate inputs: an empty signal is an error (diag::InputError). Statistics whose denominator
// is the variance (kurtosis, skewness, M6A, M8A, crest factor of an all-zero signal) are NaN when
// that denominator is exactly zero: "undefined" is the answer, not an exception.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace detect {

class Na4Ensemble;

// ---- Time-domain statistics ------------------------------------------------------------------

struct Moments {
  std::size_t count = 0;  // N
  double mean = 0;        // x_bar
  double m2 = 0;          // sum (x - x_bar)^2
  double m3 = 0;          // sum (x - x_bar)^3
  double m4 = 0;          // sum (x - x_bar)^4
  double min = 0;         // smallest sample
  double max = 0;         // largest sample

  double variance() const;      // m2 / N (population)
  double rms() const;           // sqrt(x_bar^2 + m2 / N) = sqrt(sum x^2 / N)
  double peak() const;          // max |x| = max(|min|, |max|)
  double peak_to_peak() const;  // max - min
  double crest_factor() const;  // peak / rms; sqrt(2) for a sine
  // Normalised kurtosis N m4 / m2^2 [Z93 eq. for FM4; L00]: 3 for Gaussian noise, 1.5 for a sine.
  // No "-3": this is the kurtosis the gear literature uses, not the excess kurtosis.
  double kurtosis() const;
  double skewness() const;  // sqrt(N) m3 / m2^(3/2): 0 for any symmetric distribution
};

// Two passes over an in-memory signal (mean first, then the central sums): the reference.
Moments moments(std::span<const double> x);

// Streaming moments for recordings that do not fit in memory: feed chunks in order (or in any
// order: the statistics do not depend on it beyond round-off), read result() at any time.
// Each chunk is reduced exactly (two passes) and merged with the running state by Pebay's
// pairwise update [P08 eqs. 3.1-3.4, p = 2..4], which stays accurate when the mean is large
// compared with the spread (no sum-of-powers cancellation). Memory: O(1).
class MomentAccumulator {
 public:
  void add(std::span<const double> chunk);
  void add(double x) { add(std::span<const double>(&x, 1)); }
  void merge(const MomentAccumulator& other);  // combine two accumulators (e.g. per thread)
  // InputError if nothing was added.
  const Moments& result() const;
  std::size_t count() const { return m_.count; }
  void reset() { m_ = Moments{}; }

 private:
  void merge(const Moments& b);
  Moments m_;
};

double rms(std::span<const double> x);           // sqrt(sum x^2 / N)
double peak(std::span<const double> x);          // max |x|
double peak_to_peak(std::span<const double> x);  // max x - min x
double crest_factor(std::span<const double> x);  // peak / rms
double kurtosis(std::span<const double> x);      // N sum (x-x_bar)^4 / (sum (x-x_bar)^2)^2
double skewness(std::span<const double> x);      // sqrt(N) sum (x-x_bar)^3 / (sum ...^2)^(3/2)

// ---- Gear metrics from the TSA and its derived signals -----------------------------------------

// FM4 = N sum (d - d_bar)^4 / (sum (d - d_bar)^2)^2: the kurtosis of the difference signal
// [Z93; D02; ML]. About 3 for a healthy gear (Gaussian-like difference signal).
double fm4(std::span<const double> difference);
// M6A = N^2 sum (d - d_bar)^6 / (sum (d - d_bar)^2)^3 [Z93 (Martin's M6A); D02; ML]: 15 for
// Gaussian, 2.5 for a sine.
double m6a(std::span<const double> difference);
// M8A = N^3 sum (d - d_bar)^8 / (sum (d - d_bar)^2)^4 [Z93; D02; ML]: 105 for Gaussian, 35/8 for a
// sine.
double m8a(std::span<const double> difference);
// ER = RMS(d) / RMS(y) [D02 "energy ratio"; ML]: the difference signal's energy relative to the
// regular (shaft + mesh harmonics) signal's.
double energy_ratio(std::span<const double> difference, std::span<const double> regular);

// The single-sided amplitude spectrum of one revolution of a TSA, indexed by shaft order:
// a[0] = |X_0| / N (the mean), a[k] = 2 |X_k| / N for 0 < k < N/2, a[N/2] = |X_{N/2}| / N for even
// N, where X is the DFT of the N samples. A term A cos(k theta + phi) gives a[k] = A exactly.
// Uses detect::RealFft.
std::vector<double> order_amplitudes(std::span<const double> tsa_rev);

struct GearMetricOptions {
  int mesh_order = 0;      // teeth on the monitored gear = mesh order of the TSA's shaft
                           // [cycles/rev], >= 1; with the other fields, orders up to
                           // mesh_harmonics * mesh_order + ser_sidebands must lie below N/2
  int mesh_harmonics = 3;  // H: mesh harmonics 1..H summed in FM0's denominator, 1..32
  int ser_sidebands = 6;   // sidebands on each side of the mesh order summed in SER [ML: 6],
                           // 1..64 and < mesh_order (lower sidebands must be positive orders)

  // Throws diag::InputError naming the field; tsa_samples: samples per revolution N.
  void validate(std::size_t tsa_samples) const;
};

// FM0 = PP(tsa) / sum_{h=1..H} A(h z) [Z93, after Stewart; D02; ML], A the order amplitudes of the
// TSA, z the mesh order. CAUTION: [Z93] prints the sum from n = 0; the 0th "harmonic" is the mean,
// which carries no mesh information and would make FM0 depend on a sensor offset, so the sum
// starts at h = 1 (as [ML]: "sum of the amplitudes of the gear mesh frequency and its
// harmonics"). A pure mesh tone gives FM0 = 2.
double fm0(std::span<const double> tsa_rev, std::span<const double> order_amps,
           const GearMetricOptions& opt);
// SER = sum_{k=1..K} (A(z - k) + A(z + k)) / A(z) [ML "sideband energy ratio", K = 6 there]:
// sidebands of the mesh fundamental on both sides over its amplitude.
double sideband_energy_ratio(std::span<const double> order_amps, const GearMetricOptions& opt);
// SLF = (A(z - 1) + A(z + 1)) / RMS(tsa) [D02 "sideband level factor" divides by the standard
// deviation of the TSA: the same for the usual zero-mean TSA; RMS is what [ML] uses].
double sideband_level_factor(std::span<const double> tsa_rev, std::span<const double> order_amps,
                             const GearMetricOptions& opt);
// SI = (A(z - 1) + A(z + 1)) / 2 [D02 "sideband index"]: in the TSA's units.
double sideband_index(std::span<const double> order_amps, const GearMetricOptions& opt);

// One revolution of each signal for one gear, all of the same length N (samples per revolution).
// Spans may be empty when a metric is not wanted: metrics that need a missing signal are NaN.
struct GearSignals {
  std::span<const double> tsa;         // time-synchronous average
  std::span<const double> difference;  // d: TSA minus shaft orders, mesh harmonics and their
                                       // first-order sidebands
  std::span<const double> regular;     // y: shaft orders + mesh harmonics only
  std::span<const double> residual;    // r: TSA minus shaft orders and mesh harmonics
};

struct GearIndicators {
  double rms = 0, peak = 0, crest_factor = 0, kurtosis = 0;  // of the TSA
  double fm0 = 0;                                            // TSA
  double fm4 = 0;                                            // difference
  double m6a = 0;                                            // difference
  double m8a = 0;                                            // difference
  double na4 = 0;  // residual, against the run ensemble (see na4.hpp)
  double er = 0;   // difference / regular
  double ser = 0;  // TSA spectrum
  double slf = 0;  // TSA spectrum and RMS
  double si = 0;   // TSA spectrum
};

// Every metric above for one record. NA4 uses `ensemble` as it stands (add this record's residual
// to it first, as the trend definition [Z93] includes the current record); with no ensemble, NA4
// is computed against the current residual alone (an ensemble of one: NA4 = kurtosis(r)).
GearIndicators gear_indicators(const GearSignals& s, const GearMetricOptions& opt,
                               const Na4Ensemble* ensemble = nullptr);

}  // namespace detect
