#include "sim/dynamics/gearbox_model.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "sim/mesh/profile_fault.hpp"

namespace sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kShearModulusSteelPa = 79.3e9;
constexpr double kDefaultShaftLengthM = 0.1;
constexpr int kFrictionTablePoints = 257;
// derivatives() accumulates the forces in a local array: stores to it cannot alias the model's
// parameters, so the compiler keeps those in registers instead of reloading every one after each
// force update (stores through a double* into dydt may alias any double member of Impl).
constexpr int kMaxDofs = 256;

struct MeshData {
  int a = -1, b = -1;       // driver / driven gear (= their rotation DOF)
  int xa = -1, xb = -1;     // x DOF of their shafts (y = x + 1)
  double rba = 0, rbb = 0;  // base radii
  double ra = 0, rb = 0;    // speed ratios of the gears to the input
  double nx = 0, ny = 0;    // LOA unit vector, fixed frame
  double tx = 0, ty = 0;    // sliding direction unit vector, fixed frame
  double pitch_a = 0, inv_pitch_a = 0;
  int za = 0, zb = 0;
  double s_start = 0, s_end = 0, pb = 0, loa = 0, s_pitch = 0;
  double k_mean = 0, c_z = 0, inv_k_mean = 0;
  double backlash = 0;
  bool back_flank = true;
  std::unique_ptr<MeshStiffness> stiffness;
  std::vector<double> mu;  // mu over [s_start, s_end], kFrictionTablePoints points
  double mu_inv_ds = 0;
  bool friction = false;
  bool faulty = false;     // faults on either gear: use MeshStiffness::pair_force
  bool per_tooth = false;  // faults or pitch errors: the teeth in contact matter
  bool gap_free = true;    // no pitch errors and no faults: every pair's gap is exactly 0
  double runout_a = 0, runout_b = 0, phase_a = 0, phase_b = 0;
  double omega_table = -1;           // driver speed at which mu was tabulated [rad/s]
  std::vector<double> te_a, te_phi;  // static TE harmonics (DynamicsOptions::te_*)
};

struct Link {  // torsional spring-damper between two gears on one shaft
  int g1 = -1, g2 = -1;
  double k = 0, c = 0;
};

// The mesh index of each MeshWear (by mesh name, or the one mesh of its gear); one per mesh.
std::vector<int> wear_meshes(const diag::Gearbox& gb, const std::vector<MeshWear>& wear) {
  std::vector<int> out;
  for (const MeshWear& w : wear) {
    std::vector<int> hits;
    std::string names;
    for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
      const diag::Mesh& me = gb.meshes()[j];
      const std::string name = diag::mesh_name(gb, static_cast<int>(j));
      names += (names.empty() ? "" : ", ") + name;
      const bool by_gear = w.mesh.empty() && (gb.gears()[me.driver].name == w.gear ||
                                              gb.gears()[me.driven].name == w.gear);
      if (name == w.mesh || by_gear) hits.push_back(static_cast<int>(j));
    }
    const std::string field = w.mesh.empty() ? "gear" : "mesh";
    const std::string value = w.mesh.empty() ? w.gear : w.mesh;
    if (hits.empty()) {
      throw diag::InputError(diag::format_error(
          w.where, field,
          "'" + value + "' is not " + (w.mesh.empty() ? "a gear of a mesh" : "a mesh") +
              " of the gearbox (meshes: " + names + ")"));
    }
    if (hits.size() > 1) {
      throw diag::InputError(diag::format_error(
          w.where, "gear", "'" + w.gear + "' is in more than one mesh: name it with mesh"));
    }
    if (std::find(out.begin(), out.end(), hits[0]) != out.end()) {
      throw diag::InputError(
          diag::format_error(w.where, field, "a mesh can be worn only once per scenario"));
    }
    out.push_back(hits[0]);
  }
  return out;
}

// Resolves one mesh's wear (computing the worn state when not given) and applies its gap.
AppliedWear apply_wear(const diag::Gearbox& gb, int mesh, const MeshWear& w, double torque_nm,
                       MeshStiffness& stiffness) {
  AppliedWear a;
  a.mesh = mesh;
  a.law = w.law;
  if (!w.state.depth_driver_m.empty()) {
    a.state = w.state;
  } else {
    WearOptions o;
    o.law = w.law;
    o.steps = w.steps;
    o.cycles = w.cycles > 0 ? w.cycles : 1.0;
    o.depth_limit_m = 0.0099;  // no limit: the state asked for is the one wanted
    o.input_torque_nm = torque_nm;
    try {
      a.state = wear_pair(gb, mesh, o, w.depth_m);
    } catch (const diag::InputError& e) {
      throw diag::InputError(w.where + ": " + e.what());
    }
  }
  std::vector<double> s, g;
  worn_profile_gap(gb.meshes()[static_cast<std::size_t>(mesh)].pair, a.state, s, g);
  stiffness.set_profile_gap(s, g);
  a.max_gap_m = *std::max_element(g.begin(), g.end());
  return a;
}

}  // namespace

