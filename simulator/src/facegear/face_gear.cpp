#include "sim/facegear/face_gear.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <numbers>

#include "diag/error.hpp"

namespace sim::facegear {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Position of `a` (in [0, period)) in the periodic grid: lower index, upper index, weight.
struct Bracket {
  std::size_t i0, i1;
  double w;
};

Bracket bracket_angle(const std::vector<double>& grid, double a, double period) {
  const std::size_t n = grid.size();
  if (n == 1) return {0, 0, 0.0};
  auto it = std::upper_bound(grid.begin(), grid.end(), a);
  if (it == grid.begin() || it == grid.end()) {
    // Across the period end: from the last point to the first + period.
    const double x0 = grid.back();
    const double x1 = grid.front() + period;
    const double aa = (a < grid.front()) ? a + period : a;
    return {n - 1, 0, (aa - x0) / (x1 - x0)};
  }
  const std::size_t i1 = static_cast<std::size_t>(it - grid.begin());
  const std::size_t i0 = i1 - 1;
  return {i0, i1, (a - grid[i0]) / (grid[i1] - grid[i0])};
}

double wrap(double angle, double period) {
  double a = std::fmod(angle, period);
  if (a < 0) a += period;
  return a;
}

}  // namespace

double FlankTable::stiffness(double a, double load, double period) const {
  const Bracket ba = bracket_angle(angle_rad, a, period);
  const std::size_t nl = load_nm.size();
  std::size_t l0 = 0, l1 = 0;
  double wl = 0.0;
  if (nl > 1 && load > load_nm.front()) {
    if (load >= load_nm.back()) {
      l0 = l1 = nl - 1;  // constant extrapolation above the table
    } else {
      l1 = static_cast<std::size_t>(std::upper_bound(load_nm.begin(), load_nm.end(), load) -
                                    load_nm.begin());
      l0 = l1 - 1;
      wl = (load - load_nm[l0]) / (load_nm[l1] - load_nm[l0]);
    }
  }
  auto at = [&](std::size_t ia) { return (1.0 - wl) * k[ia * nl + l0] + wl * k[ia * nl + l1]; };
  return (1.0 - ba.w) * at(ba.i0) + ba.w * at(ba.i1);
}

FlankTable::Elastic FlankTable::elastic_torque(double a, double d, double period,
                                               double scale) const {
  Elastic out;
  const Bracket ba = bracket_angle(angle_rad, a, period);
  const std::size_t nl = load_nm.size();
  auto k_at = [&](std::size_t il) {
    return scale * ((1.0 - ba.w) * k[ba.i0 * nl + il] + ba.w * k[ba.i1 * nl + il]);
  };
  if (!(d > 0)) {
    out.k = k_at(0);
    return out;
  }
  // Below the first grid load and above the last the row is constant: T = k d.
  if (nl == 1 || k_at(0) * d <= load_nm.front()) {
    out.k = k_at(0);
  } else if (k_at(nl - 1) * d >= load_nm.back()) {
    out.k = k_at(nl - 1);
  } else {
    // The segment [T_i, T_i+1] whose deflections T / k(T) bracket d; within it k = a + s T, so
    // T = a d / (1 - s d) (exact for the linear interpolation between the grid loads).
    std::size_t i = 0;
    while (i + 2 < nl && load_nm[i + 1] / k_at(i + 1) < d) ++i;
    const double k0 = k_at(i), k1 = k_at(i + 1);
    const double slope = (k1 - k0) / (load_nm[i + 1] - load_nm[i]);
    const double intercept = k0 - slope * load_nm[i];
    const double t = intercept * d / (1.0 - slope * d);
    out.k = k0 + slope * (t - load_nm[i]);
    out.torque = t;
    return out;
  }
  out.torque = out.k * d;
  return out;
}

double FlankTable::e0(double a, double period) const {
  const Bracket ba = bracket_angle(angle_rad, a, period);
  return (1.0 - ba.w) * e0_rad[ba.i0] + ba.w * e0_rad[ba.i1];
}

