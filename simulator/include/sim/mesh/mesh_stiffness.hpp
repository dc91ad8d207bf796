// Time-varying mesh stiffness of an external spur pair (driver = gear 1, driven = gear 2), with
// tooth faults and per-tooth pitch errors, tabulated once and evaluated by inline interpolation.
//
// Positions on the line of action (LOA) are s [m] from T1 (diag::GearPair): contact runs from
// s_start to s_end; a point of gear 1's flank in contact at s has roll distance rho1 = s, gear 2's
// rho2 = T1T2 - s.
//
// Single-pair stiffness, potential-energy method (Yang & Lin 1987; Tian 2004; Chen & Shao 2011):
// each tooth is a cantilever on the root circle, loaded at the contact point by the normal force F
// along the LOA. With y the coordinate along the tooth centre line (from the gear centre), H(y)
// the section height, A = b H, I = b H^3 / 12, G = E / (2 (1 + nu)), alpha1 the angle of the load
// with the normal to the centre line (alpha1 = rho / r_b - alpha2, alpha2 = pi / (2 z) + inv(alpha)
// + 2 x tan(alpha) / z the half tooth angle at the base circle) and (y_c, h_c) the contact point:
//     1/k_b = Int [cos(alpha1) (y_c - y) - h_c sin(alpha1)]^2 / (E I) dy        bending
//     1/k_s = Int 1.2 cos^2(alpha1) / (G A) dy                                   shear
//     1/k_a = Int sin^2(alpha1) / (E A) dy                                       axial compression
// from the root circle to the contact. Below the base circle (r_f < r_b) the flank is the straight
// line parallel to the centre line at h = r_b sin(alpha2) down to the root circle (Chen & Shao
// 2011, section 2); above it the involute. When r_f > r_b the beam starts on the involute at r_f.
// Fillet foundation (Sainsot, Velex & Duverger 2004, J. Mech. Des. 126:748, eq. 9 and table 1):
//     1/k_f = cos^2(alpha1) / (E b) [L* (u_f/S_f)^2 + M* (u_f/S_f) + P* (1 + Q* tan^2(alpha1))]
// u_f = r_b / cos(alpha1) - r_f: from the root circle, along the centre line, to the point where
// the load line crosses the centre line; S_f = 2 r_f theta_f the tooth thickness (arc) at the root
// circle; X* = A/theta_f^2 + B h_fi^2 + C h_fi/theta_f + D/theta_f + E h_fi + F with h_fi = r_f /
// r_int (r_int the bore radius). Hertzian contact of two steel cylinders, load-independent
// (Yang & Lin 1987), generalised to two materials:
//     k_h = (pi b / 2) E*,   1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2
// which is k_h = pi E b / (4 (1 - nu^2)) for equal materials; b the common face width.
//     k_pair(s) = 1 / (1/k_h + sum over both gears of (1/k_b + 1/k_s + 1/k_a + 1/k_f)).
// Plane stress (E, not E / (1 - nu^2)) in the beam terms, as in the sources.
//
// Tooth numbering: at phi1 = 0 driver tooth 0 meets driven tooth 0 at s_start; the k-th pair to
// enter contact (k = 0, 1, ...) is driver tooth k mod z1 against driven tooth k mod z2. Teeth are
// numbered in the order they enter the mesh.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "diag/faults/fault_kind.hpp"
#include "diag/geometry/gear.hpp"
#include "diag/geometry/gear_pair.hpp"

