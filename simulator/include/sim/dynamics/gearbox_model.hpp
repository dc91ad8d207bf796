// Lumped-parameter dynamics of a gearbox (docs/physics.md; seed 000, Kalinin & Temis 2018,
// generalised from one pair to the gearbox description's meshes).
//
// Degrees of freedom. Every gear g turns by theta_g = r_g theta_in,nom(t) + psi_g, where
// theta_in,nom is the motor's prescribed angle, r_g = |omega_g / omega_in| and angles are
// counted in each gear's own sense of rotation (forward positive); psi_g is the vibratory part
// (the state). Every shaft s that carries gears translates on its bearings by (x_s, y_s) in one
// fixed frame (x horizontal, y vertical). A pair of gears on separate shafts is the seed's 6-DOF
// model: q = {psi1, psi2, x1, y1, x2, y2} (the seed's order differs; docs/physics.md).
//
// Mesh j (driver a on shaft A, driven b on shaft B). Its frame has x along the centre line from A
// to B and the line of action (LOA) along n = (sin a_w, cos a_w) when the driver turns
// counter-clockwise (mirrored in y otherwise); t = (-cos a_w, sin a_w) is the tangential direction
// of both surfaces' sliding. The dynamic transmission error (compression of the mesh) is
//     delta = r_ba psi_a - r_bb psi_b + n . (u_A - u_B) + e_runout(t) - e(theta_a)  (seed eq. 4)
// and its gradient g = d delta / dq (r_ba, -r_bb, n, -n) is what couples the DOFs: the mesh
// stiffness matrix is k g g^T (so K56 = -k cos^2 a_w, corrected: docs/physics.md).
// e(theta_a) = sum_h A_h cos(h z_a theta_a + phi_h) is the mesh-periodic static transmission
// error (the unloaded TE of profile modifications and manufacture, as a displacement along the
// LOA), the classic displacement excitation of a mesh (Ozguven & Houser, J. Sound Vib. 121 (1988)
// 383; Kahraman & Singh 1990): each pair's force is k_i (delta_0 - e) + c (delta_0' - e') with
// delta_0 the compression without it, k(t)(delta - e(t)) in the usual notation.
// Tooth pairs i in contact sit at LOA positions s_i (GearPair convention) found from the driver's
// total angle; each carries
//     F_i = max(0, k_i(s_i) (delta - gap_i(s_i)) + c_z (k_i / k_mean) delta')
// (k_i, gap_i from MeshStiffness: load sharing, tooth faults, pitch errors). The back flank
// carries k_sum (delta + b) + c_z delta' when delta < -b (three-state backlash, b the backlash
// along the LOA); in between, free flight. c_z = 2 zeta sqrt(k_mean / (r_ba^2/J_a + r_bb^2/J_b)).
// Friction on each drive pair, perpendicular to the LOA (the seed's eq. 6 corrected,
// docs/physics.md):
//     on gear a's centre  -sigma_i mu_i F_i t,   moment -sigma_i mu_i F_i rho1_i
//     on gear b's centre  +sigma_i mu_i F_i t,   moment +sigma_i mu_i F_i rho2_i
// sigma_i = sign of the sliding speed v1 - v2 at s_i (-1 in the approach, +1 in the recess, 0 at
// the pitch point: friction reverses there), rho1 = s_i and rho2 = T1T2 - s_i the arms (the
// seed's l(phi) measured from each gear's tangency point).
//
// Drive: a speed-controlled motor (prescribed angle) through a torsional coupling to the input
// gear, or a torque-driven motor (constant torque) with a load torque proportional to speed (a
// generator) that holds the mean speed. Load: constant torque on the output gear. Gears on one
// shaft are joined by the shaft's torsional stiffness. Bearings: stiffness and damping per shaft
// in x and y (the sum over the shaft's bearings).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"
#include "sim/dynamics/speed_profile.hpp"
#include "sim/mesh/friction.hpp"
#include "sim/mesh/mesh_stiffness.hpp"
#include "sim/wear/wear.hpp"

