#include "sim/bearing/bearing_signal.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/truth.hpp"
#include "diag/units.hpp"

namespace sim {

using diag::units::kTwoPi;

namespace {

constexpr const char* kWhere = "bearing signal";

// Stribeck's load distribution, normalised to 1 at theta = 0 (see the header).
double load(double theta_rad, double eps) {
  const double b = 1.0 - (1.0 - std::cos(theta_rad)) / (2.0 * eps);
  return b > 0 ? std::pow(b, 1.5) : 0.0;
}

// Adds a * h(t - t0) to x, h the resonance's impulse response, from t0 until its envelope has
// decayed by 60 dB.
void add_ring(std::vector<double>& x, double fs, double t0, double a, double wn, double zeta) {
  if (a == 0) return;
  const double wd = wn * std::sqrt(1 - zeta * zeta);
  const double t_end = t0 + std::log(1000.0) / (zeta * wn);
  const auto j0 = static_cast<std::size_t>(std::max(0.0, std::ceil(t0 * fs)));
  const auto j1 = std::min(x.size(), static_cast<std::size_t>(std::ceil(t_end * fs)));
  for (std::size_t j = j0; j < j1; ++j) {
    const double t = static_cast<double>(j) / fs - t0;
    x[j] += a * std::exp(-zeta * wn * t) * std::sin(wd * t);
  }
}

// Impact times at mean rate rate_hz (already slipped) with cumulative interval jitter, starting
// at a random phase within the first interval.
std::vector<double> impact_times(double rate_hz, double jitter, double duration_s,
                                 std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double period = 1.0 / rate_hz;
  std::vector<double> t;
  for (double tk = u(rng) * period; tk < duration_s;
       tk += period * std::max(0.1, 1 + jitter * g(rng)))
    t.push_back(tk);
  return t;
}

}  // namespace

diag::FaultKind fault_kind(BearingFaultKind k) {
  switch (k) {
    case BearingFaultKind::kOuterRace:
      return diag::FaultKind::kOuterRace;
    case BearingFaultKind::kInnerRace:
      return diag::FaultKind::kInnerRace;
    case BearingFaultKind::kRollingElement:
      return diag::FaultKind::kRollingElement;
    case BearingFaultKind::kCage:
      return diag::FaultKind::kCage;
    case BearingFaultKind::kNone:
      break;
  }
  return diag::FaultKind::kNone;
}

const char* to_string(BearingFaultKind k) { return diag::to_string(fault_kind(k)).data(); }

std::optional<BearingFaultKind> bearing_fault_kind(std::string_view name) {
  const std::optional<diag::FaultKind> k = diag::fault_kind_from_string(name);
  for (BearingFaultKind b : {BearingFaultKind::kOuterRace, BearingFaultKind::kInnerRace,
                             BearingFaultKind::kRollingElement, BearingFaultKind::kCage}) {
    if (k && fault_kind(b) == *k) return b;
  }
  return std::nullopt;
}

void BearingSignalOptions::validate() const {
  diag::require(std::isfinite(fs_hz) && fs_hz > 0, kWhere, "fs_hz", "must be finite and > 0");
  diag::require(duration_s > 0 && duration_s <= 600, kWhere, "duration_s", "must be in (0, 600]");
  diag::require(std::isfinite(shaft_hz) && shaft_hz > 0, kWhere, "shaft_hz",
                "must be finite and > 0");
  diag::require(impact_amplitude > 0 && std::isfinite(impact_amplitude), kWhere, "impact_amplitude",
                "must be finite and > 0");
  diag::require(snr_db >= -60 && snr_db <= 60, kWhere, "snr_db", "must be in [-60, 60]");
  diag::require(resonance_hz > 0 && resonance_hz < 0.45 * fs_hz, kWhere, "resonance_hz",
                "must be in (0, 0.45 fs_hz)");
  diag::require(damping_ratio > 0 && damping_ratio <= 0.5, kWhere, "damping_ratio",
                "must be in (0, 0.5]");
  diag::require(mean_slip >= -0.05 && mean_slip <= 0.05, kWhere, "mean_slip",
                "must be in [-0.05, 0.05]");
  diag::require(jitter >= 0 && jitter <= 0.1, kWhere, "jitter", "must be in [0, 0.1]");
  diag::require(load_zone_factor > 0 && load_zone_factor <= 1, kWhere, "load_zone_factor",
                "must be in (0, 1]");
  diag::require(std::isfinite(defect_angle_rad), kWhere, "defect_angle_rad", "must be finite");
  diag::require(inner_strike_gain >= 0 && inner_strike_gain <= 1, kWhere, "inner_strike_gain",
                "must be in [0, 1]");
  diag::require(ball_track_probability >= 0 && ball_track_probability <= 1, kWhere,
                "ball_track_probability", "must be in [0, 1]");
  diag::require(shaft_amplitude >= 0 && std::isfinite(shaft_amplitude), kWhere, "shaft_amplitude",
                "must be finite and >= 0");
  diag::require(mesh_hz >= 0 && mesh_hz < 0.5 * fs_hz, kWhere, "mesh_hz",
                "must be in [0, fs_hz / 2)");
  diag::require(mesh_amplitude >= 0 && std::isfinite(mesh_amplitude), kWhere, "mesh_amplitude",
                "must be finite and >= 0");
}

std::vector<double> bearing_fault_samples(const diag::BearingSpec& bearing,
                                          const BearingSignalOptions& opt, int& impacts) {
  opt.validate();
  const BearingRates r = diag::bearing_rates(bearing, opt.shaft_hz, kWhere);
  const double fs = opt.fs_hz;
  const auto n = static_cast<std::size_t>(std::llround(opt.duration_s * fs));
  diag::require(n >= 16, kWhere, "duration_s", "gives fewer than 16 samples");
  const double wn = kTwoPi * opt.resonance_hz, zeta = opt.damping_ratio;
  const double slip = 1 - opt.mean_slip;
  const double eps = opt.load_zone_factor, a = opt.impact_amplitude;

  // Independent streams per purpose, so that changing e.g. the noise does not move the impacts
  // (simulate_bearing_signal draws the noise and the interference's phases from the others).
  std::mt19937_64 rng_impacts(opt.seed * 4 + 0), rng_phase(opt.seed * 4 + 1),
      rng_track(opt.seed * 4 + 3);
  std::uniform_real_distribution<double> uphase(0.0, kTwoPi);
  const double phi0 = uphase(rng_phase);  // defect's angle at t = 0 (inner race, ball, cage)

  impacts = 0;
  std::vector<double> fault(n, 0.0);
  switch (opt.fault) {
    case BearingFaultKind::kNone:
      break;
    case BearingFaultKind::kOuterRace: {
      const double q = load(opt.defect_angle_rad, eps);
      for (double t : impact_times(r.bpfo_hz * slip, opt.jitter, opt.duration_s, rng_impacts)) {
        add_ring(fault, fs, t, a * q, wn, zeta);
        ++impacts;
      }
      break;
    }
    case BearingFaultKind::kInnerRace: {
      const double fr = r.shaft_hz;  // the inner race turns with the shaft: no slip
      for (double t : impact_times(r.bpfi_hz * slip, opt.jitter, opt.duration_s, rng_impacts)) {
        add_ring(fault, fs, t, a * load(kTwoPi * fr * t + phi0, eps), wn, zeta);
        ++impacts;
      }
      break;
    }
    case BearingFaultKind::kRollingElement: {
      const double fc = r.ftf_hz * slip;
      std::bernoulli_distribution in_track(opt.ball_track_probability);
      std::vector<char> track;  // per cage revolution
      const auto revs = static_cast<std::size_t>(std::ceil(opt.duration_s * fc)) + 2;
      for (std::size_t k = 0; k < revs; ++k) track.push_back(in_track(rng_track) ? 1 : 0);
      const double phase_rev = phi0 / kTwoPi;
      int strike = 0;  // even: outer race, odd: inner race
      for (double t :
           impact_times(r.ball_fault_hz * slip, opt.jitter, opt.duration_s, rng_impacts)) {
        // The ball enters the load zone (theta = -pi) once per cage revolution.
        const double rev = fc * t + phase_rev + 0.5;
        const auto k = static_cast<std::size_t>(std::max(0.0, std::floor(rev)));
        const double g = (strike++ % 2 == 0) ? 1.0 : opt.inner_strike_gain;
        if (!track[std::min(k, track.size() - 1)]) continue;
        add_ring(fault, fs, t, a * g * load(kTwoPi * fc * t + phi0, eps), wn, zeta);
        ++impacts;
      }
      break;
    }
    case BearingFaultKind::kCage: {
      // Noise-driven resonance: an impact of random amplitude at every sample (a discretised
      // white-noise force), modulated by the pocket's load. Equivalent to filtering modulated
      // white noise through h; done as a recursive two-pole resonator for speed.
      std::normal_distribution<double> g(0.0, 1.0);
      const double fc = r.ftf_hz * slip;
      const double rr = std::exp(-zeta * wn / fs);
      const double wd = wn * std::sqrt(1 - zeta * zeta) / fs;
      const double c1 = 2 * rr * std::cos(wd), c2 = -rr * rr;
      double y1 = 0, y2 = 0;
      for (std::size_t j = 0; j < n; ++j) {
        const double t = static_cast<double>(j) / fs;
        const double u = a * load(kTwoPi * fc * t + phi0, eps) * g(rng_impacts);
        const double y = c1 * y1 + c2 * y2 + u * std::sin(wd);
        y2 = y1;
        y1 = y;
        fault[j] = y;
      }
      break;
    }
  }
  return fault;
}

BearingSignal simulate_bearing_signal(const diag::BearingSpec& bearing,
                                      const BearingSignalOptions& opt) {
  BearingSignal out;
  const std::vector<double> fault = bearing_fault_samples(bearing, opt, out.impacts);
  out.rates = diag::bearing_rates(bearing, opt.shaft_hz, kWhere);
  const BearingRates& r = out.rates;
  const double fs = opt.fs_hz;
  const std::size_t n = fault.size();
  const double wn = kTwoPi * opt.resonance_hz, zeta = opt.damping_ratio;
  const double slip = 1 - opt.mean_slip;
  const double a = opt.impact_amplitude;
  std::mt19937_64 rng_phase(opt.seed * 4 + 1), rng_noise(opt.seed * 4 + 2);
  std::uniform_real_distribution<double> uphase(0.0, kTwoPi);
  uphase(rng_phase);  // the defect's phase, drawn by bearing_fault_samples

  double p_fault = 0;
  for (double v : fault) p_fault += v * v;
  p_fault /= static_cast<double>(n);
  out.fault_rms = std::sqrt(p_fault);
  const double p_ref =
      opt.fault == BearingFaultKind::kNone ? a * a * r.bpfo_hz * slip / (4 * zeta * wn) : p_fault;
  out.noise_rms = std::sqrt(p_ref / std::pow(10.0, opt.snr_db / 10));

  std::normal_distribution<double> noise(0.0, out.noise_rms);
  const double ph_shaft = uphase(rng_phase), ph_mesh = uphase(rng_phase);
  std::vector<double> x(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double t = static_cast<double>(j) / fs;
    double v = fault[j] + noise(rng_noise);
    if (opt.shaft_amplitude > 0)
      for (int h = 1; h <= 5; ++h)
        v += opt.shaft_amplitude / h * std::sin(kTwoPi * h * r.shaft_hz * t + h * ph_shaft);
    if (opt.mesh_amplitude > 0 && opt.mesh_hz > 0) {
      const double am = 1 + 0.3 * std::cos(kTwoPi * r.shaft_hz * t);
      for (int h = 1; h <= 3 && h * opt.mesh_hz < 0.5 * fs; ++h)
        v += opt.mesh_amplitude / h * am * std::sin(kTwoPi * h * opt.mesh_hz * t + h * ph_mesh);
    }
    x[j] = v;
  }

  out.signal.name = "acc";
  out.signal.fs_hz = fs;
  out.signal.unit = "m/s^2";
  out.signal.location = bearing.name;
  out.signal.samples = std::move(x);
  diag::SimulationTruth truth;  // diag/io/truth.hpp
  truth.kind = "bearing";
  if (opt.fault != BearingFaultKind::kNone) {
    diag::TruthDefect d;
    d.kind = fault_kind(opt.fault);
    d.bearing = bearing.name;
    truth.defects.push_back(std::move(d));
  }
  truth.extra = {{"bearing", bearing.name},
                 {"rates",
                  {{"shaft_hz", r.shaft_hz},
                   {"cage_hz", r.ftf_hz},
                   {"bpfo_hz", r.bpfo_hz},
                   {"bpfi_hz", r.bpfi_hz},
                   {"spin_hz", r.bsf_hz},
                   {"ball_fault_hz", r.ball_fault_hz}}},
                 {"impacts", out.impacts},
                 {"fault_rms", out.fault_rms},
                 {"noise_rms", out.noise_rms},
                 {"snr_db", opt.snr_db},
                 {"impact_amplitude", a},
                 {"mean_slip", opt.mean_slip},
                 {"jitter", opt.jitter},
                 {"resonance_hz", opt.resonance_hz},
                 {"seed", opt.seed}};
  out.truth = truth.to_json();
  return out;
}

}  // namespace sim