namespace sim {

// A localised tooth fault. Interpretation of the sizes by kind:
//  kRootCrack: straight crack from the root of the loaded flank (where the flank meets the root
//    circle), at options.crack_angle_rad to the tooth centre line, of length size_m. The section
//    behind the crack carries nothing: the effective section spans from the unloaded flank to the
//    line through the crack tip parallel to the centre line (Tian 2004; Chen & Shao 2011, case 1);
//    when the tip has crossed the centre line, to the straight line from the crack tip to the
//    centre of the top land (case 2). width_fraction of the face is cracked; that part and the
//    intact part act as parallel springs. Requires size_m sin(angle) <= 1.8 h_root (the crack must
//    leave at least 10 % of the root section).
//  kChip: the tooth tip is lost down to size_m [m] measured along the involute from the tip, over
//    width_fraction of the face. Where the mate would touch the lost part, that part never carries
//    load (gap +inf) and the pair's stiffness is scaled by (1 - width_fraction); with
//    width_fraction = 1 the pair carries nothing there, i.e. the tooth's contact ends early
//    (driver) or starts late (driven).
//  kMissing: the tooth never carries load (size_m, depth_m ignored).
//  kSpall: over [s_center - size_m/2, s_center + size_m/2] on the LOA, width_fraction of the face
//    is recessed by depth_m: the remaining width carries load from the first contact (stiffness
//    scaled by 1 - width_fraction), the spalled width only once the compression exceeds depth_m.
//    A full-width spall (width_fraction = 1) is a gap of depth_m at full stiffness.
struct ToothFault {
  enum class Kind { kRootCrack, kChip, kMissing, kSpall };
  Kind kind = Kind::kRootCrack;
  int gear = 0;                 // 0 driver, 1 driven
  int tooth = 0;                // 0 .. z - 1 (numbering above)
  double size_m = 0.0;          // crack length / chip depth along the profile / spall length [m]
  double depth_m = 0.0;         // spall depth (the gap it opens) [m], >= 0
  double width_fraction = 1.0;  // part of the face width affected, (0, 1]
  double s_center_m = std::numeric_limits<double>::quiet_NaN();  // spall centre on the LOA [m];
                                                                 // NaN: the pitch point
};

// The fault vocabulary's kind of a tooth fault (diag/faults/fault_kind.hpp): crack, chip, missing,
// spall.
diag::FaultKind fault_kind(ToothFault::Kind k);

struct StiffnessOptions {
  bool fillet_foundation = true;  // add Sainsot's fillet-foundation compliance (off: stiffer)
  int grid_points = 401;          // tabulation points over the path of contact, >= 16
  double crack_angle_rad = std::numbers::pi / 4;  // crack to tooth centre line [rad], (0, pi/2]
  double bore_radius_ratio = 0.5;  // r_int / r_f: bore over root radius for Sainsot's h_fi, (0, 1)
                                   // (h_fi = 2 at the default)

  void validate() const;  // throws diag::InputError naming the field
};

// Compliances [m/N] of one tooth loaded at roll distance rho (distance along the LOA from the
// gear's own base-circle tangency point to the contact; rho = s for the driver, T1T2 - s for the
// driven gear).
struct ToothCompliance {
  double bending_m_per_n = 0, shear_m_per_n = 0, axial_m_per_n = 0, fillet_m_per_n = 0;
  double total() const { return bending_m_per_n + shear_m_per_n + axial_m_per_n + fillet_m_per_n; }
};
// crack_depth_m > 0: the root crack described under ToothFault (over the full face width).
// Throws diag::InputError when rho is outside (0, tip roll distance] or the crack is too deep.
ToothCompliance tooth_compliance(const diag::Gear& gear, double rho_m,
                                 const StiffnessOptions& options = {}, double crack_depth_m = 0.0);

// Hertzian contact stiffness k_h [N/m] of the pair (formula above).
double hertz_stiffness(const diag::GearPair& pair);

struct ToothContact {
  double s_m = 0;        // position on the LOA [m]
  int driver_tooth = 0;  // 0 .. z1 - 1
  int driven_tooth = 0;  // 0 .. z2 - 1
};
struct MeshContacts {  // every pair in contact, s increasing (same as GearPair::contacts_at)
  int count = 0;
  std::array<ToothContact, 4> pairs{};
};

class MeshStiffness {
 public:
  // Tabulates the healthy pair stiffness and each faulty tooth's own compliance. Pitch errors are
  // per-tooth flank position deviations along the LOA [m] (positive: the flank lies behind its
  // nominal place, a gap; negative: ahead), one per tooth or empty for none (see
  // pitch_errors_iso1328). Throws diag::InputError for bad options, faults or error vectors.
  MeshStiffness(const diag::GearPair& pair, const StiffnessOptions& options = {},
                std::vector<ToothFault> faults = {}, std::vector<double> driver_pitch_errors_m = {},
                std::vector<double> driven_pitch_errors_m = {});

  // A measured / FEM table: k_n_per_m[i][j] is the total mesh stiffness [N/m] at angle_deg[i]
  // (driver rotation within the mesh period [0, 360/z1) from the moment a pair enters at s_start,
  // strictly increasing, periodic) and load_n[j] (strictly increasing, > 0). At static_load_n
  // (linear in load; outside [load_n.front(), load_n.back()] is an error, not an extrapolation)
  // the table gives k_tab(phi), linear and periodic in angle. Each pair then gets
  // k_pair(s) = k_pem(s) k_tab(phi) / k_mesh_pem(phi), phi the mesh phase of s, so the sum over
  // the pairs in contact reproduces k_tab(phi) and the split follows the analytical stiffnesses.
  // CAUTION: within one grid cell of a change in the number of pairs in contact the tabulated
  // split is linearly blended, so the sum there departs from k_tab.
  static MeshStiffness from_table(const diag::GearPair& pair, std::vector<double> angle_deg,
                                  std::vector<double> load_n,
                                  std::vector<std::vector<double>> k_n_per_m, double static_load_n,
                                  const StiffnessOptions& options = {});