struct GearboxModel::Impl {
  const diag::Gearbox* gb = nullptr;
  DynamicsOptions opt;
  std::vector<AppliedWear> wear;
  int n = 0;  // DOFs
  int gears = 0;
  std::vector<int> shaft_x;  // per shaft: x DOF or -1
  std::vector<double> mass;  // per DOF: J or m
  std::vector<double> inv_mass;
  std::vector<double> ratio;           // per gear: |omega_g / omega_in|
  std::vector<double> kx, ky, cx, cy;  // per DOF index of x (stored at x DOF), per shaft
  std::vector<MeshData> meshes;
  std::vector<Link> links;
  int in_gear = -1, out_gear = -1;
  double k_c = 0, c_c = 0;  // coupling (speed mode)
  double torque_in = 0, torque_load = 0, c_load = 0;

  bool constant_speed = true;  // the speed profile is constant: omega_c t, no profile calls
  double omega_c = 0.0;
  double nominal_angle(double t) const {
    return constant_speed ? omega_c * t : opt.speed.angle_rad(t);
  }
  double nominal_speed(double t) const {
    return constant_speed ? omega_c : opt.speed.speed_rad_per_s(t);
  }
  struct Support {  // one shaft's bearings: x DOF (y = x + 1), stiffness and damping
    int x;
    double kx, ky, cx, cy;
  };
  std::vector<Support> supports;

  void tabulate_friction(MeshData& m, double omega_in) {
    const double omega_a = omega_in * m.ra;
    // Static normal load of this mesh: the driver's torque / r_ba. The driver's torque is the
    // input torque times the ratio from the input shaft to the driver's shaft (1 / r_a).
    const double f_static = torque_in / m.ra / m.rba;
    FrictionModel model(opt.friction, gb->meshes()[&m - meshes.data()].pair);
    m.mu = model.tabulate(omega_a, f_static, kFrictionTablePoints);
    m.mu_inv_ds = (kFrictionTablePoints - 1) / (m.s_end - m.s_start);
    m.friction = opt.friction.law != FrictionLaw::kNone &&
                 std::any_of(m.mu.begin(), m.mu.end(), [](double v) { return v > 0; });
    m.omega_table = omega_in;
  }

  double mu_at(const MeshData& m, double s) const {
    double x = (s - m.s_start) * m.mu_inv_ds;
    x = std::clamp(x, 0.0, static_cast<double>(kFrictionTablePoints - 1) - 1e-9);
    const int i = static_cast<int>(x);
    const double f = x - i;
    return m.mu[i] + f * (m.mu[i + 1] - m.mu[i]);
  }

  // Mesh j's compression, its rate, and the driver's total angle.
  void mesh_kinematics(const MeshData& m, double t, const double* q, const double* v, double& delta,
                       double& delta_dot, double& theta_a) const {
    const double th_in = nominal_angle(t);
    theta_a = m.ra * th_in + q[m.a];
    delta = m.rba * q[m.a] - m.rbb * q[m.b] + m.nx * (q[m.xa] - q[m.xb]) +
            m.ny * (q[m.xa + 1] - q[m.xb + 1]);
    delta_dot = m.rba * v[m.a] - m.rbb * v[m.b] + m.nx * (v[m.xa] - v[m.xb]) +
                m.ny * (v[m.xa + 1] - v[m.xb + 1]);
    if (m.runout_a > 0 || m.runout_b > 0) {
      const double w_in = nominal_speed(t);
      const double theta_b = m.rb * th_in + q[m.b];
      const double wa = m.ra * w_in + v[m.a], wb = m.rb * w_in + v[m.b];
      delta +=
          m.runout_a * std::sin(theta_a + m.phase_a) + m.runout_b * std::sin(theta_b + m.phase_b);
      delta_dot += m.runout_a * wa * std::cos(theta_a + m.phase_a) +
                   m.runout_b * wb * std::cos(theta_b + m.phase_b);
    }
    if (!m.te_a.empty()) {
      // Static transmission error e(theta_a): the mesh force is k (delta - e) + c (delta' - e').
      const double wa = m.ra * nominal_speed(t) + v[m.a];
      for (std::size_t h = 0; h < m.te_a.size(); ++h) {
        const double w = static_cast<double>(h + 1) * m.za;
        const double arg = w * theta_a + m.te_phi[h];
        delta -= m.te_a[h] * std::cos(arg);
        delta_dot += m.te_a[h] * w * wa * std::sin(arg);
      }
    }
  }

  // Stiffness matrix at mean mesh stiffness: each mesh k g g^T with g = d delta / dq
  // (docs/physics.md: K from the gradient of delta), the shafts' torsion, the bearings and the
  // motor coupling.
  Eigen::MatrixXd stiffness_matrix() const {
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
    for (const MeshData& d : meshes) {
      Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
      g[d.a] += d.rba;
      g[d.b] -= d.rbb;
      g[d.xa] += d.nx;
      g[d.xa + 1] += d.ny;
      g[d.xb] -= d.nx;
      g[d.xb + 1] -= d.ny;
      K += d.k_mean * g * g.transpose();
    }
    for (const Link& l : links) {
      K(l.g1, l.g1) += l.k;
      K(l.g2, l.g2) += l.k;
      K(l.g1, l.g2) -= l.k;
      K(l.g2, l.g1) -= l.k;
    }
    for (int x : shaft_x) {
      if (x < 0) continue;
      K(x, x) += kx[x];
      K(x + 1, x + 1) += ky[x];
    }
    if (opt.motor == MotorMode::kSpeed) K(in_gear, in_gear) += k_c;
    return K;
  }

