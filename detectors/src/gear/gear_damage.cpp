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
// Pulse correction (GearDamageOptions::refine_speed): the line followed must have an amplitude
// steady to 0.1 of its mean over the revolutions, i.e. a phase known to about 0.1 rad in each.
constexpr double kMaxPhaseNoise = 0.1;
// Relative tolerance for "this speed ratio is the integer / rational p/q": the gearbox ratios are
// exact products of tooth-count ratios, so only round-off separates them from p/q.
constexpr double kRatioTol = 1e-9;
constexpr int kMaxDenominator = 64;
// Pulse fit (smooth_pulses): the fit of the time of pulse k is replaced by the fit of the angle
// at the time of a pulse when its residual is this many times larger. For constant speed both
// are exact and leave the same residual (the pulses' jitter); 2 keeps steady records on the
// first fit by a wide margin (their residuals differ by the fit's noise, ~1/sqrt(N)).
constexpr double kMaxFitResidualRatio = 2.0;
// Speed varying within the record (the averages weighted by revolution, see the shaft loop): the
// fitted revolution periods spread by more than this share of their mean, as analyze's
// "non-stationary" (max - min speed above 1 % of the mean). A steady record (the closed loop)
// keeps the plain average.
constexpr double kVaryingSpeedSpread = 0.01;
// Revolutions either side over which a revolution's noise energy is averaged for its weight: 9
// revolutions of a few hundred orders each give the weight to ~2 %; the speed changes by less
// than 15 % over them in a run-up 500 -> 3000 rpm over 9 s.
constexpr std::ptrdiff_t kWeightHalfWindow = 4;

void fail(const std::string& field, const std::string& reason) {
  throw diag::InputError(diag::format_error("GearDamageOptions", field, reason));
}

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

// The sensors of `shaft` by the channel contract (diag::shaft_sensors: the channel's shaft, or
// a location naming a bearing of the shaft): the first location only (the simulator's bearing1 /
// bearing2 see the same rigid shaft motion), along each line of action when there are such;
// without sensors on the shaft, every sensor channel (a casing sensor serves all shafts).
std::vector<const diag::Signal*> shaft_channels(const diag::Recording& rec, const diag::Gearbox& gb,
                                                const std::string& shaft) {
  std::vector<const diag::Signal*> along, any;
  std::string first_location;
  bool first = true;
  for (std::size_t i : diag::shaft_sensors(rec, gb, shaft)) {
    const diag::Signal& s = rec.signals[i];
    if (first) first_location = s.location, first = false;
    if (s.location != first_location) continue;
    any.push_back(&s);
    if (s.direction == diag::Direction::kAlongLoa) along.push_back(&s);
  }
  if (!along.empty()) return along;
  if (!any.empty()) return any;
  std::vector<const diag::Signal*> casing;
  for (std::size_t i : diag::sensor_channels(rec)) casing.push_back(&rec.signals[i]);
  return casing;
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

int next_power_of_two(double x) {
  int p = 1;
  while (p < x && p < (1 << 30)) p <<= 1;
  return p;
}

// Least-squares polynomial of degree `degree` through the points (x_i, y_i), x scaled to [-1, 1]
// (conditioning): its coefficients in the scaled variable.
struct PolyFit {
  Eigen::VectorXd c;
  double x0 = 0.0, x_scale = 1.0;  // u = (x - x0) * x_scale
  double operator()(double x) const {
    const double u = (x - x0) * x_scale;
    double v = 0.0;
    for (Eigen::Index j = c.size() - 1; j >= 0; --j) v = v * u + c(j);
    return v;
  }
  double slope(double x) const {
    const double u = (x - x0) * x_scale;
    double v = 0.0;
    for (Eigen::Index j = c.size() - 1; j >= 1; --j) v = v * u + static_cast<double>(j) * c(j);
    return v * x_scale;
  }
};
PolyFit poly_fit(const std::vector<double>& x, const std::vector<double>& y, int degree) {
  const auto n = static_cast<Eigen::Index>(x.size());
  PolyFit f;
  f.x0 = 0.5 * (x.front() + x.back());
  f.x_scale = 2.0 / (x.back() - x.front());
  Eigen::MatrixXd a(n, degree + 1);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double u = (x[static_cast<std::size_t>(i)] - f.x0) * f.x_scale;
    double p = 1.0;
    for (int j = 0; j <= degree; ++j, p *= u) a(i, j) = p;
    b(i) = y[static_cast<std::size_t>(i)];
  }
  f.c = a.colPivHouseholderQr().solve(b);
  return f;
}

