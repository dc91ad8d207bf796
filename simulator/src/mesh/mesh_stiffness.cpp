#include "sim/mesh/mesh_stiffness.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>

#include "diag/error.hpp"
#include "diag/geometry/profile.hpp"
#include "diag/units.hpp"

namespace sim {

diag::FaultKind fault_kind(ToothFault::Kind k) {
  switch (k) {
    case ToothFault::Kind::kChip:
      return diag::FaultKind::kChip;
    case ToothFault::Kind::kMissing:
      return diag::FaultKind::kMissing;
    case ToothFault::Kind::kSpall:
      return diag::FaultKind::kSpall;
    case ToothFault::Kind::kRootCrack:
      break;
  }
  return diag::FaultKind::kCrack;
}

namespace {

using diag::format_error;
using diag::InputError;

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();

template <class T>
std::string fail_value(T value, const std::string& range) {
  std::ostringstream m;
  m << "must be " << range << " (got " << value << ")";
  return m.str();
}

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n from the Tricomi starting values).
struct GaussLegendre {
  static constexpr int kN = 16;  // exact for polynomials of degree 31 on each panel
  std::array<double, kN> x{}, w{};
  GaussLegendre() {
    for (int i = 0; i < kN; ++i) {
      double z = std::cos(kPi * (i + 0.75) / (kN + 0.5));
      double dp = 1;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1, p1 = z;
        for (int k = 2; k <= kN; ++k) {
          const double p2 = ((2.0 * k - 1) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = kN * (z * p1 - p0) / (z * z - 1);
        const double step = p1 / dp;
        z -= step;
        if (std::abs(step) < 1e-16) break;
      }
      x[i] = z;
      w[i] = 2.0 / ((1 - z * z) * dp * dp);
    }
  }
};
const GaussLegendre& gauss() {
  static const GaussLegendre g;
  return g;
}

// One tooth as a cantilever (see the header). y: along the centre line from the gear centre;
constexpr double kMinBoreRadiusRatio = 0.2;  // h_fi <= 5 (see Tooth)

// h: half thickness; t = rho / r_b the roll parameter of an involute point.
struct Tooth {
  double rb, rf, ra, alpha2, E, G, b;
  double t_lo;    // roll parameter where the involute part of the beam starts
  bool has_rect;  // r_f < r_b: straight part at h = h_b from y_f to y_b
  double h_b, y_f, y_b;
  double y_root, h_root;  // beam root (crack start) on the loaded flank
  double y_tip;           // centre of the top land
  double theta_f, hfi;    // Sainsot's half tooth angle at the root circle, r_f / r_int
  double rho_tip;
  // Generated section (StiffnessOptions::tooth_section): the beam from y_f up to the form
  // radius as Gauss nodes (y, h, weight dy) with h = min(model h, generated h); t_lo then starts
  // the involute part at the form radius. Empty otherwise.
  std::vector<std::array<double, 3>> tab;