  // Spring energy of mesh m with contacts placed by driver angle theta_pos and compression delta.
  double mesh_energy(const MeshData& m, double theta_pos, double delta) const {
    const double cycles = std::floor(theta_pos * m.inv_pitch_a);
    const double phase = theta_pos - cycles * m.pitch_a;
    const long long nc = static_cast<long long>(cycles);
    double e = 0.0, ksum = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double s = m.s_start + m.rba * phase + k * m.pb;
      if (s > m.s_end) break;
      const int ta = static_cast<int>(((nc - k) % m.za + m.za) % m.za);
      const int tb = static_cast<int>(((nc - k) % m.zb + m.zb) % m.zb);
      const double kp = m.stiffness->pair_stiffness(s, ta, tb);
      const double d = delta - m.stiffness->pair_gap(s, ta, tb);
      ksum += kp;
      // (partial-width faults have a piecewise law; the energy check runs on healthy meshes)
      if (d > 0 && std::isfinite(d)) e += 0.5 * kp * d * d;
    }
    if (m.back_flank && delta < -m.backlash)
      e += 0.5 * ksum * (delta + m.backlash) * (delta + m.backlash);
    return e;
  }
};

void DynamicsOptions::validate(const std::string& where) const {
  auto positive = [&](double v, const char* field) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw diag::InputError(diag::format_error(where, field, std::to_string(v) + " is not > 0"));
    }
  };
  auto nonneg = [&](double v, const char* field) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      throw diag::InputError(diag::format_error(where, field, std::to_string(v) + " is not >= 0"));
    }
  };
  if (!(speed.kind == SpeedProfile::Kind::kConstant && speed.rpm == 0.0))
    speed.validate(where + ": speed");
  nonneg(coupling_stiffness_nm_per_rad, "coupling_stiffness_nm_per_rad");
  if (!(coupling_damping_ratio > 0 && coupling_damping_ratio <= 2)) {
    throw diag::InputError(
        diag::format_error(where, "coupling_damping_ratio", "must be in (0, 2]"));
  }
  if (!(mesh_damping_ratio >= 0 && mesh_damping_ratio <= 1)) {
    throw diag::InputError(diag::format_error(
        where, "mesh_damping_ratio", std::to_string(mesh_damping_ratio) + " is not in [0, 1]"));
  }
  positive(bearing_stiffness_x_n_per_m, "bearing_stiffness_x_n_per_m");
  positive(bearing_stiffness_y_n_per_m, "bearing_stiffness_y_n_per_m");
  nonneg(bearing_damping_ratio, "bearing_damping_ratio");
  nonneg(shaft_torsional_stiffness_nm_per_rad, "shaft_torsional_stiffness_nm_per_rad");
  nonneg(shaft_damping_ratio, "shaft_damping_ratio");
  nonneg(runout_m, "runout_m");
  for (double a : te_amplitude_m) nonneg(a, "transmission_error.amplitude_um");
  for (double p : te_phase_rad) {
    if (!std::isfinite(p)) {
      throw diag::InputError(
          diag::format_error(where, "transmission_error.phase_deg", "must be finite"));
    }
  }
  if (te_phase_rad.size() > te_amplitude_m.size()) {
    throw diag::InputError(diag::format_error(where, "transmission_error.phase_deg",
                                              "has more entries than amplitude_um"));
  }
  if (accuracy_grade < 0 || accuracy_grade > 12) {
    throw diag::InputError(diag::format_error(where, "accuracy_grade",
                                              std::to_string(accuracy_grade) + " is not in 0..12"));
  }
  stiffness.validate();
  friction.validate(where + ": friction");
}