void FlankTable::validate(const std::string& where, const std::string& field, double period) const {
  if (angle_rad.empty()) diag::fail(where, field + ".angle", "the table has no angles");
  if (load_nm.empty()) diag::fail(where, field + ".load_nm", "the table has no loads");
  for (std::size_t i = 0; i < angle_rad.size(); ++i) {
    const double a = angle_rad[i];
    if (!std::isfinite(a) || a < 0 || a >= period) {
      diag::fail(where, field + ".angle",
                 "angle " + std::to_string(a) + " rad is outside one mesh period [0, " +
                     std::to_string(period) + ")");
    }
    if (i > 0 && !(a > angle_rad[i - 1])) {
      diag::fail(where, field + ".angle",
                 "angles must be strictly increasing (entry " + std::to_string(i) + ")");
    }
  }
  for (std::size_t i = 0; i < load_nm.size(); ++i) {
    if (!std::isfinite(load_nm[i]) || load_nm[i] < 0) {
      diag::fail(where, field + ".load_nm", "loads must be finite and >= 0");
    }
    if (i > 0 && !(load_nm[i] > load_nm[i - 1])) {
      diag::fail(where, field + ".load_nm", "loads must be strictly increasing");
    }
  }
  if (k.size() != angle_rad.size() * load_nm.size()) {
    diag::fail(where, field + ".stiffness",
               "the grid is incomplete: " + std::to_string(k.size()) + " values for " +
                   std::to_string(angle_rad.size()) + " angles x " +
                   std::to_string(load_nm.size()) + " loads");
  }
  for (double v : k) {
    if (!std::isfinite(v) || !(v > 0)) {
      diag::fail(where, field + ".stiffness",
                 "stiffness must be finite and > 0 (got " + std::to_string(v) + ")");
    }
  }
  if (e0_rad.size() != angle_rad.size()) {
    diag::fail(where, field + ".e0", "one static TE value per angle is needed");
  }
  for (double v : e0_rad) {
    if (!std::isfinite(v)) diag::fail(where, field + ".e0", "static TE must be finite");
  }
}

double FaceGearPair::mesh_period_rad() const { return kTwoPi / pinion_teeth; }

double FaceGearPair::reduced_inertia() const {
  const double r = ratio();
  return 1.0 / (1.0 / (r * inertia_g) + r / inertia_p);
}

double FaceGearPair::mean_stiffness(double load_nm) const {
  double s = 0.0;
  for (double a : drive.angle_rad) s += drive.stiffness(a, load_nm, mesh_period_rad());
  return stiffness_scale * s / static_cast<double>(drive.angle_rad.size());
}

double FaceGearPair::mean_tangent_stiffness(double load_nm) const {
  // dT/dd by a central difference of the consistent elastic torque about the deflection that
  // carries load_nm at each angle.
  double s = 0.0;
  const double period = mesh_period_rad();
  for (double a : drive.angle_rad) {
    const double d = load_nm / (stiffness_scale * drive.stiffness(a, load_nm, period));
    const double h = 1e-4 * d;
    s += (drive.elastic_torque(a, d + h, period, stiffness_scale).torque -
          drive.elastic_torque(a, d - h, period, stiffness_scale).torque) /
         (2.0 * h);
  }
  return s / static_cast<double>(drive.angle_rad.size());
}

double FaceGearPair::natural_frequency_hz(double load_nm) const {
  return std::sqrt(mean_tangent_stiffness(load_nm) / reduced_inertia()) / kTwoPi;
}

Model::Model(const FaceGearPair& pair, const Operating& op) : pair_(pair), op_(op) {
  r_ = pair.ratio();
  period_ = pair.mesh_period_rad();
  omega_ = op.speed_rpm * kTwoPi / 60.0;
  t_static_ = op.torque_nm - pair.bearing_damping_p * omega_;
  t_load0_ = t_static_ / r_ - pair.bearing_damping_g * r_ * omega_;
  i_e_ = pair.reduced_inertia();
}

double Model::mesh_frequency_hz() const { return op_.speed_rpm / 60.0 * pair_.pinion_teeth; }

double Model::input_torque(double t) const {
  return op_.torque_nm *
         (1.0 + op_.input_amp * std::cos(kTwoPi * op_.input_freq_hz * t + op_.input_phase_rad));
}

