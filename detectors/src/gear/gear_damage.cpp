#include "detect/gear/gear_damage.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <numeric>
#include <sstream>

#include "detect/angular/pulse_refine.hpp"
#include "detect/angular/resample.hpp"
#include "detect/angular/tacho.hpp"
#include "detect/angular/tsa.hpp"
#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"

namespace detect {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// Relative tolerance for "this speed ratio is the integer / rational p/q": the gearbox ratios are
// exact products of tooth-count ratios, so only round-off separates them from p/q.
constexpr double kRatioTol = 1e-9;
constexpr int kMaxDenominator = 64;
// Speed varying within the record (the averages weighted by revolution, see the shaft loop): the
// fitted revolution periods spread by more than this share of their mean, as analyze's
// "non-stationary" (max - min speed above 1 % of the mean). A steady record (the closed loop)
// keeps the plain average.
constexpr double kVaryingSpeedSpread = 0.01;
// Revolutions either side over which a revolution's noise energy is averaged for its weight: 9
// revolutions of a few hundred orders each give the weight to ~2 %; the speed changes by less
// than 15 % over them in a run-up 500 -> 3000 rpm over 9 s.
constexpr std::ptrdiff_t kWeightHalfWindow = 4;

bool is_integer(double x, int* n) {
  const double r = std::round(x);
  if (r < 1 || std::abs(x - r) > kRatioTol * std::max(1.0, x)) return false;
  *n = static_cast<int>(r);
  return true;
}

// Smallest p with ratio = p / q, q <= kMaxDenominator; 0 when the ratio is not such a fraction.
int shared_order_step(double ratio) {
  for (int q = 1; q <= kMaxDenominator; ++q) {
    int p = 0;
    if (is_integer(ratio * q, &p)) return p;
  }
  return 0;
}

// The exclusive order set of a shaft, as a mask over the lines 0 .. spr/2 of its TSA: every
// order up to `top`, less order 0, the regular orders (shaft order 1, the mesh orders with all
// their harmonics and first sidebands: the difference signal's complement), the sidebands
// 2 .. 1 + extra around the harmonics of the shaft's own mesh orders, and every multiple of each
// step in `steps` (orders shared with faster shafts).
std::vector<bool> exclusive_orders(std::size_t spr, const std::vector<int>& mesh_orders,
                                   const std::vector<int>& steps,
                                   const std::vector<int>& own_orders, int extra, std::size_t top) {
  const std::vector<bool> regular = tsa_regular_orders(spr, mesh_orders, 1);
  std::vector<bool> keep(regular.size(), false);
  for (std::size_t k = 1; k < keep.size() && k <= top; ++k) keep[k] = !regular[k];
  const int last = static_cast<int>(keep.size()) - 1;
  for (int step : steps) {
    for (int k = step; k <= last; k += step) keep[k] = false;
  }
  for (int z : own_orders) {
    for (int h = z; h - 1 - extra <= last; h += z) {
      for (int j = 2; j <= 1 + extra; ++j) {
        if (h - j >= 0 && h - j <= last) keep[h - j] = false;
        if (h + j <= last) keep[h + j] = false;
      }
    }
  }
  return keep;
}

GearIndicators indicators_for(const Tsa& t, const std::vector<double>& diff,
                              const std::vector<int>& mesh_orders, int first_gear_teeth) {
  GearIndicators ind;
  const std::vector<double> regular = tsa_regular(t, mesh_orders, 0);
  const std::vector<double> residual = tsa_residual(t, mesh_orders, 0);
  GearMetricOptions mo;
  mo.mesh_order = first_gear_teeth;
  const int half = t.samples_per_rev / 2;
  mo.ser_sidebands = std::min(6, first_gear_teeth - 1);
  mo.mesh_harmonics = std::min(3, (half - 1 - mo.ser_sidebands) / std::max(1, first_gear_teeth));
  if (mo.ser_sidebands < 1 || mo.mesh_harmonics < 1) {
    ind.fm4 = fm4(diff), ind.m6a = m6a(diff), ind.m8a = m8a(diff);
    ind.fm0 = ind.ser = ind.slf = ind.si = kNaN;
    return ind;
  }
  GearSignals s{t.samples, diff, regular, residual};
  return gear_indicators(s, mo);
}

// Gears with fewer teeth have too few other teeth to judge the outstanding one against.
constexpr int kMinTeethForOutlier = 8;

struct ToothOutlier {
  double ratio = 1.0;       // the outstanding tooth's energy over the median of the others
  double angle_deg = kNaN;  // where in the revolution (0: the revolution's start)
};
// The tooth that stands out in one revolution-averaged signal x (e_s, high-passed) for a gear of
// z teeth: the local energy L(i) (mean of x^2 over one tooth pitch centred at sample i); its
// largest value, L(i*), over the median of L at the same place of the other teeth (i* + t n / z,
// t = 2 .. z - 2: its neighbours are left out, since a tooth's contact spans about 1.6 pitches
// and its fault reaches them).
ToothOutlier tooth_outlier(const std::vector<double>& x, int z) {
  const std::size_t n = x.size();
  const std::size_t w =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(static_cast<double>(n) / z)));
  std::vector<double> local(n, 0.0);
  double run = 0.0;
  for (std::size_t j = 0; j < w; ++j) run += x[(n - w / 2 + j) % n] * x[(n - w / 2 + j) % n];
  for (std::size_t i = 0; i < n; ++i) {
    local[i] = run / static_cast<double>(w);
    const double out = x[(i + n - w / 2) % n], in = x[(i + n - w / 2 + w) % n];
    run += in * in - out * out;
  }
  const auto peak =
      static_cast<std::size_t>(std::max_element(local.begin(), local.end()) - local.begin());
  std::vector<double> others;
  for (int t = 2; t <= z - 2; ++t) {
    const auto off = static_cast<std::size_t>(std::lround(static_cast<double>(t) * n / z));
    others.push_back(local[(peak + off) % n]);
  }
  std::nth_element(others.begin(), others.begin() + others.size() / 2, others.end());
  const double med = others[others.size() / 2];
  ToothOutlier o;
  o.ratio = med > 0.0 ? local[peak] / med : kInf;
  o.angle_deg = 360.0 * static_cast<double>(peak) / static_cast<double>(n);
  return o;
}