GearboxModel::GearboxModel(const diag::Gearbox& gb, const DynamicsOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.gb = &gb;
  m.opt = options;
  const std::string where = "dynamics";
  if (m.opt.speed.kind == SpeedProfile::Kind::kConstant && m.opt.speed.rpm == 0.0) {
    m.opt.speed = SpeedProfile::constant(gb.input().speed_rpm);
  }
  if (m.opt.input_torque_nm < 0) m.opt.input_torque_nm = gb.input().torque_nm;
  m.opt.validate(where);
  m.constant_speed = m.opt.speed.kind == SpeedProfile::Kind::kConstant;
  m.omega_c = m.opt.speed.speed_rad_per_s(0.0);
  if (gb.meshes().empty() || gb.power_path().empty()) {
    throw diag::InputError(diag::format_error(
        where, "meshes", "the dynamic simulator needs at least one mesh on the input-output path"));
  }

  // DOFs: gears first, then x, y of every shaft that carries gears.
  m.gears = static_cast<int>(gb.gears().size());
  m.n = m.gears;
  m.shaft_x.assign(gb.shafts().size(), -1);
  for (std::size_t s = 0; s < gb.shafts().size(); ++s) {
    if (!gb.shafts()[s].gears.empty()) {
      m.shaft_x[s] = m.n;
      m.n += 2;
    }
  }
  if (m.n > kMaxDofs) {
    throw diag::InputError(diag::format_error(where, "gears",
                                              std::to_string(m.n) +
                                                  " degrees of freedom; at most " +
                                                  std::to_string(kMaxDofs) + " are supported"));
  }
  m.mass.assign(m.n, 0.0);
  m.ratio.assign(m.gears, 0.0);
  for (int g = 0; g < m.gears; ++g) {
    const diag::Gear gear(gb.gears()[g].spec);
    const int s = gb.shaft_of_gear(g);
    m.mass[g] = gear.disc_inertia_kg_m2();
    m.mass[m.shaft_x[s]] += gear.disc_mass_kg();
    m.mass[m.shaft_x[s] + 1] += gear.disc_mass_kg();
    m.ratio[g] = std::abs(gb.shafts()[s].speed_ratio);
  }
  m.in_gear = gb.power_path().front().up_gear;
  m.out_gear = gb.power_path().back().down_gear;
  m.torque_in = m.opt.input_torque_nm;
  // Load torque that balances the input torque in a lossless box: T_in * |u_total|.
  m.torque_load = m.torque_in * m.ratio[m.in_gear] / m.ratio[m.out_gear];

  std::mt19937_64 rng(m.opt.seed);
  std::uniform_real_distribution<double> uniform_phase(0.0, 2 * kPi);
  std::vector<double> runout_phase(m.gears);
  for (double& p : runout_phase) p = uniform_phase(rng);

  const std::vector<int> wear_mesh = wear_meshes(gb, m.opt.wear);

  // Meshes.
  m.meshes.resize(gb.meshes().size());
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    const diag::Mesh& mesh = gb.meshes()[j];
    MeshData& d = m.meshes[j];
    const diag::GearPair& pair = mesh.pair;
    d.a = mesh.driver;
    d.b = mesh.driven;
    const int sa = gb.shaft_of_gear(d.a), sb = gb.shaft_of_gear(d.b);
    d.xa = m.shaft_x[sa];
    d.xb = m.shaft_x[sb];
    d.rba = pair.driver().base_radius_m();
    d.rbb = pair.driven().base_radius_m();
    d.ra = m.ratio[d.a];
    d.rb = m.ratio[d.b];
    d.za = pair.driver().teeth();
    d.zb = pair.driven().teeth();
    d.pitch_a = 2 * kPi / d.za;
    d.inv_pitch_a = 1.0 / d.pitch_a;
    d.s_start = pair.s_start_m();
    d.s_end = pair.s_end_m();
    d.pb = pair.base_pitch_m();
    d.loa = pair.loa_length_m();
    d.s_pitch = pair.s_pitch_m();
    // Frame: centre line along +x in the fixed frame (shafts laid out left to right along the
    // power path); mirrored in y when the driver turns clockwise (negative speed ratio).
    const double aw = pair.working_pressure_angle_rad();
    const double sigma = gb.shafts()[sa].speed_ratio >= 0 ? 1.0 : -1.0;
    d.nx = std::sin(aw);
    d.ny = sigma * std::cos(aw);
    d.tx = -std::cos(aw);
    d.ty = sigma * std::sin(aw);

    std::vector<ToothFault> faults;
    for (const GearFault& f : m.opt.faults) {
      const int g = gb.gear_index(f.gear);
      if (g < 0) {
        throw diag::InputError(diag::format_error(where, "faults: gear",
                                                  "'" + f.gear + "' is not a gear of the gearbox"));
      }
      if (g == d.a || g == d.b) {
        ToothFault tf = f.fault;
        tf.gear = g == d.a ? 0 : 1;
        if (!f.profile_json.empty()) {
          tf = profile_fault(pair, g == d.a, f.fault.tooth, nlohmann::json::parse(f.profile_json),
                             where + ": faults (" + f.gear + ")");
        }
        faults.push_back(tf);
      }
    }
    std::vector<double> errors_a, errors_b;
    if (m.opt.accuracy_grade > 0) {
      // Each gear's pitch errors drawn once from the seed and the gear index, so a gear meshing
      // twice (an idler) has the same errors in both meshes.
      errors_a =
          pitch_errors_iso1328(pair.driver(), m.opt.accuracy_grade, m.opt.seed * 1000003u + d.a);
      errors_b =
          pitch_errors_iso1328(pair.driven(), m.opt.accuracy_grade, m.opt.seed * 1000003u + d.b);
    }
    const std::string name = diag::mesh_name(gb, static_cast<int>(j));
    const StiffnessTable* table = nullptr;
    for (const StiffnessTable& t : m.opt.stiffness_tables) {
      if (t.mesh == name) table = &t;
    }
    if (table) {
      if (!faults.empty() || !errors_a.empty() || !errors_b.empty()) {
        throw diag::InputError(
            diag::format_error(where, "stiffness.tables: " + name,
                               "a tabulated mesh cannot also have tooth faults or pitch errors"));
      }
      const double f_static = m.opt.input_torque_nm / d.ra / d.rba;
      d.stiffness = std::make_unique<MeshStiffness>(MeshStiffness::from_table(
          pair, table->angle_deg, table->load_n, table->k_n_per_m, f_static, m.opt.stiffness));
    } else {
      d.stiffness =
          std::make_unique<MeshStiffness>(pair, m.opt.stiffness, faults, errors_a, errors_b);
    }
    for (std::size_t w = 0; w < m.opt.wear.size(); ++w) {
      if (wear_mesh[w] != static_cast<int>(j)) continue;
      if (table) {
        throw diag::InputError(
            diag::format_error(m.opt.wear[w].where, "mesh " + name,
                               "a tabulated mesh (stiffness.tables) cannot also be worn"));
      }
      m.wear.push_back(
          apply_wear(gb, static_cast<int>(j), m.opt.wear[w], m.opt.input_torque_nm, *d.stiffness));
    }
    d.faulty = d.stiffness->has_faults();
    d.per_tooth = d.faulty || !errors_a.empty() || !errors_b.empty();
    d.gap_free = !d.per_tooth && !d.stiffness->has_profile_gap();
    d.k_mean = d.stiffness->mean_mesh_stiffness();
    d.inv_k_mean = 1.0 / d.k_mean;
    const double inv_je = d.rba * d.rba / m.mass[d.a] + d.rbb * d.rbb / m.mass[d.b];
    d.c_z = 2 * m.opt.mesh_damping_ratio * std::sqrt(d.k_mean / inv_je);
    double b = m.opt.backlash_m >= 0 ? m.opt.backlash_m : mesh.spec.backlash_m;
    if (m.opt.backlash_m < 0 && mesh.spec.backlash_m == 0.0) {
      const double a_mm = pair.centre_distance_m() * 1e3, m_mm = pair.driver().module_m() * 1e3;
      b = (2.0 / 3.0) * (0.06 + 0.0005 * a_mm + 0.03 * m_mm) * 1e-3;
    }
    d.backlash = b;
    d.back_flank = m.opt.back_flank;
    d.runout_a = d.runout_b = m.opt.runout_m;
    d.phase_a = runout_phase[d.a];
    d.phase_b = runout_phase[d.b];
    d.te_a = m.opt.te_amplitude_m;
    d.te_phi = m.opt.te_phase_rad;
    d.te_phi.resize(d.te_a.size(), 0.0);
    m.tabulate_friction(d, m.opt.speed.speed_rad_per_s(0.0));
  }

  for (const StiffnessTable& t : m.opt.stiffness_tables) {
    bool found = false;
    for (std::size_t j = 0; j < m.meshes.size(); ++j)
      found |= diag::mesh_name(gb, static_cast<int>(j)) == t.mesh;
    if (!found) {
      throw diag::InputError(
          diag::format_error(where, "stiffness.tables",
                             "'" + t.mesh + "' is not a mesh <driver>_<driven> of the gearbox"));
    }
  }

  // Shaft torsion between consecutive gears on one shaft.
  for (std::size_t s = 0; s < gb.shafts().size(); ++s) {
    const auto& gears = gb.shafts()[s].gears;
    for (std::size_t i = 1; i < gears.size(); ++i) {
      Link l;
      l.g1 = gears[i - 1];
      l.g2 = gears[i];
      l.k = m.opt.shaft_torsional_stiffness_nm_per_rad;
      if (l.k == 0.0) {
        double d_root = std::numeric_limits<double>::infinity();
        for (int g : gears)
          d_root = std::min(d_root, 2 * diag::Gear(gb.gears()[g].spec).root_radius_m());
        const double d = 0.6 * d_root;
        l.k = kShearModulusSteelPa * kPi * std::pow(d, 4) / 32.0 / kDefaultShaftLengthM;
      }
      const double j_red = m.mass[l.g1] * m.mass[l.g2] / (m.mass[l.g1] + m.mass[l.g2]);
      l.c = 2 * m.opt.shaft_damping_ratio * std::sqrt(l.k * j_red);
      m.links.push_back(l);
    }
  }

  // Bearings: two per shaft.
  m.kx.assign(m.n, 0.0);
  m.ky.assign(m.n, 0.0);
  m.cx.assign(m.n, 0.0);
  m.cy.assign(m.n, 0.0);
  for (std::size_t s = 0; s < gb.shafts().size(); ++s) {
    const int x = m.shaft_x[s];
    if (x < 0) continue;
    m.kx[x] = 2 * m.opt.bearing_stiffness_x_n_per_m;
    m.ky[x] = 2 * m.opt.bearing_stiffness_y_n_per_m;
    m.cx[x] = 2 * m.opt.bearing_damping_ratio * std::sqrt(m.kx[x] * m.mass[x]);
    m.cy[x] = 2 * m.opt.bearing_damping_ratio * std::sqrt(m.ky[x] * m.mass[x + 1]);
    m.supports.push_back({x, m.kx[x], m.ky[x], m.cx[x], m.cy[x]});
  }

  // Drive and load.
  if (m.opt.motor == MotorMode::kSpeed) {
    m.k_c = m.opt.coupling_stiffness_nm_per_rad;
    if (m.k_c == 0.0) {
      double f_min = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < m.meshes.size(); ++j) {
        const MeshData& d = m.meshes[j];
        const double inv_je = d.rba * d.rba / m.mass[d.a] + d.rbb * d.rbb / m.mass[d.b];
        f_min = std::min(f_min, std::sqrt(d.k_mean * inv_je));
      }
      const double w_c = f_min / 20.0;
      m.k_c = m.mass[m.in_gear] * w_c * w_c;
    }
    m.c_c = 2 * m.opt.coupling_damping_ratio * std::sqrt(m.k_c * m.mass[m.in_gear]);
  } else {
    // Generator load: torque_load * (omega_out / omega_out,nominal); the slope is c_load.
    const double w_out = m.opt.speed.speed_rad_per_s(0.0) * m.ratio[m.out_gear];
    m.c_load = m.torque_load / w_out;
  }
  m.inv_mass.resize(m.n);
  for (int i = 0; i < m.n; ++i) m.inv_mass[i] = 1.0 / m.mass[i];
}