  Tooth(const diag::Gear& g, const StiffnessOptions& o) {
    const diag::GearSpec& sp = g.spec();
    rb = g.base_radius_m();
    rf = g.root_radius_m();
    ra = g.tip_radius_m();
    const double a = sp.pressure_angle_rad;
    alpha2 = kPi / (2.0 * sp.teeth) + diag::involute(a) +
             2.0 * sp.profile_shift * std::tan(a) / sp.teeth;
    E = sp.material.youngs_modulus_pa;
    G = E / (2.0 * (1.0 + sp.material.poisson_ratio));
    b = sp.face_width_m;
    has_rect = rf < rb;
    h_b = rb * std::sin(alpha2);
    y_b = rb * std::cos(alpha2);
    if (has_rect) {
      t_lo = 0.0;
      y_f = std::sqrt(rf * rf - h_b * h_b);
      y_root = y_f;
      h_root = h_b;
      theta_f = std::asin(h_b / rf);
    } else {
      t_lo = std::sqrt(rf * rf / (rb * rb) - 1.0);
      y_f = y_b;
      y_root = y(t_lo);
      h_root = h(t_lo);
      theta_f = psi(t_lo);
    }
    y_tip = ra;
    // h_fi = r_f / r_int: the gear's bore when given (GearSpec::bore_diameter_m), else the
    // option's default ratio. A solid disc (bore 0) or a bore below 0.2 x the root diameter is
    // held at h_fi = 5: Sainsot's table is a fit over finite rims and its B h_fi^2 term grows
    // without bound as the bore closes (h_fi -> infinity at bore 0); 0.2 is the smallest ratio
    // checked here. The fit's trend in h_fi (the seed pair's mean stiffness falls from 20.6
    // N/(mm um) at ratio 0.5 to 13.5 at 0.2: a smaller bore, a softer mesh) is physical: the FE
    // body is clamped at the bore (the shaft) and lies in series with the teeth, so a thicker rim
    // is a longer, more compliant path; the compliance change is 0.62..0.68 of an annular disc's
    // torsion between the same radii (tests/simulator/bore_test.cpp), not a stiffening.
    const double ratio =
        sp.bore_diameter_m >= 0 ? sp.bore_diameter_m / (2 * rf) : o.bore_radius_ratio;
    hfi = 1.0 / std::max(ratio, kMinBoreRadiusRatio);
    rho_tip = std::sqrt(ra * ra - rb * rb);
    using TS = StiffnessOptions::ToothSection;
    if (o.tooth_section == TS::kProfile ||
        (o.tooth_section == TS::kProfileWhenUndercut && g.undercut())) {
      tabulate_generated(g);
    }
  }
  // The section below the form radius from the rack-generated flank (diag::generate_tooth): at
  // each height y the half thickness is the smaller of the model's (h_b below the base circle,
  // the involute above) and the generated tooth's (+inf below the generated outline's lowest
  // point, so the beam still starts at y_f on the root circle as in the model). The root
  // quantities (y_root, h_root, theta_f for Sainsot's fillet term) stay the model's.
  void tabulate_generated(const diag::Gear& g) {
    const diag::Flank fl = diag::generate_tooth(g).flank;
    const double r_form = std::max(g.form_radius_m(), rb);
    const double t_form = std::sqrt(r_form * r_form / (rb * rb) - 1.0);
    const double y_lo = has_rect ? y_f : y(t_lo), y_hi = y(t_form);
    // The generated outline as h(y): y = r cos(psi) rises with r on a rack-generated flank (a
    // vertex that would break that is skipped).
    std::vector<double> gy, gh;
    for (std::size_t i = 0; i < fl.radius_m.size(); ++i) {
      const double rr = fl.radius_m[i], ps = fl.half_angle_rad[i];
      if (!gy.empty() && rr * std::cos(ps) <= gy.back()) continue;  // keep y strictly increasing
      gy.push_back(rr * std::cos(ps));
      gh.push_back(rr * std::sin(ps));
    }
    auto h_gen = [&](double yy) {
      if (gy.empty() || yy < gy.front() || yy > gy.back()) return kInf;
      const auto it = std::upper_bound(gy.begin(), gy.end(), yy);
      const std::size_t k = std::clamp<std::size_t>(it - gy.begin(), 1, gy.size() - 1);
      const double u = (yy - gy[k - 1]) / (gy[k] - gy[k - 1]);
      return gh[k - 1] + u * (gh[k] - gh[k - 1]);
    };
    auto h_model = [&](double yy) {
      if (has_rect && yy <= y_b) return h_b;
      double lo = t_lo, hi = t_form;  // invert y(t) = yy on the involute: y rises with t there
      for (int it = 0; it < 60; ++it) (y(0.5 * (lo + hi)) < yy ? lo : hi) = 0.5 * (lo + hi);
      const double t = 0.5 * (lo + hi);
      return h(t);
    };
    // 96 panels of 16 Gauss nodes: the generated h(y) is piecewise linear on its vertices (the
    // fillet arc's 200 points), so the panels resolve it to well below the nm chords.
    constexpr int kTabPanels = 96;
    const GaussLegendre& gl = gauss();
    const double dy = (y_hi - y_lo) / kTabPanels;
    for (int p = 0; p < kTabPanels; ++p) {
      const double mid = y_lo + (p + 0.5) * dy;
      for (int k = 0; k < GaussLegendre::kN; ++k) {
        const double yy = mid + 0.5 * dy * gl.x[k];
        tab.push_back({yy, std::min(h_model(yy), h_gen(yy)), 0.5 * dy * gl.w[k]});
      }
    }
    t_lo = t_form;
  }
  double psi(double t) const { return alpha2 - (t - std::atan(t)); }
  double r(double t) const { return rb * std::sqrt(1.0 + t * t); }
  double y(double t) const { return r(t) * std::cos(psi(t)); }
  double h(double t) const { return r(t) * std::sin(psi(t)); }
  double dy_dt(double t) const {
    const double p = psi(t);
    return (std::cos(p) + t * std::sin(p)) * rb * t / std::sqrt(1.0 + t * t);
  }
};

// Effective upper edge of the section on the loaded side for a crack whose tip is at h_q
// (no crack: h_q = +inf).
double effective_edge(const Tooth& T, double h, double y, double h_q) {
  if (h_q >= 0) return std::min(h, h_q);
  return h_q * (1.0 - (y - T.y_root) / (T.y_tip - T.y_root));
}

ToothCompliance compliance_at(const Tooth& T, double t_c, const StiffnessOptions& o, double h_q) {
  const double a1 = t_c - T.alpha2;  // load angle to the normal of the centre line
  const double ca = std::cos(a1), sa = std::sin(a1);
  const double yc = T.y(t_c), hc = T.h(t_c);
  const GaussLegendre& gl = gauss();
  double ib = 0, is = 0, ia = 0;
  // Adds the integrand at a section (y, half height h) with weight dy.
  auto add = [&](double yy, double hh, double dy) {
    const double H = hh + effective_edge(T, hh, yy, h_q);
    const double m = ca * (yc - yy) - hc * sa;
    ib += dy * m * m * 12.0 / (T.E * T.b * H * H * H);
    is += dy * 1.2 * ca * ca / (T.G * T.b * H);
    ia += dy * sa * sa / (T.E * T.b * H);
  };
  if (!T.tab.empty()) {
    for (const auto& [yy, hh, w] : T.tab) add(yy, hh, w);
  } else if (T.has_rect) {
    // The section is constant (or, for a case-2 crack, linear) in y: polynomial or smooth
    // rational integrands, one panel is enough.
    const double mid = 0.5 * (T.y_b + T.y_f), half = 0.5 * (T.y_b - T.y_f);
    for (int k = 0; k < GaussLegendre::kN; ++k) add(mid + half * gl.x[k], T.h_b, half * gl.w[k]);
  }
  // Involute part in t, in panels split where min(h, h_q) has a kink.
  std::vector<double> br{T.t_lo};
  constexpr int kPanels = 4;
  for (int p = 1; p < kPanels; ++p) br.push_back(T.t_lo + (t_c - T.t_lo) * p / kPanels);
  br.push_back(t_c);
  if (h_q >= 0 && std::isfinite(h_q)) {
    constexpr int kScan = 64;  // h(t) rises then falls: at most two crossings, well separated
    std::vector<double> extra;
    double t0 = T.t_lo, f0 = T.h(t0) - h_q;
    for (int k = 1; k <= kScan; ++k) {
      const double t1 = T.t_lo + (t_c - T.t_lo) * k / kScan, f1 = T.h(t1) - h_q;
      if ((f0 < 0) != (f1 < 0)) {
        double lo = t0, hi = t1;
        for (int it = 0; it < 80; ++it) {
          const double m = 0.5 * (lo + hi);
          if ((T.h(m) - h_q < 0) == (f0 < 0))
            lo = m;
          else
            hi = m;
        }
        extra.push_back(0.5 * (lo + hi));
      }
      t0 = t1;
      f0 = f1;
    }
    br.insert(br.end(), extra.begin(), extra.end());
    std::sort(br.begin(), br.end());
  }
  for (std::size_t p = 0; p + 1 < br.size(); ++p) {
    const double mid = 0.5 * (br[p] + br[p + 1]), half = 0.5 * (br[p + 1] - br[p]);
    if (half <= 0) continue;
    for (int k = 0; k < GaussLegendre::kN; ++k) {
      const double t = mid + half * gl.x[k];
      add(T.y(t), T.h(t), half * gl.w[k] * T.dy_dt(t));
    }
  }
  ToothCompliance c;
  c.bending_m_per_n = ib;
  c.shear_m_per_n = is;
  c.axial_m_per_n = ia;
  if (o.fillet_foundation) {
    // Sainsot et al. (2004), table 1: rows L*, M*, P*, Q*; columns A..F.
    static constexpr double kC[4][6] = {
        {-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045},
        {60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086},
        {-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236},
        {-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904}};
    double X[4];
    const double th = T.theta_f, hf = T.hfi;
    for (int i = 0; i < 4; ++i) {
      X[i] = kC[i][0] / (th * th) + kC[i][1] * hf * hf + kC[i][2] * hf / th + kC[i][3] / th +
             kC[i][4] * hf + kC[i][5];
    }
    const double uf = T.rb / ca - T.rf;  // load line crosses the centre line at y = r_b / cos(a1)
    const double Sf = 2.0 * T.rf * T.theta_f;
    const double q = uf / Sf, ta = std::tan(a1);
    c.fillet_m_per_n =
        ca * ca / (T.E * T.b) * (X[0] * q * q + X[1] * q + X[2] * (1.0 + X[3] * ta * ta));
  }
  return c;
}

double crack_tip_h(const Tooth& T, double crack_depth_m, const StiffnessOptions& o) {
  if (crack_depth_m <= 0) return kInf;
  return T.h_root - crack_depth_m * std::sin(o.crack_angle_rad);
}

void check_crack(const Tooth& T, double depth, const StiffnessOptions& o, const char* where,
                 const std::string& field) {
  const double cut = depth * std::sin(o.crack_angle_rad);
  if (!(depth >= 0) || !std::isfinite(depth) || cut > 1.8 * T.h_root) {
    std::ostringstream m;
    m << "must be >= 0 and leave 10 % of the root section: depth sin(crack angle) <= "
      << diag::units::m_to_mm(1.8 * T.h_root) << " mm (got depth " << diag::units::m_to_mm(depth)
      << " mm)";
    throw InputError(format_error(where, field, m.str()));
  }
}

int positive_mod(long long k, int n) {
  const long long r = k % n;
  return static_cast<int>(r < 0 ? r + n : r);
}

}  // namespace

void StiffnessOptions::validate() const {
  const char* where = "StiffnessOptions";
  if (grid_points < 16 || grid_points > 1000000) {
    throw InputError(format_error(where, "grid_points", fail_value(grid_points, "in [16, 1e6]")));
  }
  if (!(crack_angle_rad > 0 && crack_angle_rad <= kPi / 2)) {
    throw InputError(
        format_error(where, "crack_angle_rad", fail_value(crack_angle_rad, "in (0, pi/2]")));
  }
  if (!(bore_radius_ratio > 0 && bore_radius_ratio < 1)) {
    throw InputError(
        format_error(where, "bore_radius_ratio", fail_value(bore_radius_ratio, "in (0, 1)")));
  }
}

ToothCompliance tooth_compliance(const diag::Gear& gear, double rho_m,
                                 const StiffnessOptions& options, double crack_depth_m) {
  options.validate();
  const Tooth T(gear, options);
  const double t_c = rho_m / T.rb;
  constexpr double kRelTol = 1e-9;  // round-off at the tip / root ends of the profile
  if (!(t_c >= T.t_lo * (1 - kRelTol) && rho_m <= T.rho_tip * (1 + kRelTol)) || !(rho_m > 0)) {
    std::ostringstream m;
    m << "must lie on the flank, in (" << T.t_lo * T.rb << ", " << T.rho_tip << "] m (got " << rho_m
      << ")";
    throw InputError(format_error("tooth_compliance", "rho_m", m.str()));
  }
  check_crack(T, crack_depth_m, options, "tooth_compliance", "crack_depth_m");
  return compliance_at(T, std::clamp(t_c, T.t_lo, T.rho_tip / T.rb), options,
                       crack_tip_h(T, crack_depth_m, options));
}

double hertz_stiffness(const diag::GearPair& pair) {
  const diag::Material& m1 = pair.driver().spec().material;
  const diag::Material& m2 = pair.driven().spec().material;
  const double inv_e = (1 - m1.poisson_ratio * m1.poisson_ratio) / m1.youngs_modulus_pa +
                       (1 - m2.poisson_ratio * m2.poisson_ratio) / m2.youngs_modulus_pa;
  const double b = std::min(pair.driver().spec().face_width_m, pair.driven().spec().face_width_m);
  return 0.5 * kPi * b / inv_e;
}

// ---------------------------------------------------------------------------------------------

MeshStiffness::MeshStiffness(const diag::GearPair& pair, const StiffnessOptions& options,
                             TabulateOnly)
    : pair_(pair), options_(options) {
  options_.validate();
  // An undercut gear's tooth below its form radius comes from the rack-generated profile (Tooth::
  // tabulate_generated), unless StiffnessOptions::tooth_section says otherwise.
  if (pair_.contact_ratio() >= 4.0) {
    throw InputError(format_error("MeshStiffness", "contact_ratio",
                                  fail_value(pair_.contact_ratio(), "< 4 for a spur pair")));
  }
  const int n = options_.grid_points;
  s0_ = pair_.s_start_m();
  ds_ = pair_.path_of_contact_m() / (n - 1);
  inv_ds_ = 1.0 / ds_;
  last_ = n - 1;
  theta_ = pair_.mesh_period_rad();
  rb1_ = pair_.driver().base_radius_m();
  pb_ = pair_.base_pitch_m();
  constexpr double kEdgeTol = 5e-10;  // as GearPair::contacts_at
  s_end_tol_ = pair_.s_end_m() + kEdgeTol;
  const Tooth t1(pair_.driver(), options_), t2(pair_.driven(), options_);
  const double L = pair_.loa_length_m();
  c_hertz_ = 1.0 / hertz_stiffness(pair_);
  c1_.resize(n);
  c2_.resize(n);
  k_pair_.resize(n);
  for (int i = 0; i < n; ++i) {
    const double s = s0_ + i * ds_;
    const double tc1 = std::clamp(s / t1.rb, t1.t_lo, t1.rho_tip / t1.rb);
    const double tc2 = std::clamp((L - s) / t2.rb, t2.t_lo, t2.rho_tip / t2.rb);
    c1_[i] = compliance_at(t1, tc1, options_, kInf).total();
    c2_[i] = compliance_at(t2, tc2, options_, kInf).total();
    k_pair_[i] = 1.0 / (c_hertz_ + c1_[i] + c2_[i]);
  }
  k_max_ = *std::max_element(k_pair_.begin(), k_pair_.end());
  const int z1 = pair_.driver().teeth(), z2 = pair_.driven().teeth();
  faulty1_.assign(z1, 0);
  faulty2_.assign(z2, 0);
  gap1_.assign(z1, 0.0);
  gap2_.assign(z2, 0.0);
  state1_.assign(z1, -1);
  state2_.assign(z2, -1);
}

MeshStiffness::MeshStiffness(const diag::GearPair& pair, const StiffnessOptions& options,
                             std::vector<ToothFault> faults,
                             std::vector<double> driver_pitch_errors_m,
                             std::vector<double> driven_pitch_errors_m)
    : MeshStiffness(pair, options, TabulateOnly{}) {
  const char* where = "MeshStiffness";
  auto take_errors = [&](std::vector<double>& e, std::vector<double>& gap, int z, const char* f) {
    if (e.empty()) return;
    if (static_cast<int>(e.size()) != z) {
      std::ostringstream m;
      m << "must have one value per tooth (" << z << ") or none (got " << e.size() << ")";
      throw InputError(format_error(where, f, m.str()));
    }
    for (double v : e) {
      if (!std::isfinite(v)) throw InputError(format_error(where, f, "must be finite"));
      has_pitch_errors_ = has_pitch_errors_ || v != 0.0;
    }
    gap = std::move(e);
  };
  take_errors(driver_pitch_errors_m, gap1_, pair_.driver().teeth(), "driver_pitch_errors_m");
  take_errors(driven_pitch_errors_m, gap2_, pair_.driven().teeth(), "driven_pitch_errors_m");
  for (const ToothFault& f : faults) add_fault(f);
  faults_ = std::move(faults);
}

void MeshStiffness::add_fault(const ToothFault& f) {
  const std::string field = "faults[" + std::to_string(faults_.size()) + "]";
  const char* where = "MeshStiffness";
  if (f.gear != 0 && f.gear != 1) {
    throw InputError(format_error(where, field + ".gear", fail_value(f.gear, "0 (driver) or 1")));
  }
  const diag::Gear& g = f.gear == 0 ? pair_.driver() : pair_.driven();
  if (f.tooth < 0 || f.tooth >= g.teeth()) {
    throw InputError(
        format_error(where, field + ".tooth",
                     fail_value(f.tooth, "in [0, " + std::to_string(g.teeth() - 1) + "]")));
  }
  if (!(f.width_fraction > 0 && f.width_fraction <= 1)) {
    throw InputError(
        format_error(where, field + ".width_fraction", fail_value(f.width_fraction, "in (0, 1]")));
  }
  if (f.kind != ToothFault::Kind::kMissing && !(f.size_m > 0 && std::isfinite(f.size_m))) {
    throw InputError(format_error(where, field + ".size_m", fail_value(f.size_m, "> 0")));
  }
  if (!(f.depth_m >= 0 && std::isfinite(f.depth_m))) {
    throw InputError(format_error(where, field + ".depth_m", fail_value(f.depth_m, ">= 0")));
  }
  std::vector<int>& index = f.gear == 0 ? state1_ : state2_;
  if (index[f.tooth] < 0) {
    index[f.tooth] = static_cast<int>(states_.size());
    states_.emplace_back();
  }
  (f.gear == 0 ? faulty1_ : faulty2_)[f.tooth] = 1;
  ToothState& st = states_[index[f.tooth]];
  const Tooth T(g, options_);
  const double L = pair_.loa_length_m();
  switch (f.kind) {
    case ToothFault::Kind::kMissing:
      st.missing = true;
      break;
    case ToothFault::Kind::kRootCrack: {
      if (!st.compliance.empty()) {
        throw InputError(format_error(where, field, "a tooth takes at most one root crack"));
      }
      check_crack(T, f.size_m, options_, where, field + ".size_m");
      const double h_q = crack_tip_h(T, f.size_m, options_);
      const std::vector<double>& healthy = f.gear == 0 ? c1_ : c2_;
      st.compliance.resize(healthy.size());
      for (std::size_t i = 0; i < healthy.size(); ++i) {
        const double s = s0_ + i * ds_;
        const double rho = f.gear == 0 ? s : L - s;
        const double tc = std::clamp(rho / T.rb, T.t_lo, T.rho_tip / T.rb);
        const double cracked = compliance_at(T, tc, options_, h_q).total();
        // The cracked and intact parts of the face width act as parallel springs.
        const double w = f.width_fraction;
        st.compliance[i] = 1.0 / (w / cracked + (1.0 - w) / healthy[i]);
      }
      break;
    }
    case ToothFault::Kind::kChip: {
      // Roll distance below which the profile survives: the involute's arc length from the base
      // circle is rho^2 / (2 r_b).
      const double rho2 = T.rho_tip * T.rho_tip - 2.0 * T.rb * f.size_m;
      const double rho_c = rho2 > 0 ? std::sqrt(rho2) : 0.0;
      if (f.gear == 0) {
        st.intervals.push_back({rho_c, kInf, f.width_fraction, kInf});
      } else {
        st.intervals.push_back({-kInf, L - rho_c, f.width_fraction, kInf});
      }
      break;
    }
    case ToothFault::Kind::kSpall: {
      const double c = std::isnan(f.s_center_m) ? pair_.s_pitch_m() : f.s_center_m;
      if (!std::isfinite(c)) {
        throw InputError(format_error(where, field + ".s_center_m", "must be finite or NaN"));
      }
      st.intervals.push_back({c - 0.5 * f.size_m, c + 0.5 * f.size_m, f.width_fraction, f.depth_m});
      break;
    }
  }
  if (st.intervals.size() > 2) {
    throw InputError(format_error(where, field, "a tooth takes at most two chips/spalls"));
  }
}

double MeshStiffness::full_width_pair_stiffness(double s_m, int i, int j) const {
  const double x = (s_m - s0_) * inv_ds_;
  const int a = state1_[i], b = state2_[j];
  const bool cracked1 = a >= 0 && !states_[a].compliance.empty();
  const bool cracked2 = b >= 0 && !states_[b].compliance.empty();
  // Uncracked teeth take the healthy table itself, so that a chip or spall scales exactly the
  // value a healthy pair would have.
  if (!cracked1 && !cracked2) return interpolate(k_pair_, x);
  const double c1 = cracked1 ? interpolate(states_[a].compliance, x) : interpolate(c1_, x);
  const double c2 = cracked2 ? interpolate(states_[b].compliance, x) : interpolate(c2_, x);
  return 1.0 / (c_hertz_ + c1 + c2);
}

// The width strips of the pair at s: each tooth's intervals split its face into (fraction, gap)
// strips, taken as independent across the two teeth. Returns the number of strips (0: none can
// ever touch).
int MeshStiffness::parts(double s_m, int i, int j, std::array<Part, 16>& out) const {
  std::array<Part, 4> t[2];
  int nt[2] = {1, 1};
  const int idx[2] = {state1_[i], state2_[j]};
  for (int g = 0; g < 2; ++g) {
    t[g][0] = {1.0, 0.0};
    if (idx[g] < 0) continue;
    const ToothState& st = states_[idx[g]];
    if (st.missing) return 0;
    for (const auto& iv : st.intervals) {
      if (s_m < iv.s_lo || s_m > iv.s_hi) continue;
      const int n0 = nt[g];
      for (int p = 0; p < n0; ++p) {
        t[g][nt[g]++] = {t[g][p].fraction * iv.fraction, t[g][p].gap_m + iv.gap_m};
        t[g][p].fraction *= 1.0 - iv.fraction;
      }
    }
  }
  int n = 0;
  for (int p = 0; p < nt[0]; ++p) {
    for (int q = 0; q < nt[1]; ++q) {
      const double f = t[0][p].fraction * t[1][q].fraction;
      const double gap = t[0][p].gap_m + t[1][q].gap_m;
      if (f > 0 && std::isfinite(gap)) out[n++] = {f, gap};
    }
  }
  return n;
}

double MeshStiffness::faulty_pair_stiffness(double s_m, int i, int j) const {
  std::array<Part, 16> p;
  const int n = parts(s_m, i, j, p);
  if (n == 0) return 0.0;
  double g = kInf;
  for (int k = 0; k < n; ++k) g = std::min(g, p[k].gap_m);
  double f = 0;
  for (int k = 0; k < n; ++k) {
    if (p[k].gap_m == g) f += p[k].fraction;
  }
  return f * full_width_pair_stiffness(s_m, i, j);
}

double MeshStiffness::faulty_pair_gap(double s_m, int i, int j) const {
  std::array<Part, 16> p;
  const int n = parts(s_m, i, j, p);
  if (n == 0) return kInf;
  double g = kInf;
  for (int k = 0; k < n; ++k) g = std::min(g, p[k].gap_m);
  return gap1_[i] + gap2_[j] + profile_gap(s_m) + g;
}

double MeshStiffness::pair_force(double s_m, int i, int j, double compression_m) const {
  const double x = (s_m - s0_) * inv_ds_;
  if (!(x >= -kEdgeCells && x <= last_ + kEdgeCells)) return 0.0;
  const double d = compression_m - gap1_[i] - gap2_[j] - profile_gap(s_m);
  if (!(faulty1_[i] | faulty2_[j])) return d > 0 ? interpolate(k_pair_, x) * d : 0.0;
  std::array<Part, 16> p;
  const int n = parts(s_m, i, j, p);
  double f = 0;
  for (int k = 0; k < n; ++k) f += p[k].fraction * std::max(d - p[k].gap_m, 0.0);
  return f > 0 ? f * full_width_pair_stiffness(s_m, i, j) : 0.0;
}

void MeshStiffness::set_profile_gap(const std::vector<double>& s_m,
                                    const std::vector<double>& gap_m) {
  const char* where = "MeshStiffness::set_profile_gap";
  if (s_m.size() != gap_m.size() || s_m.size() < 2) {
    throw InputError(format_error(where, "s_m", "needs as many gaps as positions, at least 2"));
  }
  for (std::size_t i = 0; i < s_m.size(); ++i) {
    if (!std::isfinite(s_m[i]) || (i > 0 && !(s_m[i] > s_m[i - 1]))) {
      throw InputError(format_error(where, "s_m", "must be finite and strictly increasing"));
    }
    if (!(gap_m[i] >= 0) || !std::isfinite(gap_m[i])) {
      throw InputError(format_error(where, "gap_m", "must be finite and >= 0"));
    }
  }
  profile_gap_.resize(k_pair_.size());
  for (std::size_t i = 0; i < profile_gap_.size(); ++i) {
    const double s = s0_ + static_cast<double>(i) * ds_;
    const auto hi = static_cast<std::size_t>(
        std::clamp<std::ptrdiff_t>(std::upper_bound(s_m.begin(), s_m.end(), s) - s_m.begin(), 1,
                                   static_cast<std::ptrdiff_t>(s_m.size()) - 1));
    const double t = std::clamp((s - s_m[hi - 1]) / (s_m[hi] - s_m[hi - 1]), 0.0, 1.0);
    profile_gap_[i] = gap_m[hi - 1] + t * (gap_m[hi] - gap_m[hi - 1]);
  }
}

MeshContacts MeshStiffness::contacts(double phi1) const {
  // Same positions, in the same floating-point steps, as diag::GearPair::contacts_at.
  double frac = std::fmod(phi1, theta_);
  if (frac < 0) frac += theta_;
  const long long k = std::llround((phi1 - frac) / theta_);
  const int z1 = static_cast<int>(faulty1_.size()), z2 = static_cast<int>(faulty2_.size());
  MeshContacts c;
  for (double p = s0_ + rb1_ * frac; p <= s_end_tol_ && c.count < static_cast<int>(c.pairs.size());
       p += pb_) {
    c.pairs[c.count] = {p, positive_mod(k - c.count, z1), positive_mod(k - c.count, z2)};
    ++c.count;
  }
  return c;
}

double MeshStiffness::mesh_stiffness(double phi1) const {
  // The positions of contacts(), without the tooth bookkeeping.
  double frac = std::fmod(phi1, theta_);
  if (frac < 0) frac += theta_;
  double k = 0;
  for (double p = s0_ + rb1_ * frac; p <= s_end_tol_; p += pb_) {
    k += interpolate(k_pair_, (p - s0_) * inv_ds_);
  }
  return k;
}

double MeshStiffness::faulty_mesh_stiffness(double phi1) const {
  const MeshContacts c = contacts(phi1);
  double k = 0;
  for (int i = 0; i < c.count; ++i) {
    k += pair_stiffness(c.pairs[i].s_m, c.pairs[i].driver_tooth, c.pairs[i].driven_tooth);
  }
  return k;
}

double MeshStiffness::mean_mesh_stiffness() const {
  // Over one mesh period the pairs in contact sweep the path once: mean = Int k ds / p_b, exact
  // for the piecewise-linear table (trapezoids).
  double sum = 0;
  for (std::size_t i = 0; i + 1 < k_pair_.size(); ++i) sum += 0.5 * (k_pair_[i] + k_pair_[i + 1]);
  return sum * ds_ / pair_.base_pitch_m();
}

MeshStiffness MeshStiffness::from_table(const diag::GearPair& pair, std::vector<double> angle_deg,
                                        std::vector<double> load_n,
                                        std::vector<std::vector<double>> k_n_per_m,
                                        double static_load_n, const StiffnessOptions& options) {
  const char* where = "MeshStiffness::from_table";
  const double period_deg = 360.0 / pair.driver().teeth();
  if (angle_deg.empty()) throw InputError(format_error(where, "angle_deg", "must not be empty"));
  if (load_n.empty()) throw InputError(format_error(where, "load_n", "must not be empty"));
  for (std::size_t i = 0; i < angle_deg.size(); ++i) {
    const bool ok = angle_deg[i] >= 0 && angle_deg[i] < period_deg &&
                    (i == 0 || angle_deg[i] > angle_deg[i - 1]);
    if (!ok) {
      std::ostringstream m;
      m << "must increase strictly within the mesh period [0, " << period_deg << ") deg (entry "
        << i << " is " << angle_deg[i] << ")";
      throw InputError(format_error(where, "angle_deg", m.str()));
    }
  }
  for (std::size_t j = 0; j < load_n.size(); ++j) {
    if (!(load_n[j] > 0 && std::isfinite(load_n[j])) || (j > 0 && load_n[j] <= load_n[j - 1])) {
      throw InputError(format_error(where, "load_n", "must be > 0 and strictly increasing"));
    }
  }
  if (k_n_per_m.size() != angle_deg.size()) {
    throw InputError(format_error(where, "k_n_per_m", "needs one row per angle"));
  }
  for (const auto& row : k_n_per_m) {
    if (row.size() != load_n.size()) {
      throw InputError(format_error(where, "k_n_per_m", "needs one column per load"));
    }
    for (double v : row) {
      if (!(v > 0 && std::isfinite(v))) {
        throw InputError(format_error(where, "k_n_per_m", fail_value(v, "finite and > 0")));
      }
    }
  }
  if (!(static_load_n >= load_n.front() && static_load_n <= load_n.back())) {
    std::ostringstream m;
    m << "must lie within the table's loads [" << load_n.front() << ", " << load_n.back()
      << "] N (got " << static_load_n << ")";
    throw InputError(format_error(where, "static_load_n", m.str()));
  }
  // k_tab at the static load, per angle.
  std::vector<double> k_tab(angle_deg.size());
  std::size_t j = 0;
  while (j + 2 < load_n.size() && static_load_n > load_n[j + 1]) ++j;
  for (std::size_t i = 0; i < angle_deg.size(); ++i) {
    if (load_n.size() == 1) {
      k_tab[i] = k_n_per_m[i][0];
    } else {
      const double f = (static_load_n - load_n[j]) / (load_n[j + 1] - load_n[j]);
      k_tab[i] = k_n_per_m[i][j] + f * (k_n_per_m[i][j + 1] - k_n_per_m[i][j]);
    }
  }
  auto table_at = [&](double deg) {  // linear, periodic
    const std::size_t n = angle_deg.size();
    if (n == 1) return k_tab[0];
    auto it = std::upper_bound(angle_deg.begin(), angle_deg.end(), deg);
    std::size_t hi = static_cast<std::size_t>(it - angle_deg.begin());
    double a0, a1, k0, k1;
    if (hi == 0) {
      a0 = angle_deg[n - 1] - period_deg;
      k0 = k_tab[n - 1];
      a1 = angle_deg[0];
      k1 = k_tab[0];
    } else if (hi == n) {
      a0 = angle_deg[n - 1];
      k0 = k_tab[n - 1];
      a1 = angle_deg[0] + period_deg;
      k1 = k_tab[0];
    } else {
      a0 = angle_deg[hi - 1];
      k0 = k_tab[hi - 1];
      a1 = angle_deg[hi];
      k1 = k_tab[hi];
    }
    return k0 + (deg - a0) / (a1 - a0) * (k1 - k0);
  };

  MeshStiffness m(pair, options, TabulateOnly{});
  const double rb1 = pair.driver().base_radius_m(), pb = pair.base_pitch_m();
  std::vector<double> scaled(m.k_pair_.size());
  for (std::size_t i = 0; i < scaled.size(); ++i) {
    const double s = m.s0_ + i * m.ds_;
    const double phi = std::fmod(s - m.s0_, pb) / rb1;
    double k_mesh = 0;
    for (double p = m.s0_ + rb1 * phi; p <= pair.s_end_m() + 5e-10; p += pb) {
      k_mesh += interpolate(m.k_pair_, (p - m.s0_) * m.inv_ds_);
    }
    scaled[i] = m.k_pair_[i] * table_at(diag::units::rad_to_deg(phi)) / k_mesh;
  }
  m.k_pair_ = std::move(scaled);
  m.k_max_ = *std::max_element(m.k_pair_.begin(), m.k_pair_.end());
  return m;
}

// ---------------------------------------------------------------------------------------------

Iso6336Stiffness iso6336_method_b(const diag::GearPair& pair) {
  const diag::GearSpec& a = pair.driver().spec();
  const diag::GearSpec& b = pair.driven().spec();
  constexpr double C[10] = {0,        0.04723,  0.15551,  0.25791, -0.00635,
                            -0.11654, -0.00193, -0.24188, 0.00529, 0.00182};
  const double zn1 = a.teeth, zn2 = b.teeth;  // spur: z_n = z
  const double x1 = a.profile_shift, x2 = b.profile_shift;
  const double q = C[1] + C[2] / zn1 + C[3] / zn2 + C[4] * x1 + C[5] * x1 / zn1 + C[6] * x2 +
                   C[7] * x2 / zn2 + C[8] * x1 * x1 + C[9] * x2 * x2;  // [mm um / N]
  const double c_th = 1.0 / q;                                         // [N / (mm um)]
  constexpr double kCM = 0.8, kCR = 1.0;
  auto cb = [](const diag::GearSpec& g) {
    const double hfp = g.addendum_coefficient + g.clearance_coefficient;  // h_fP / m
    const double alpha_deg = diag::units::rad_to_deg(g.pressure_angle_rad);
    return (1.0 + 0.5 * (1.2 - hfp)) * (1.0 - 0.02 * (20.0 - alpha_deg));
  };
  const double CB = 0.5 * (cb(a) + cb(b));
  const double E1 = a.material.youngs_modulus_pa, E2 = b.material.youngs_modulus_pa;
  const double e_ratio = 2.0 * E1 * E2 / (E1 + E2) / 206e9;
  const double c_prime = c_th * kCM * kCR * CB * e_ratio;  // cos(beta) = 1
  Iso6336Stiffness r;
  r.c_prime_th_n_per_m2 = c_th * 1e9;
  r.c_prime_n_per_m2 = c_prime * 1e9;
  r.c_gamma_alpha_n_per_m2 = c_prime * (0.75 * pair.contact_ratio() + 0.25) * 1e9;
  return r;
}

double single_pitch_tolerance_iso1328_m(const diag::Gear& gear, int grade) {
  if (grade < 0 || grade > 12) {
    throw InputError(format_error("single_pitch_tolerance_iso1328", "accuracy_grade",
                                  fail_value(grade, "an integer in [0, 12]")));
  }
  const double m = diag::units::m_to_mm(gear.module_m());
  const double d = diag::units::m_to_mm(2.0 * gear.pitch_radius_m());
  const double fpt5_um = 0.3 * (m + 0.4 * std::sqrt(d)) + 4.0;
  return diag::units::um_to_m(fpt5_um * std::pow(2.0, 0.5 * (grade - 5)));
}

std::vector<double> pitch_errors_iso1328(const diag::Gear& gear, int grade, std::uint64_t seed,
                                         PitchErrorDistribution distribution) {
  const double tol = single_pitch_tolerance_iso1328_m(gear, grade);
  const int z = gear.teeth();
  std::mt19937_64 rng(seed);
  // Own uniform and Box-Muller: std:: distributions differ between standard libraries.
  auto uniform01 = [&] { return (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53; };
  std::vector<double> f(z);
  for (int i = 0; i < z; ++i) {
    if (distribution == PitchErrorDistribution::kUniform) {
      f[i] = tol * (2.0 * uniform01() - 1.0);
    } else {
      double v;
      do {
        const double u1 = uniform01(), u2 = uniform01();
        v = tol / 3.0 * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
      } while (std::abs(v) > tol);
      f[i] = v;
    }
  }
  // Close the pitch circle: the single pitch deviations of a whole gear sum to zero.
  double mean = 0;
  for (double v : f) mean += v;
  mean /= z;
  double worst = 0;
  for (double& v : f) {
    v -= mean;
    worst = std::max(worst, std::abs(v));
  }
  if (worst > tol) {
    for (double& v : f) v *= tol / worst;
  }
  std::vector<double> pos(z);
  double acc = 0, sum = 0;
  for (int i = 0; i < z; ++i) {
    acc += f[i];
    pos[i] = acc;
    sum += acc;
  }
  for (double& p : pos) p -= sum / z;
  return pos;
}

}  // namespace sim
