#include "detect/angular/pulse_refine.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <numeric>
#include <sstream>

#include "detect/angular/resample.hpp"
#include "detect/angular/tsa.hpp"
#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"

namespace detect {

namespace {

// The line followed must have an amplitude steady to 0.1 of its mean over the revolutions, i.e.
// a phase known to about 0.1 rad in each.
constexpr double kMaxPhaseNoise = 0.1;
// The fit of the time of pulse k is replaced by the fit of the angle at the time of a pulse when
// its residual is this many times larger. For constant speed both are exact and leave the same
// residual (the pulses' jitter); 2 keeps steady records on the first fit by a wide margin (their
// residuals differ by the fit's noise, ~1/sqrt(N)).
constexpr double kMaxFitResidualRatio = 2.0;
// Relative tolerance for "this speed ratio is the integer p": the gearbox ratios are exact
// products of tooth-count ratios, so only round-off separates them from p.
constexpr double kRatioTol = 1e-9;

bool is_integer(double x, int* n) {
  const double r = std::round(x);
  if (r < 1 || std::abs(x - r) > kRatioTol * std::max(1.0, x)) return false;
  *n = static_cast<int>(r);
  return true;
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

void check_pulses(std::span<const double> p, const std::string& where) {
  if (p.size() < 3) {
    throw diag::InputError(diag::format_error(
        where, "pulse_times_s", std::to_string(p.size()) + " pulses; at least 3 are needed"));
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!std::isfinite(p[i]) || (i > 0 && !(p[i] > p[i - 1]))) {
      throw diag::InputError(
          diag::format_error(where, "pulse_times_s",
                             "not finite and strictly increasing at pulse " + std::to_string(i)));
    }
  }
}

}  // namespace

std::vector<double> smooth_pulse_times_polynomial(std::span<const double> pulse_times_s,
                                                  int degree) {
  if (degree < 0 || degree > 8) {
    throw diag::InputError(diag::format_error("smooth_pulse_times_polynomial", "degree",
                                              std::to_string(degree) + " is outside [0, 8]"));
  }
  return smooth_pulses(std::vector<double>(pulse_times_s.begin(), pulse_times_s.end()), degree);
}

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

TsaResolution tsa_resolution(double fs_hz, double shaft_hz, double band_fraction,
                             int samples_per_rev) {
  const double top_order = band_fraction * 0.5 * fs_hz / shaft_hz;
  TsaResolution r;
  r.samples_per_rev = samples_per_rev > 0
                          ? samples_per_rev
                          : std::clamp(next_power_of_two(2.8 * top_order), 64, 16384);
  r.top = static_cast<std::size_t>(std::min(top_order, 0.72 * (r.samples_per_rev / 2)));
  return r;
}

PhaseRefinement refine_pulses_from_phase(const diag::Signal& ch,
                                         std::span<const double> pulse_times_s, int spr,
                                         const std::vector<bool>& regular, std::size_t first,
                                         int min_revolutions) {
  const std::vector<double> pulses(pulse_times_s.begin(), pulse_times_s.end());
  PhaseRefinement out;
  std::size_t* line = &out.line;
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
  out.pulses = std::move(best);
  return out;
}

std::vector<const diag::Signal*> shaft_vibration_channels(const diag::Recording& rec,
                                                          const diag::Gearbox& gb,
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

void PulseRefineOptions::validate() const {
  if (pulse_fit_degree < 0 || pulse_fit_degree > 8) {
    diag::fail("PulseRefineOptions", "pulse_fit_degree",
               std::to_string(pulse_fit_degree) + " is outside [0, 8]");
  }
  if (!(band_fraction > 0.0 && band_fraction <= 1.0)) {
    diag::fail("PulseRefineOptions", "band_fraction",
               std::to_string(band_fraction) + " is outside (0, 1]");
  }
  if (samples_per_rev != 0 &&
      (samples_per_rev < 64 || (samples_per_rev & (samples_per_rev - 1)) != 0)) {
    diag::fail("PulseRefineOptions", "samples_per_rev",
               std::to_string(samples_per_rev) + " is not 0 (automatic) or a power of two >= 64");
  }
  if (min_revolutions < 2)
    diag::fail("PulseRefineOptions", "min_revolutions", std::to_string(min_revolutions) + " < 2");
}

RefinedPulses refine_pulses(const diag::Recording& rec, const diag::Gearbox& gb,
                            const std::string& reference_shaft,
                            std::span<const double> pulse_times_s,
                            const PulseRefineOptions& options) {
  options.validate();
  const std::string where = "refine_pulses";
  const int ref_index = gb.shaft_index(reference_shaft);
  if (ref_index < 0) {
    throw diag::InputError(
        diag::format_error(where, "reference_shaft", "unknown shaft '" + reference_shaft + "'"));
  }
  check_pulses(pulse_times_s, where);
  const auto& shafts = gb.shafts();
  RefinedPulses out;
  out.shaft = reference_shaft;
  out.pulses = smooth_pulse_times_polynomial(pulse_times_s, options.pulse_fit_degree);
  if (!options.phase_correction) return out;
  const double ref_ratio = std::abs(shafts[static_cast<std::size_t>(ref_index)].speed_ratio);
  const double ref_hz = (pulse_times_s.size() - 1) / (pulse_times_s.back() - pulse_times_s.front());
  // The fastest shaft with gears and a channel.
  const diag::Shaft* fast = nullptr;
  std::vector<const diag::Signal*> chans;
  for (const diag::Shaft& sh : shafts) {
    if (sh.gears.empty() || (fast && std::abs(sh.speed_ratio) <= std::abs(fast->speed_ratio))) {
      continue;
    }
    std::vector<const diag::Signal*> c;
    if (auto it = options.channels.find(sh.name); it != options.channels.end()) {
      for (const auto& n : it->second) c.push_back(&rec.require(n, where));
    } else {
      c = shaft_vibration_channels(rec, gb, sh.name);
    }
    if (!c.empty()) fast = &sh, chans = std::move(c);
  }
  if (!fast) return out;
  const double rel = std::abs(fast->speed_ratio) / ref_ratio;
  const std::vector<double> fast_pulses = scale_pulses(out.pulses, rel);
  const TsaResolution res = tsa_resolution(chans.front()->fs_hz, ref_hz * rel,
                                           options.band_fraction, options.samples_per_rev);
  const std::vector<int> orders = synchronous_mesh_orders(gb, *fast, res.samples_per_rev / 2);
  const std::vector<bool> regular =
      tsa_regular_orders(static_cast<std::size_t>(res.samples_per_rev), orders, 1);
  const std::size_t first =
      orders.empty() ? 0
                     : static_cast<std::size_t>(*std::min_element(orders.begin(), orders.end()));
  for (const diag::Signal* ch : chans) {
    PhaseRefinement p;
    try {
      p = refine_pulses_from_phase(*ch, fast_pulses, res.samples_per_rev, regular, first,
                                   options.min_revolutions);
    } catch (const diag::InputError&) {
      continue;  // too short to resample: the TSA's user says why
    }
    if (p.line == 0) continue;
    out.shaft = fast->name;
    out.pulses = std::move(p.pulses);
    out.line = p.line;
    out.channel = ch->name;
    std::ostringstream note;
    note << "pulses corrected from the phase of order " << p.line << " of shaft '" << fast->name
         << "' on " << ch->name << ". ";
    out.note = note.str();
    break;
  }
  return out;
}

}  // namespace detect
