// Gear oil: kinematic viscosity vs temperature (Walther / ASTM D341), density vs temperature,
// dynamic viscosity. Used by the mesh friction laws (docs/physics.md, seed 000: "oil viscosity
// falls with temperature").
//
// Viscosity. ASTM D341 (Walther, 1931):
//     log10(log10(nu + 0.7)) = A - B log10(T)        nu [cSt = mm^2/s], T [K]
// A and B are fitted exactly through the two reference points (40 degC, nu40) and (100 degC,
// nu100) of a data sheet. CAUTION: the 0.7 form is ASTM D341's law for nu >= 2 cSt; below that
// (hot light oils) it drifts, so validate() requires nu100 >= 2 cSt and the evaluation
// temperature is limited to [-30, 150] degC (the range of D341's chart).
//
// Density. Linear thermal expansion from 15 degC:
//     rho(T) = rho15 (1 - beta (T - 15)),  beta = 6.4e-4 1/K
// (mineral oils of rho15 ~ 0.88...0.90 g/cm^3: ASTM D1250 / API 2540 give 6.3...6.5e-4 1/K).
//
// Dynamic viscosity eta = nu rho (1 cSt = 1e-6 m^2/s).
#pragma once

#include <string>

namespace sim {

struct Lubricant {
  double nu40_cst = 220.0;             // kinematic viscosity at 40 degC [cSt], > nu100
  double nu100_cst = 18.75;            // kinematic viscosity at 100 degC [cSt], >= 2
  double density15_kg_per_m3 = 890.0;  // density at 15 degC [kg/m^3], 700...1200

  // Presets by ISO 3448 viscosity grade: nu40 = the grade's mid-point and nu100 of a mineral oil
  // of viscosity index 95, from the ASTM D2270 definition VI = 100 (L - nu40) / (L - H) with the
  // L, H table of D2270 (interpolated):
  //     VG 68: 8.53   VG 100: 11.07   VG 150: 14.55   VG 220: 18.75   VG 320: 23.95 cSt
  // (data sheets of mineral VG 220 gear oils list VI 95...97: Castrol Alpha SP 220 95, Shell
  // Omala S2 GX 220 and Mobilgear 600 XP 220 97; VI 100 would be nu100 = 19.2 cSt).
  // Density 890 kg/m^3 (typical of mineral gear oils). Other grades throw diag::InputError.
  static Lubricant iso_vg(int grade);

  // The oil with nu_a at t_a and nu_b at t_b [degC, cSt] (any two distinct temperatures, e.g. a
  // data sheet or table that does not list 40 and 100 degC). The Walther line through the two
  // points is the same line as through its own nu40 and nu100, which are what is stored.
  static Lubricant from_two_points(double t_a_c, double nu_a_cst, double t_b_c, double nu_b_cst,
                                   double density15_kg_per_m3);

  // Walther constants of log10(log10(nu + 0.7)) = A - B log10(T[K]).
  double walther_a() const;
  double walther_b() const;

  // temperature_c in [-30, 150] degC (else diag::InputError).
  double kinematic_viscosity_cst(double temperature_c) const;
  double density_kg_per_m3(double temperature_c) const;
  double dynamic_viscosity_pa_s(double temperature_c) const;

  // Throws diag::InputError naming `where` and the field when a value is out of range.
  void validate(const std::string& where) const;
};

}  // namespace sim