// The pulse times with their jitter averaged out (GearDamageOptions::pulse_fit_degree): the
// least-squares polynomial t(k) of the pulse index k, or, when that leaves a residual above
// kMaxFitResidualRatio x that of the other fit, the polynomial k(t) (the shaft angle in
// revolutions as a function of time) inverted at every integer k. Why both: t(k) is exact for
// constant speed and, over a short record, for a linear run-up, but over a long run-up t(k) ~
// sqrt(k) is not a polynomial (500 -> 3000 rpm over 263 revolutions: a cubic t(k) is off by 5
// revolutions), while the angle of a linear run-up is exactly quadratic in time. The residuals
// are compared in time: k(t)'s residual in revolutions over the local speed.
std::vector<double> smooth_pulses(const std::vector<double>& t, int degree) {
  const int n = static_cast<int>(t.size());
  if (degree <= 0 || n <= degree + 1) return t;
  Eigen::MatrixXd a(n, degree + 1);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    const double u = 2.0 * i / (n - 1) - 1.0;
    double p = 1.0;
    for (int j = 0; j <= degree; ++j, p *= u) a(i, j) = p;
    b(i) = t[i] - t.front();
  }
  const Eigen::VectorXd fit = a * a.colPivHouseholderQr().solve(b);
  const double t_rms_s = std::sqrt((b - fit).squaredNorm() / n);
  std::vector<double> out(t.size());
  for (int i = 0; i < n; ++i) out[i] = t.front() + fit(i);
  std::vector<double> k(t.size());
  std::iota(k.begin(), k.end(), 0.0);
  const PolyFit k_of_t = poly_fit(t, k, degree);
  double sq = 0.0;  // k(t)'s residual in time
  bool increasing = true;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double rate = k_of_t.slope(t[i]);
    increasing = increasing && rate > 0.0;
    const double r = (k[i] - k_of_t(t[i])) / rate;
    sq += r * r;
  }
  const double k_rms_s = std::sqrt(sq / n);
  // Round-off (exact pulses, e.g. from a nominal speed) is no reason to switch.
  const double floor_s = 1e-12 * (t.back() - t.front());
  if (!increasing || !(t_rms_s > kMaxFitResidualRatio * k_rms_s + floor_s)) return out;
  // Invert k(t) by Newton's method from the measured time (within a fraction of a period).
  std::vector<double> inv(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    double x = t[i];
    for (int it = 0; it < 20; ++it) {
      const double dx = (k_of_t(x) - k[i]) / k_of_t.slope(x);
      x -= dx;
      if (std::abs(dx) < 1e-12 * std::max(1.0, std::abs(x))) break;
    }
    inv[i] = x;
  }
  for (std::size_t i = 1; i < inv.size(); ++i) {
    if (!(inv[i] > inv[i - 1]) || !std::isfinite(inv[i])) return out;
  }
  return inv;
}

// The regular order (shaft order 1, mesh harmonics, their first sidebands) in 1..top with the
// largest TSA amplitude; 0 when there is none.
std::size_t strongest_line(const std::vector<std::complex<double>>& mean_spec,
                           const std::vector<bool>& regular, std::size_t top) {
  std::size_t best = 0;
  for (std::size_t k = 1; k <= top && k < mean_spec.size(); ++k) {
    if (regular[k] && (best == 0 || std::norm(mean_spec[k]) > std::norm(mean_spec[best]))) best = k;
  }
  return best;
}