// The rotation phi [revolutions] of the baseline's average b that best matches x: the maximum of
// C(phi) = Re sum_k x_k conj(b_k) exp(i 2 pi k phi) over the orders in `mask` (x(theta) =
// b(theta - phi) gives x_k = b_k exp(-i 2 pi k phi)). Coarse on the TSA's sample grid (one
// inverse FFT), then a parabola through the peak and three Newton steps on C.
double baseline_rotation(const std::vector<std::complex<double>>& x,
                         const std::vector<std::complex<double>>& b, const std::vector<bool>& mask,
                         RealFft& fft) {
  std::vector<std::complex<double>> p(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) p[k] = mask[k] ? x[k] * std::conj(b[k]) : 0.0;
  std::vector<double> c(fft.size());
  fft.inverse(p, c);
  const std::size_t n = c.size();
  const auto j = static_cast<std::size_t>(std::max_element(c.begin(), c.end()) - c.begin());
  const double cm = c[(j + n - 1) % n], c0 = c[j], cp = c[(j + 1) % n];
  const double den = cm - 2.0 * c0 + cp;
  double phi =
      (static_cast<double>(j) + (den < 0.0 ? 0.5 * (cm - cp) / den : 0.0)) / static_cast<double>(n);
  for (int it = 0; it < 3; ++it) {
    double d1 = 0.0, d2 = 0.0;
    for (std::size_t k = 1; k < p.size(); ++k) {
      if (p[k] == 0.0) continue;
      const double w = 2.0 * std::numbers::pi * static_cast<double>(k);
      const std::complex<double> e = p[k] * std::polar(1.0, w * phi);
      d1 += -w * e.imag();
      d2 += -w * w * e.real();
    }
    if (!(d2 < 0.0)) break;
    phi -= d1 / d2;
  }
  return phi;
}

}  // namespace

void GearDamageOptions::validate() const {
  if (samples_per_rev != 0 &&
      (samples_per_rev < 64 || (samples_per_rev & (samples_per_rev - 1)) != 0)) {
    diag::fail("GearDamageOptions", "samples_per_rev",
               std::to_string(samples_per_rev) + " is not 0 (automatic) or a power of two >= 64");
  }
  if (pulse_fit_degree < 0 || pulse_fit_degree > 8) {
    diag::fail("GearDamageOptions", "pulse_fit_degree",
               std::to_string(pulse_fit_degree) + " is outside [0, 8]");
  }
  if (extra_sideband_orders < 0) {
    diag::fail("GearDamageOptions", "extra_sideband_orders",
               std::to_string(extra_sideband_orders) + " is negative");
  }
  if (!(band_fraction > 0.0 && band_fraction <= 1.0)) {
    diag::fail("GearDamageOptions", "band_fraction",
               std::to_string(band_fraction) + " is outside (0, 1]");
  }
  if (!(min_level >= 0.0) || !std::isfinite(min_level)) {
    diag::fail("GearDamageOptions", "min_level",
               std::to_string(min_level) + " must be finite and >= 0");
  }
  if (!(min_exclusive_share >= 0.0 && min_exclusive_share < 1.0)) {
    diag::fail("GearDamageOptions", "min_exclusive_share",
               std::to_string(min_exclusive_share) + " is outside [0, 1)");
  }
  if (!(min_snr >= 1.0) || !std::isfinite(min_snr)) {
    diag::fail("GearDamageOptions", "min_snr",
               std::to_string(min_snr) + " must be finite and >= 1 (noise alone)");
  }
  if (min_revolutions < 2) {
    diag::fail("GearDamageOptions", "min_revolutions",
               std::to_string(min_revolutions) + " is below 2");
  }
  if (!(healthy_fm4 > 1.0) || !std::isfinite(healthy_fm4)) {
    diag::fail("GearDamageOptions", "healthy_fm4",
               std::to_string(healthy_fm4) + " must be finite and > 1 (no tooth stands out)");
  }
  if (!(damaged_fm4 > healthy_fm4) || !std::isfinite(damaged_fm4)) {
    diag::fail("GearDamageOptions", "damaged_fm4",
               std::to_string(damaged_fm4) + " must be finite and > healthy_fm4 (" +
                   std::to_string(healthy_fm4) + ")");
  }
  if (!more_baselines.empty() && !baseline) {
    diag::fail("GearDamageOptions", "more_baselines", "given without a baseline");
  }
  for (const auto& b : more_baselines) {
    if (!b) diag::fail("GearDamageOptions", "more_baselines", "an empty baseline");
  }
}

