// Wear of a spur gear pair over its life (seed 004, Avsievich, Reut & Dubovskaya;
// docs/wear.md), iterated in blocks of cycles: wear, update both flanks, recompute contact, load
// sharing, contact ratio, mesh stiffness and the unloaded transmission error; stop at a depth
// limit.
//
// Profile points. Wear is tracked on each gear's active flank (the path of contact s_start..s_end
// of diag::GearPair mapped to roll distances rho1 = s, rho2 = T1T2 - s), on a grid with a node at
// the pitch point. All teeth of a gear wear alike (every tooth meets the mate the same way on
// average); a driver tooth passes the mesh once per driver revolution ("cycle"), a driven tooth
// once per 1/u of a cycle.
//
// Load sharing (quasi-static, rigid bodies, linear teeth). At driver angle phi the pairs in contact
// sit at s_j = s + j p_b; a worn pair is separated along the line of action by the sum of the two
// normal wear depths, g_j = h1(s_j) + h2(T1T2 - s_j) (exact for involutes: normal wear of an
// involute is a rotation of it, see diag/geometry/profile.hpp). With the pair stiffness k(s) of
// sim::MeshStiffness (potential energy + fillet + Hertz) the compression d solves
//     F = sum_j k(s_j) max(d - g_j, 0),   F = T_driver / r_b1,
// and pair j carries F_j = k(s_j) (d - g_j)^+.
// State measures over a mesh period (te_points_per_mesh driver angles):
// - loaded contact ratio: the mean number of pairs with F_j > 0 (the count, not a load weighting);
// - mesh stiffness: the mean of sum_j k(s_j) over the pairs with F_j > 0, i.e. the tangent mesh
//   stiffness dF/dd the dynamics sees at the operating point. k(s) is the unworn pair's: the
//   thinning of a worn tooth is left out (estimated with the same potential-energy beam, the
//   loaded side's half thickness less w / cos(alpha1): +0.18..0.53 % pair compliance, mean 0.25 %,
//   for the 18/36 m = 3 mm pair after 52 um of Archard wear; Hertz included; the fillet-foundation
//   term, left out of it and untouched by wear, makes it smaller still). So wear changes it only
//   when pairs lose their load. Archard's law never unloads a pair: a point's wear rate falls with
//   its load, so a worn zone unloads partially and its partner catches up; over 1e7 cycles (52 um)
//   of the pair above the smallest load any pair carries stays at 4.0 % of F (1e6 cycles: 5.0 %),
//   so the count and the stiffness stay those of the new pair while the sharing between the pairs
//   moves. The seed law's intensity does not fall with the load, so a point in double contact wears
//   until it stands at the edge of contact (F_j ~ 0, held there by the contact condition below):
//   the count falls, and where pairs sit at the edge it is ill-conditioned (that pair at 1e7
//   cycles: 1.14..1.17 in 10 blocks over sub-block depths 0.25..2 um, 1.23 in 100 blocks, while the
//   deepest wear agrees to 1 % and the TE p-p is 2.5e-4 rad in all);
// - largest Hertz pressure, with the unworn flanks' curvature radii.
// Archard (Archard 1953; per pass as in Flodin & Andersson 1997, Wear 207:16): wear depth
//     h = k_w p s, with p = F' / (2 a) the mean Hertz pressure over the contact band, half width
//     a = sqrt(4 F' R / (pi E*)), F' = F_j / b, R = rho1 rho2 / (rho1 + rho2), and s the sliding
//     distance while a flank point crosses the band, 2 a |v1 - v2| / v1 = 2 a |lambda1| on gear 1
// so h1 = k_w F' |lambda1| per pass (and k_w F' |lambda2| on gear 2).
// Seed 004, eq. (4)-(5): I_i = k |lambda_i| rho_red^m |V_s|^n at each profile point, with
// V_s = omega1 (rho1 - u21 rho2) the sliding speed; the depth per pass is U_i = U_max I_i / I_max.
// The seed leaves k, m, n and U_max to experiment; defaults here: m = -1/2 (Hertz pressure ~
// rho^-1/2: the seed's "rho stands in for pressure"), n = 0, and U_max taken from Archard's
// largest depth per pass on the unworn pair, so that the two laws have the same scale and differ
// in shape only; I_max is that of the unworn pair (k = U_max / I_max is the material constant of
// eq. (1) and stays fixed over the life). Why n = 0: the seed's own form is that the intensity
// depends strongly on the pressure and only weakly on the sliding speed, and the specific sliding
// lambda already is the sliding per unit of rolling (the sliding distance a point sees while it
// crosses the contact); a V_s^1 on top of it counts the sliding a second time (with n = 1 the
// deepest wear of the 18/36 pair after 1e7 cycles is 17.8 um against 25.1 um with n = 0, and
// its driven gear's profile correlates only 0.68-0.90 with Archard's). n > 0 stays available for a
// measured speed dependence (--seed-n).
// Transmission error. The reported TE (te_peak_to_peak_rad, te_harmonics_rad) is that of the
// geometry the dynamic simulator runs: every tooth pair separated along the line of action by
// g(s) = h1(s) + h2(T1T2 - s) (worn_profile_gap) with the unworn involute kinematics, so the
// first pair to touch at driver position s is the one with the smallest g over the pairs in
// contact, and TE = -min_j g(s_j) / r_b2 (driven rad; the worn driven gear lags). Rolling the
// worn flanks over each other (diag::unloaded_transmission_error) also finds corner contact on
// the unworn step just beyond the tracked flank, which carries the teeth where the gap model
// lets them separate: smaller (1e7 Archard cycles on 18/36: 820 against 1 161 urad); it is kept
// as te_rolled_peak_to_peak_rad.
// Contact. The seed's intensity is a geometric stand-in for the pressure of a point in contact;
// a point that carries no load (its pair's gap exceeds the compression) has no pressure and
// nothing sliding on it, and does not wear. The seed iterates exactly so: after each cycle the
// line of contact of the worn profiles is rebuilt and the next cycle wears along it. So U_i = 0
// where F_j = 0. (An earlier version applied the intensity at every point of the path of
// contact whatever its load: points at the start of contact went on wearing after they had lost
// contact, 91..128 um clear of their mate after 1e7 cycles on 23/61 and 18/36 pairs, and the
// loaded contact ratio of the 18/36 pair fell to 1.30 through wear that cannot happen.)
// Steps. Archard's depth rate follows the load each point carries, and wear moves the load
// (a worn zone unloads and stops wearing); the seed's rate follows whether a point is in contact.
// An explicit block that wears deeper than about the teeth's elastic deflection overshoots and the
// history depends on the number of blocks (measured on an 18/36-tooth m = 3 mm pair at 50 N m,
// static deflection ~5 um: 4 blocks to 1e7 cycles gave 80 um deepest, 40 blocks 52 um). Each
// block is therefore integrated in sub-blocks of at most substep_depth_m (1 um) of wear at any
// point, the load sharing recomputed between them (cheap: the TE and stiffness are measured once
// per block); the history is then the same whatever the number of blocks.
// The profile update is the normal depth applied to the generated flank (diag::apply_normal_depth,
// the exact form of the seed's d theta = U / r; see the correction noted there).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"

