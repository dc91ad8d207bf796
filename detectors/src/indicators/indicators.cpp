#include "detect/indicators/indicators.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <string>

#include "detect/indicators/na4.hpp"
#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace detect {

using diag::InputError;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void require_samples(std::span<const double> x, const char* where) {
  if (x.empty()) throw InputError(diag::format_error(where, "signal", "empty (needs >= 1 sample)"));
}

double ratio_or_nan(double num, double den) { return den == 0.0 ? kNaN : num / den; }

// Sum of (x - mean)^p for p = 2, 6 or 8 in one pass after the mean: the higher-order metrics.
struct EvenSums {
  double s2 = 0, s4 = 0, s6 = 0, s8 = 0;
};
EvenSums even_central_sums(std::span<const double> x) {
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  EvenSums s;
  for (double v : x) {
    const double d = v - mean, d2 = d * d, d4 = d2 * d2;
    s.s2 += d2;
    s.s4 += d4;
    s.s6 += d4 * d2;
    s.s8 += d4 * d4;
  }
  return s;
}

}  // namespace

// ---- Moments ------------------------------------------------------------------------------------

double Moments::variance() const { return m2 / static_cast<double>(count); }
double Moments::rms() const { return std::sqrt(mean * mean + variance()); }
double Moments::peak() const { return std::max(std::abs(min), std::abs(max)); }
double Moments::peak_to_peak() const { return max - min; }
double Moments::crest_factor() const { return ratio_or_nan(peak(), rms()); }
double Moments::kurtosis() const { return ratio_or_nan(static_cast<double>(count) * m4, m2 * m2); }
double Moments::skewness() const {
  return ratio_or_nan(std::sqrt(static_cast<double>(count)) * m3, m2 * std::sqrt(m2));
}

// Two passes (the mean, then the central sums about it), each with four independent partial
// sums per quantity, combined at the end ((l0 + l1) + (l2 + l3)): no loop-carried dependency
// chain of one add per sample (4x the throughput), and the rounding errors of a sum of n terms
// spread over four sums of n/4, no larger than the single chain's (Higham 2002, "Accuracy and
// Stability of Numerical Algorithms", section 4.2). The same bytes on every run and CPU (scalar
// code in a fixed order; the build has no fast-math).
Moments moments(std::span<const double> x) {
  require_samples(x, "moments");
  const std::size_t n = x.size();
  const double* p = x.data();
  constexpr std::size_t kLanes = 4;
  Moments m;
  m.count = n;
  double sum[kLanes] = {0, 0, 0, 0};
  double lo[kLanes] = {p[0], p[0], p[0], p[0]}, hi[kLanes] = {p[0], p[0], p[0], p[0]};
  std::size_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (std::size_t q = 0; q < kLanes; ++q) {
      const double v = p[i + q];
      sum[q] += v;
      lo[q] = std::min(lo[q], v);
      hi[q] = std::max(hi[q], v);
    }
  }
  for (; i < n; ++i) {
    sum[0] += p[i];
    lo[0] = std::min(lo[0], p[i]);
    hi[0] = std::max(hi[0], p[i]);
  }
  m.min = std::min(std::min(lo[0], lo[1]), std::min(lo[2], lo[3]));
  m.max = std::max(std::max(hi[0], hi[1]), std::max(hi[2], hi[3]));
  m.mean = ((sum[0] + sum[1]) + (sum[2] + sum[3])) / static_cast<double>(n);
  double s2[kLanes] = {0, 0, 0, 0}, s3[kLanes] = {0, 0, 0, 0}, s4[kLanes] = {0, 0, 0, 0};
  const double mean = m.mean;
  for (i = 0; i + kLanes <= n; i += kLanes) {
    for (std::size_t q = 0; q < kLanes; ++q) {
      const double d = p[i + q] - mean, d2 = d * d;
      s2[q] += d2;
      s3[q] += d2 * d;
      s4[q] += d2 * d2;
    }
  }
  for (; i < n; ++i) {
    const double d = p[i] - mean, d2 = d * d;
    s2[0] += d2;
    s3[0] += d2 * d;
    s4[0] += d2 * d2;
  }
  m.m2 = (s2[0] + s2[1]) + (s2[2] + s2[3]);
  m.m3 = (s3[0] + s3[1]) + (s3[2] + s3[3]);
  m.m4 = (s4[0] + s4[1]) + (s4[2] + s4[3]);
  return m;
}

void MomentAccumulator::add(std::span<const double> chunk) {
  if (chunk.empty()) return;
  merge(moments(chunk));
}

void MomentAccumulator::merge(const MomentAccumulator& other) {
  if (other.m_.count > 0) merge(other.m_);
}