  // Stiffness [N/m] of the pair driver_tooth / driven_tooth at s once it carries load: 0 outside
  // the path of contact (allowance 1e-3 grid cell) and for a missing tooth. Fast when both teeth
  // are healthy: one flag test and a linear interpolation. Teeth must be in 0 .. z - 1.
  double pair_stiffness(double s_m, int driver_tooth, int driven_tooth) const {
    const double x = (s_m - s0_) * inv_ds_;
    if (!(x >= -kEdgeCells && x <= last_ + kEdgeCells)) return 0.0;
    if (faulty1_[driver_tooth] | faulty2_[driven_tooth]) {
      return faulty_pair_stiffness(s_m, driver_tooth, driven_tooth);
    }
    return interpolate(k_pair_, x);
  }

  // pair_stiffness for a mesh without faults (has_faults() false): the same value without the
  // per-tooth fault test.
  double healthy_pair_stiffness(double s_m) const {
    const double x = (s_m - s0_) * inv_ds_;
    if (!(x >= -kEdgeCells && x <= last_ + kEdgeCells)) return 0.0;
    return interpolate(k_pair_, x);
  }

  // Compression [m] the pair must exceed before it carries load (faults + pitch errors); +inf:
  // never (missing tooth, full-width chip). Where a partial-width spall has a second, deeper
  // contact, this is the first one (pair_force has both).
  double pair_gap(double s_m, int driver_tooth, int driven_tooth) const {
    if (faulty1_[driver_tooth] | faulty2_[driven_tooth]) {
      return faulty_pair_gap(s_m, driver_tooth, driven_tooth);
    }
    return gap1_[driver_tooth] + gap2_[driven_tooth] + profile_gap(s_m);
  }

  // A flank deviation shared by every tooth pair (worn profiles: sim::worn_profile_gap): pair
  // separation g(s) [m] along the LOA at position s, given at increasing s_m (linear in between,
  // held at the ends), resampled on the stiffness grid and added to every pair's gap. Throws
  // diag::InputError for unequal lengths, fewer than 2 points, non-increasing s or a g that is
  // negative or not finite.
  void set_profile_gap(const std::vector<double>& s_m, const std::vector<double>& gap_m);
  bool has_profile_gap() const { return !profile_gap_.empty(); }
  // The shared gap at s [m] (0 without one).
  double profile_gap(double s_m) const {
    if (profile_gap_.empty()) return 0.0;
    return interpolate(profile_gap_, std::clamp((s_m - s0_) * inv_ds_, 0.0, last_));
  }

  // Normal force [N] of the pair at compression delta [m] (tooth separation gives 0): the
  // piecewise-linear law k_pair sum_parts fraction (delta - gap_part)^+, exact for partial-width
  // spalls and chips. For a healthy pair this is pair_stiffness * max(delta - pair_gap, 0).
  double pair_force(double s_m, int driver_tooth, int driven_tooth, double compression_m) const;

  // The pairs in contact at driver rotation phi1 [rad] with their teeth (numbering above).
  MeshContacts contacts(double phi1_rad) const;

  double mesh_stiffness(double phi1_rad) const;         // healthy teeth: sum over pairs in contact
  double faulty_mesh_stiffness(double phi1_rad) const;  // same with the actual teeth's
                                                        // pair_stiffness (gaps not applied)
  double mean_mesh_stiffness() const;                   // average over one mesh period [N/m]
  double max_pair_stiffness() const { return k_max_; }  // largest pair stiffness [N/m]
  const diag::GearPair& pair() const { return pair_; }
  bool has_faults() const { return !faults_.empty(); }
  bool has_pitch_errors() const { return has_pitch_errors_; }  // any nonzero per-tooth gap
  const std::vector<ToothFault>& faults() const { return faults_; }

 private:
  struct Part {  // a strip of the face width in a faulty contact
    double fraction, gap_m;
  };
  struct ToothState {  // a faulty tooth
    struct Interval {  // on [s_lo, s_hi], `fraction` of the face lies gap_m back (+inf: lost)
      double s_lo, s_hi, fraction, gap_m;
    };
    std::vector<double> compliance;  // the tooth's compliance on the grid [m/N]; empty: healthy
    bool missing = false;
    std::vector<Interval> intervals;
  };