namespace {

// The locator's inputs: a known reference shaft, at least 3 finite, strictly increasing pulse
// times, and channel lists naming known shafts and channels of `rec`.
void check_locate_inputs(const diag::Recording& rec, const diag::Gearbox& gb,
                         const std::string& ref, std::span<const double> pulse_times_s,
                         const GearDamageOptions& options, const std::string& where) {
  if (gb.shaft_index(ref) < 0) {
    throw diag::InputError(
        diag::format_error(where, "reference_shaft", "unknown shaft '" + ref + "'"));
  }
  if (pulse_times_s.size() < 3) {
    throw diag::InputError(diag::format_error(
        where, "pulse_times_s",
        std::to_string(pulse_times_s.size()) + " pulses; at least 3 are needed"));
  }
  for (std::size_t i = 0; i < pulse_times_s.size(); ++i) {
    if (!std::isfinite(pulse_times_s[i]) || (i > 0 && !(pulse_times_s[i] > pulse_times_s[i - 1]))) {
      throw diag::InputError(
          diag::format_error(where, "pulse_times_s",
                             "not finite and strictly increasing at pulse " + std::to_string(i)));
    }
  }
  for (const auto& [shaft, names] : options.channels) {
    if (gb.shaft_index(shaft) < 0) {
      throw diag::InputError(
          diag::format_error("GearDamageOptions", "channels", "unknown shaft '" + shaft + "'"));
    }
    for (const auto& n : names) rec.require(n, where);
  }
}

// Varying speed: the reference's revolution periods (fitted) spread by more than
// kVaryingSpeedSpread of their mean.
bool speed_varies(const std::vector<double>& ref_pulses) {
  if (ref_pulses.size() < 3) return false;
  double lo = kInf, hi = 0.0;
  for (std::size_t i = 1; i < ref_pulses.size(); ++i) {
    lo = std::min(lo, ref_pulses[i] - ref_pulses[i - 1]);
    hi = std::max(hi, ref_pulses[i] - ref_pulses[i - 1]);
  }
  const double mean = (ref_pulses.back() - ref_pulses.front()) / (ref_pulses.size() - 1);
  return hi - lo > kVaryingSpeedSpread * mean;
}

// The spectrum of a shaft's revolution average (mean_spec) and the noise of each order in it
// (var), from the revolutions of `ar` (t: their plain average; keep: the exclusive orders).
void revolution_spectrum(const AngleResampled& ar, const Tsa& t, bool varying,
                         const std::vector<bool>& keep, RealFft& fft,
                         std::vector<std::complex<double>>& mean_spec, std::vector<double>& var) {
  const int spr = ar.samples_per_rev;
  std::vector<std::complex<double>> rev_spec(fft.bins());
  // Spectrum of the TSA and the revolution-to-revolution variance of every order. When the
  // speed varies (a run-up), the average is weighted: revolution r by 1 / n_r, n_r its
  // energy in the exclusive orders (noise and non-synchronous content: the fault's share of
  // one revolution is small) averaged over +-kWeightHalfWindow revolutions; the variance is
  // then that of the weighted mean. Why: the non-synchronous content changes strongly with
  // speed (in the two-stage box run up 500 -> 3000 rpm the last fifth of the revolutions held
  // 6-12x the exclusive-order energy of each earlier fifth), so the plain average is as
  // noisy as its loudest revolutions; the inverse-variance weighting is the least-variance
  // unbiased mean of revolutions with the same synchronous part. (Dividing each revolution
  // by its mesh lines' RMS instead, as for a synchronous part that scales with speed, made
  // it worse: it amplifies the quiet slow revolutions' sensor noise.)
  std::fill(var.begin(), var.end(), 0.0);
  if (varying) {
    std::vector<std::vector<std::complex<double>>> rev_specs(
        static_cast<std::size_t>(ar.revolutions));
    std::vector<double> w(rev_specs.size());
    for (std::size_t r = 0; r < rev_specs.size(); ++r) {
      rev_specs[r].resize(fft.bins());
      fft.forward(std::span<const double>(ar.samples).subspan(r * spr, spr), rev_specs[r]);
      double e = 0.0;
      for (std::size_t k = 0; k < keep.size(); ++k) {
        if (keep[k]) e += std::norm(rev_specs[r][k]);
      }
      w[r] = e;
    }
    // Smoothed: a weight that follows the speed, not each revolution's own noise.
    {
      const std::vector<double> e = w;
      const auto nr = static_cast<std::ptrdiff_t>(e.size());
      for (std::ptrdiff_t r = 0; r < nr; ++r) {
        const std::ptrdiff_t lo = std::max<std::ptrdiff_t>(0, r - kWeightHalfWindow);
        const std::ptrdiff_t hi = std::min<std::ptrdiff_t>(nr - 1, r + kWeightHalfWindow);
        const double m = std::accumulate(e.begin() + lo, e.begin() + hi + 1, 0.0) /
                         static_cast<double>(hi - lo + 1);
        w[static_cast<std::size_t>(r)] = m > 0.0 ? 1.0 / m : 0.0;
      }
    }
    const double sum_w = std::accumulate(w.begin(), w.end(), 0.0);
    double sum_w2 = 0.0;
    for (double x : w) sum_w2 += x * x;
    std::fill(mean_spec.begin(), mean_spec.end(), 0.0);
    for (std::size_t r = 0; r < rev_specs.size(); ++r) {
      for (std::size_t k = 0; k < mean_spec.size(); ++k)
        mean_spec[k] += w[r] / sum_w * rev_specs[r][k];
    }
    for (std::size_t r = 0; r < rev_specs.size(); ++r) {
      for (std::size_t k = 0; k < var.size(); ++k)
        var[k] += w[r] * w[r] * std::norm(rev_specs[r][k] - mean_spec[k]);
    }
    // So that var / (N (N - 1)) below estimates Var(M) = sum w_r^2 s_r^2 / W^2 (W = sum w) by
    // sum w_r^2 |X_r - M|^2 / (W^2 - sum w^2): the unweighted N (N - 1) for equal weights,
    // nearly unbiased when no weight dominates.
    const double n = ar.revolutions;
    for (double& v : var) v *= n * (n - 1) / (sum_w * sum_w - sum_w2);
  } else {
    fft.forward(t.samples, mean_spec);
    for (int r = 0; r < ar.revolutions; ++r) {
      fft.forward(std::span<const double>(ar.samples)
                      .subspan(static_cast<std::size_t>(r) * spr, static_cast<std::size_t>(spr)),
                  rev_spec);
      for (std::size_t k = 0; k < var.size(); ++k) var[k] += std::norm(rev_spec[k] - mean_spec[k]);
    }
  }
  // The noise of each order in the average: var_k / (N (N - 1)).
  for (double& v : var) v /= static_cast<double>(ar.revolutions) * (ar.revolutions - 1);
}

// The decision over the shafts' scores: the slowest damaged shaft is the finding (a faster one
// whose period divides its own is where the fault folds in, said so); a slower shaft in the
// uncertain band makes the result ambiguous (both listed, at half confidence). `note` gets the
// shafts whose periods are whole multiples of one another and whether the baseline was used.
void decide_damaged_shafts(GearDamageResult& res, const diag::Gearbox& gb,
                           const GearDamageOptions& options, bool used_baseline,
                           std::ostringstream& note) {
  const auto& shafts = gb.shafts();
  auto speed_of = [&](const ShaftDamage& d) {
    return std::abs(shafts[static_cast<std::size_t>(gb.shaft_index(d.shaft))].speed_ratio);
  };
  // Shafts whose periods are whole multiples of one another (sub-harmonic ratios): said, since
  // a fault on the slower one folds into the faster one's average.
  for (const ShaftDamage& a : res.shafts) {
    for (const ShaftDamage& b : res.shafts) {
      int m = 0;
      if (is_integer(speed_of(b) / speed_of(a), &m) && m > 1) {
        note << "the period of '" << a.shaft << "' is " << m << " x that of '" << b.shaft
             << "': a fault on '" << a.shaft << "' would also show in '" << b.shaft
             << "''s average; it is attributed to '" << a.shaft << "'. ";
      }
    }
  }
  if (options.baseline) {
    note << (used_baseline ? "compared with the healthy baseline (its TSA subtracted). "
                           : "the baseline has none of these shafts and channels: not used. ");
  }
  // ---- decision: the slowest damaged shaft ----
  std::vector<std::size_t> order(res.shafts.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return res.shafts[a].frequency_hz < res.shafts[b].frequency_hz;
  });
  auto make_finding = [&](const ShaftDamage& sd, const std::string& why) {
    Finding f;
    f.kind = "gear_damage";
    f.fault = diag::FaultKind::kToothDamage;
    f.shaft = sd.shaft;
    for (int g : shafts[gb.shaft_index(sd.shaft)].gears) f.gears.push_back(gb.gears()[g].name);
    f.channel = sd.channel;
    f.evidence = {{"score", sd.score},
                  {"snr", sd.snr},
                  {"exclusive_share", sd.exclusive_share},
                  {"angle_deg", sd.angle_deg}};
    f.confidence = std::clamp(
        (sd.score - options.healthy_fm4) / (2.0 * (options.damaged_fm4 - options.healthy_fm4)), 0.0,
        1.0);
    f.note = why;
    return f;
  };
  for (std::size_t k = 0; k < order.size(); ++k) {
    const ShaftDamage& sd = res.shafts[order[k]];
    if (!sd.damaged) continue;
    std::ostringstream why;
    // The tooth score is taken per gear of the shaft with that gear's pitch as the window, which
    // favours the gear with more teeth whichever gear the fault is on (a chip on the 21-tooth z3
    // scores highest as a tooth of the 44-tooth z2 on the same shaft): the gear is named only
    // when the shaft carries one.
    const std::vector<int>& on_shaft = shafts[gb.shaft_index(sd.shaft)].gears;
    std::string which = sd.gear;
    if (on_shaft.size() > 1) {
      which.clear();
      for (std::size_t g = 0; g < on_shaft.size(); ++g) {
        which += (g == 0                     ? ""
                  : g + 1 == on_shaft.size() ? " or "
                                             : ", ") +
                 gb.gears()[static_cast<std::size_t>(on_shaft[g])].name;
      }
      which += " (the tooth score cannot tell which)";
    }
    why << "a tooth of " << which << " stands out at " << std::lround(sd.angle_deg)
        << " deg of the shaft's revolution: its energy in the exclusive difference signal is "
        << sd.score << " x the median of the other teeth' (> " << options.damaged_fm4 << ") on "
        << sd.channel;
    // A faster shaft flagged as well whose period divides this one's: the fault folds into it.
    for (std::size_t j = k + 1; j < order.size(); ++j) {
      const ShaftDamage& faster = res.shafts[order[j]];
      int m = 0;
      if (faster.damaged && is_integer(speed_of(faster) / speed_of(sd), &m) && m > 1) {
        why << "; '" << faster.shaft << "' (period 1/" << m << " of this shaft's) is flagged too: "
            << "a fault here repeats in its average every " << m
            << " revolutions, so it is put on the slower shaft, whose exclusive orders hold it";
      }
    }
    res.findings.push_back(make_finding(sd, why.str()));
    res.status = "damaged";
    for (std::size_t j = 0; j < k; ++j) {
      const ShaftDamage& slower = res.shafts[order[j]];
      if (!slower.uncertain) continue;
      std::ostringstream w2;
      w2 << "tooth score " << slower.score << " in the uncertain band (" << options.healthy_fm4
         << ", " << options.damaged_fm4 << "]: a fault here would also flag '" << sd.shaft << "'";
      res.findings.push_back(make_finding(slower, w2.str()));
      res.status = "ambiguous";
    }
    if (res.status == "ambiguous") {
      for (auto& f : res.findings) f.confidence *= 0.5;
    }
    break;
  }
}