namespace sim {

enum class WearLaw {
  kArchard,  // k_w p s in physical units
  kSeed004,  // seed 004's intensity k lambda rho^m V^n, scaled by U_max
};

// "archard" / "seed004"; the parse throws diag::InputError naming `field`.
const char* wear_law_name(WearLaw law);
WearLaw parse_wear_law(const std::string& name, const std::string& field);

struct WearOptions {
  WearLaw law = WearLaw::kArchard;
  double cycles = 1e6;       // driver revolutions over the history, > 0
  int steps = 100;           // blocks of cycles / steps revolutions, >= 1 (and <= 100000)
  int profile_points = 101;  // points on each active flank, >= 11
  // Archard wear coefficient [m^2/N = m^3/(N m)], > 0. 1e-16 is the order Flodin & Andersson
  // measured for boundary-lubricated steel (they quote 5.4e-17 ... 5e-16).
  double archard_coefficient_m2_per_n = 1e-16;
  double seed_exponent_m = -0.5;            // m of rho_red^m [-]
  double seed_exponent_n = 0.0;             // n of V_s^n [-], >= 0 (header: why 0)
  double seed_max_depth_per_cycle_m = 0.0;  // U_max [m] per pass; 0: Archard's on the new pair
  double depth_limit_m = 100e-6;            // stop once a flank point has worn this deep, > 0
  int te_points_per_mesh = 64;              // driver angles per mesh period for the TE, >= 16
  // Largest Archard wear [m] at any point between two load sharings: a block is split into
  // sub-blocks that wear at most this much (header, "Steps").
  double substep_depth_m = 1e-6;
  double input_torque_nm = -1.0;  // load: torque on the gearbox's input shaft [N m]; < 0: the
                                  // description's input.torque_nm