  struct TabulateOnly {};  // the healthy tables only, no faults or errors yet
  MeshStiffness(const diag::GearPair& pair, const StiffnessOptions& options, TabulateOnly);
  static double interpolate(const std::vector<double>& table, double x) {
    int i = static_cast<int>(x);
    if (i < 0) i = 0;
    const int last = static_cast<int>(table.size()) - 2;
    if (i > last) i = last;
    const double f = x - i;
    return table[i] + f * (table[i + 1] - table[i]);
  }
  double faulty_pair_stiffness(double s_m, int i, int j) const;
  double faulty_pair_gap(double s_m, int i, int j) const;
  double full_width_pair_stiffness(double s_m, int i, int j) const;  // crack only, no width loss
  int parts(double s_m, int i, int j, std::array<Part, 16>& out) const;
  void add_fault(const ToothFault& f);

  static constexpr double kEdgeCells = 1e-3;  // allowance past the path ends, in grid cells

  diag::GearPair pair_;
  StiffnessOptions options_;
  double s0_ = 0, ds_ = 0, inv_ds_ = 0, last_ = 0;
  double theta_ = 0, rb1_ = 0, pb_ = 0, s_end_tol_ = 0;  // mesh period, r_b1, p_b, s_end + 0.5 nm
  std::vector<double> k_pair_;                           // healthy pair stiffness on the grid [N/m]
  std::vector<double> c1_, c2_;  // healthy tooth compliances on the grid [m/N]
  double c_hertz_ = 0;           // 1 / k_h [m/N]
  double k_max_ = 0;
  std::vector<std::uint8_t> faulty1_, faulty2_;  // per tooth: has a fault
  std::vector<double> gap1_, gap2_;              // per tooth: pitch error gap [m]
  std::vector<double> profile_gap_;              // shared by all pairs, on the grid [m]; or empty
  bool has_pitch_errors_ = false;
  std::vector<int> state1_, state2_;  // per tooth: index into states_ or -1
  std::vector<ToothState> states_;
  std::vector<ToothFault> faults_;
};

// ISO 6336-1:2006 method B (clause 9): single stiffness and mesh stiffness per unit face width
// [N/m^2 = N/m per m of face width]:
//   q' = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1^2 + C9 x2^2
//        [mm um / N], C1..C9 = 0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188,
//        0.00529, 0.00182;  c'_th = 1/q'
//   c' = c'_th C_M C_R C_B cos(beta) (E/E_st),  C_M = 0.8, C_R = 1 (solid discs),
//   C_B = [1 + 0.5 (1.2 - h_fP/m)] [1 - 0.02 (20 deg - alpha_P)] averaged over the two racks,
//   E = 2 E1 E2 / (E1 + E2), E_st = 206 GPa;   c_gamma_alpha = c' (0.75 eps_alpha + 0.25).
// Valid as the standard states for specific loads F_t/b >= 100 N/mm (no low-load reduction here).
struct Iso6336Stiffness {
  double c_prime_th_n_per_m2 = 0, c_prime_n_per_m2 = 0, c_gamma_alpha_n_per_m2 = 0;
};
Iso6336Stiffness iso6336_method_b(const diag::GearPair& pair);
// 1 N/(mm um) = 1e9 N/m^2.
constexpr double to_n_per_mm_um(double n_per_m2) { return n_per_m2 * 1e-9; }

// ISO 1328-1:1995 single pitch tolerance f_pt [m] for accuracy grade Q (0..12):
//   f_pt = (0.3 (m + 0.4 sqrt(d)) + 4) 2^((Q - 5)/2) um,  m, d in mm
// with the gear's own m and d (not the geometric means of the standard's ranges, and unrounded).
// Correction: the brief printed 0.3 (m + 0.4 sqrt(d) + 4); the standard's grade-5 value for
// d = 20..50 mm, m = 2..3.5 mm (5.5 um) fits only 0.3 (m + 0.4 sqrt(d)) + 4.
double single_pitch_tolerance_iso1328_m(const diag::Gear& gear, int accuracy_grade);

enum class PitchErrorDistribution {
  kUniform,  // single pitch deviations uniform in [-f_pt, f_pt]
  kNormal,   // normal, sigma = f_pt / 3, redrawn outside [-f_pt, f_pt]
};
// Per-tooth flank position deviations along the LOA [m] for MeshStiffness (z values, one per
// tooth): single pitch deviations drawn with `seed` (std::mt19937_64), made to close around the
// gear (their sum is zero; rescaled if that pushed one past f_pt), accumulated into positions and
// centred (a common offset is a rigid rotation, not an error). Consecutive differences (cyclic)
// are the single pitch deviations, each within +-f_pt. Deterministic for a given seed.
std::vector<double> pitch_errors_iso1328(
    const diag::Gear& gear, int accuracy_grade, std::uint64_t seed,
    PitchErrorDistribution distribution = PitchErrorDistribution::kUniform);

}  // namespace sim
