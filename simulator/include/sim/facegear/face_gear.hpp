// Torsional dynamics of a single-input single-output face-gear pair (seed 002, docs/face-gear.md):
//   G. Feng, X. Huang, X. Lan, M. Zhou, "Torsional vibration modeling and analysis of a
//   face-gear pair", J. Tsinghua Univ. (Sci. & Tech.) (the seed's eqs. 1-8, 14-15).
//
// Coordinates: pinion angle theta_p, face-gear angle theta_g, ratio r = N_p / N_g. The state is
// y = [theta_p, omega_p, e, omega_g] with the dynamic transmission error (DTE, eq. 3)
//   e = theta_g - r theta_p                       [face-gear rad]
// integrated directly (not recovered from two large angles), so it keeps full precision.
//
// Contact (eqs. 4-6), b the half backlash in pinion angle, so r b in face-gear angle:
//   drive-flank deflection  d_d = -(e - e0_d(theta_p)) - r b ;  drive contact when d_d >= 0
//   coast-flank deflection  d_c =  (e - e0_c(theta_p)) - r b ;  coast contact when d_c >= 0
//   free flight otherwise (k = 0).
// e0_d, e0_c are the static TE of each flank (the paper's e0_CW, e0_CCW) as signed functions of
// theta_p; the paper's |e0_CCW| in eq. 5 only holds for a non-negative e0_CCW and is replaced by
// the signed value (the deflection must vanish where the unloaded flanks touch).
//
// Mesh torque (pinion side, positive when the drive flank carries load), eq. 8 with that sign
// and clamped so that a flank in contact only pushes:
//   T_mesh = max(0, k_d d_d + c_d d_d')  (drive),  -max(0, k_c d_c + c_c d_c')  (coast),  0 (free)
// Why the clamp: teeth in contact are pressed together and cannot pull; a Kelvin-Voigt contact
// whose deflection shrinks faster than k d / c would transmit tension (eq. 8 as printed does:
// down to -108 N m in 8-9 % of the contact samples of an impacting case). With the clamp the
// surfaces separate at the instant the contact force reaches zero, as in the spur-gear model, and
// the mesh still only dissipates: (T_mesh - k d) d' / r >= 0 when clamped, because then
// c d' < -k d <= 0 (the energy balance of the tests counts that term).
// k [N m per face-gear rad] is the paper's eq. 11 k = T_1 / |dphi_2 - e0|: pinion torque over
// face-gear deflection. Equations of motion, derived from the one potential
//   V = (1/2) (k / r) d^2      (d the loaded flank's deflection, k and e0 frozen in theta_p)
// whose generalised forces are Q_p = -dV/dtheta_p = -k d = -T_mesh (elastic part) and
// Q_g = -dV/dtheta_g = k d / r = T_mesh / r, and the Rayleigh function (1/2)(c/r) d'^2 for the mesh
// damping:
//   I_p omega_p' = T_p(t) - T_mesh - c_p omega_p
//   I_g omega_g' = (N_g/N_p) T_mesh - T_g(t) - c_g omega_g
// This is the seed's eqs. 1-2 with f = -d: the printed pinion equation, read with eq. 8's T_mesh,
// is T_p - T_mesh, the same as above; what the potential fixes is which flank carries which sign
// (docs/face-gear.md, the model), and it shows that the parametric terms (dk/dtheta_p,
// de0/dtheta_p) are not forces of the pair but an energy exchange with the drive: the energy
// balance
//   W_in - W_out + W_param = E_kin + V + D,
//   W_param = int (1/2)(d^2/r) dk + (T_mesh/r) de0_flank,  D = int c_p w_p^2 + c_g w_g^2 + (c/r)
//   d'^2
// (the same for both flanks) is checked in tests/simulator/face_gear_test.cpp.
//
// Load dependence: k is the secant stiffness of eq. 11 (k = T / d at the load T), so the elastic
// torque solves T = k(theta_p, T) d. The table is piecewise linear in the load, so within a load
// segment T = (k_i - s_i T_i) d / (1 - s_i d): the segment is found from the deflections at the
// grid loads (T / k(T) grows with T for any table whose k grows slower than T, the Hertz law
// included), and the solve is exact, a function of the state (FlankTable::elastic_torque). The
// small-vibration stiffness of the mesh mode is the tangent dT/dd, not the secant (1.5x it for
// the T^(1/3) of a point contact): natural_frequency_hz uses the tangent.
//
// Damping, eq. 7 with the inertias referred to the DTE coordinate (the printed
// alpha I_p I_g / (I_p + I_g) adds a pinion and a face-gear inertia, which is only meaningful
// when both refer to one coordinate):
//   c = alpha I_e + beta k,   1 / I_e = 1 / (r I_g) + r / I_p   [pinion torque s per gear rad]
// so that alpha and beta are the usual Rayleigh coefficients of the mesh mode
// (zeta = alpha / (2 omega_n) + beta omega_n / 2, omega_n^2 = k / I_e).
//
// Torque fluctuation (eqs. 14-15):
//   T_p = T_p0 (1 + a cos(2 pi f_p t + phi_p)),  T_g = T_g0 (1 + b cos(2 pi f_g t + phi_g)).
// T_g0 is set so that the steady mean speed is the requested one: T_g0 = (T_p0 - c_p Omega) / r -
// c_g r Omega. The static mesh torque (DLF reference) is T_static = T_p0 - c_p Omega.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace sim::facegear {

