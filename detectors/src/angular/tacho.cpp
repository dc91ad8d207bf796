#include "detect/angular/tacho.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>

#include "diag/error.hpp"

namespace detect {

using diag::InputError;

namespace {

using diag::fail;
using diag::require;

void check_pulse_times(std::span<const double> t, const std::string& where) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i]))
      fail(where, "pulse_times_s", "pulse " + std::to_string(i) + " is NaN or Inf");
    if (i > 0 && !(t[i] > t[i - 1]))
      fail(where, "pulse_times_s", "not strictly increasing at pulse " + std::to_string(i));
  }
}

// Median of d over a window of w intervals centred on i. Near the ends the window shrinks to stay
// centred (down to 3 intervals, then shifted inside), so that a run-up's trend does not bias it.
double local_median(const std::vector<double>& d, std::size_t i, std::size_t w,
                    std::vector<double>& scratch) {
  const std::size_t n = d.size();
  const std::size_t to_end = std::min(i, n - 1 - i);
  w = std::min({w, std::max<std::size_t>(3, 2 * to_end + 1), n});
  std::size_t lo = i >= w / 2 ? i - w / 2 : 0;
  if (lo + w > n) lo = n - w;
  scratch.assign(d.begin() + static_cast<std::ptrdiff_t>(lo),
                 d.begin() + static_cast<std::ptrdiff_t>(lo + w));
  auto mid = scratch.begin() + static_cast<std::ptrdiff_t>(w / 2);
  std::nth_element(scratch.begin(), mid, scratch.end());
  return *mid;
}

std::vector<double> intervals(const std::vector<double>& t) {
  std::vector<double> d(t.size() > 1 ? t.size() - 1 : 0);
  for (std::size_t i = 0; i + 1 < t.size(); ++i) d[i] = t[i + 1] - t[i];
  return d;
}

std::vector<double> local_medians(const std::vector<double>& d, int window) {
  std::vector<double> m(d.size()), scratch;
  for (std::size_t i = 0; i < d.size(); ++i) {
    m[i] = local_median(d, i, static_cast<std::size_t>(window), scratch);
  }
  return m;
}

// Times of the k - 1 pulses missing between t[i] and t[i+1]: pulse count vs time fitted by a
// quadratic (constant angular acceleration) through the two pulses on each side, least squares.
std::vector<double> fill_gap(const std::vector<double>& t, std::size_t i, int k) {
  const double t0 = t[i];
  const double h = t[i + 1] - t[i];
  std::vector<std::pair<double, double>> pts;  // (tau, count)
  if (i >= 1) pts.emplace_back((t[i - 1] - t0) / h, -1.0);
  pts.emplace_back(0.0, 0.0);
  pts.emplace_back(1.0, static_cast<double>(k));
  if (i + 2 < t.size()) pts.emplace_back((t[i + 2] - t0) / h, static_cast<double>(k + 1));
  double a = 0, b = static_cast<double>(k), c = 0;  // count = a + b tau + c tau^2
  if (pts.size() >= 3) {
    Eigen::MatrixXd A(pts.size(), 3);
    Eigen::VectorXd y(pts.size());
    for (std::size_t p = 0; p < pts.size(); ++p) {
      A(p, 0) = 1.0;
      A(p, 1) = pts[p].first;
      A(p, 2) = pts[p].first * pts[p].first;
      y(p) = pts[p].second;
    }
    const Eigen::Vector3d coef = A.colPivHouseholderQr().solve(y);
    a = coef(0);
    b = coef(1);
    c = coef(2);
  }
  std::vector<double> out;
  for (int j = 1; j < k; ++j) {
    const double rhs = j - a;
    double tau = static_cast<double>(j) / k;  // fallback: equal split
    const double disc = b * b + 4 * c * rhs;
    if (b > 0 && disc >= 0) {
      const double root = 2 * rhs / (b + std::sqrt(disc));  // stable root of c tau^2 + b tau = rhs
      if (root > 0 && root < 1) tau = root;
    }
    out.push_back(t0 + tau * h);
  }
  return out;
}

}  // namespace