// The pulses corrected revolution by revolution from the phase of a line of order k, as
// measured in each revolution of the resampled record (`phasors`, revolution j between pulses
// first_rev + j and first_rev + j + 1); the pulses unchanged when the line's amplitude scatters
// by more than max_phase_noise of its mean over the revolutions (additive noise moves the phase
// about as much as the amplitude, so the phase would carry more noise than the pulses' error).
// In revolution j the line's phase is c + k e_j, e_j the mean error of the pulses' angle
// there (true minus assumed, rad); e is interpolated to the pulses between revolution middles
// (held beyond the first and last) and each pulse moved by -e / (2 pi) of the local period.
std::vector<double> phase_corrected_pulses(const std::vector<double>& pulses,
                                           const std::vector<std::complex<double>>& phasors,
                                           std::size_t k, double first_rev,
                                           double max_phase_noise) {
  const std::size_t n = phasors.size();
  if (n < 3 || k == 0 || pulses.size() < 2) return pulses;
  double mean_amp = 0.0, mean_sq = 0.0;
  for (const auto& z : phasors) {
    mean_amp += std::abs(z);
    mean_sq += std::norm(z);
  }
  mean_amp /= static_cast<double>(n);
  mean_sq /= static_cast<double>(n);
  const double amp_sd = std::sqrt(std::max(0.0, mean_sq - mean_amp * mean_amp));
  if (!(mean_amp > 0.0) || amp_sd > max_phase_noise * mean_amp) return pulses;
  std::vector<double> e(n);
  e[0] = std::arg(phasors[0]);
  for (std::size_t j = 1; j < n; ++j)
    e[j] = e[j - 1] + std::arg(phasors[j] * std::conj(phasors[j - 1]));
  const double e_mean = std::accumulate(e.begin(), e.end(), 0.0) / static_cast<double>(n);
  for (double& v : e) v = (v - e_mean) / static_cast<double>(k);
  std::vector<double> out(pulses.size());
  for (std::size_t b = 0; b < pulses.size(); ++b) {
    const double x =
        std::clamp(static_cast<double>(b) - first_rev - 0.5, 0.0, static_cast<double>(n - 1));
    const auto j = std::min(static_cast<std::size_t>(x), n - 2);
    const double err = e[j] + (x - static_cast<double>(j)) * (e[j + 1] - e[j]);
    const double period =
        b + 1 < pulses.size() ? pulses[b + 1] - pulses[b] : pulses[b] - pulses[b - 1];
    out[b] = pulses[b] - err / (2.0 * std::numbers::pi) * period;
  }
  for (std::size_t b = 1; b < out.size(); ++b) {
    if (!(out[b] > out[b - 1])) return pulses;
  }
  return out;
}

// Every mesh frequency of the gearbox that is an integer order of shaft `sh`, up to `half`.
std::vector<int> synchronous_mesh_orders(const diag::Gearbox& gb, const diag::Shaft& sh, int half) {
  const auto& shafts = gb.shafts();
  std::vector<int> orders;
  for (std::size_t m = 0; m < gb.meshes().size(); ++m) {
    const double f_mesh_over_in =
        gb.gears()[gb.meshes()[m].driver].spec.teeth *
        std::abs(shafts[gb.shaft_of_gear(gb.meshes()[m].driver)].speed_ratio);
    int order = 0;
    if (is_integer(f_mesh_over_in / std::abs(sh.speed_ratio), &order) && order <= half &&
        std::find(orders.begin(), orders.end(), order) == orders.end()) {
      orders.push_back(order);
    }
  }
  return orders;
}

// TSA resolution for a shaft turning at shaft_hz (GearDamageOptions::samples_per_rev) and the
// highest order analysed.
struct Resolution {
  int spr = 0;
  std::size_t top = 0;
};
Resolution resolution(const GearDamageOptions& o, double fs, double shaft_hz) {
  const double top_order = o.band_fraction * 0.5 * fs / shaft_hz;
  Resolution r;
  r.spr = o.samples_per_rev > 0 ? o.samples_per_rev
                                : std::clamp(next_power_of_two(2.8 * top_order), 64, 16384);
  r.top = static_cast<std::size_t>(std::min(top_order, 0.72 * (r.spr / 2)));
  return r;
}