// One flank's mesh stiffness and static TE: k(angle, load) on a grid, e0(angle). Angles are the
// pinion angle within one mesh period [0, 2 pi / N_p), strictly increasing; the table is
// periodic in angle (linear interpolation across the period end). Loads [N m, pinion torque]
// strictly increasing, >= 0; outside the load range the nearest load's row is used (constant
// extrapolation, stated in docs/face-gear.md). Bilinear interpolation.
struct FlankTable {
  std::vector<double> angle_rad;  // n_a
  std::vector<double> load_nm;    // n_l
  std::vector<double> k;          // n_a x n_l, row-major: k[ia * n_l + il] [N m / rad]
  std::vector<double> e0_rad;     // n_a [face-gear rad]

  double stiffness(double angle_in_period, double load_nm, double period) const;
  // The elastic torque T >= 0 solving T = scale k(angle, T) d at a deflection d >= 0 (header,
  // "Load dependence"), and the secant stiffness scale k(angle, T) there.
  struct Elastic {
    double torque = 0.0, k = 0.0;
  };
  Elastic elastic_torque(double angle_in_period, double deflection, double period,
                         double scale) const;
  double e0(double angle_in_period, double period) const;
  // Checks the table (monotone angle within [0, period), loads, k > 0 and finite, e0 finite);
  // throws diag::InputError naming `where` and `field`.
  void validate(const std::string& where, const std::string& field, double period) const;
};

struct FaceGearPair {
  int pinion_teeth = 15;           // N_p
  int gear_teeth = 121;            // N_g
  double inertia_p = 0.0;          // I_p [kg m^2], > 0
  double inertia_g = 0.0;          // I_g [kg m^2], > 0
  double half_backlash_rad = 0.0;  // b [pinion rad], >= 0
  double damping_alpha = 0.0;      // alpha [1/s], >= 0
  double damping_beta = 0.0;       // beta [s], >= 0
  double bearing_damping_p = 0.0;  // c_p [N m s / rad], >= 0
  double bearing_damping_g = 0.0;  // c_g [N m s / rad], >= 0
  FlankTable drive, coast;
  double stiffness_scale = 1.0;  // multiplies both tables (the paper's 10x case)

  double ratio() const { return double(pinion_teeth) / gear_teeth; }  // r
  double mesh_period_rad() const;                                     // 2 pi / N_p
  double reduced_inertia() const;                                     // I_e
  // Mean drive-flank (secant) stiffness over the angle grid at `load_nm` (scaled).
  double mean_stiffness(double load_nm) const;
  // Mean drive-flank tangent stiffness dT/dd over the angle grid at `load_nm` (scaled).
  double mean_tangent_stiffness(double load_nm) const;
  // Torsional natural frequency of the mesh mode at `load_nm` [Hz], from the tangent stiffness.
  double natural_frequency_hz(double load_nm) const;
};