std::string_view to_string(TachoRepair::Kind k) {
  switch (k) {
    case TachoRepair::Kind::kMissedPulse:
      return "missed_pulse";
    case TachoRepair::Kind::kExtraPulse:
      return "extra_pulse";
    case TachoRepair::Kind::kIrregularInterval:
      return "irregular_interval";
  }
  return "unknown";
}

void TachoOptions::validate() const {
  const std::string w = "TachoOptions";
  require(pulses_per_rev >= 1, w, "pulses_per_rev",
          std::to_string(pulses_per_rev) + " is not >= 1");
  require(std::isnan(threshold) || std::isfinite(threshold), w, "threshold",
          "must be finite (or NaN for auto)");
  require(hysteresis_fraction >= 0 && hysteresis_fraction <= 0.9, w, "hysteresis_fraction",
          std::to_string(hysteresis_fraction) + " is not in [0, 0.9]");
  require(repair_tolerance > 0 && repair_tolerance <= 0.45, w, "repair_tolerance",
          std::to_string(repair_tolerance) + " is not in (0, 0.45]");
  require(median_window >= 5 && median_window % 2 == 1, w, "median_window",
          std::to_string(median_window) + " is not an odd number >= 5");
}

TachoResult repair_pulses(std::span<const double> pulse_times_s, const TachoOptions& opt) {
  opt.validate();
  check_pulse_times(pulse_times_s, "repair_pulses");
  TachoResult res;
  res.pulses_per_rev = opt.pulses_per_rev;
  std::vector<double> t(pulse_times_s.begin(), pulse_times_s.end());
  const double tol = opt.repair_tolerance;
  if (t.size() < 4) {  // fewer than 3 intervals: no local median to judge by
    res.pulse_times_s = std::move(t);
    return res;
  }

  // Pass 1: extra pulses. A short interval is merged with the neighbour that completes it best.
  std::vector<bool> extra(t.size(), false);  // pulses found extra (kept when repair is off)
  {
    const std::vector<double> d = intervals(t);
    const std::vector<double> m = local_medians(d, opt.median_window);
    std::vector<bool> drop(t.size(), false);
    for (std::size_t i = 0; i < d.size(); ++i) {
      if (d[i] / m[i] >= 1 - tol) continue;
      double best = tol;
      std::size_t victim = 0;
      if (i >= 1 && !drop[i - 1] && !drop[i]) {
        const double e = std::abs((d[i - 1] + d[i]) / m[i] - 1);
        if (e <= best) best = e, victim = i;
      }
      if (i + 1 < d.size()) {
        const double e = std::abs((d[i] + d[i + 1]) / m[i] - 1);
        if (e < best || (victim == 0 && e <= best)) best = e, victim = i + 1;
      }
      if (victim == 0) continue;  // not explained by one extra pulse; pass 2 reports it
      res.repairs.push_back({TachoRepair::Kind::kExtraPulse, t[victim]});
      extra[victim] = true;
      if (opt.repair) drop[victim] = true;
      if (victim == i + 1) ++i;  // the next interval is consumed
    }
    std::vector<double> kept;
    std::vector<bool> kept_extra;
    kept.reserve(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (!drop[i]) kept.push_back(t[i]), kept_extra.push_back(extra[i]);
    }
    t.swap(kept);
    extra.swap(kept_extra);
  }

  // Pass 2: missed pulses (an interval of ~k medians), and whatever else is irregular.
  {
    const std::vector<double> d = intervals(t);
    const std::vector<double> m = local_medians(d, opt.median_window);
    std::vector<double> out;
    out.reserve(t.size() + 16);
    for (std::size_t i = 0; i < t.size(); ++i) {
      out.push_back(t[i]);
      if (i + 1 == t.size()) break;
      if (extra[i] || extra[i + 1]) continue;  // already reported (repair off)
      const double r = d[i] / m[i];
      const double k = std::round(r);
      if (std::abs(r - 1) <= tol) continue;
      if (k >= 2 && std::abs(r - k) <= tol) {
        for (double ti : fill_gap(t, i, static_cast<int>(k))) {
          res.repairs.push_back({TachoRepair::Kind::kMissedPulse, ti});
          if (opt.repair) out.push_back(ti);
        }
      } else {
        res.repairs.push_back({TachoRepair::Kind::kIrregularInterval, t[i]});
      }
    }
    t.swap(out);
  }
  std::stable_sort(res.repairs.begin(), res.repairs.end(),
                   [](const TachoRepair& a, const TachoRepair& b) { return a.time_s < b.time_s; });
  res.pulse_times_s = std::move(t);
  return res;
}