  void validate() const;  // throws diag::InputError naming the field
};

struct WearHistory {
  // Profile points (fixed): roll distance and radius on each gear's flank [m].
  std::vector<double> roll_driver_m, roll_driven_m, radius_driver_m, radius_driven_m;
  // One entry per completed step (K <= options.steps): cycles at the end of the step.
  std::vector<double> cycles;
  std::vector<std::vector<double>> depth_driver_m, depth_driven_m;  // K x points [m]
  std::vector<double> te_peak_to_peak_rad;  // unloaded TE of the gap model [rad, driven] (header)
  std::vector<std::array<double, 3>> te_harmonics_rad;  // its mesh harmonics 1..3 (amplitudes)
  std::vector<double> te_rolled_peak_to_peak_rad;       // the worn flanks rolled (header)
  std::vector<double> loaded_contact_ratio;    // mean number of loaded pairs over a mesh period
  std::vector<double> mesh_stiffness_n_per_m;  // mean loaded (tangent) mesh stiffness (header)
  std::vector<double> max_pressure_pa;         // largest Hertz pressure over a mesh period
  // The unworn pair stiffness k(s) [N/m] at the driver's profile points (the sharing's k).
  std::vector<double> pair_stiffness_n_per_m;
  // The unworn state (before the first step), for comparison.
  double te_peak_to_peak_new_rad = 0, loaded_contact_ratio_new = 0, max_pressure_new_pa = 0;
  double normal_force_n = 0;      // total normal force F on the mesh
  bool stopped_at_limit = false;  // the depth limit ended the history before options.steps
};

// The wear history of gb.meshes()[mesh]. Throws diag::InputError for bad options, a mesh index out
// of range or a mesh without load (input torque 0).
WearHistory simulate_wear(const diag::Gearbox& gb, int mesh, const WearOptions& options);

// One point of a pair's life: the depths on both flanks' profile points (WearHistory's grids).
struct WornPair {
  double cycles = 0;  // driver revolutions
  std::vector<double> roll_driver_m, depth_driver_m, roll_driven_m, depth_driven_m;
  double te_peak_to_peak_rad = 0;  // unloaded TE of the gap model [rad, driven] (header)
  double max_depth_driver_m() const;
  double max_depth_driven_m() const;
};

// Entry `step` (0-based) of a history.
WornPair worn_pair(const WearHistory& h, std::size_t step);

// The worn pair of gb.meshes()[mesh] after options.cycles driver revolutions (target_depth_m 0:
// the last step of simulate_wear), or, with target_depth_m > 0, when its deepest flank point
// first reaches target_depth_m: the history is run (options.steps blocks per run, the length
// grown from the new pair's wear rate until the depth is passed) and the two states around the
// depth are interpolated linearly in the deepest depth, so the result's deepest point is
// target_depth_m (to round-off) and its cycles the interpolated life. options.cycles and
// depth_limit_m are ignored then. Throws diag::InputError as simulate_wear, and when the depth
// is not reached within 1e15 cycles.
WornPair wear_pair(const diag::Gearbox& gb, int mesh, WearOptions options,
                   double target_depth_m = 0.0);

// What the worn flanks do to every tooth pair of the mesh: the separation along the line of
// action at contact position s (driver roll), g(s) = h1(s) + h2(T1T2 - s) (header), on the
// driver's profile points s_m. The gap MeshStiffness::set_profile_gap applies to every pair.
void worn_profile_gap(const diag::GearPair& pair, const WornPair& w, std::vector<double>& s_m,
                      std::vector<double>& gap_m);

// The unloaded TE [rad, driven] of the gap model at `points` driver positions over one base
// pitch, s = s_start + p_b (i + 0.5) / points: -min over the pairs in contact of g(s_j) / r_b2
// (header, "Transmission error").
std::vector<double> worn_gap_transmission_error(const diag::GearPair& pair, const WornPair& w,
                                                int points);

// Pearson correlation of two equally long profiles (used to compare the laws' shapes).
double shape_correlation(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace sim