// What every shaft's scoring shares (locate_impl): the recording, the options, the reference's
// frequency and the corrected revolutions (`base`, once per revolution of a shaft turning at
// |speed_ratio| = base_ratio), and where to put a baseline's averages when one is being made.
struct LocateContext {
  const diag::Recording& rec;
  const diag::Gearbox& gb;
  const GearDamageOptions& options;
  double ref_ratio, ref_hz;
  const std::vector<double>& base;
  double base_ratio;
  bool varying_speed;
  GearDamageBaseline* capture;
};

// The channels a shaft is scored on: the options' for it, else those near its gears.
std::vector<const diag::Signal*> shaft_channels(const LocateContext& cx, const diag::Shaft& sh) {
  std::vector<const diag::Signal*> chans;
  if (auto it = cx.options.channels.find(sh.name); it != cx.options.channels.end()) {
    for (const auto& n : it->second) chans.push_back(&cx.rec.require(n, "locate_gear_damage"));
  } else {
    chans = shaft_vibration_channels(cx.rec, cx.gb, sh.name);
  }
  return chans;
}

// Steps 2-5 for one shaft with gears: its revolutions averaged on each of its channels, the
// exclusive orders, significance, level and the tooth score, kept from the channel that scores
// highest; with a baseline, its averages subtracted first (`used_baseline` set). When a baseline
// is being made (capture), the averages go there and nothing is scored.
ShaftDamage score_shaft(const LocateContext& cx, const diag::Shaft& sh, std::ostringstream& note,
                        bool& used_baseline) {
  const diag::Gearbox& gb = cx.gb;
  const GearDamageOptions& options = cx.options;
  GearDamageBaseline* capture = cx.capture;
  ResampleOptions ro;
  ro.pulses_per_rev = 1;
  auto baseline_of = [&](const GearDamageBaseline* baseline, const std::string& shaft,
                         const std::string& channel) {
    const BaselineTsa* b = nullptr;
    if (!baseline) return b;
    if (auto it = baseline->tsa.find(shaft); it != baseline->tsa.end()) {
      if (auto jt = it->second.find(channel); jt != it->second.end()) b = &jt->second;
    }
    return b;
  };
  ShaftDamage sd;
  sd.shaft = sh.name;
  sd.score = sd.fm4 = sd.snr = kNaN;
  const double rel = std::abs(sh.speed_ratio) / cx.ref_ratio;  // f_s / f_ref
  sd.frequency_hz = cx.ref_hz * rel;

  const std::vector<const diag::Signal*> chans = shaft_channels(cx, sh);
  if (chans.empty()) {
    note << "shaft '" << sh.name << "': no channel. ";
    return sd;
  }
  // Highest order analysed and the TSA resolution (options).
  const TsaResolution reso = tsa_resolution(chans.front()->fs_hz, sd.frequency_hz,
                                            options.band_fraction, options.samples_per_rev);
  const int spr = reso.samples_per_rev;
  const int half = spr / 2;
  const std::size_t top = reso.top;
  sd.samples_per_rev = spr;
  ro.samples_per_rev = spr;
  const std::vector<int> mesh_orders = synchronous_mesh_orders(gb, sh, half);
  std::vector<int> own_orders;
  for (int g : sh.gears) own_orders.push_back(gb.gears()[g].spec.teeth);
  // Orders shared with faster shafts.
  std::vector<int> shared_steps;
  for (const diag::Shaft& other : gb.shafts()) {
    if (other.gears.empty() || &other == &sh) continue;
    const double r = std::abs(other.speed_ratio) / std::abs(sh.speed_ratio);
    if (r <= 1.0 + kRatioTol) continue;
    const int p = shared_order_step(r);
    if (p > 0 && p <= half) shared_steps.push_back(p);
  }
  const std::vector<bool> keep =
      exclusive_orders(static_cast<std::size_t>(spr), mesh_orders, shared_steps, own_orders,
                       options.extra_sideband_orders, top);

  // The same band without the removal of the shared orders (the exclusive share's reference).
  const std::vector<bool> in_band =
      exclusive_orders(static_cast<std::size_t>(spr), mesh_orders, {}, own_orders,
                       options.extra_sideband_orders, top);
  const std::vector<bool> regular =
      tsa_regular_orders(static_cast<std::size_t>(spr), mesh_orders, 1);
  const std::vector<double> pulses =
      scale_pulses(cx.base, std::abs(sh.speed_ratio) / cx.base_ratio);
  RealFft fft(static_cast<std::size_t>(spr));
  std::vector<std::complex<double>> mean_spec(fft.bins());
  std::vector<double> var(fft.bins());
  // The leading channels of the first one's rate and length through one plan (its taps
  // computed once for all: resample.hpp; the same bytes as one call per channel); the others,
  // or all when the plan cannot be built, one by one below, where a failure is reported.
  std::vector<AngleResampled> shared;
  try {
    const diag::Signal& first = *chans.front();
    std::vector<std::span<const double>> same;
    for (const diag::Signal* ch : chans) {
      if (ch->fs_hz != first.fs_hz || ch->samples.size() != first.samples.size() ||
          !std::all_of(ch->samples.begin(), ch->samples.end(),
                       [](double v) { return std::isfinite(v); })) {
        break;
      }
      same.emplace_back(ch->samples);
    }
    if (!same.empty()) {
      shared =
          resample_by_angle(same, make_angle_plan(pulses, first.fs_hz, first.samples.size(), ro));
    }
  } catch (const diag::InputError&) {
    shared.clear();
  }
  // The orders a baseline is subtracted in: the analysed band and the exclusive orders.
  std::vector<bool> band_mask(keep.size());
  for (std::size_t k = 0; k < keep.size(); ++k) band_mask[k] = in_band[k] || keep[k];
  std::vector<const GearDamageBaseline*> baselines = {options.baseline.get()};
  for (const auto& b : options.more_baselines) baselines.push_back(b.get());
  std::vector<ShaftDamage> candidates(baselines.size(), sd);
  // Per baseline, the difference's energy relative to each channel's regular signal, summed over
  // the channels compared, and their count.
  std::vector<double> residual(baselines.size(), 0.0);
  std::vector<int> residual_channels(baselines.size(), 0);
  for (std::size_t ci = 0; ci < chans.size(); ++ci) {
    const diag::Signal* ch = chans[ci];
    AngleResampled ar;
    Tsa t;
    try {
      ar = ci < shared.size() ? std::move(shared[ci])
                              : resample_by_angle(ch->samples, ch->fs_hz, pulses, ro);
      t = tsa(ar, options.min_revolutions);
    } catch (const diag::InputError& e) {
      note << "shaft '" << sh.name << "' skipped: " << e.what() << ". ";
      break;
    }
    revolution_spectrum(ar, t, cx.varying_speed, keep, fft, mean_spec, var);
    if (capture) {
      capture->tsa[sh.name][ch->name] = {mean_spec, var};
      continue;
    }
    double regular_energy = 0.0;
    for (std::size_t k = 1; k < keep.size() && k <= top; ++k) {
      if (regular[k]) regular_energy += std::norm(mean_spec[k]);
    }
    // Against each baseline in turn (the first none when there is none), into its candidate.
    for (std::size_t bi = 0; bi < candidates.size(); ++bi) {
      ShaftDamage& cd = candidates[bi];
      std::vector<std::complex<double>> spec = mean_spec;
      std::vector<double> v = var;
      bool compared = false;
      if (const BaselineTsa* b = baseline_of(baselines[bi], sh.name, ch->name);
          b && b->spectrum.size() == spec.size()) {
        // NA4-style: the healthy pattern (pitch errors, runout, the mesh's own shape) rotated
        // into this record's angle and subtracted in the analysed band; its noise adds.
        const double phi = baseline_rotation(spec, b->spectrum, band_mask, fft);
        for (std::size_t k = 0; k < keep.size(); ++k) {
          if (!band_mask[k]) continue;
          spec[k] -= b->spectrum[k] *
                     std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>(k) * phi);
          v[k] += b->noise[k];
        }
        used_baseline = true;
        compared = true;
      }
      double energy = 0.0, noise = 0.0, band = 0.0;
      for (std::size_t k = 0; k < keep.size(); ++k) {
        if (in_band[k]) band += std::norm(spec[k]);
        if (keep[k]) {
          energy += std::norm(spec[k]);
          noise += v[k];
        } else {
          spec[k] = 0.0;
        }
      }
      if (compared && regular_energy > 0.0) {
        residual[bi] += energy / regular_energy;
        ++residual_channels[bi];
      }
      std::vector<double> excl(static_cast<std::size_t>(spr));
      fft.inverse(spec, excl);
      const double raw = energy > 0.0 ? fm4(excl) : kNaN;
      const double snr = noise > 0.0 ? energy / noise : (energy > 0.0 ? kInf : 0.0);
      // The tooth that stands out, per gear of the shaft (its own high-passed copy of e_s).
      double score = 1.0;
      ToothOutlier best_tooth;
      std::string best_gear;
      if ((compared || snr >= options.min_snr) && energy > 0.0) {
        for (int g : sh.gears) {
          const int z = gb.gears()[static_cast<std::size_t>(g)].spec.teeth;
          if (z < kMinTeethForOutlier) continue;
          std::vector<std::complex<double>> hp = spec;
          const auto cut = static_cast<std::size_t>(z / 2);
          for (std::size_t k = 0; k < cut && k < hp.size(); ++k) hp[k] = 0.0;
          std::vector<double> x(static_cast<std::size_t>(spr));
          fft.inverse(hp, x);
          const ToothOutlier to = tooth_outlier(x, z);
          if (to.ratio > score) score = to.ratio, best_tooth = to, best_gear = gb.gears()[g].name;
        }
      }
      if (std::isnan(cd.score) || score > cd.score || (score == cd.score && snr > cd.snr)) {
        cd.score = score;
        cd.gear = best_gear;
        cd.angle_deg = best_tooth.angle_deg;
        cd.fm4 = raw;
        cd.snr = snr;
        cd.exclusive_share = band > 0.0 ? energy / band : 0.0;
        const double synchronous = compared ? energy : std::max(0.0, energy - noise);
        cd.level = regular_energy > 0.0 ? std::sqrt(synchronous / regular_energy) : kInf;
        cd.compared = compared;
        cd.channel = ch->name;
        cd.revolutions = t.revolutions;
        const std::vector<double> diff = tsa_difference(t, mesh_orders);
        cd.indicators = indicators_for(t, diff, mesh_orders, gb.gears()[sh.gears[0]].spec.teeth);
      }
    }
  }
  // The baseline that explains the shaft best (GearDamageOptions::more_baselines): the least
  // energy left in the difference, on average over the channels compared (each relative to the
  // channel's regular signal); one that compared none, last; the first when they tie.
  auto left = [&](std::size_t bi) {
    return residual_channels[bi] > 0 ? residual[bi] / residual_channels[bi] : kInf;
  };
  std::size_t pick = 0;
  for (std::size_t bi = 1; bi < candidates.size(); ++bi) {
    if (left(bi) < left(pick)) pick = bi;
  }
  sd = std::move(candidates[pick]);
  const bool significant =
      (sd.compared || sd.snr >= options.min_snr) && !(sd.level < options.min_level) &&
      !(shared_steps.size() > 0 && sd.exclusive_share < options.min_exclusive_share);
  sd.significant = significant;
  sd.damaged = significant && sd.score > options.damaged_fm4;
  sd.uncertain = significant && !sd.damaged && sd.score > options.healthy_fm4;
  return sd;
}