namespace sim {

enum class MotorMode {
  kSpeed,   // the motor follows the speed profile exactly; a coupling spring drives the input gear
  kTorque,  // constant input torque; the load torque grows with output speed (generator)
};

// A tooth fault placed on a gear of the gearbox, by name.
struct GearFault {
  std::string gear;  // gear name in the gearbox description
  ToothFault fault;  // fault.gear (0/1) is filled in per mesh; fault.tooth is the tooth index
  std::string profile_json;  // a flank deviation (sim::profile_fault) replacing `fault`, or empty
};

// A measured or FEM mesh stiffness table for one mesh (MeshStiffness::from_table): total mesh
// stiffness k[i][j] [N/m] at driver angle angle_deg[i] within the mesh period and load load_n[j].
struct StiffnessTable {
  std::string mesh;  // "<driver>_<driven>" gear names
  std::vector<double> angle_deg;
  std::vector<double> load_n;
  std::vector<std::vector<double>> k_n_per_m;
};

// Worn flanks of one mesh (seed 004, sim/wear.hpp, docs/wear.md): the scenario's faults[] entry
// {"type": "wear"} or a point of life of `geardiag wear --record-every`. Every tooth pair of the
// mesh gets the worn flanks' separation g(s) (sim::worn_profile_gap) as a gap on the line of
// action (MeshStiffness::set_profile_gap), the same path as a profile defect's gap on one tooth:
// load sharing, the loaded mesh stiffness (pairs losing contact) and the transmission error then
// follow from the worn profiles.
struct MeshWear {
  std::string mesh;  // "<driver>_<driven>"; or empty, with `gear` a gear of exactly one mesh
  std::string gear;
  std::string where;  // for messages, e.g. "sc.json: faults[2]"
  WornPair state;     // given (state.depth_driver_m non-empty), or computed from the fields below
  WearLaw law = WearLaw::kArchard;
  double cycles = 0;   // > 0: the wear of this many driver revolutions at the run's input torque
  double depth_m = 0;  // > 0: worn until the deepest flank point reaches this depth
  int steps = 10;      // blocks of the wear history that computes the state
};

// A mesh's wear as the model applied it (for the truth).
struct AppliedWear {
  int mesh = 0;
  WearLaw law = WearLaw::kArchard;
  WornPair state;
  double max_gap_m = 0;  // largest pair separation g(s) over the path of contact
};

struct DynamicsOptions {
  SpeedProfile speed;             // input shaft speed; kind kConstant with rpm 0 means: the
                                  // gearbox's input speed_rpm
  double input_torque_nm = -1.0;  // < 0: the gearbox's input torque_nm
  MotorMode motor = MotorMode::kSpeed;
  double coupling_stiffness_nm_per_rad = 0.0;  // motor coupling [N m/rad]; 0: automatic (the
                                               // coupling mode at 1/20 of the lowest mesh's
                                               // torsional natural frequency)
  double coupling_damping_ratio = 0.5;         // [-], (0, 2]
  double mesh_damping_ratio = 0.1;             // zeta of c_z [-], seed: 0.05..0.17, default 0.1
  double bearing_stiffness_x_n_per_m = 2.0e8;  // per bearing [N/m] (two per shaft), > 0
  double bearing_stiffness_y_n_per_m = 2.0e8;  // per bearing [N/m], > 0
  double bearing_damping_ratio = 0.05;         // [-] of each shaft's translational mode
  double shaft_torsional_stiffness_nm_per_rad = 0.0;  // between gears on one shaft; 0: a steel
                                                      // shaft of 0.6 x the smallest root diameter
                                                      // and 100 mm length
  double shaft_damping_ratio = 0.02;                  // [-]
  double backlash_m = -1.0;                      // < 0: each mesh's backlash_m, and when that is
                                                 // 0, the ISO/TR 10064-2 minimum
                                                 // (2/3)(0.06 + 0.0005 a + 0.03 m) mm
  bool back_flank = true;                        // false: infinite backlash (the seed's h(delta))
  StiffnessOptions stiffness;                    // potential-energy method options
  std::vector<StiffnessTable> stiffness_tables;  // meshes whose stiffness comes from a table
                                                 // (no faults or pitch errors on those meshes)
  FrictionOptions friction;                      // law, mu, oil and temperature
  std::vector<GearFault> faults;                 // tooth faults
  std::vector<MeshWear> wear;                    // worn flanks, at most one per mesh
  int accuracy_grade = 0;                        // ISO 1328-1 grade of pitch errors, 0: none, 1..12
  double runout_m = 0.0;                         // eccentricity of every gear [m], >= 0
  // Static transmission error of every mesh, harmonic h = 1, 2, ... of the mesh frequency:
  // amplitude A_h [m] (>= 0) and phase phi_h [rad] of e = sum A_h cos(h z_a theta_a + phi_h)
  // (theta_a the driver's total angle). Empty: none. Phases may be shorter (missing: 0).
  std::vector<double> te_amplitude_m;
  std::vector<double> te_phase_rad;
  std::uint64_t seed = 1;  // pitch errors and runout phases

