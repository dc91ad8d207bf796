// Coefficient of friction in a spur gear mesh (docs/physics.md; seed 000, Kalinin & Temis 2018,
// eqs. 1-3). The laws here return the magnitude mu >= 0; the dynamics applies the sign of the
// sliding velocity (seed eq. 2: friction reverses at the pitch point).
//
// Laws:
//  * kNone: mu = 0.  kConstant: mu = mu_constant everywhere (the cap does not apply).
//  * kDrozdov (Drozdov & Smirnov 1977, as printed in seed 000 eq. 3; units as in the seed):
//        mu = 0.57 (7 + lg(HB Ra / (E' rho))) rho^0.1 / (nu^0.07 Vs^0.35 Vsum^0.1 rho^0.25)
//    HB  Brinell hardness of the softer flank [kgf/cm^2]. Material::hardness_hb is the usual
//        Brinell number in kgf/mm^2, so HB[kgf/cm^2] = 100 hardness_hb. (The seed's validity
//        bound "HB >= 50 kgf/cm^2" reads like the Brinell number itself; with HB in kgf/mm^2
//        the bracket drops by 2 and mu halves to ~0.01-0.03 for the seed's pair, below measured
//        gear friction, so the printed unit is kept.)
//    Ra  arithmetic-mean roughness [um], the mean of the two flanks' Ra;
//    E'  reduced modulus in the Russian convention E' = 2 E1 E2 / (E1 + E2) [kgf/cm^2] (the seed
//        says "приведённый модуль"; for equal steels E' = E);
//    rho reduced radius of curvature rho1 rho2 / (rho1 + rho2) [mm];
//    nu  kinematic viscosity at the oil temperature [cSt]; Vs = |v1 - v2|, Vsum = v1 + v2 [mm/s].
//    For the seed's pair (z = 49/51, m = 4 mm, b = 20 mm, 2000 N m, steel HB 300, Ra 0.8 um,
//    ISO VG 220 at 60 degC) the printed formula gives mu = 0.030...0.052 at 1000 rpm and
//    0.019...0.032 at 3000 rpm away from the capped zone: the magnitude of measured gear
//    friction, within a factor 1.5 of Benedict-Kelley, so no correction of the formula is made.
//    (Unverified suspicion: rho^0.1 / rho^0.25 is an odd way to write rho^-0.15; the original
//    may have had a load term q^0.1 in the numerator. Kept as printed.)
//    CAUTION, temperature: mu ~ nu^-0.07 RISES as the oil heats and thins (25 -> 95 degC:
//    +26 %), as in every mixed-lubrication law (film thickness grows with viscosity). The seed
//    states the opposite (NASA data, its Fig. 4: mu falls ~4x from 25 to 100 degC, and Fig. 11:
//    less friction-driven vibration at 95 degC), which eq. 3 as printed cannot reproduce.
//  * kBenedictKelley (Benedict & Kelley, ASLE Trans. 4 (1961) 59-70), in US customary units:
//        mu = 0.0127 log10(3.17e8 X W / (nu0 Vs Ve^2))
//    X W the load carried by the tooth pair per unit face width [lb/in] (load-sharing factor X
//    times the total load per width), nu0 dynamic viscosity at the oil temperature [cP], Vs
//    sliding and Ve rolling (sum) velocity [in/s]. The inputs are converted from SI; the constants
//    are the paper's. The roughness factor 50 / (50 - S_avg[uin]) of the original is not applied
//    (smooth-surface form). mu < 0 (log argument < 1, very light load / high speed) is clamped to
//    0. Like Drozdov's law it gives a higher mu for hotter, thinner oil (-0.0127 log10(nu0)).
//  * kXuKahraman (Xu, Kahraman, Anderson & Maddock, J. Tribol. 129 (2007) 58-68): a regression
//    of thermal EHL solutions, mu = exp(f(SR, P_h, nu0, S)) P_h^b2 |SR|^b3 V_e^b6 nu0^b7 R^b8
//    (see friction.cpp for the terms and units). mu RISES with viscosity (b7 = 0.75), so it falls
//    as the oil heats (25 -> 95 degC: about 4x for ISO VG 220), as the seed's NASA data (its
//    Fig. 4) and its result Fig. 11 show; this is the law that reproduces the seed's oil-
//    temperature result, which eq. 3 as printed cannot. It vanishes with the sliding at the pitch
//    point.
// Both Drozdov and Benedict-Kelley diverge at the pitch point (Vs -> 0): mu is capped at the
// boundary-friction value mu_cap (default 0.12) wherever the law exceeds it, and mu = mu_cap
// where Vs = 0 or Vsum = 0 exactly.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "diag/geometry/gear_pair.hpp"
#include "sim/mesh/lubricant.hpp"