GearDamageResult locate_impl(const diag::Recording& rec, const diag::Gearbox& gb,
                             const std::string& reference_shaft,
                             std::span<const double> pulse_times_s,
                             const GearDamageOptions& options, GearDamageBaseline* capture) {
  options.validate();
  const std::string where = "locate_gear_damage";
  const auto& shafts = gb.shafts();
  const std::string& ref = reference_shaft;
  check_locate_inputs(rec, gb, ref, pulse_times_s, options, where);
  GearDamageResult res;
  res.reference_shaft = ref;
  std::ostringstream note;
  const double ref_ratio = std::abs(shafts[gb.shaft_index(ref)].speed_ratio);
  const double ref_hz = (pulse_times_s.size() - 1) / (pulse_times_s.back() - pulse_times_s.front());
  const std::vector<double> ref_pulses =
      smooth_pulse_times_polynomial(pulse_times_s, options.pulse_fit_degree);

  const bool varying_speed = speed_varies(ref_pulses);

  // ---- pulse correction (pulse_refine.hpp): smoothed, then corrected from a mesh line's phase
  // on the fastest shaft; every shaft's revolutions are scaled from the result ----
  const RefinedPulses refined =
      refine_pulses(rec, gb, ref, pulse_times_s, pulse_refine_options(options));
  note << refined.note;
  const std::vector<double>& base = refined.pulses;  // once per revolution of a shaft turning at
  const double base_ratio =                          // |speed_ratio| = base_ratio
      std::abs(shafts[static_cast<std::size_t>(gb.shaft_index(refined.shaft))].speed_ratio);

  bool used_baseline = false;
  const LocateContext cx{rec,  gb,         options,       ref_ratio, ref_hz,
                         base, base_ratio, varying_speed, capture};
  for (const diag::Shaft& sh : shafts) {
    if (sh.gears.empty()) continue;
    res.shafts.push_back(score_shaft(cx, sh, note, used_baseline));
    for (int g : sh.gears) res.shafts.back().gears.push_back(gb.gears()[g].name);
  }
  decide_damaged_shafts(res, gb, options, used_baseline, note);
  res.note = note.str();
  return res;
}

}  // namespace