// The pulses of one shaft corrected from the phase of its regular lines in channel `ch`
// (GearDamageOptions::refine_speed). Two stages: the lowest mesh order of the shaft (`first`;
// its phase step per revolution, k eps, stays unambiguous up to a speed error of 0.5 / k), then
// the strongest regular line (its phase is the most precise). Each stage corrects twice (the
// first pass measures each revolution's phase through the error it corrects: a revolution's
// spectrum is blurred by the error's change within it) and is kept only if no pulse moves by
// half a period of the line or more and it raises the energy of the TSA's regular lines, i.e.
// makes them more coherent. So the correction is for small errors (the tacho's quantisation and
// the rate error of its fit, ~1e-5); a larger speed error is left as it is and smears the
// averages: no finding rather than a wrong one. *line: the last order followed that was kept, 0
// when the pulses stay as they are. Throws diag::InputError when the record cannot be
// resampled.
std::vector<double> refined_pulses(const diag::Signal& ch, const std::vector<double>& pulses,
                                   int spr, const std::vector<bool>& regular, std::size_t first,
                                   int min_revolutions, std::size_t* line) {
  ResampleOptions ro;
  ro.pulses_per_rev = 1;
  ro.samples_per_rev = spr;
  RealFft fft(static_cast<std::size_t>(spr));
  std::vector<std::complex<double>> spec(fft.bins());
  const auto passband = static_cast<std::size_t>(0.72 * (spr / 2));
  // The TSA's spectrum and the energy of its regular lines, for pulses p.
  auto coherent = [&](const AngleResampled& ar) {
    fft.forward(tsa(ar, min_revolutions).samples, spec);
    double e = 0.0;
    for (std::size_t k = 1; k <= passband && k < spec.size(); ++k) {
      if (regular[k]) e += std::norm(spec[k]);
    }
    return e;
  };
  AngleResampled ar = resample_by_angle(ch.samples, ch.fs_hz, pulses, ro);
  double energy = coherent(ar);
  const std::size_t strongest = strongest_line(spec, regular, passband);
  std::vector<double> best = pulses;
  *line = 0;
  std::vector<std::complex<double>> phasors;
  for (const std::size_t k : {first, strongest}) {
    if (k == 0 || k > passband || k == *line) continue;
    std::vector<double> p = best;
    AngleResampled a = ar;
    for (int pass = 0; pass < 2; ++pass) {
      phasors.clear();
      for (int r = 0; r < a.revolutions; ++r) {
        fft.forward(std::span<const double>(a.samples).subspan(static_cast<std::size_t>(r) * spr,
                                                               static_cast<std::size_t>(spr)),
                    spec);
        phasors.push_back(spec[k]);
      }
      std::vector<double> q = phase_corrected_pulses(p, phasors, k, a.first_rev, kMaxPhaseNoise);
      if (q == p) break;
      p = std::move(q);
      a = resample_by_angle(ch.samples, ch.fs_hz, p, ro);
    }
    if (p == best) continue;
    // No pulse may move by half a period of the line or more from where the tacho put it: the
    // phase steps would then be ambiguous (a rate error of eps over N revolutions moves the end
    // pulses by k eps N / 2 periods of order k), and following them can lock the angle onto a
    // neighbouring order.
    bool near = true;
    for (std::size_t b = 0; b < p.size() && near; ++b) {
      const double period =
          b + 1 < p.size() ? pulses[b + 1] - pulses[b] : pulses[b] - pulses[b - 1];
      near = std::abs(p[b] - pulses[b]) < 0.5 * period / static_cast<double>(k);
    }
    if (!near) continue;
    const double e = coherent(a);
    if (!(e > energy)) continue;
    energy = e;
    best = std::move(p);
    ar = std::move(a);
    *line = k;
  }
  return best;
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

}  // namespace

