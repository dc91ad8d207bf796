#include "detect/baseline/baseline.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "detect/indicators/indicators.hpp"
#include "detect/spectral/welch.hpp"
#include "diag/error.hpp"

namespace detect {

namespace {

// Median of v (v is reordered).
double median_of(std::vector<double>& v) {
  const std::size_t n = v.size();
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(v.begin(), mid, v.end());
  const double upper = *mid;
  if (n % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(v.begin(), mid));
}

// 1 / Phi^{-1}(3/4): makes the MAD a consistent estimator of a Gaussian standard deviation.
constexpr double kMadToSigma = 1.482602218505602;

}  // namespace

void BaselineFeatureOptions::validate() const {
  const std::string w = "baseline_features";
  if (nperseg < 64 || nperseg > (std::size_t(1) << 20))
    diag::fail(w, "nperseg", std::to_string(nperseg) + " is not in [64, 2^20]");
  if (!(lowest_band_fraction >= 1.0 / static_cast<double>(nperseg)) ||
      !(lowest_band_fraction <= 0.125))
    diag::fail(w, "lowest_band_fraction",
               std::to_string(lowest_band_fraction) + " is not in [1/nperseg, 1/8]");
  if (bands < 1 || bands > 32) diag::fail(w, "bands", std::to_string(bands) + " is not in [1, 32]");
}

FeatureSet baseline_features(const diag::Signal& channel, const BaselineFeatureOptions& options) {
  options.validate();
  diag::validate(channel, "baseline_features");
  const std::span<const double> x(channel.samples);
  if (x.size() < 4 * options.nperseg)
    diag::fail("baseline_features", "channel " + channel.name,
               std::to_string(x.size()) +
                   " samples, needs at least 4 nperseg = " + std::to_string(4 * options.nperseg));

  const Moments m = moments(x);
  if (!(m.m2 > 0)) diag::fail("baseline_features", "channel " + channel.name, "all samples equal");
  const double sd = std::sqrt(m.variance());
  const double peak_dev = std::max(m.max - m.mean, m.mean - m.min);

  FeatureSet f;
  f["kurtosis_log"] = std::log(m.kurtosis());
  f["crest_log"] = std::log(peak_dev / sd);
  f["skewness"] = m.skewness();

  WelchOptions wo;
  wo.fs_hz = channel.fs_hz;
  wo.nperseg = options.nperseg;
  const Psd psd = welch(x, wo);
  const double f_lo = options.lowest_band_fraction * channel.fs_hz;
  const double f_hi = 0.5 * channel.fs_hz;
  const double ratio = f_hi / f_lo;

  // Bins in [f_lo, fs/2]; the band of bin k is floor(bands * ln(f_k / f_lo) / ln(f_hi / f_lo)),
  // the Nyquist bin joining the top band.
  std::vector<double> band_energy(static_cast<std::size_t>(options.bands), 0.0);
  double total = 0, log_sum = 0;
  std::size_t bins = 0;
  // CAUTION: a PSD bin can be exactly 0 (a synthetic, band-limited record); the log of the
  // geometric mean uses max(P_k, 1e-300) so that flatness stays finite (and very negative).
  for (std::size_t k = 0; k < psd.frequency_hz.size(); ++k) {
    const double fk = psd.frequency_hz[k];
    if (fk < f_lo * (1 - 1e-12)) continue;
    const double p = psd.value[k];
    int b = static_cast<int>(std::floor(options.bands * std::log(fk / f_lo) / std::log(ratio)));
    b = std::clamp(b, 0, options.bands - 1);
    band_energy[static_cast<std::size_t>(b)] += p;
    total += p;
    log_sum += std::log(std::max(p, 1e-300));
    ++bins;
  }
  if (!(total > 0))
    diag::fail("baseline_features", "channel " + channel.name, "no energy above f_lo");
  for (int b = 0; b < options.bands; ++b) {
    // An empty band (all its bins zero) reads ln(1e-300 / total): very negative, finite.
    const double share = std::max(band_energy[static_cast<std::size_t>(b)] / total, 1e-300);
    f["band" + std::to_string(b) + "_log_fraction"] = std::log(share);
  }
  const double mean_p = total / static_cast<double>(bins);
  f["flatness_log"] = log_sum / static_cast<double>(bins) - std::log(mean_p);
  return f;
}

FeatureSet prefixed(const std::string& prefix, const FeatureSet& features) {
  FeatureSet out;
  for (const auto& [name, value] : features) out.emplace(prefix + "." + name, value);
  return out;
}

void BaselineOptions::validate() const {
  const std::string w = "baseline";
  if (!(alarm_threshold > 0) || !std::isfinite(alarm_threshold))
    diag::fail(w, "alarm_threshold", std::to_string(alarm_threshold) + " is not finite and > 0");
  if (!(spread_floor > 0) || !std::isfinite(spread_floor))
    diag::fail(w, "spread_floor", std::to_string(spread_floor) + " is not finite and > 0");
  if (min_samples < 3) diag::fail(w, "min_samples", std::to_string(min_samples) + " is not >= 3");
}

Baseline Baseline::fit(const std::vector<FeatureSet>& healthy, const BaselineOptions& options) {
  options.validate();
  const std::string w = "Baseline::fit";
  if (healthy.size() < options.min_samples)
    diag::fail(w, "healthy",
               std::to_string(healthy.size()) + " feature sets, needs at least min_samples = " +
                   std::to_string(options.min_samples));
  if (healthy.front().empty()) diag::fail(w, "healthy[0]", "no features");
  Baseline b;
  b.options_ = options;
  b.samples_ = healthy.size();
  for (std::size_t i = 1; i < healthy.size(); ++i)
    if (healthy[i].size() != healthy.front().size())
      diag::fail(w, "healthy[" + std::to_string(i) + "]",
                 std::to_string(healthy[i].size()) + " features, healthy[0] has " +
                     std::to_string(healthy.front().size()));
  std::vector<double> values(healthy.size()), dev(healthy.size());
  for (const auto& [name, unused] : healthy.front()) {
    (void)unused;
    for (std::size_t i = 0; i < healthy.size(); ++i) {
      const auto it = healthy[i].find(name);
      if (it == healthy[i].end())
        diag::fail(w, "healthy[" + std::to_string(i) + "]", "feature '" + name + "' missing");
      if (!std::isfinite(it->second))
        diag::fail(w, "healthy[" + std::to_string(i) + "]." + name, "not finite");
      values[i] = it->second;
    }
    std::vector<double> tmp = values;
    const double centre = median_of(tmp);
    for (std::size_t i = 0; i < values.size(); ++i) dev[i] = std::abs(values[i] - centre);
    const double mad = median_of(dev);
    b.stats_[name] = FeatureStats{centre, std::max(kMadToSigma * mad, options.spread_floor)};
  }
  return b;
}

Baseline::Score Baseline::score(const FeatureSet& features) const {
  Score s;
  s.threshold = options_.alarm_threshold;
  double sum_sq = 0, largest = -1;
  for (const auto& [name, st] : stats_) {
    const auto it = features.find(name);
    if (it == features.end()) diag::fail("Baseline::score", name, "feature missing");
    if (!std::isfinite(it->second)) diag::fail("Baseline::score", name, "not finite");
    const double z = (it->second - st.centre) / st.spread;
    s.deviation[name] = z;
    sum_sq += z * z;
    if (std::abs(z) > largest) {
      largest = std::abs(z);
      s.largest = name;
    }
  }
  s.anomaly_score = sum_sq / static_cast<double>(stats_.size());
  s.alarm = s.anomaly_score > s.threshold;
  return s;
}

nlohmann::json Baseline::to_json() const {
  nlohmann::json j;
  j["options"] = {{"alarm_threshold", options_.alarm_threshold},
                  {"spread_floor", options_.spread_floor},
                  {"min_samples", options_.min_samples}};
  j["samples"] = samples_;
  nlohmann::json f = nlohmann::json::object();
  for (const auto& [name, st] : stats_) f[name] = {{"centre", st.centre}, {"spread", st.spread}};
  j["features"] = f;
  return j;
}

Baseline Baseline::from_json(const nlohmann::json& j) {
  const std::string w = "Baseline::from_json";
  try {
    Baseline b;
    const auto& o = j.at("options");
    b.options_.alarm_threshold = o.at("alarm_threshold").get<double>();
    b.options_.spread_floor = o.at("spread_floor").get<double>();
    b.options_.min_samples = o.at("min_samples").get<std::size_t>();
    b.options_.validate();
    b.samples_ = j.at("samples").get<std::size_t>();
    for (const auto& [name, st] : j.at("features").items()) {
      const FeatureStats fs{st.at("centre").get<double>(), st.at("spread").get<double>()};
      if (!std::isfinite(fs.centre) || !(fs.spread > 0) || !std::isfinite(fs.spread))
        diag::fail(w, name, "centre must be finite and spread finite and > 0");
      b.stats_[name] = fs;
    }
    if (b.stats_.empty()) diag::fail(w, "features", "empty");
    return b;
  } catch (const nlohmann::json::exception& e) {
    diag::fail(w, "", e.what());
  }
}

nlohmann::json to_json(const Baseline::Score& score) {
  return {{"anomaly_score", score.anomaly_score},
          {"alarm", score.alarm},
          {"threshold", score.threshold},
          {"largest", score.largest},
          {"deviation", score.deviation}};
}

}  // namespace detect