namespace {

// The reference shaft's once-per-revolution pulse times from its tacho (GearDamageOptions::
// reference_shaft, else the input's, else the first tacho of a known shaft); *ref its name,
// *repairs the tacho's repairs.
std::vector<double> reference_pulses(const diag::Recording& rec, const diag::Gearbox& gb,
                                     const GearDamageOptions& options, std::string* ref_out,
                                     std::size_t* repairs) {
  const std::string where = "locate_gear_damage";
  const auto& shafts = gb.shafts();

  // ---- reference tacho ----
  std::string ref = options.reference_shaft;
  if (!ref.empty() && gb.shaft_index(ref) < 0) {
    throw diag::InputError(
        diag::format_error(where, "reference_shaft", "unknown shaft '" + ref + "'"));
  }
  const diag::Signal* tacho = nullptr;
  auto tacho_of = [&](const std::string& shaft) { return diag::shaft_tacho(rec, shaft); };
  if (!ref.empty()) {
    tacho = tacho_of(ref);
  } else {
    ref = shafts[gb.input_shaft()].name;
    tacho = tacho_of(ref);
    for (std::size_t s = 0; !tacho && s < shafts.size(); ++s) {
      tacho = tacho_of(shafts[s].name);
      if (tacho) ref = shafts[s].name;
    }
  }
  if (!tacho) {
    throw diag::InputError(
        diag::format_error(where, "tachos", "no tacho for shaft '" + ref + "' in the recording"));
  }
  // The tacho's own pulses per revolution (a keyphasor: 1); every ppr-th pulse starts a
  // revolution.
  TachoOptions to;
  to.pulses_per_rev = diag::pulses_per_rev(*tacho);
  const TachoResult tr = tacho_pulses(tacho->samples, tacho->fs_hz, to);
  std::vector<double> once;
  for (std::size_t i = 0; i < tr.pulse_times_s.size(); i += to.pulses_per_rev) {
    once.push_back(tr.pulse_times_s[i]);
  }
  if (once.size() < 3) {
    throw diag::InputError(
        diag::format_error(where, "tacho '" + tacho->name + "'",
                           std::to_string(once.size()) + " revolutions; at least 3 are needed"));
  }
  *ref_out = ref;
  *repairs = tr.repairs.size();
  return once;
}

}  // namespace