GearboxModel::~GearboxModel() = default;
GearboxModel::GearboxModel(GearboxModel&&) noexcept = default;

int GearboxModel::dofs() const { return impl_->n; }
int GearboxModel::shaft_x_dof(int shaft) const { return impl_->shaft_x.at(shaft); }
const DynamicsOptions& GearboxModel::options() const { return impl_->opt; }
const diag::Gearbox& GearboxModel::gearbox() const { return *impl_->gb; }
const std::vector<AppliedWear>& GearboxModel::applied_wear() const { return impl_->wear; }
double GearboxModel::gear_speed_ratio(int gear) const { return impl_->ratio.at(gear); }
int GearboxModel::input_gear() const { return impl_->in_gear; }
int GearboxModel::output_gear() const { return impl_->out_gear; }
double GearboxModel::load_torque_nm() const { return impl_->torque_load; }
double GearboxModel::input_torque_nm() const { return impl_->torque_in; }
double GearboxModel::mean_mesh_stiffness_n_per_m(int mesh) const {
  return impl_->meshes.at(mesh).k_mean;
}
double GearboxModel::mesh_backlash_m(int mesh) const { return impl_->meshes.at(mesh).backlash; }

std::pair<double, double> GearboxModel::loa_direction(int mesh) const {
  const MeshData& d = impl_->meshes.at(mesh);
  return {d.nx, d.ny};
}