double Model::load_torque(double t) const {
  return t_load0_ *
         (1.0 + op_.load_amp * std::cos(kTwoPi * op_.load_freq_hz * t + op_.load_phase_rad));
}

double Model::switching(const double* y, Contact c) const {
  const double a = wrap(y[0], period_);
  const double rb = r_ * pair_.half_backlash_rad;
  const double dd = -(y[2] - pair_.drive.e0(a, period_)) - rb;
  if (c == Contact::kDrive) return dd;
  const double dc = (y[2] - pair_.coast.e0(a, period_)) - rb;
  if (c == Contact::kCoast) return dc;
  return std::max(dd, dc);
}

Contact Model::contact(const double* y) const {
  if (switching(y, Contact::kDrive) >= 0) return Contact::kDrive;
  if (switching(y, Contact::kCoast) >= 0) return Contact::kCoast;
  return Contact::kFree;
}

Model::Mesh Model::mesh(double /*t*/, const double* y, Contact c) const {
  Mesh m;
  m.contact = c;
  const double a = wrap(y[0], period_);
  if (c == Contact::kFree) {
    m.e0 = pair_.drive.e0(a, period_);
    return m;
  }
  const FlankTable& tab = (c == Contact::kDrive) ? pair_.drive : pair_.coast;
  const double sign = (c == Contact::kDrive) ? -1.0 : 1.0;
  const double e0 = tab.e0(a, period_);
  // de0/dtheta_p by the table's local slope (central difference over a small angle).
  const double da = 1e-6 * period_;
  const double de0 =
      (tab.e0(wrap(a + da, period_), period_) - tab.e0(wrap(a - da + period_, period_), period_)) /
      (2.0 * da);
  const double d = sign * (y[2] - e0) - r_ * pair_.half_backlash_rad;
  // d' = sign * (e' - e0' omega_p), e' = omega_g - r omega_p.
  const double ddot = sign * ((y[3] - r_ * y[1]) - de0 * y[1]);
  const FlankTable::Elastic el = tab.elastic_torque(a, d, period_, pair_.stiffness_scale);
  const double c_mesh = pair_.damping_alpha * i_e_ + pair_.damping_beta * el.k;
  const double push = el.torque + c_mesh * ddot;
  m.deflection = d;
  m.deflection_rate = ddot;
  m.k = el.k;
  m.e0 = e0;
  m.clamped = push < 0;
  m.torque = -sign * std::max(0.0, push);
  return m;
}

void Model::derivatives(double t, const double* y, double* dydt, Contact c) const {
  const Mesh m = mesh(t, y, c);
  dydt[0] = y[1];
  dydt[1] = (input_torque(t) - m.torque - pair_.bearing_damping_p * y[1]) / pair_.inertia_p;
  dydt[2] = y[3] - r_ * y[1];
  dydt[3] = (m.torque / r_ - load_torque(t) - pair_.bearing_damping_g * y[3]) / pair_.inertia_g;
}

std::array<double, 4> Model::initial_state() const {
  const double k = pair_.stiffness_scale * pair_.drive.stiffness(0.0, t_static_, period_);
  const double d = std::max(t_static_, 0.0) / k;  // the secant k at T_static: T(d) = T_static
  const double e = pair_.drive.e0(0.0, period_) - r_ * pair_.half_backlash_rad - d;
  return {0.0, omega_, e, r_ * omega_};
}

void RunOptions::validate() const {
  if (steps_per_period < 8 || steps_per_period > 100000) {
    throw diag::InputError("face-gear run: steps_per_period must be in [8, 100000]");
  }
  if (transient_periods < 0 || record_periods < 1 || decimation < 1) {
    throw diag::InputError(
        "face-gear run: transient_periods >= 0, record_periods >= 1 and decimation >= 1 needed");
  }
  if (!(rel_tol > 0) || !(abs_tol > 0)) {
    throw diag::InputError("face-gear run: tolerances must be > 0");
  }
}