GearDamageResult locate_gear_damage(const diag::Recording& rec, const diag::Gearbox& gb,
                                    const GearDamageOptions& options) {
  options.validate();
  std::string ref;
  std::size_t repairs = 0;
  const std::vector<double> once = reference_pulses(rec, gb, options, &ref, &repairs);
  GearDamageResult res = locate_gear_damage(rec, gb, ref, once, options);
  if (repairs > 0) {
    res.note = std::to_string(repairs) + " tacho repair(s) on '" + ref + "'. " + res.note;
  }
  return res;
}

GearDamageBaseline gear_damage_baseline(const diag::Recording& healthy, const diag::Gearbox& gb,
                                        const GearDamageOptions& options) {
  options.validate();
  std::string ref;
  std::size_t repairs = 0;
  const std::vector<double> once = reference_pulses(healthy, gb, options, &ref, &repairs);
  return gear_damage_baseline(healthy, gb, ref, once, options);
}

GearDamageBaseline gear_damage_baseline(const diag::Recording& healthy, const diag::Gearbox& gb,
                                        const std::string& reference_shaft,
                                        std::span<const double> pulse_times_s,
                                        const GearDamageOptions& options) {
  GearDamageOptions o = options;
  o.baseline.reset();
  o.more_baselines.clear();
  GearDamageBaseline b;
  locate_impl(healthy, gb, reference_shaft, pulse_times_s, o, &b);
  return b;
}