// Pebay 2008, eqs. (3.1)-(3.4) for p = 2, 3, 4: the central sums of the union of two sets from
// each set's count, mean and central sums.
void MomentAccumulator::merge(const Moments& b) {
  if (m_.count == 0) {
    m_ = b;
    return;
  }
  const Moments a = m_;
  const double na = static_cast<double>(a.count), nb = static_cast<double>(b.count);
  const double n = na + nb;
  const double delta = b.mean - a.mean;
  const double delta_n = delta / n;
  const double delta_n2 = delta_n * delta_n;
  m_.count = a.count + b.count;
  m_.mean = a.mean + nb * delta_n;
  m_.m2 = a.m2 + b.m2 + delta * delta_n * na * nb;
  m_.m3 = a.m3 + b.m3 + delta * delta_n2 * na * nb * (na - nb) +
          3.0 * delta_n * (na * b.m2 - nb * a.m2);
  m_.m4 = a.m4 + b.m4 + delta * delta_n2 * delta_n * na * nb * (na * na - na * nb + nb * nb) +
          6.0 * delta_n2 * (na * na * b.m2 + nb * nb * a.m2) +
          4.0 * delta_n * (na * b.m3 - nb * a.m3);
  m_.min = std::min(a.min, b.min);
  m_.max = std::max(a.max, b.max);
}

const Moments& MomentAccumulator::result() const {
  if (m_.count == 0)
    throw InputError(
        diag::format_error("MomentAccumulator::result", "count", "no samples were added"));
  return m_;
}

double rms(std::span<const double> x) {
  require_samples(x, "rms");
  double s = 0;
  for (double v : x) s += v * v;
  return std::sqrt(s / static_cast<double>(x.size()));
}
double peak(std::span<const double> x) {
  require_samples(x, "peak");
  double p = 0;
  for (double v : x) p = std::max(p, std::abs(v));
  return p;
}
double peak_to_peak(std::span<const double> x) {
  require_samples(x, "peak_to_peak");
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  return *hi - *lo;
}
double crest_factor(std::span<const double> x) {
  require_samples(x, "crest_factor");
  return ratio_or_nan(peak(x), rms(x));
}
double kurtosis(std::span<const double> x) { return moments(x).kurtosis(); }
double skewness(std::span<const double> x) { return moments(x).skewness(); }

// ---- Gear metrics -------------------------------------------------------------------------------

double fm4(std::span<const double> difference) {
  require_samples(difference, "fm4");
  const EvenSums s = even_central_sums(difference);
  return ratio_or_nan(static_cast<double>(difference.size()) * s.s4, s.s2 * s.s2);
}

double m6a(std::span<const double> difference) {
  require_samples(difference, "m6a");
  const EvenSums s = even_central_sums(difference);
  const double n = static_cast<double>(difference.size());
  return ratio_or_nan(n * n * s.s6, s.s2 * s.s2 * s.s2);
}

double m8a(std::span<const double> difference) {
  require_samples(difference, "m8a");
  const EvenSums s = even_central_sums(difference);
  const double n = static_cast<double>(difference.size());
  const double s2sq = s.s2 * s.s2;
  return ratio_or_nan(n * n * n * s.s8, s2sq * s2sq);
}

double energy_ratio(std::span<const double> difference, std::span<const double> regular) {
  require_samples(difference, "energy_ratio: difference");
  require_samples(regular, "energy_ratio: regular");
  return ratio_or_nan(rms(difference), rms(regular));
}

std::vector<double> order_amplitudes(std::span<const double> tsa_rev) {
  require_samples(tsa_rev, "order_amplitudes");
  const std::size_t n = tsa_rev.size();
  RealFft fft(n);
  std::vector<std::complex<double>> spec(fft.bins());
  fft.forward(tsa_rev, spec);
  std::vector<double> a(spec.size());
  const double inv_n = 1.0 / static_cast<double>(n);
  for (std::size_t k = 0; k < spec.size(); ++k) {
    const bool unpaired = k == 0 || (n % 2 == 0 && k == n / 2);  // bins without a mirror image
    a[k] = magnitude(spec[k]) * inv_n * (unpaired ? 1.0 : 2.0);
  }
  return a;
}