void rk4_step(const Model& model, double t, double h, double* y) {
  double k1[4], k2[4], k3[4], k4[4], tmp[4];
  model.derivatives(t, y, k1);
  for (int i = 0; i < 4; ++i) tmp[i] = y[i] + 0.5 * h * k1[i];
  model.derivatives(t + 0.5 * h, tmp, k2);
  for (int i = 0; i < 4; ++i) tmp[i] = y[i] + 0.5 * h * k2[i];
  model.derivatives(t + 0.5 * h, tmp, k3);
  for (int i = 0; i < 4; ++i) tmp[i] = y[i] + h * k3[i];
  model.derivatives(t + h, tmp, k4);
  for (int i = 0; i < 4; ++i) y[i] += h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
}

namespace {

// GSL odeiv2 with the contact state held fixed within each step and its switches located by
// bisection on the step length (the switching function of Model::switching changes sign).
class AdaptiveStepper {
 public:
  AdaptiveStepper(const Model& model, double rel_tol, double abs_tol, double h0)
      : model_(model), h_(h0) {
    sys_ = gsl_odeiv2_system{&AdaptiveStepper::rhs, nullptr, 4, this};
    step_.reset(gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, 4));
    control_.reset(gsl_odeiv2_control_y_new(abs_tol, rel_tol));
    evolve_.reset(gsl_odeiv2_evolve_alloc(4));
  }

  // Advances y from t to t1, locating every contact switch; returns the switches.
  int advance(double& t, double t1, double* y) {
    int events = 0;
    mode_ = model_.contact(y);
    while (t < t1) {
      double y0[4];
      std::copy(y, y + 4, y0);
      const double t0 = t;
      const int status = gsl_odeiv2_evolve_apply(evolve_.get(), control_.get(), step_.get(), &sys_,
                                                 &t, t1, &h_, y);
      if (status != GSL_SUCCESS) {
        throw std::runtime_error("face-gear adaptive integrator failed: " +
                                 std::string(gsl_strerror(status)));
      }
      if (!left(y)) continue;
      // Bisection on the step length for the first sign change (to 1e-13 of the mesh period).
      double lo = 0.0, hi = t - t0, yt[4], yerr[4];
      const double resolution = 1e-13 / model_.mesh_frequency_hz();
      while (hi - lo > resolution) {
        const double mid = 0.5 * (lo + hi);
        std::copy(y0, y0 + 4, yt);
        gsl_odeiv2_step_reset(step_.get());
        gsl_odeiv2_step_apply(step_.get(), t0, mid, yt, yerr, nullptr, nullptr, &sys_);
        (left(yt) ? hi : lo) = mid;
      }
      std::copy(y0, y0 + 4, y);
      gsl_odeiv2_step_reset(step_.get());
      gsl_odeiv2_step_apply(step_.get(), t0, hi, y, yerr, nullptr, nullptr, &sys_);
      t = t0 + hi;
      mode_ = model_.contact(y);
      gsl_odeiv2_evolve_reset(evolve_.get());
      ++events;
    }
    return events;
  }

 private:
  bool left(const double* y) const {
    const double g = model_.switching(y, mode_);
    return mode_ == Contact::kFree ? g >= 0 : g < 0;
  }
  static int rhs(double t, const double y[], double dydt[], void* self) {
    const auto* me = static_cast<const AdaptiveStepper*>(self);
    me->model_.derivatives(t, y, dydt, me->mode_);
    return GSL_SUCCESS;
  }
  struct StepFree {
    void operator()(gsl_odeiv2_step* p) const { gsl_odeiv2_step_free(p); }
  };
  struct ControlFree {
    void operator()(gsl_odeiv2_control* p) const { gsl_odeiv2_control_free(p); }
  };
  struct EvolveFree {
    void operator()(gsl_odeiv2_evolve* p) const { gsl_odeiv2_evolve_free(p); }
  };

  const Model& model_;
  Contact mode_ = Contact::kDrive;
  double h_;
  gsl_odeiv2_system sys_{};
  std::unique_ptr<gsl_odeiv2_step, StepFree> step_;
  std::unique_ptr<gsl_odeiv2_control, ControlFree> control_;
  std::unique_ptr<gsl_odeiv2_evolve, EvolveFree> evolve_;
};

}  // namespace