void GearDamageOptions::validate() const {
  if (samples_per_rev != 0 &&
      (samples_per_rev < 64 || (samples_per_rev & (samples_per_rev - 1)) != 0)) {
    fail("samples_per_rev",
         std::to_string(samples_per_rev) + " is not 0 (automatic) or a power of two >= 64");
  }
  if (pulse_fit_degree < 0 || pulse_fit_degree > 8) {
    fail("pulse_fit_degree", std::to_string(pulse_fit_degree) + " is outside [0, 8]");
  }
  if (extra_sideband_orders < 0) {
    fail("extra_sideband_orders", std::to_string(extra_sideband_orders) + " is negative");
  }
  if (!(band_fraction > 0.0 && band_fraction <= 1.0)) {
    fail("band_fraction", std::to_string(band_fraction) + " is outside (0, 1]");
  }
  if (!(min_level >= 0.0) || !std::isfinite(min_level)) {
    fail("min_level", std::to_string(min_level) + " must be finite and >= 0");
  }
  if (!(min_exclusive_share >= 0.0 && min_exclusive_share < 1.0)) {
    fail("min_exclusive_share", std::to_string(min_exclusive_share) + " is outside [0, 1)");
  }
  if (!(min_snr >= 1.0) || !std::isfinite(min_snr)) {
    fail("min_snr", std::to_string(min_snr) + " must be finite and >= 1 (noise alone)");
  }
  if (min_revolutions < 2) {
    fail("min_revolutions", std::to_string(min_revolutions) + " is below 2");
  }
  if (!(healthy_fm4 > 3.0) || !std::isfinite(healthy_fm4)) {
    fail("healthy_fm4", std::to_string(healthy_fm4) + " must be finite and > 3 (Gaussian noise)");
  }
  if (!(damaged_fm4 > healthy_fm4) || !std::isfinite(damaged_fm4)) {
    fail("damaged_fm4", std::to_string(damaged_fm4) + " must be finite and > healthy_fm4 (" +
                            std::to_string(healthy_fm4) + ")");
  }
}

GearDamageResult locate_gear_damage(const diag::Recording& rec, const diag::Gearbox& gb,
                                    const GearDamageOptions& options) {
  options.validate();
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
  GearDamageResult res = locate_gear_damage(rec, gb, ref, once, options);
  if (!tr.repairs.empty()) {
    res.note = std::to_string(tr.repairs.size()) + " tacho repair(s) on '" + ref + "'. " + res.note;
  }
  return res;
}