  void validate(const std::string& where) const;
};

// What one evaluation of the equations gives besides the derivatives (for sensors and checks).
struct MeshState {
  double delta_m = 0;            // dynamic transmission error (mesh compression) [m]
  double force_n = 0;            // total normal force (drive flank > 0, back flank < 0) [N]
  double friction_n = 0;         // sum of sigma_i mu_i F_i (force on gear b along t) [N]
  double stiffness_n_per_m = 0;  // sum of the pairs' stiffnesses in contact
  int contact = 0;               // 1 drive flank, 0 free flight, -1 back flank
  int pairs = 0;                 // pairs carrying load
};

struct Observation {
  std::vector<double> acceleration;  // q'' of every DOF
  std::vector<MeshState> meshes;
  double motor_power_w = 0;     // power into the system at the motor
  double load_power_w = 0;      // power taken by the load
  double damping_power_w = 0;   // dissipated in all dampers
  double friction_power_w = 0;  // dissipated by mesh friction (>= 0 up to discretisation)
};

class GearboxModel {
 public:
  GearboxModel(const diag::Gearbox& gb, const DynamicsOptions& options);
  ~GearboxModel();
  GearboxModel(GearboxModel&&) noexcept;

  int dofs() const;  // n; the state has 2n entries (q, q')
  int gear_dof(int gear) const { return gear; }
  int shaft_x_dof(int shaft) const;  // -1 for a shaft without gears
  // dy/dt at time t. `obs` may be null; when given it is filled too.
  void derivatives(double t, const double* y, double* dydt, Observation* obs = nullptr) const;
  // Static equilibrium under the mean loads at mean mesh stiffness (the initial state).
  std::vector<double> equilibrium_state() const;
  // Undamped natural frequencies at mean mesh stiffness, ascending [Hz] (rigid-body modes
  // included as 0 in torque mode).
  std::vector<double> natural_frequencies_hz() const;
  // The classic torsional natural frequency of mesh j alone:
  // sqrt(k_mean (r_ba^2/J_a + r_bb^2/J_b)) / 2 pi [Hz].
  double mesh_torsional_frequency_hz(int mesh) const;
  double mean_mesh_stiffness_n_per_m(int mesh) const;
  double mesh_backlash_m(int mesh) const;

  // Energy bookkeeping for the energy-balance check: kinetic (with the nominal rotation) plus
  // every spring's potential energy [J], and the work done on the system by the time variation of
  // the mesh stiffness when the driver angle goes from y0's to y1's at fixed deflections
  // (trapezoidal in the deflection) [J].
  double total_energy_j(double t, const double* y) const;
  double parametric_work_j(double t0, const double* y0, double t1, const double* y1) const;

  // The set of tooth pairs in contact at (t, y), as a number that changes whenever a pair enters
  // or leaves any mesh's path of contact or crosses its pitch point (the mesh cycle index, the
  // pair count and the pairs before the pitch point). The pair stiffness jumps at the path's ends
  // (potential-energy method: 0 to a finite value) and friction reverses at the pitch point, so a
  // fixed-step integrator that steps across such an instant makes an error that depends on where
  // in the step it falls; simulate() refines those steps (RunOptions).
  std::uint64_t contact_signature(double t, const double* y) const;

  // Total angle of gear g (forward sense) [rad] and the nominal input angle.
  double gear_angle_rad(int gear, double t, const double* y) const;
  double gear_speed_ratio(int gear) const;  // r_g = |omega_g / omega_in|
  int input_gear() const;
  int output_gear() const;
  double load_torque_nm() const;
  double input_torque_nm() const;
  // Unit vectors (x, y) of mesh j's LOA and of its normal (cos a_w, -sin a_w) mapped to the fixed
  // frame: the "along" and "normal" sensor directions.
  std::pair<double, double> loa_direction(int mesh) const;
  std::pair<double, double> normal_direction(int mesh) const;
  const DynamicsOptions& options() const;
  const diag::Gearbox& gearbox() const;
  const std::vector<AppliedWear>& applied_wear() const;  // DynamicsOptions::wear, resolved
  // Updates the friction tables for the speed at time t (called by the integrator when the
  // speed has changed by more than 2 % since the last update; cheap to call).
  void update_speed(double t);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sim