std::pair<double, double> GearboxModel::normal_direction(int mesh) const {
  const MeshData& d = impl_->meshes.at(mesh);
  return {-d.tx, -d.ty};  // (cos a_w, -sin a_w) in the mesh frame (docs/physics.md)
}

std::uint64_t GearboxModel::contact_signature(double t, const double* y) const {
  const Impl& m = *impl_;
  const double th_in = m.nominal_angle(t);
  std::uint64_t sig = 0;
  for (const MeshData& d : m.meshes) {
    const double theta_a = d.ra * th_in + y[d.a];
    const double cycles = std::floor(theta_a * d.inv_pitch_a);
    const double phase = theta_a - cycles * d.pitch_a;
    int pairs = 0, approach = 0;
    for (; pairs < 3; ++pairs) {
      const double s = d.s_start + d.rba * phase + pairs * d.pb;
      if (s > d.s_end) break;
      if (d.friction && s < d.s_pitch) ++approach;  // friction reverses at the pitch point
    }
    // Mix (cycle, pairs, pairs before the pitch point) of every mesh into one number (FNV-1a
    // style); a change of any changes it (collisions between consecutive steps are practically
    // impossible).
    sig = (sig ^
           static_cast<std::uint64_t>(static_cast<long long>(cycles) * 16 + pairs * 4 + approach)) *
          0x100000001b3ULL;
  }
  return sig;
}

double GearboxModel::gear_angle_rad(int gear, double t, const double* y) const {
  return impl_->ratio.at(gear) * impl_->nominal_angle(t) + y[gear];
}

double GearboxModel::mesh_torsional_frequency_hz(int mesh) const {
  const Impl& m = *impl_;
  const MeshData& d = m.meshes.at(mesh);
  const double inv_je = d.rba * d.rba / m.mass[d.a] + d.rbb * d.rbb / m.mass[d.b];
  return std::sqrt(d.k_mean * inv_je) / (2 * kPi);
}

void GearboxModel::update_speed(double t) {
  Impl& m = *impl_;
  const double w = m.nominal_speed(t);
  for (MeshData& d : m.meshes) {
    if (m.opt.friction.law == FrictionLaw::kNone || m.opt.friction.law == FrictionLaw::kConstant)
      continue;
    if (std::abs(w - d.omega_table) > 0.02 * std::abs(d.omega_table)) m.tabulate_friction(d, w);
  }
}