Trace run(const Model& model, const RunOptions& opt) {
  opt.validate();
  Trace tr;
  const double t_mesh = 1.0 / model.mesh_frequency_hz();
  const int n = opt.steps_per_period;
  const double h = t_mesh / n;
  tr.dt = h * opt.decimation;
  std::array<double, 4> ys = opt.has_start ? opt.start : model.initial_state();
  double* y = ys.data();
  std::unique_ptr<AdaptiveStepper> adaptive;
  if (opt.integrator == Integrator::kAdaptive) {
    adaptive = std::make_unique<AdaptiveStepper>(model, opt.rel_tol, opt.abs_tol, h);
  }
  const double r = model.pair().ratio();
  Contact last = model.contact(y);
  const long total = static_cast<long>(opt.transient_periods + opt.record_periods) * n;
  const long first_recorded = static_cast<long>(opt.transient_periods) * n;
  if (opt.keep_trace) {
    const std::size_t cap = static_cast<std::size_t>(opt.record_periods) * n / opt.decimation + 1;
    for (auto* v :
         {&tr.t, &tr.dte, &tr.mesh_torque, &tr.stiffness, &tr.theta_p, &tr.theta_g, &tr.dte_rate}) {
      v->reserve(cap);
    }
    tr.contact.reserve(cap);
  }
  // The GMF / 2 and GMF components of the DTE (half_gmf_ratio): the DTE less its first recorded
  // value (a constant has no component at these frequencies over whole periods; removing most of
  // it keeps the rounding of the sums at the level of the dynamic part).
  const long spectral_steps = 2L * (opt.record_periods / 2) * n;
  std::complex<double> sum_half{}, sum_gmf{};
  double dte_ref = 0.0, sum_torque = 0.0;
  double t = 0.0;
  for (long i = 0; i <= total; ++i) {
    // The step index sets the time (no accumulated rounding): t = i h.
    const double ti = static_cast<double>(i) * h;
    if (i >= first_recorded) {
      const Model::Mesh m = model.mesh(ti, y);
      if ((i - first_recorded) % n == 0 && i < total) tr.poincare.push_back(y[2]);
      tr.max_abs_mesh_torque = std::max(tr.max_abs_mesh_torque, std::abs(m.torque));
      if (i < total) sum_torque += m.torque;
      if (opt.integrator == Integrator::kRk4 && m.contact != last) ++tr.events;
      last = m.contact;
      ++tr.contact_steps[static_cast<int>(m.contact) + 1];
      if (i == first_recorded) tr.dte_min = tr.dte_max = dte_ref = y[2];
      if (const long k = i - first_recorded; k < spectral_steps) {
        // Phase of GMF / 2 at step k: pi k / n, taken modulo its period of 2 n steps.
        const std::complex<double> e =
            std::polar(1.0, -std::numbers::pi * static_cast<double>(k % (2L * n)) / n);
        sum_half += (y[2] - dte_ref) * e;
        sum_gmf += (y[2] - dte_ref) * e * e;
      }
      tr.dte_min = std::min(tr.dte_min, y[2]);
      tr.dte_max = std::max(tr.dte_max, y[2]);
      if (opt.keep_trace && (i - first_recorded) % opt.decimation == 0) {
        tr.t.push_back(ti);
        tr.dte.push_back(y[2]);
        tr.dte_rate.push_back(y[3] - r * y[1]);
        tr.mesh_torque.push_back(m.torque);
        tr.stiffness.push_back(m.k);
        tr.theta_p.push_back(y[0]);
        tr.theta_g.push_back(y[2] + r * y[0]);
        tr.contact.push_back(static_cast<int>(m.contact));
      }
    }
    if (i == total) break;
    if (adaptive) {
      t = ti;
      const int ev = adaptive->advance(t, ti + h, y);
      if (i >= first_recorded) tr.events += ev;
    } else {
      rk4_step(model, ti, h, y);
    }
    if (!std::isfinite(y[2]) || !std::isfinite(y[1])) {
      throw diag::InputError(
          "face-gear simulation diverged (check the stiffness tables, inertias and damping)");
    }
  }
  tr.final_state = ys;
  tr.mean_mesh_torque = sum_torque / static_cast<double>(total - first_recorded);
  tr.period_rel_tol = poincare_rel_tol(opt, tr.dte_max - tr.dte_min,
                                       std::max(std::abs(tr.dte_min), std::abs(tr.dte_max)));
  if (spectral_steps > 0 && std::abs(sum_gmf) > 0) {
    tr.half_gmf_ratio = std::abs(sum_half) / std::abs(sum_gmf);
  }
  return tr;
}