void GearMetricOptions::validate(std::size_t tsa_samples) const {
  if (mesh_order < 1)
    diag::fail("GearMetricOptions", "mesh_order", std::to_string(mesh_order) + " (must be >= 1)");
  if (mesh_harmonics < 1 || mesh_harmonics > 32)
    diag::fail("GearMetricOptions", "mesh_harmonics",
               std::to_string(mesh_harmonics) + " (valid 1..32)");
  if (ser_sidebands < 1 || ser_sidebands > 64)
    diag::fail("GearMetricOptions", "ser_sidebands",
               std::to_string(ser_sidebands) + " (valid 1..64)");
  if (ser_sidebands >= mesh_order)
    diag::fail("GearMetricOptions", "ser_sidebands",
               std::to_string(ser_sidebands) +
                   " (must be < mesh_order = " + std::to_string(mesh_order) + ")");
  const long top = std::max(static_cast<long>(mesh_harmonics) * mesh_order,
                            static_cast<long>(mesh_order) + ser_sidebands);
  if (2 * top >= static_cast<long>(tsa_samples))
    diag::fail("GearMetricOptions", "mesh_order",
               "order " + std::to_string(top) + " needed but a TSA of " +
                   std::to_string(tsa_samples) + " samples/rev resolves orders < " +
                   std::to_string(tsa_samples / 2) +
                   " (lower mesh_harmonics or ser_sidebands, or sample the TSA finer)");
}

namespace {
// Orders are indices into order_amps (N/2 + 1 of them): the same bound validate() puts on the TSA.
void check_amps(std::span<const double> order_amps, const GearMetricOptions& opt) {
  opt.validate(order_amps.empty() ? 0 : 2 * (order_amps.size() - 1));
}
}  // namespace

double fm0(std::span<const double> tsa_rev, std::span<const double> order_amps,
           const GearMetricOptions& opt) {
  require_samples(tsa_rev, "fm0");
  opt.validate(tsa_rev.size());
  check_amps(order_amps, opt);
  double sum = 0;
  for (int h = 1; h <= opt.mesh_harmonics; ++h) sum += order_amps[h * opt.mesh_order];
  return ratio_or_nan(peak_to_peak(tsa_rev), sum);
}

double sideband_energy_ratio(std::span<const double> order_amps, const GearMetricOptions& opt) {
  check_amps(order_amps, opt);
  const int z = opt.mesh_order;
  double sum = 0;
  for (int k = 1; k <= opt.ser_sidebands; ++k) sum += order_amps[z - k] + order_amps[z + k];
  return ratio_or_nan(sum, order_amps[z]);
}

double sideband_level_factor(std::span<const double> tsa_rev, std::span<const double> order_amps,
                             const GearMetricOptions& opt) {
  require_samples(tsa_rev, "sideband_level_factor");
  check_amps(order_amps, opt);
  const int z = opt.mesh_order;
  return ratio_or_nan(order_amps[z - 1] + order_amps[z + 1], rms(tsa_rev));
}

double sideband_index(std::span<const double> order_amps, const GearMetricOptions& opt) {
  check_amps(order_amps, opt);
  const int z = opt.mesh_order;
  return 0.5 * (order_amps[z - 1] + order_amps[z + 1]);
}

GearIndicators gear_indicators(const GearSignals& s, const GearMetricOptions& opt,
                               const Na4Ensemble* ensemble) {
  GearIndicators g;
  g.rms = g.peak = g.crest_factor = g.kurtosis = g.fm0 = g.ser = g.slf = g.si = kNaN;
  g.fm4 = g.m6a = g.m8a = g.na4 = g.er = kNaN;
  const std::size_t n = s.tsa.size();
  for (auto sig : {s.difference, s.regular, s.residual}) {
    if (!sig.empty() && n != 0 && sig.size() != n)
      throw InputError(diag::format_error(
          "gear_indicators", "signals",
          "difference/regular/residual must have the TSA's length " + std::to_string(n) +
              " (one revolution each), got " + std::to_string(sig.size())));
  }
  if (!s.tsa.empty()) {
    opt.validate(n);
    const Moments m = moments(s.tsa);
    g.rms = m.rms();
    g.peak = m.peak();
    g.crest_factor = m.crest_factor();
    g.kurtosis = m.kurtosis();
    const std::vector<double> amps = order_amplitudes(s.tsa);
    g.fm0 = fm0(s.tsa, amps, opt);
    g.ser = sideband_energy_ratio(amps, opt);
    g.slf = sideband_level_factor(s.tsa, amps, opt);
    g.si = sideband_index(amps, opt);
  }
  if (!s.difference.empty()) {
    g.fm4 = fm4(s.difference);
    g.m6a = m6a(s.difference);
    g.m8a = m8a(s.difference);
    if (!s.regular.empty()) g.er = energy_ratio(s.difference, s.regular);
  }
  if (!s.residual.empty()) {
    if (ensemble != nullptr) {
      g.na4 = ensemble->value(s.residual);
    } else {
      Na4Ensemble one;
      g.na4 = one.push(s.residual);
    }
  }
  return g;
}

}  // namespace detect