namespace {

// Step 7 of the header: the answer against the baseline (`cmp`) fused with the recording's own
// (`alone`).
GearDamageResult fuse_with_alone(GearDamageResult cmp, const GearDamageResult& alone) {
  for (ShaftDamage& s : cmp.shafts) {
    for (const ShaftDamage& a : alone.shafts) {
      if (a.shaft == s.shaft) s.score_alone = a.score;
    }
  }
  const bool cmp_flags = !cmp.findings.empty();
  const bool alone_flags = !alone.findings.empty();
  std::string why;
  if (cmp_flags && alone_flags && cmp.findings.front().shaft != alone.findings.front().shaft) {
    Finding a = cmp.findings.front();
    Finding b = alone.findings.front();
    a.note = "against the baseline: " + a.note;
    b.note = "the recording alone: " + b.note;
    a.confidence = 0.5 * std::min(a.confidence, 1.0);
    b.confidence = 0.5 * std::min(b.confidence, 1.0);
    cmp.findings = {a, b};
    cmp.status = "ambiguous";
    why = "against the baseline '" + a.shaft + "' is flagged, the recording alone flags '" +
          b.shaft +
          "': a fault on one shaft can change the response of another's gears to their own "
          "pitch errors, which the baseline does not cancel; both are reported. ";
  } else if (!cmp_flags && alone_flags) {
    const std::string note = cmp.note;
    std::vector<ShaftDamage> shafts = std::move(cmp.shafts);
    cmp = alone;
    cmp.shafts = std::move(shafts);
    cmp.note = note;
    why = "against the baseline no shaft stands out, the recording alone flags '" +
          alone.findings.front().shaft +
          "': reported from the recording alone (was the fault in the baseline too?). ";
  } else if (cmp_flags && alone_flags) {
    why = "the recording alone flags the same shaft. ";
  } else if (cmp_flags) {
    why = "the recording alone flags no shaft (the baseline removes the pitch errors' pattern). ";
  }
  cmp.note += why;
  return cmp;
}

}  // namespace

GearDamageResult locate_gear_damage(const diag::Recording& rec, const diag::Gearbox& gb,
                                    const std::string& reference_shaft,
                                    std::span<const double> pulse_times_s,
                                    const GearDamageOptions& options) {
  GearDamageResult res = locate_impl(rec, gb, reference_shaft, pulse_times_s, options, nullptr);
  if (!options.baseline) return res;
  GearDamageOptions alone_options = options;
  alone_options.baseline.reset();
  alone_options.more_baselines.clear();
  return fuse_with_alone(
      std::move(res), locate_impl(rec, gb, reference_shaft, pulse_times_s, alone_options, nullptr));
}

nlohmann::json to_json(const GearDamageResult& r) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); };
  nlohmann::json j;
  j["status"] = r.status;
  j["reference_shaft"] = r.reference_shaft;
  j["note"] = r.note;
  j["shafts"] = nlohmann::json::array();
  for (const auto& s : r.shafts) {
    j["shafts"].push_back({{"shaft", s.shaft},
                           {"frequency_hz", s.frequency_hz},
                           {"revolutions", s.revolutions},
                           {"channel", s.channel},
                           {"score", num(s.score)},
                           {"samples_per_rev", s.samples_per_rev},
                           {"fm4_exclusive", num(s.fm4)},
                           {"snr", num(s.snr)},
                           {"exclusive_share", num(s.exclusive_share)},
                           {"level", num(s.level)},
                           {"gear", s.gear},
                           {"tooth_angle_deg", num(s.angle_deg)},
                           {"compared_with_baseline", s.compared},
                           {"score_alone", num(s.score_alone)},
                           {"significant", s.significant},
                           {"damaged", s.damaged},
                           {"uncertain", s.uncertain},
                           {"fm4", num(s.indicators.fm4)},
                           {"m6a", num(s.indicators.m6a)},
                           {"na4", num(s.indicators.na4)},
                           {"kurtosis", num(s.indicators.kurtosis)},
                           {"crest_factor", num(s.indicators.crest_factor)},
                           {"er", num(s.indicators.er)},
                           {"ser", num(s.indicators.ser)}});
  }
  j["findings"] = nlohmann::json::array();
  for (const auto& f : r.findings) j["findings"].push_back(to_json(f));
  return j;
}

PulseRefineOptions pulse_refine_options(const GearDamageOptions& options) {
  PulseRefineOptions pro;
  pro.pulse_fit_degree = options.pulse_fit_degree;
  pro.phase_correction = options.refine_speed;
  pro.band_fraction = options.band_fraction;
  pro.samples_per_rev = options.samples_per_rev;
  pro.min_revolutions = options.min_revolutions;
  pro.channels = options.channels;
  return pro;
}

}  // namespace detect