GearDamageResult locate_gear_damage(const diag::Recording& rec, const diag::Gearbox& gb,
                                    const std::string& reference_shaft,
                                    std::span<const double> pulse_times_s,
                                    const GearDamageOptions& options) {
  options.validate();
  const std::string where = "locate_gear_damage";
  const auto& shafts = gb.shafts();
  const std::string& ref = reference_shaft;
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
  GearDamageResult res;
  res.reference_shaft = ref;
  std::ostringstream note;
  const std::vector<double> ref_pulses = smooth_pulses(
      std::vector<double>(pulse_times_s.begin(), pulse_times_s.end()), options.pulse_fit_degree);
  const double ref_ratio = std::abs(shafts[gb.shaft_index(ref)].speed_ratio);
  const double ref_hz = (pulse_times_s.size() - 1) / (pulse_times_s.back() - pulse_times_s.front());

  ResampleOptions ro;
  ro.pulses_per_rev = 1;
  // Varying speed: the reference's revolution periods (fitted) spread by more than
  // kVaryingSpeedSpread of their mean.
  bool varying_speed = false;
  if (ref_pulses.size() >= 3) {
    double lo = kInf, hi = 0.0;
    for (std::size_t i = 1; i < ref_pulses.size(); ++i) {
      lo = std::min(lo, ref_pulses[i] - ref_pulses[i - 1]);
      hi = std::max(hi, ref_pulses[i] - ref_pulses[i - 1]);
    }
    const double mean = (ref_pulses.back() - ref_pulses.front()) / (ref_pulses.size() - 1);
    varying_speed = hi - lo > kVaryingSpeedSpread * mean;
  }

  auto channels_of = [&](const diag::Shaft& sh) {
    std::vector<const diag::Signal*> chans;
    if (auto it = options.channels.find(sh.name); it != options.channels.end()) {
      for (const auto& n : it->second) chans.push_back(&rec.require(n, where));
    } else {
      chans = shaft_channels(rec, gb, sh.name);
    }
    return chans;
  };

  // ---- pulse correction (refine_speed) on the fastest shaft with gears and channels ----
  // Once for all shafts: the error is the reference pulses' (every shaft's revolutions are
  // scaled from them), and the fastest shaft sees it at the lowest orders, where a phase step
  // per revolution stays unambiguous longest. Correcting each shaft on its own could leave the
  // slow shafts smeared while a fast one is corrected: a slow shaft's fault, which folds into
  // the faster shafts' averages, would then be put on the fast shaft.
  std::vector<double> base = ref_pulses;  // once-per-revolution times of a shaft turning at
  double base_ratio = ref_ratio;          // |speed_ratio| = base_ratio
  if (options.refine_speed) {
    const diag::Shaft* fast = nullptr;
    std::vector<const diag::Signal*> fast_chans;
    for (const diag::Shaft& sh : shafts) {
      if (sh.gears.empty() || (fast && std::abs(sh.speed_ratio) <= std::abs(fast->speed_ratio))) {
        continue;
      }
      std::vector<const diag::Signal*> c = channels_of(sh);
      if (!c.empty()) fast = &sh, fast_chans = std::move(c);
    }
    if (fast) {
      const double rel = std::abs(fast->speed_ratio) / ref_ratio;
      const std::vector<double> fast_pulses = scale_pulses(ref_pulses, rel);
      const Resolution res_f = resolution(options, fast_chans.front()->fs_hz, ref_hz * rel);
      const std::vector<int> orders = synchronous_mesh_orders(gb, *fast, res_f.spr / 2);
      const std::vector<bool> regular =
          tsa_regular_orders(static_cast<std::size_t>(res_f.spr), orders, 1);
      const std::size_t first =
          orders.empty()
              ? 0
              : static_cast<std::size_t>(*std::min_element(orders.begin(), orders.end()));
      for (const diag::Signal* ch : fast_chans) {
        std::size_t line = 0;
        std::vector<double> p;
        try {
          p = refined_pulses(*ch, fast_pulses, res_f.spr, regular, first, options.min_revolutions,
                             &line);
        } catch (const diag::InputError&) {
          continue;  // the shaft loop below says why
        }
        if (line == 0) continue;
        base = std::move(p);
        base_ratio = std::abs(fast->speed_ratio);
        note << "pulses corrected from the phase of order " << line << " of shaft '" << fast->name
             << "' on " << ch->name << ". ";
        break;
      }
    }
  }

  for (std::size_t si = 0; si < shafts.size(); ++si) {
    const diag::Shaft& sh = shafts[si];
    if (sh.gears.empty()) continue;
    ShaftDamage sd;
    sd.shaft = sh.name;
    sd.score = sd.fm4 = sd.snr = kNaN;
    const double rel = std::abs(sh.speed_ratio) / ref_ratio;  // f_s / f_ref
    sd.frequency_hz = ref_hz * rel;

    const std::vector<const diag::Signal*> chans = channels_of(sh);
    if (chans.empty()) {
      note << "shaft '" << sh.name << "': no channel. ";
      res.shafts.push_back(sd);
      continue;
    }
    // Highest order analysed and the TSA resolution (options).
    const Resolution reso = resolution(options, chans.front()->fs_hz, sd.frequency_hz);
    const int spr = reso.spr;
    const int half = spr / 2;
    const std::size_t top = reso.top;
    sd.samples_per_rev = spr;
    ro.samples_per_rev = spr;
    const std::vector<int> mesh_orders = synchronous_mesh_orders(gb, sh, half);
    std::vector<int> own_orders;
    for (int g : sh.gears) own_orders.push_back(gb.gears()[g].spec.teeth);
    // Orders shared with faster shafts.
    std::vector<int> shared_steps;
    for (const diag::Shaft& other : shafts) {
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
    const std::vector<double> pulses = scale_pulses(base, std::abs(sh.speed_ratio) / base_ratio);
    RealFft fft(static_cast<std::size_t>(spr));
    std::vector<std::complex<double>> mean_spec(fft.bins()), rev_spec(fft.bins());
    std::vector<double> var(fft.bins());
    std::vector<std::vector<std::complex<double>>> rev_specs;
    for (const diag::Signal* ch : chans) {
      AngleResampled ar;
      Tsa t;
      try {
        ar = resample_by_angle(ch->samples, ch->fs_hz, pulses, ro);
        t = tsa(ar, options.min_revolutions);
      } catch (const diag::InputError& e) {
        note << "shaft '" << sh.name << "' skipped: " << e.what() << ". ";
        break;
      }
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
      if (varying_speed) {
        rev_specs.assign(static_cast<std::size_t>(ar.revolutions), {});
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
          fft.forward(
              std::span<const double>(ar.samples)
                  .subspan(static_cast<std::size_t>(r) * spr, static_cast<std::size_t>(spr)),
              rev_spec);
          for (std::size_t k = 0; k < var.size(); ++k)
            var[k] += std::norm(rev_spec[k] - mean_spec[k]);
        }
      }
      double energy = 0.0, noise = 0.0, band = 0.0, regular_energy = 0.0;
      for (std::size_t k = 0; k < keep.size(); ++k) {
        if (in_band[k]) band += std::norm(mean_spec[k]);
        if (k > 0 && k <= top && regular[k]) regular_energy += std::norm(mean_spec[k]);
        if (keep[k]) {
          energy += std::norm(mean_spec[k]);
          noise += var[k] / (static_cast<double>(ar.revolutions) * (ar.revolutions - 1));
        } else {
          mean_spec[k] = 0.0;
        }
      }
      std::vector<double> excl(static_cast<std::size_t>(spr));
      fft.inverse(mean_spec, excl);
      const double raw = energy > 0.0 ? fm4(excl) : kNaN;
      const double snr = noise > 0.0 ? energy / noise : (energy > 0.0 ? kInf : 0.0);
      // Kurtosis of the synchronous part (options): only where it stands out of the noise.
      double score = 3.0;
      if (snr >= options.min_snr && std::isfinite(raw)) {
        const double gain = std::isfinite(snr) ? snr / (snr - 1.0) : 1.0;
        score = 3.0 + (raw - 3.0) * gain * gain;
      }
      if (std::isnan(sd.score) || score > sd.score || (score == sd.score && snr > sd.snr)) {
        sd.score = score;
        sd.fm4 = raw;
        sd.snr = snr;
        sd.exclusive_share = band > 0.0 ? energy / band : 0.0;
        sd.level =
            regular_energy > 0.0 ? std::sqrt(std::max(0.0, energy - noise) / regular_energy) : kInf;
        sd.channel = ch->name;
        sd.revolutions = t.revolutions;
        const std::vector<double> diff = tsa_difference(t, mesh_orders);
        sd.indicators = indicators_for(t, diff, mesh_orders, gb.gears()[sh.gears[0]].spec.teeth);
      }
    }
    const bool significant =
        sd.snr >= options.min_snr && !(sd.level < options.min_level) &&
        !(shared_steps.size() > 0 && sd.exclusive_share < options.min_exclusive_share);
    sd.damaged = significant && sd.score > options.damaged_fm4;
    sd.uncertain = significant && !sd.damaged && sd.score > options.healthy_fm4;
    res.shafts.push_back(sd);
  }

  // ---- decision: the slowest damaged shaft ----
  std::vector<std::size_t> order(res.shafts.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return res.shafts[a].frequency_hz < res.shafts[b].frequency_hz;
  });
  auto make_finding = [&](const ShaftDamage& sd, const std::string& why) {
    GearDamageFinding f;
    f.shaft = sd.shaft;
    for (int g : shafts[gb.shaft_index(sd.shaft)].gears) f.gears.push_back(gb.gears()[g].name);
    f.channel = sd.channel;
    f.score = sd.score;
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
    why << "noise-corrected kurtosis of the exclusive difference signal " << sd.score << " > "
        << options.damaged_fm4 << " on " << sd.channel;
    res.findings.push_back(make_finding(sd, why.str()));
    res.status = "damaged";
    for (std::size_t j = 0; j < k; ++j) {
      const ShaftDamage& slower = res.shafts[order[j]];
      if (!slower.uncertain) continue;
      std::ostringstream w2;
      w2 << "FM4 " << slower.score << " in the uncertain band (" << options.healthy_fm4 << ", "
         << options.damaged_fm4 << "]: a fault here would also flag '" << sd.shaft << "'";
      res.findings.push_back(make_finding(slower, w2.str()));
      res.status = "ambiguous";
    }
    if (res.status == "ambiguous") {
      for (auto& f : res.findings) f.confidence *= 0.5;
    }
    break;
  }
  res.note = note.str();
  return res;
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
  for (const auto& f : r.findings) {
    j["findings"].push_back({{"shaft", f.shaft},
                             {"gears", f.gears},
                             {"channel", f.channel},
                             {"score", f.score},
                             {"confidence", f.confidence},
                             {"note", f.note}});
  }
  return j;
}

}  // namespace detect