TachoResult tacho_pulses(std::span<const double> x, double fs_hz, const TachoOptions& opt) {
  opt.validate();
  require(fs_hz > 0 && std::isfinite(fs_hz), "tacho_pulses", "fs_hz",
          std::to_string(fs_hz) + " is not > 0");
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]))
      fail("tacho_pulses", "tacho", "sample " + std::to_string(i) + " is NaN or Inf");
  }
  TachoResult none;
  none.pulses_per_rev = opt.pulses_per_rev;
  if (x.size() < 2) return none;

  // Robust range: the k-th smallest and largest samples ignore up to k - 1 spikes.
  const std::size_t k = std::min<std::size_t>(10, x.size() / 20 + 1);
  std::vector<double> s(x.begin(), x.end());
  std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(k - 1), s.end());
  const double lo = s[k - 1];
  std::nth_element(s.begin(), s.end() - static_cast<std::ptrdiff_t>(k), s.end());
  const double hi = s[s.size() - k];
  const double thr = std::isnan(opt.threshold) ? 0.5 * (lo + hi) : opt.threshold;
  const double band = opt.hysteresis_fraction * (hi - lo);
  none.threshold = thr;
  none.hysteresis = band;
  if (!(hi > lo)) return none;
  const double upper = thr + 0.5 * band;
  const double lower = thr - 0.5 * band;

  std::vector<double> times;
  bool armed = false;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!armed) {
      armed = x[i] < lower || (band == 0 && x[i] < thr);
      continue;
    }
    if (x[i] < upper || (band == 0 && x[i] < thr)) continue;
    // Fired: walk back to the last sample below the threshold; one exists since we were armed.
    std::size_t j = i - 1;
    while (x[j] >= thr) --j;
    const double frac = (thr - x[j]) / (x[j + 1] - x[j]);
    times.push_back((static_cast<double>(j) + frac) / fs_hz);
    armed = false;
  }
  TachoResult res = repair_pulses(times, opt);
  res.threshold = thr;
  res.hysteresis = band;
  return res;
}

SpeedProfile speed_profile(std::span<const double> t, int pulses_per_rev, int window_intervals) {
  require(pulses_per_rev >= 1, "speed_profile", "pulses_per_rev",
          std::to_string(pulses_per_rev) + " is not >= 1");
  require(window_intervals >= 1, "speed_profile", "window_intervals",
          std::to_string(window_intervals) + " is not >= 1");
  check_pulse_times(t, "speed_profile");
  SpeedProfile sp;
  const auto w = static_cast<std::size_t>(window_intervals);
  if (t.size() < w + 1) return sp;
  const std::size_t n = t.size() - w;
  sp.time_s.resize(n);
  sp.rpm.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    sp.time_s[j] = 0.5 * (t[j] + t[j + w]);
    sp.rpm[j] = 60.0 * window_intervals / (pulses_per_rev * (t[j + w] - t[j]));
  }
  return sp;
}

SpeedProfile speed_profile(const TachoResult& tacho, int pulses_per_rev, int window_intervals) {
  return speed_profile(tacho.pulse_times_s, pulses_per_rev, window_intervals);
}

}  // namespace detect
