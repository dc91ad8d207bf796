// Baseline comparison: unit-free features of a vibration channel, a robust healthy baseline
// (median / MAD per feature) and an anomaly score with an alarm threshold.
//
// ---- Features (baseline_features) ----
// Every feature is dimensionless and independent of the sensor's gain and of the sampling rate
// when the rate is only nominal (band edges are fractions of fs), so a baseline can be compared
// across sensors of unknown calibration and recordings of unknown rate:
//   kurtosis_log   ln K,  K = N sum (x - x_bar)^4 / (sum (x - x_bar)^2)^2   (3 for Gaussian noise)
//   crest_log      ln CF, CF = max |x - x_bar| / std(x)                  (sqrt 2 for a sine)
//   skewness       sqrt(N) sum (x - x_bar)^3 / (sum (x - x_bar)^2)^(3/2)
//   band<i>_log_fraction   ln(E_i / E_tot): the share of the Welch PSD P_k (Hann, 50 % overlap,
//                  nperseg samples) in log-spaced band i of `bands` bands between
//                  f_lo = lowest_band_fraction fs and fs/2 (edges f_lo (fs/(2 f_lo))^(i/bands));
//                  E_tot = sum of P_k over [f_lo, fs/2]. Default: 7 octave bands from fs/256.
//   flatness_log   ln(geometric mean / arithmetic mean of P_k over [f_lo, fs/2]) (Wiener entropy;
//                  Johnston 1988): 0 for a flat spectrum, near 0 for white noise averaged over
//                  many segments (-0.58 = -Euler's gamma for a single periodogram), very
//                  negative for a line spectrum
// Logarithms make the ratios' scatter roughly symmetric and additive, so that one spread per
// feature describes it and a factor-of-e change reads 1 whatever the feature.
// Why these: a localised gear fault (broken tooth, spall) adds short impacts, which raise the
// moments and move vibration energy towards the structural resonances they excite, i.e. change
// the spectrum's *shape*; load and speed change mainly the level (removed by the normalisation)
// and the low-frequency content (left out below f_lo, where shaft-rate harmonics and rigid-body
// motion live; with nperseg = 1024 and fs/256 the lowest band also holds at least 4 Welch bins).
//
// ---- Baseline and score (Baseline) ----
// fit: per feature j over the healthy feature sets, centre c_j = median, spread
//   s_j = max(1.4826 MAD_j, spread_floor),  MAD_j = median |x_j - c_j|
// (1.4826 MAD is the standard deviation for Gaussian data; Rousseeuw & Croux, JASA 88 (1993)).
// score: z_j = (x_j - c_j) / s_j (robust sigmas), anomaly_score = (1/d) sum_j z_j^2 over the d
// features of the baseline, alarm when anomaly_score > alarm_threshold.
//
// Threshold (default 25, i.e. an RMS deviation of 5 robust sigmas): if the z_j were independent
// standard normals, d * score would be chi-square with d degrees of freedom and a threshold near 1
// would do; but the features are strongly correlated (band shares sum to one, channels see one
// machine) and the worst case, all z_j equal, makes the score chi-square with ONE degree of
// freedom whatever d is. That case is the worst for every correlation: with R the features'
// correlation matrix, d * score = sum mu_i Z_i^2 (mu_i the eigenvalues of R, sum d), and
// P(sum lambda_i Z_i^2 >= t) over lambda_i >= 0, sum lambda_i = 1 is largest at a single
// lambda = 1 for every t > 1.5364 (Szekely & Bakirov, "Extremal probabilities for Gaussian
// quadratic forms", Probab. Theory Relat. Fields 126 (2003) 184-202). So for Gaussian features,
// P(false alarm) <= P(chi2_1 > 25) = P(|z| > 5) = 5.7e-7, whatever their correlation.
// The factor of about 2.3 between the chi2_1 99.9 % point (10.8) and 25 is the allowance for
// operating points outside the ones the baseline holds: a baseline fitted over a few loads sees
// their spread only, and a healthy machine at a new load extrapolates (measured on the
// SpectraQuest set: RMS 3.2 sigma for the healthy gear at 0 % load from a 20-80 % baseline,
// against 7-11 sigma for its broken tooth at every load).
// CAUTION: a feature whose baseline never varies (a constant) has spread spread_floor; choose
// the floor in the features' units (default 0.05: a 5 % change of a ratio, below repeatability).
#pragma once

#include <cstddef>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "diag/io/recording.hpp"

namespace detect {

struct BaselineFeatureOptions {
  std::size_t nperseg = 1024;  // Welch segment [samples], [64, 2^20]; the channel needs
                               // at least 4 nperseg samples
  double lowest_band_fraction = 1.0 / 256;  // f_lo / fs, [1/nperseg, 1/8]: the PSD below is left
                                            // out (shaft-rate, rigid-body and load effects)
  int bands = 7;                            // log-spaced bands in [f_lo, fs/2], [1, 32]; with
                                            // the default f_lo, 7 bands are octaves

  void validate() const;  // throws diag::InputError "baseline_features: <field>: ..."
};

using FeatureSet = std::map<std::string, double>;

// The features above, named as listed ("band0_log_fraction" is the lowest band). The channel is
// validated (diag::validate) and must hold at least 4 nperseg samples, not all equal.
FeatureSet baseline_features(const diag::Signal& channel,
                             const BaselineFeatureOptions& options = {});

// Prepends "<prefix>." to every name: features of several channels in one set ("a1.skewness").
FeatureSet prefixed(const std::string& prefix, const FeatureSet& features);

struct BaselineOptions {
  double alarm_threshold = 25.0;  // on anomaly_score (mean squared robust z), > 0; see above
  double spread_floor = 0.05;     // smallest spread of a feature [feature units], > 0: guards
                                  // small or constant baselines against division by ~0
  std::size_t min_samples = 3;    // healthy feature sets needed to fit, >= 3 (a MAD of two is
                                  // half their distance, of one is zero)

  void validate() const;  // throws diag::InputError "baseline: <field>: ..."
};

class Baseline {
 public:
  struct FeatureStats {
    double centre = 0;  // median over the healthy sets
    double spread = 0;  // max(1.4826 MAD, spread_floor), > 0
  };

  // healthy: at least min_samples feature sets with the same names, all finite. Throws
  // diag::InputError naming the set and feature at fault.
  static Baseline fit(const std::vector<FeatureSet>& healthy, const BaselineOptions& options = {});

  struct Score {
    std::map<std::string, double> deviation;  // z_j [robust sigmas], every baseline feature
    double anomaly_score = 0;                 // (1/d) sum z_j^2
    bool alarm = false;                       // anomaly_score > threshold
    double threshold = 0;                     // the options' alarm_threshold
    std::string largest;                      // the feature with the largest |z_j|
  };

  // features must hold every baseline feature (extra ones are ignored), finite.
  Score score(const FeatureSet& features) const;

  const std::map<std::string, FeatureStats>& features() const { return stats_; }
  const BaselineOptions& options() const { return options_; }
  std::size_t samples() const { return samples_; }

  // {"options": {...}, "samples": n, "features": {name: {"centre", "spread"}}}
  nlohmann::json to_json() const;
  static Baseline from_json(const nlohmann::json& j);  // throws diag::InputError when malformed

 private:
  std::map<std::string, FeatureStats> stats_;
  BaselineOptions options_;
  std::size_t samples_ = 0;
};

nlohmann::json to_json(const Baseline::Score& score);

}  // namespace detect
