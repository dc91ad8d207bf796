// Single-degree-of-freedom spur gear pair with backlash and time-varying mesh stiffness, in the
// non-dimensional form of Kahraman & Singh:
//   A. Kahraman, R. Singh, "Non-linear dynamics of a spur gear pair", J. Sound Vib. 142(1)
//     (1990) 49-75 (time-invariant stiffness), and
//   A. Kahraman, R. Singh, "Interactions between time-varying mesh stiffness and clearance
//     non-linearities in a geared system", J. Sound Vib. 146(1) (1991) 135-156.
// (The title sometimes cited with 142(1) 1990 is the 1991 paper in 146(1).)
//
//   x'' + 2 zeta x' + k(tau) f(x) = F_m + sum_r F_r (r Omega)^2 cos(r Omega tau + phi_r)
//   k(tau) = 1 + sum_r alpha_r cos(r Omega tau + psi_r)
//   f(x) = x - b  for x > b        drive-flank contact
//        = 0      for |x| <= b     free flight (contact lost)
//        = x + b  for x < -b       back-flank contact
//
// x is the dynamic transmission error along the line of action divided by the half-backlash
// b_c (so the normalised half-backlash b = 1; b = 0 is the linear system f(x) = x); time is
// tau = omega_n t with omega_n = sqrt(k_mean / m_e); Omega = omega_mesh / omega_n; F_m is the
// mean load F / (m_e b_c omega_n^2) = the static deflection over b_c; F_r the amplitude of the
// r-th harmonic of the static transmission error over b_c (the displacement excitation e(t)
// enters as m_e e'' on the right side, hence the (r Omega)^2). Parameters of the papers'
// figures: zeta = 0.05, F_m = 0.1, alpha_1 = 0.2 (1991), F_1 of order 0.01...0.1.
//
// Integration: classic fixed-step RK4 with `steps_per_period` steps per excitation period
// 2 pi / Omega. CAUTION: f(x) has kinks at |x| = b, where RK4 drops to first order locally; the
// error stays small with >= 200 steps per period (checked against the linear closed form).
#pragma once

#include <string>
#include <vector>

namespace sim {

struct Harmonic {
  double amplitude = 0.0;  // alpha_r [-] (stiffness) or F_r [-] (transmission error)
  double phase_rad = 0.0;  // psi_r or phi_r [rad]
};

struct SdofBacklashOptions {
  double damping_ratio = 0.05;  // zeta [-], [0, 1)
  double mean_load = 0.1;       // F_m [-], >= 0 (static deflection / half-backlash)
  double half_backlash = 1.0;   // b [-]: 1 in the papers' normalisation, 0 = linear system
  // k(tau) = 1 + sum alpha_r cos(r Omega tau + psi_r); |sum alpha_r| < 1 so that k > 0.
  std::vector<Harmonic> stiffness = {{0.2, 0.0}};
  // Static transmission error harmonics F_r (r = 1, 2, ...), force F_r (r Omega)^2.
  std::vector<Harmonic> transmission_error = {{0.05, 0.0}};
  int steps_per_period = 256;   // RK4 steps per excitation period, >= 32
  int transient_periods = 300;  // periods discarded before recording at each frequency, >= 0
  int record_periods = 40;      // periods recorded at each frequency, >= 1

  // Throws diag::InputError naming `where` and the field.
  void validate(const std::string& where) const;
};

struct SdofState {
  double x = 0.0;  // non-dimensional DTE
  double v = 0.0;  // dx/dtau
};

// Right-hand side: the acceleration x'' at time tau for excitation frequency Omega.
double sdof_acceleration(const SdofBacklashOptions& o, double omega, double tau, double x,
                         double v);

// Integrates `periods` excitation periods from tau = 0 (the excitation phase restarts at 0) and
// returns the final state. If `samples` is non-null, appends x at every step (steps_per_period
// per period, the initial state excluded).
SdofState sdof_integrate(const SdofBacklashOptions& o, double omega, SdofState start, int periods,
                         std::vector<double>* samples = nullptr);

// Steady-state response at one frequency.
struct SdofResponse {
  double omega = 0.0;  // Omega [-]
  double mean = 0.0;   // mean of x over the recorded periods
  double rms = 0.0;    // RMS of x - mean
  double peak = 0.0;   // max |x - mean|
  double x_min = 0.0, x_max = 0.0;
  bool contact_lost = false;        // x < b at some recorded step (drive flank separated)
  bool back_impact = false;         // x < -b at some recorded step (back-flank contact)
  double separated_fraction = 0.0;  // fraction of recorded steps with |x| <= b
};

// Runs transient_periods (discarded) then record_periods from `start`; `end` (if non-null)
// receives the final state.
SdofResponse sdof_steady_state(const SdofBacklashOptions& o, double omega, SdofState start,
                               SdofState* end = nullptr);

struct SdofSweep {
  std::vector<SdofResponse> up;    // Omega increasing
  std::vector<SdofResponse> down;  // Omega decreasing (down[0] at omega_max)
};

// Frequency sweep: `points` (>= 2) equally spaced Omega in [omega_min, omega_max] run up, then
// the same points run down. Every frequency starts from the previous one's final state; the run
// up starts from static equilibrium (x = b + F_m, v = 0), the run down from the run up's end.
SdofSweep sdof_sweep(const SdofBacklashOptions& o, double omega_min, double omega_max, int points);

}  // namespace sim