void GearboxModel::derivatives(double t, const double* y, double* dydt, Observation* obs) const {
  const Impl& m = *impl_;
  const int n = m.n;
  const double* q = y;
  const double* v = y + n;
  double f[kMaxDofs];  // forces, scaled by 1/M into dydt at the end
  std::fill_n(f, n, 0.0);
  const double w_in = m.nominal_speed(t);
  if (!m.constant_speed) {
    const double alpha = m.opt.speed.acceleration_rad_per_s2(t);
    if (alpha != 0.0) {
      for (int g = 0; g < m.gears; ++g) f[g] -= m.mass[g] * m.ratio[g] * alpha;
    }
  }
  // Powers are bookkept only for an observation.
  double damping_power = 0.0, friction_power = 0.0, motor_power = 0.0, load_power = 0.0;
  // Drive and load.
  if (m.opt.motor == MotorMode::kSpeed) {
    const int g = m.in_gear;
    const double tc = -m.k_c * q[g] - m.c_c * v[g];
    f[g] += tc;
    f[m.out_gear] -= m.torque_load;
    if (obs) {
      motor_power = tc * w_in * m.ratio[g];  // the coupling torque times the motor's speed
      damping_power += m.c_c * v[g] * v[g];
      load_power = m.torque_load * (m.ratio[m.out_gear] * w_in + v[m.out_gear]);
    }
  } else {
    f[m.in_gear] += m.torque_in;
    const double w_out = m.ratio[m.out_gear] * w_in + v[m.out_gear];
    const double tl = m.c_load * w_out;
    f[m.out_gear] -= tl;
    if (obs) {
      motor_power = m.torque_in * (m.ratio[m.in_gear] * w_in + v[m.in_gear]);
      load_power = tl * w_out;
    }
  }
  // Shafts.
  for (const Link& l : m.links) {
    const double dv = v[l.g1] - v[l.g2];
    const double tau = l.k * (q[l.g1] - q[l.g2]) + l.c * dv;
    f[l.g1] -= tau;
    f[l.g2] += tau;
    if (obs) damping_power += l.c * dv * dv;
  }
  // Bearings.
  for (const Impl::Support& b : m.supports) {
    const int x = b.x;
    f[x] -= b.kx * q[x] + b.cx * v[x];
    f[x + 1] -= b.ky * q[x + 1] + b.cy * v[x + 1];
    if (obs) damping_power += b.cx * v[x] * v[x] + b.cy * v[x + 1] * v[x + 1];
  }
  // Meshes.
  for (std::size_t j = 0; j < m.meshes.size(); ++j) {
    const MeshData& d = m.meshes[j];
    double delta, delta_dot, theta_a;
    m.mesh_kinematics(d, t, q, v, delta, delta_dot, theta_a);
    const double cycles = std::floor(theta_a * d.inv_pitch_a);
    const double phase = theta_a - cycles * d.pitch_a;
    const long long nc = static_cast<long long>(cycles);
    double force = 0.0, fric = 0.0, moment_a = 0.0, moment_b = 0.0, ksum = 0.0, c_share = 0.0;
    int pairs = 0;
    for (int k = 0; k < 3; ++k) {
      const double s = d.s_start + d.rba * phase + k * d.pb;
      if (s > d.s_end) break;
      // Tooth indices matter only with faults or pitch errors (integer division is the most
      // expensive operation here, so healthy meshes skip it).
      int ta = 0, tb = 0;
      if (d.per_tooth) {
        ta = static_cast<int>(((nc - k) % d.za + d.za) % d.za);
        tb = static_cast<int>(((nc - k) % d.zb + d.zb) % d.zb);
      }
      const double kp = d.faulty ? d.stiffness->pair_stiffness(s, ta, tb)
                                 : d.stiffness->healthy_pair_stiffness(s);
      ksum += kp;
      double elastic;
      if (d.faulty) {
        // Partial-width chips and spalls have a piecewise-linear force law.
        elastic = d.stiffness->pair_force(s, ta, tb, delta);
        if (!(elastic > 0.0)) continue;
      } else {
        const double comp = d.gap_free ? delta : delta - d.stiffness->pair_gap(s, ta, tb);
        if (!(comp > 0.0)) continue;
        elastic = kp * comp;
      }
      const double cp = d.c_z * kp * d.inv_k_mean;
      const double fi = elastic + cp * delta_dot;
      if (fi <= 0.0) continue;
      ++pairs;
      c_share += cp;
      force += fi;
      if (d.friction) {
        const double sigma = s < d.s_pitch ? -1.0 : (s > d.s_pitch ? 1.0 : 0.0);
        const double ff = sigma * m.mu_at(d, s) * fi;
        fric += ff;
        moment_a -= ff * s;
        moment_b += ff * (d.loa - s);
      }
    }
    int contact = pairs > 0 ? 1 : 0;
    if (d.back_flank && delta < -d.backlash) {
      const double fb = ksum * (delta + d.backlash) + d.c_z * delta_dot;
      if (fb < 0.0) {
        force += fb;
        c_share += d.c_z;
        contact = -1;
      }
    }
    if (obs) damping_power += c_share * delta_dot * delta_dot;
    // Normal force: -F n on A, +F n on B; torques -r_ba F on a, +r_bb F on b.
    f[d.a] += -d.rba * force + moment_a;
    f[d.b] += d.rbb * force + moment_b;
    f[d.xa] += -force * d.nx - fric * d.tx;
    f[d.xa + 1] += -force * d.ny - fric * d.ty;
    f[d.xb] += force * d.nx + fric * d.tx;
    f[d.xb + 1] += force * d.ny + fric * d.ty;
    if (obs) {
      // Friction power: the friction forces times the sliding of the surfaces along t.
      const double wa = d.ra * w_in + v[d.a], wb = d.rb * w_in + v[d.b];
      MeshState& st = obs->meshes[j];
      st.delta_m = delta;
      st.force_n = force;
      st.friction_n = fric;
      st.stiffness_n_per_m = ksum;
      st.contact = contact;
      st.pairs = pairs;
      // Power of the friction forces and moments on both gears (negative = dissipated).
      const double p = moment_a * wa + moment_b * wb + (-fric * d.tx) * v[d.xa] +
                       (-fric * d.ty) * v[d.xa + 1] + (fric * d.tx) * v[d.xb] +
                       (fric * d.ty) * v[d.xb + 1];
      friction_power -= p;
    }
  }
  for (int i = 0; i < n; ++i) {
    f[i] *= m.inv_mass[i];
    dydt[i] = v[i];
    dydt[n + i] = f[i];
  }
  if (obs) {
    obs->acceleration.assign(f, f + n);
    obs->motor_power_w = motor_power;
    obs->load_power_w = load_power;
    obs->damping_power_w = damping_power;
    obs->friction_power_w = friction_power;
  }
}