struct Operating {
  double speed_rpm = 4000.0;  // pinion (input) speed [rpm], > 0
  double torque_nm = 300.0;   // mean input torque T_p0 [N m], > 0
  // Torque fluctuation (eqs. 14-15).
  double input_amp = 0.0, input_freq_hz = 0.0, input_phase_rad = 0.0;  // a, f_p, phi_p
  double load_amp = 0.0, load_freq_hz = 0.0, load_phase_rad = 0.0;     // b, f_g, phi_g
};

enum class Contact : int { kCoast = -1, kFree = 0, kDrive = 1 };

// The right-hand side and the derived quantities at one state.
class Model {
 public:
  Model(const FaceGearPair& pair, const Operating& op);

  // Contact state from the geometry (drive preferred when both flanks touch, b = 0).
  Contact contact(const double* y) const;
  // dy/dt at (t, y) in contact state `c` (a located-event integrator passes the state of the
  // step; the fixed-step RK4 passes contact(y)).
  void derivatives(double t, const double* y, double* dydt, Contact c) const;
  void derivatives(double t, const double* y, double* dydt) const {
    derivatives(t, y, dydt, contact(y));
  }

  struct Mesh {
    Contact contact = Contact::kDrive;
    double deflection = 0.0;       // d of the loaded flank (drive: d_d, coast: d_c, free: 0)
    double deflection_rate = 0.0;  // d' (0 in free flight)
    double k = 0.0;                // secant stiffness at the elastic torque (0 in free flight)
    bool clamped = false;          // k d + c d' < 0: the flank touches but carries nothing
    double torque = 0.0;           // T_mesh [N m, pinion side]
    double e0 = 0.0;               // static TE of the flank in contact (drive flank's when free)
  };
  Mesh mesh(double t, const double* y, Contact c) const;
  Mesh mesh(double t, const double* y) const { return mesh(t, y, contact(y)); }
  // Switching function of leaving state `c` (sign change = event): drive: d_d, coast: d_c,
  // free: max(d_d, d_c) (>= 0 means contact).
  double switching(const double* y, Contact c) const;

  double input_torque(double t) const;
  double load_torque(double t) const;
  double static_torque() const { return t_static_; }
  double mesh_frequency_hz() const;
  // Static equilibrium on the drive flank at theta_p = 0, omega at the nominal speed.
  std::array<double, 4> initial_state() const;
  const FaceGearPair& pair() const { return pair_; }
  const Operating& operating() const { return op_; }

 private:
  FaceGearPair pair_;
  Operating op_;
  double r_, period_, omega_, t_static_, t_load0_, i_e_;
};

// Output of a run: recorded samples (every `decimation` steps) after the transients.
struct Trace {
  double dt = 0.0;
  std::vector<double> t, dte, mesh_torque, stiffness, theta_p, theta_g;
  std::vector<double>
      dte_rate;  // d(DTE)/dt = omega_g - r omega_p [rad/s]: with dte, the phase portrait
  std::vector<int> contact;
  std::vector<double> poincare;  // DTE once per mesh period (at the start of each period)
  double max_abs_mesh_torque = 0.0;
  int events = 0;  // contact switches located (adaptive integrator) or seen (RK4)
  // Recorded steps in each contact state, indexed by Contact + 1 (coast, free, drive).
  std::array<long, 3> contact_steps{};
  std::array<double, 4> final_state{};  // y at the end (to continue a sweep)
  double dte_min = 0.0, dte_max = 0.0;  // over the recorded steps
  // Subharmonic ratio A(GMF / 2) / A(GMF) of the DTE (amplitudes of the two DFT components, as
  // amplitude_at), accumulated at every step (trace kept or not, no decimation) over the first
  // 2 floor(record_periods / 2) recorded mesh periods, so that both lines fall on DFT bins (no
  // leakage from one into the other). A period-2 response has a line at GMF / 2, a period-1
  // response none (only multiples of the GMF): how users see the period doubling in the
  // spectrum. 0 with fewer than 2 recorded periods.
  double half_gmf_ratio = 0.0;
  // Mean mesh torque over the recorded steps [N m, pinion side]: what the mesh carries, less
  // than the input torque by what the pinion bearing damping takes (c_p Omega).
  double mean_mesh_torque = 0.0;
  // Relative tolerance (of the DTE peak-to-peak) below which two Poincare points count as one,
  // set by run() from the integrator's error (poincare_rel_tol).
  double period_rel_tol = 1e-3;
};

