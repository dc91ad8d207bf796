#include "sim/mesh/friction.hpp"

#include <algorithm>
#include <cmath>

#include "diag/error.hpp"
#include "diag/range_check.hpp"
#include "diag/units.hpp"

namespace sim {

using diag::InputError;

namespace {

constexpr double kPi = 3.14159265358979323846;

// US customary units of Benedict & Kelley (exact by definition of the inch and the pound-force).
constexpr double kMetresPerInch = 0.0254;
constexpr double kNewtonsPerPoundForce = 4.4482216152605;
// Half a nanometre: a pair exactly at the end of contact counts as in contact (as in
// GearPair::contacts_at).
constexpr double kEdgeTolM = 5e-10;

}  // namespace

FrictionLaw friction_law_from_string(std::string_view name) {
  if (name == "none") return FrictionLaw::kNone;
  if (name == "constant") return FrictionLaw::kConstant;
  if (name == "drozdov") return FrictionLaw::kDrozdov;
  if (name == "benedict_kelley") return FrictionLaw::kBenedictKelley;
  if (name == "xu_kahraman") return FrictionLaw::kXuKahraman;
  throw InputError(diag::format_error(
      "friction_law_from_string", "law",
      "'" + std::string(name) +
          "' is not one of none, constant, drozdov, benedict_kelley, xu_kahraman"));
}

const char* to_string(FrictionLaw law) {
  switch (law) {
    case FrictionLaw::kNone:
      return "none";
    case FrictionLaw::kConstant:
      return "constant";
    case FrictionLaw::kDrozdov:
      return "drozdov";
    case FrictionLaw::kBenedictKelley:
      return "benedict_kelley";
    case FrictionLaw::kXuKahraman:
      return "xu_kahraman";
  }
  return "unknown";
}

void FrictionOptions::validate(const std::string& where) const {
  diag::require_range(
      law == FrictionLaw::kNone || law == FrictionLaw::kConstant || law == FrictionLaw::kDrozdov ||
          law == FrictionLaw::kBenedictKelley || law == FrictionLaw::kXuKahraman,
      where, "law", static_cast<double>(static_cast<int>(law)), "a FrictionLaw value");
  diag::require_range(std::isfinite(mu_constant) && mu_constant >= 0.0 && mu_constant <= 1.0, where,
                      "mu_constant", mu_constant, "[0, 1]");
  diag::require_range(std::isfinite(mu_cap) && mu_cap > 0.0 && mu_cap <= 1.0, where, "mu_cap",
                      mu_cap, "(0, 1]");
  diag::require_range(
      std::isfinite(oil_temperature_c) && oil_temperature_c >= -30.0 && oil_temperature_c <= 150.0,
      where, "oil_temperature_c", oil_temperature_c,
      "[-30, 150] degC (range of the ASTM D341 viscosity law)");
  oil.validate(where + ": oil");
}

FrictionModel::FrictionModel(const FrictionOptions& options, const diag::GearPair& pair)
    : options_(options), pair_(pair) {
  options_.validate("friction options");
  nu_cst_ = options_.oil.kinematic_viscosity_cst(options_.oil_temperature_c);
  eta_pa_s_ = options_.oil.dynamic_viscosity_pa_s(options_.oil_temperature_c);
  const diag::Material& m1 = pair_.driver().spec().material;
  const diag::Material& m2 = pair_.driven().spec().material;
  const double hb_kgf_per_cm2 =
      diag::units::hb_to_kgf_per_cm2(std::min(m1.hardness_hb, m2.hardness_hb));
  const double ra_um = diag::units::m_to_um(0.5 * (m1.roughness_ra_m + m2.roughness_ra_m));
  const double e1 = m1.youngs_modulus_pa, e2 = m2.youngs_modulus_pa;
  const double e_reduced_kgf_per_cm2 = diag::units::pa_to_kgf_per_cm2(2.0 * e1 * e2 / (e1 + e2));
  drozdov_material_ = hb_kgf_per_cm2 * ra_um / e_reduced_kgf_per_cm2;
  face_width_m_ = std::min(pair_.driver().spec().face_width_m, pair_.driven().spec().face_width_m);
  e_star_pa_ = 1.0 / ((1 - m1.poisson_ratio * m1.poisson_ratio) / e1 +
                      (1 - m2.poisson_ratio * m2.poisson_ratio) / e2);
  roughness_um_ = ra_um;
}

double FrictionModel::drozdov(const diag::ContactKinematics& k) const {
  const double rho_mm = diag::units::m_to_mm(k.reduced_radius_m);
  const double vs_mm_s = diag::units::m_to_mm(std::abs(k.sliding_m_per_s));
  const double vsum_mm_s = diag::units::m_to_mm(std::abs(k.rolling_sum_m_per_s));
  if (vs_mm_s == 0.0 || vsum_mm_s == 0.0 || !(rho_mm > 0.0)) return options_.mu_cap;
  const double mu = 0.57 * (7.0 + std::log10(drozdov_material_ / rho_mm)) * std::pow(rho_mm, 0.1) /
                    (std::pow(nu_cst_, 0.07) * std::pow(vs_mm_s, 0.35) * std::pow(vsum_mm_s, 0.1) *
                     std::pow(rho_mm, 0.25));
  return std::clamp(mu, 0.0, options_.mu_cap);
}

double FrictionModel::benedict_kelley(const diag::ContactKinematics& k,
                                      double normal_load_n) const {
  const double w_lb_per_in = normal_load_n / face_width_m_ / kNewtonsPerPoundForce * kMetresPerInch;
  const double nu0_cp = eta_pa_s_ * 1e3;  // 1 cP = 1 mPa s
  const double vs_in_s = std::abs(k.sliding_m_per_s) / kMetresPerInch;
  const double ve_in_s = std::abs(k.rolling_sum_m_per_s) / kMetresPerInch;
  if (vs_in_s == 0.0 || ve_in_s == 0.0) return options_.mu_cap;
  if (w_lb_per_in == 0.0) return 0.0;  // an unloaded pair has no friction force anyway
  const double mu =
      0.0127 * std::log10(3.17e8 * w_lb_per_in / (nu0_cp * vs_in_s * ve_in_s * ve_in_s));
  return std::clamp(mu, 0.0, options_.mu_cap);
}

double FrictionModel::xu_kahraman(const diag::ContactKinematics& k, double normal_load_n) const {
  // Xu, Kahraman, Anderson & Maddock, J. Tribol. 129 (2007) 58-68, eqs. 11-12 and table 2:
  //   mu = exp(f) P_h^b2 |SR|^b3 V_e^b6 nu0^b7 R^b8,
  //   f = b1 + b4 |SR| P_h log10(nu0) + b5 exp(-|SR| P_h log10(nu0)) + b9 exp(S)
  // P_h [GPa] maximum Hertzian pressure of the line contact, SR = 2 (v1 - v2) / (v1 + v2),
  // V_e = (v1 + v2) / 2 [m/s], nu0 dynamic viscosity at the inlet [cP = mPa s], R reduced
  // radius [m], S composite roughness [um] (mean Ra). A regression of thermal non-Newtonian EHL
  // solutions: mu grows with viscosity (b7 > 0), so hotter, thinner oil lowers friction, and mu
  // vanishes where the sliding does (at the pitch point) without a cap.
  constexpr double b1 = -8.916465, b2 = 1.03303, b3 = 1.036077, b4 = -0.354068, b5 = 2.812084,
                   b6 = -0.100601, b7 = 0.752755, b8 = -0.390958, b9 = 0.620305;
  const double ve = 0.5 * std::abs(k.rolling_sum_m_per_s);
  const double r = k.reduced_radius_m;
  if (ve == 0.0 || !(r > 0.0) || normal_load_n == 0.0) return 0.0;
  const double sr = std::abs(2.0 * k.sliding_m_per_s / k.rolling_sum_m_per_s);
  if (sr == 0.0) return 0.0;
  const double w = normal_load_n / face_width_m_;                      // [N/m]
  const double ph_gpa = std::sqrt(w * e_star_pa_ / (kPi * r)) * 1e-9;  // line contact
  const double nu0_cp = eta_pa_s_ * 1e3;
  const double lg = std::log10(nu0_cp);
  const double f =
      b1 + b4 * sr * ph_gpa * lg + b5 * std::exp(-sr * ph_gpa * lg) + b9 * std::exp(roughness_um_);
  const double mu = std::exp(f) * std::pow(ph_gpa, b2) * std::pow(sr, b3) * std::pow(ve, b6) *
                    std::pow(nu0_cp, b7) * std::pow(r, b8);
  return std::clamp(mu, 0.0, options_.mu_cap);
}

double FrictionModel::coefficient(const diag::ContactKinematics& k, double normal_load_n) const {
  diag::require_range(std::isfinite(normal_load_n) && normal_load_n >= 0.0,
                      "FrictionModel::coefficient", "normal_load_n", normal_load_n, ">= 0 N");
  switch (options_.law) {
    case FrictionLaw::kNone:
      return 0.0;
    case FrictionLaw::kConstant:
      return options_.mu_constant;
    case FrictionLaw::kDrozdov:
      return drozdov(k);
    case FrictionLaw::kBenedictKelley:
      return benedict_kelley(k, normal_load_n);
    case FrictionLaw::kXuKahraman:
      return xu_kahraman(k, normal_load_n);
  }
  return 0.0;
}

int FrictionModel::pairs_in_contact(double s_m) const {
  const double pb = pair_.base_pitch_m();
  const double lo = pair_.s_start_m() - kEdgeTolM, hi = pair_.s_end_m() + kEdgeTolM;
  if (s_m < lo || s_m > hi) return 0;
  int n = 1;
  for (double p = s_m - pb; p >= lo; p -= pb) ++n;
  for (double p = s_m + pb; p <= hi; p += pb) ++n;
  return n;
}

std::vector<double> FrictionModel::tabulate(double omega1_rad_per_s, double normal_load_n,
                                            int points) const {
  const char* where = "FrictionModel::tabulate";
  diag::require_range(points >= 2, where, "points", points, ">= 2");
  diag::require_range(std::isfinite(omega1_rad_per_s), where, "omega1_rad_per_s", omega1_rad_per_s,
                      "finite");
  diag::require_range(std::isfinite(normal_load_n) && normal_load_n >= 0.0, where, "normal_load_n",
                      normal_load_n, ">= 0 N");
  std::vector<double> mu(static_cast<std::size_t>(points));
  const double s0 = pair_.s_start_m(), ds = pair_.path_of_contact_m() / (points - 1);
  for (int i = 0; i < points; ++i) {
    const double s = s0 + ds * i;
    const diag::ContactKinematics k = pair_.kinematics(s, omega1_rad_per_s);
    mu[static_cast<std::size_t>(i)] = coefficient(k, normal_load_n / pairs_in_contact(s));
  }
  return mu;
}

}  // namespace sim