std::vector<double> GearboxModel::equilibrium_state() const {
  const Impl& m = *impl_;
  const int n = m.n;
  const Eigen::MatrixXd K = m.stiffness_matrix();
  Eigen::VectorXd F = Eigen::VectorXd::Zero(n);
  if (m.opt.motor == MotorMode::kSpeed) {
    F[m.out_gear] -= m.torque_load;
  } else {
    F[m.in_gear] += m.torque_in;
    F[m.out_gear] -= m.torque_load;
  }
  const Eigen::VectorXd q = K.completeOrthogonalDecomposition().solve(F);
  std::vector<double> y(2 * n, 0.0);
  for (int i = 0; i < n; ++i) y[i] = q[i];
  return y;
}

std::vector<double> GearboxModel::natural_frequencies_hz() const {
  const Impl& m = *impl_;
  const int n = m.n;
  const Eigen::MatrixXd K = m.stiffness_matrix();
  // Mass-normalised: M^-1/2 K M^-1/2 is symmetric.
  Eigen::VectorXd s(n);
  for (int i = 0; i < n; ++i) s[i] = 1.0 / std::sqrt(m.mass[i]);
  const Eigen::MatrixXd A = s.asDiagonal() * K * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);
  std::vector<double> f(n);
  for (int i = 0; i < n; ++i) f[i] = std::sqrt(std::max(0.0, es.eigenvalues()[i])) / (2 * kPi);
  std::sort(f.begin(), f.end());
  return f;
}

double GearboxModel::total_energy_j(double t, const double* y) const {
  const Impl& m = *impl_;
  const double* q = y;
  const double* v = y + m.n;
  const double w_in = m.nominal_speed(t);
  double e = 0.0;
  for (int g = 0; g < m.gears; ++g) {
    const double w = m.ratio[g] * w_in + v[g];
    e += 0.5 * m.mass[g] * w * w;
  }
  for (int i = m.gears; i < m.n; ++i) e += 0.5 * m.mass[i] * v[i] * v[i];
  for (const Link& l : m.links) e += 0.5 * l.k * (q[l.g1] - q[l.g2]) * (q[l.g1] - q[l.g2]);
  for (int x : m.shaft_x) {
    if (x < 0) continue;
    e += 0.5 * m.kx[x] * q[x] * q[x] + 0.5 * m.ky[x] * q[x + 1] * q[x + 1];
  }
  if (m.opt.motor == MotorMode::kSpeed) e += 0.5 * m.k_c * q[m.in_gear] * q[m.in_gear];
  for (const MeshData& d : m.meshes) {
    double delta, delta_dot, theta_a;
    m.mesh_kinematics(d, t, q, v, delta, delta_dot, theta_a);
    e += m.mesh_energy(d, theta_a, delta);
  }
  return e;
}

double GearboxModel::parametric_work_j(double t0, const double* y0, double t1,
                                       const double* y1) const {
  const Impl& m = *impl_;
  double w = 0.0;
  for (const MeshData& d : m.meshes) {
    double delta0, dd0, th0, delta1, dd1, th1;
    m.mesh_kinematics(d, t0, y0, y0 + m.n, delta0, dd0, th0);
    m.mesh_kinematics(d, t1, y1, y1 + m.n, delta1, dd1, th1);
    w += 0.5 * ((m.mesh_energy(d, th1, delta0) - m.mesh_energy(d, th0, delta0)) +
                (m.mesh_energy(d, th1, delta1) - m.mesh_energy(d, th0, delta1)));
  }
  return w;
}

}  // namespace sim