namespace sim {

enum class FrictionLaw {
  kNone,            // no friction
  kConstant,        // mu = mu_constant
  kDrozdov,         // seed 000 eq. 3
  kBenedictKelley,  // Benedict & Kelley (1961)
  kXuKahraman,      // Xu, Kahraman et al. (2007), EHL regression; mu falls as the oil thins
};

// "none", "constant", "drozdov", "benedict_kelley", "xu_kahraman"; anything else throws
// diag::InputError.
FrictionLaw friction_law_from_string(std::string_view name);
const char* to_string(FrictionLaw law);

struct FrictionOptions {
  FrictionLaw law = FrictionLaw::kDrozdov;
  double mu_constant = 0.05;        // mu of kConstant [-], [0, 1]
  double mu_cap = 0.12;             // boundary-friction cap of kDrozdov/kBenedictKelley [-], (0, 1]
  double oil_temperature_c = 60.0;  // oil temperature at the mesh outlet [degC], [-30, 150]
  Lubricant oil = Lubricant::iso_vg(220);

  // Throws diag::InputError naming `where` and the field (oil fields as "<where>: oil: <field>").
  void validate(const std::string& where) const;
};

class FrictionModel {
 public:
  // Validates the options; takes hardness, roughness, moduli and face width from the pair's
  // gears (softer flank's HB, mean Ra, E' = 2 E1 E2 / (E1 + E2), the narrower face width).
  FrictionModel(const FrictionOptions& options, const diag::GearPair& pair);

  const FrictionOptions& options() const { return options_; }
  double viscosity_cst() const { return nu_cst_; }     // at the oil temperature
  double viscosity_pa_s() const { return eta_pa_s_; }  // at the oil temperature

  // mu magnitude at contact kinematics k (from GearPair::kinematics) with normal_load_n [N] the
  // load carried by this tooth pair over the face width (used by Benedict-Kelley only).
  // Throws diag::InputError for a negative or non-finite load.
  double coefficient(const diag::ContactKinematics& k, double normal_load_n) const;

  // mu at `points` (>= 2) equally spaced LOA positions s_i = s_start + i (s_end - s_start) /
  // (points - 1) for driver speed omega1 [rad/s] and total normal load normal_load_n [N]. The
  // load of the pair at s_i is the total divided equally among the pairs in contact when one pair
  // is at s_i (1 or 2 for 1 < eps < 2). The 6-DOF integrator interpolates this table each step;
  // rebuild it when the speed or the load changes.
  std::vector<double> tabulate(double omega1_rad_per_s, double normal_load_n, int points) const;

  // Number of tooth pairs in contact when one pair is at LOA position s (itself included).
  int pairs_in_contact(double s_m) const;

 private:
  double drozdov(const diag::ContactKinematics& k) const;
  double benedict_kelley(const diag::ContactKinematics& k, double normal_load_n) const;
  double xu_kahraman(const diag::ContactKinematics& k, double normal_load_n) const;

  FrictionOptions options_;
  diag::GearPair pair_;
  double nu_cst_ = 0, eta_pa_s_ = 0;
  double drozdov_material_ = 0;  // HB [kgf/cm^2] Ra [um] / E' [kgf/cm^2]
  double face_width_m_ = 0;
  double e_star_pa_ = 0;     // 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2
  double roughness_um_ = 0;  // mean Ra [um]
};

}  // namespace sim