enum class Integrator { kRk4, kAdaptive };

struct RunOptions {
  Integrator integrator = Integrator::kRk4;
  int steps_per_period = 64;    // RK4 steps per mesh period (the adaptive: output grid), >= 8
  int transient_periods = 400;  // mesh periods discarded, >= 0
  int record_periods = 200;     // mesh periods recorded, >= 1
  int decimation = 1;           // keep every n-th step in the trace (Poincare is per period)
  bool keep_trace = true;       // false: only Poincare points and the maxima
  double rel_tol = 1e-9, abs_tol = 1e-12;  // adaptive integrator tolerances
  bool has_start = false;                  // start from `start` instead of static equilibrium
  std::array<double, 4> start{};
  void validate() const;
};

Trace run(const Model& model, const RunOptions& opt);

// RK4 steps per mesh period for `model`: at least `min_steps`, and at least 32 steps per period of
// the stiffest mesh mode (the table's largest stiffness), so that the step resolves the contact
// dynamics (and stays well inside RK4's stability limit h omega_n < 2.8).
int rk4_steps_per_period(const Model& model, int min_steps = 64);

// One classic RK4 step y(t) -> y(t + h), the contact state taken from y at every stage.
void rk4_step(const Model& model, double t, double h, double* y);

// Analyses of a steady response.
enum class ImpactClass { kNoImpact, kSingleSided, kDoubleSided };
const char* to_string(ImpactClass c);
ImpactClass classify_impacts(const std::vector<int>& contact);
// From the step counts of Trace::contact_steps: coast and drive both touched -> double-sided; free
// flight or coast contact alone -> single-sided; drive only -> no impact.
ImpactClass classify_impacts(const std::array<long, 3>& contact_steps);

// Period of a Poincare sequence: the smallest n <= max_period with |p_i - p_{i+n}| <= tol for
// all i, tol = rel_tol * scale, scale the DTE's peak-to-peak over the same window (the dynamic
// amplitude: the numerical jitter of the points, ~1e-4 of it where the table's kinks fall between
// RK4 stages, stays below; a period-2 split is a sizeable share of it). 0 when none (chaos or
// quasi-periodic motion; the two are not told apart).
int poincare_period(const std::vector<double>& points, double scale, double rel_tol = 1e-3,
                    int max_period = 8);
// "period-1", "period-2", "period-n" (3..max_period), "chaos" (no period found).
std::string classify_period(const std::vector<double>& points, double scale, double rel_tol = 1e-3);
// scale = trace.dte_max - trace.dte_min, rel_tol = trace.period_rel_tol.
std::string classify_period(const Trace& trace);

// The Poincare tolerance (relative to the DTE peak-to-peak `scale`) for a run with `opt`:
//  - RK4: 1e-3. Its contact switches fall between stages, so it converges at first order in
//    impacting cases; the jitter of the points is ~1e-4 of the range (measured), so 1e-3 keeps
//    a period-1 response period-1, and splits smaller than that are not resolved;
//  - adaptive (rk8pd, switches located): the error control bounds the local error of the DTE by
//    abs_tol + rel_tol max|DTE|; the tolerance is 1e4 times that (the global error grows over the
//    run; the located switches add 1e-13 of a mesh period times the DTE rate), and at least
//    1e-4 of the range (what is left of a transient after a few hundred periods of a lightly
//    damped mode), so that a split is labelled only where it is 1e4 times the error bound.
double poincare_rel_tol(const RunOptions& opt, double scale, double max_abs_dte);

// Single-sided amplitude spectrum of x at frequencies k fs / N (naive DFT up to f_max, the mean
// removed); returns pairs (f, amplitude).
std::vector<std::array<double, 2>> amplitude_spectrum(const std::vector<double>& x, double fs,
                                                      double f_max);
// Amplitude of the component at f (projection on cos/sin over the whole record).
double amplitude_at(const std::vector<double>& x, double fs, double f);

}  // namespace sim::facegear