int rk4_steps_per_period(const Model& model, int min_steps) {
  double k_max = 0.0;
  for (const FlankTable* t : {&model.pair().drive, &model.pair().coast}) {
    for (double k : t->k) k_max = std::max(k_max, k);
  }
  const double f_max =
      std::sqrt(model.pair().stiffness_scale * k_max / model.pair().reduced_inertia()) / kTwoPi;
  const double n = std::ceil(32.0 * f_max / model.mesh_frequency_hz());
  return static_cast<int>(std::min(100000.0, std::max<double>(min_steps, n)));
}

const char* to_string(ImpactClass c) {
  switch (c) {
    case ImpactClass::kNoImpact:
      return "no impact";
    case ImpactClass::kSingleSided:
      return "single-sided impact";
    case ImpactClass::kDoubleSided:
      return "double-sided impact";
  }
  return "?";
}

ImpactClass classify_impacts(const std::vector<int>& contact) {
  std::array<long, 3> n{};
  for (int c : contact) {
    if (c >= -1 && c <= 1) ++n[c + 1];
  }
  return classify_impacts(n);
}

ImpactClass classify_impacts(const std::array<long, 3>& n) {
  if (n[0] > 0 && n[2] > 0) return ImpactClass::kDoubleSided;
  return (n[0] > 0 || n[1] > 0) ? ImpactClass::kSingleSided : ImpactClass::kNoImpact;
}

int poincare_period(const std::vector<double>& p, double scale, double rel_tol, int max_period) {
  if (p.size() < static_cast<std::size_t>(2 * max_period + 2)) {
    throw diag::InputError("poincare_period: needs at least 2 max_period + 2 points");
  }
  const double tol = rel_tol * scale;
  for (int n = 1; n <= max_period; ++n) {
    bool ok = true;
    for (std::size_t i = 0; i + n < p.size() && ok; ++i) ok = std::abs(p[i] - p[i + n]) <= tol;
    if (ok) return n;
  }
  return 0;
}

double poincare_rel_tol(const RunOptions& opt, double scale, double max_abs_dte) {
  if (opt.integrator == Integrator::kRk4) return 1e-3;
  if (!(scale > 0)) return 1e-4;
  return std::max(1e-4, 1e4 * (opt.abs_tol + opt.rel_tol * max_abs_dte) / scale);
}

std::string classify_period(const std::vector<double>& points, double scale, double rel_tol) {
  const int n = poincare_period(points, scale, rel_tol);
  if (n == 0) return "chaos";
  if (n <= 2) return "period-" + std::to_string(n);
  return "period-n";
}

std::string classify_period(const Trace& trace) {
  return classify_period(trace.poincare, trace.dte_max - trace.dte_min, trace.period_rel_tol);
}

double amplitude_at(const std::vector<double>& x, double fs, double f) {
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double re = 0.0, im = 0.0;
  const double w = kTwoPi * f / fs;
  for (std::size_t i = 0; i < x.size(); ++i) {
    re += (x[i] - mean) * std::cos(w * static_cast<double>(i));
    im += (x[i] - mean) * std::sin(w * static_cast<double>(i));
  }
  return 2.0 * std::hypot(re, im) / static_cast<double>(x.size());
}

std::vector<std::array<double, 2>> amplitude_spectrum(const std::vector<double>& x, double fs,
                                                      double f_max) {
  std::vector<std::array<double, 2>> out;
  const double df = fs / static_cast<double>(x.size());
  for (std::size_t k = 1; k * df <= std::min(f_max, fs / 2); ++k) {
    out.push_back({k * df, amplitude_at(x, fs, k * df)});
  }
  return out;
}

}  // namespace sim::facegear
