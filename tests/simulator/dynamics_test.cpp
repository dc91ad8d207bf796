// The gearbox dynamics (seed 000, docs/physics.md) against physics: the stiffness matrix and
// natural frequencies against the seed's printed matrix (with the K56 correction), the seed's
// results 1-5, energy balance, RK4 against GSL's adaptive integrator, defaults and bad input.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "sim/dynamics/gearbox_model.hpp"
#include "sim/dynamics/rk4.hpp"
#include "sim/dynamics/scenario.hpp"
#include "sim/dynamics/simulate.hpp"
#include "sim/dynamics/sweep.hpp"
#include "sim/mesh/mesh_stiffness.hpp"

namespace {

constexpr double kPi = std::numbers::pi;

// The seed's pair (z = 49/51, m = 4 mm, alpha = 20 deg, b = 20 mm), with the addendum
// coefficient that sets the contact ratio.
diag::Gearbox seed_pair(double torque_nm = 2000.0, double rpm = 3000.0, double addendum = 1.0) {
  nlohmann::json j = {
      {"shafts", {{{"name", "input"}}, {{"name", "output"}}}},
      {"gears",
       {{{"name", "pinion"},
         {"shaft", "input"},
         {"teeth", 49},
         {"module_mm", 4.0},
         {"face_width_mm", 20.0},
         {"addendum_coefficient", addendum}},
        {{"name", "wheel"},
         {"shaft", "output"},
         {"teeth", 51},
         {"module_mm", 4.0},
         {"face_width_mm", 20.0},
         {"addendum_coefficient", addendum}}}},
      {"meshes", {{{"driver", "pinion"}, {"driven", "wheel"}}}},
      {"input", {{"shaft", "input"}, {"speed_rpm", rpm}, {"torque_nm", torque_nm}}}};
  return diag::parse_gearbox(j, "seed_pair");
}

// Addendum coefficient giving contact ratio eps for the seed's pair (bisection; eps grows with
// the addendum).
double addendum_for_contact_ratio(double eps) {
  double lo = 0.62, hi = 1.2;  // 0.62: contact ratio just above 1
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (seed_pair(2000, 3000, mid).meshes()[0].pair.contact_ratio() < eps ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double rms(const std::vector<double>& x) {
  double m = 0;
  for (double v : x) m += v;
  m /= x.size();
  double s = 0;
  for (double v : x) s += (v - m) * (v - m);
  return std::sqrt(s / x.size());
}

// ---- the stiffness matrix and natural frequencies ----

// K built by hand from the seed's printed entries (q = phi1, phi2, x1, x2, y1, y2; delta =
// r1 phi1 + r2 phi2 + (y1 - y2) cos a + (x1 - x2) sin a) with the correction K56 = -k cos^2 a,
// M = diag(J1, J2, m1, m2, m1, m2) (docs/physics.md corrects the printed M). The model builds K
// from delta's gradient in its own coordinates; the natural frequencies must agree to round-off
// (1e-9 relative: an eigenvalue problem of size 6 in double precision).
TEST(GearboxModel, NaturalFrequenciesMatchTheSeedsCorrectedStiffnessMatrix) {
  const diag::Gearbox gb = seed_pair();
  sim::DynamicsOptions o;
  o.motor = sim::MotorMode::kTorque;  // free-free: no coupling stiffness, as in the seed
  o.bearing_stiffness_x_n_per_m = 1.5e8;
  o.bearing_stiffness_y_n_per_m = 2.5e8;
  const sim::GearboxModel model(gb, o);
  const double k = model.mean_mesh_stiffness_n_per_m(0);
  const diag::GearPair& p = gb.meshes()[0].pair;
  const double r1 = p.driver().base_radius_m(), r2 = p.driven().base_radius_m();
  const double a = p.working_pressure_angle_rad(), s = std::sin(a), c = std::cos(a);
  const double kbx = 2 * 1.5e8, kby = 2 * 2.5e8;  // two bearings per shaft
  Eigen::Matrix<double, 6, 6> K;
  K << k * r1 * r1, k * r1 * r2, k * r1 * s, -k * r1 * s, k * r1 * c, -k * r1 * c, k * r1 * r2,
      k * r2 * r2, k * r2 * s, -k * r2 * s, k * r2 * c, -k * r2 * c, k * r1 * s, k * r2 * s,
      k * s * s + kbx, -k * s * s, k * s * c, -k * s * c, -k * r1 * s, -k * r2 * s, -k * s * s,
      k * s * s + kbx, -k * s * c, k * s * c, k * r1 * c, k * r2 * c, k * s * c, -k * s * c,
      k * c * c + kby, -k * c * c, -k * r1 * c, -k * r2 * c, -k * s * c, k * s * c, -k * c * c,
      k * c * c + kby;
  const diag::Gear g1(gb.gears()[0].spec), g2(gb.gears()[1].spec);
  Eigen::Matrix<double, 6, 1> m;
  m << g1.disc_inertia_kg_m2(), g2.disc_inertia_kg_m2(), g1.disc_mass_kg(), g2.disc_mass_kg(),
      g1.disc_mass_kg(), g2.disc_mass_kg();
  const Eigen::Matrix<double, 6, 1> si = m.cwiseSqrt().cwiseInverse();
  const Eigen::Matrix<double, 6, 6> A = si.asDiagonal() * K * si.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(A);
  std::vector<double> expected;
  for (int i = 0; i < 6; ++i)
    expected.push_back(std::sqrt(std::max(0.0, es.eigenvalues()[i])) / (2 * kPi));
  std::sort(expected.begin(), expected.end());
  const std::vector<double> got = model.natural_frequencies_hz();
  ASSERT_EQ(got.size(), 6u);
  for (int i = 1; i < 6; ++i) EXPECT_NEAR(got[i], expected[i], 1e-9 * expected[5]) << i;
  EXPECT_LT(got[0], 1e-6 * got[5]);  // the rigid-body rotation
}

// With bearings far stiffer than the mesh, the torsional mode is the classic
// sqrt(k (r1^2/J1 + r2^2/J2)) / 2 pi. Tolerance 1e-4: the bearings (1e6 x stiffer) still couple
// a little.
TEST(GearboxModel, TorsionalModeIsTheClassicFormulaOnRigidBearings) {
  const diag::Gearbox gb = seed_pair();
  sim::DynamicsOptions o;
  o.motor = sim::MotorMode::kTorque;
  o.bearing_stiffness_x_n_per_m = o.bearing_stiffness_y_n_per_m = 1e15;
  const sim::GearboxModel model(gb, o);
  const std::vector<double> f = model.natural_frequencies_hz();
  EXPECT_NEAR(f[1], model.mesh_torsional_frequency_hz(0), 1e-4 * f[1]);
}

// A measured/FEM stiffness table replaces the potential-energy stiffness: a table of constant
// k0 (at two loads) gives mean mesh stiffness k0 (4e-3: the split between pairs is blended within
// a grid cell of each change of the pair count) and a scenario naming an unknown mesh is refused.
TEST(GearboxModel, AStiffnessTableSetsTheMeshStiffness) {
  const diag::Gearbox gb = seed_pair();
  const sim::Scenario sc = sim::parse_scenario(nlohmann::json::parse(R"({"stiffness": {"tables": [
      {"mesh": "pinion_wheel", "angle_deg": [0, 2, 4, 6], "load_n": [1000, 100000],
       "k_n_per_m": [[3e8, 3e8], [3e8, 3e8], [3e8, 3e8], [3e8, 3e8]]}]}})"),
                                               "sc.json");
  const sim::GearboxModel model(gb, sc.dynamics);
  EXPECT_NEAR(model.mean_mesh_stiffness_n_per_m(0), 3e8, 4e-3 * 3e8);
  sim::Scenario bad = sc;
  bad.dynamics.stiffness_tables[0].mesh = "pinion_idler";
  EXPECT_THROW(sim::GearboxModel(gb, bad.dynamics), diag::InputError);
}

// ---- seed result 2: normal-to-LOA vibration is friction's ----

sim::RunOptions short_run(double duration = 0.1, double fs = 40000) {
  sim::RunOptions r;
  r.duration_s = duration;
  r.fs_hz = fs;
  r.settle_s = 0.05;
  return r;
}

// Equal bearing stiffness in x and y, no friction: the mesh force acts along the LOA only and the
// isotropic bearings keep every centre on it, so the acceleration normal to the LOA is zero up to
// round-off (1e-9 of the along-LOA level). With friction it grows with mu, about in proportion
// (friction force ~ mu F): doubling mu gives 1.6..2.4 x (the dynamic coupling makes it not exact).
TEST(SeedResults, NormalToLoaVibrationIsZeroWithoutFrictionAndGrowsWithMu) {
  const diag::Gearbox gb = seed_pair();
  sim::DynamicsOptions o;
  o.friction.law = sim::FrictionLaw::kNone;
  const sim::DynamicResult r0 = sim::simulate_dynamic(gb, o, short_run());
  const double along0 = rms(r0.find("input_bearing1_along_loa")->samples);
  const double normal0 = rms(r0.find("input_bearing1_normal_loa")->samples);
  ASSERT_GT(along0, 1.0);  // m/s^2: the mesh excites the bearings
  EXPECT_LT(normal0, 1e-9 * along0);
  double previous = normal0;
  std::vector<double> levels;
  for (double mu : {0.02, 0.05, 0.1}) {
    o.friction.law = sim::FrictionLaw::kConstant;
    o.friction.mu_constant = mu;
    const sim::DynamicResult r = sim::simulate_dynamic(gb, o, short_run());
    const double normal = rms(r.find("input_bearing1_normal_loa")->samples);
    EXPECT_GT(normal, previous) << "mu = " << mu;
    previous = normal;
    levels.push_back(normal);
  }
  EXPECT_GT(levels[2] / levels[1], 1.6);
  EXPECT_LT(levels[2] / levels[1], 2.4);
}

// Result 2, sign and size: with isotropic bearings the mesh stiffness acts along the LOA only,
// so each shaft's motion normal to the LOA is its own linear oscillator driven by the friction
// force alone: on the driver's shaft the friction force along the sensor's normal direction
// (-t) is +F_fr (F_fr the "_friction" channel, the force on gear b along t), so
//     m_A x'' + c_A x' + k_A x = F_fr,   a_n = x''
// with m_A the pinion's disc mass, k_A = 2 k_bearing, c_A = 2 zeta_b sqrt(k_A m_A). At each
// mesh harmonic the complex ratio a_n / F_fr must equal -W^2 / (k_A - m_A W^2 + i c_A W):
// magnitude within 2 % and phase within 0.01 rad (RK4 and the contact sub-steps; both channels
// pass the same linear-phase filter; measured 0.2 % / 0.6 % and < 1 mrad at harmonics 1 / 2). A
// friction force on the wrong gear or with the wrong sign is off by pi in phase; a missing friction
// force gives no normal response at all.
TEST(SeedResults, NormalToLoaResponseIsTheFrictionForceThroughTheBearing) {
  const diag::Gearbox gb = seed_pair();
  sim::DynamicsOptions o;
  o.friction.law = sim::FrictionLaw::kConstant;
  o.friction.mu_constant = 0.06;
  const double fs = 40000;
  const sim::DynamicResult r = sim::simulate_dynamic(gb, o, short_run(0.1, fs));
  const std::vector<double>& fr = r.find("pinion_wheel_friction")->samples;
  const std::vector<double>& an = r.find("input_bearing1_normal_loa")->samples;
  const double m = diag::Gear(gb.gears()[0].spec).disc_mass_kg();
  const double k = 2 * o.bearing_stiffness_x_n_per_m;
  const double c = 2 * o.bearing_damping_ratio * std::sqrt(k * m);
  auto phasor = [&](const std::vector<double>& x, double f) {
    const std::size_t n = static_cast<std::size_t>(std::floor(x.size() * f / fs) * fs / f);
    std::complex<double> z = 0;
    for (std::size_t i = 0; i < n; ++i) z += x[i] * std::polar(1.0, -2 * kPi * f * i / fs);
    return 2.0 * z / static_cast<double>(n);
  };
  const double fz = gb.mesh_frequency_hz(0);
  for (int h = 1; h <= 2; ++h) {
    const double w = 2 * kPi * h * fz;
    const std::complex<double> expected = -w * w / std::complex<double>(k - m * w * w, c * w);
    const std::complex<double> got = phasor(an, h * fz) / phasor(fr, h * fz);
    ASSERT_GT(std::abs(phasor(fr, h * fz)), 1.0) << h;  // N: friction does excite harmonic h
    EXPECT_NEAR(std::abs(got) / std::abs(expected), 1.0, 0.02) << "harmonic " << h;
    EXPECT_NEAR(std::arg(got / expected), 0.0, 0.01) << "harmonic " << h;
    std::cout << "[ result 2 ] harmonic " << h << ": |a_n / F_fr| " << std::abs(got)
              << " (oscillator " << std::abs(expected) << "), phase error "
              << std::arg(got / expected) << " rad\n";
  }
}

// Amplitude of the component at frequency f (an integer number of its periods in the window:
// a single-bin DFT over whole periods, exact for a periodic signal).
double amplitude_at(const std::vector<double>& x, double fs, double f) {
  const std::size_t period_samples = static_cast<std::size_t>(fs / f);
  const double periods = std::floor(x.size() / (fs / f));
  const std::size_t n = static_cast<std::size_t>(periods * fs / f);
  (void)period_samples;
  double re = 0, im = 0;
  for (std::size_t i = 0; i < n; ++i) {
    re += x[i] * std::cos(2 * kPi * f * i / fs);
    im -= x[i] * std::sin(2 * kPi * f * i / fs);
  }
  return 2.0 * std::hypot(re, im) / n;
}

// ---- seed result 1: friction barely changes the dynamic mesh force ----

// A sweep 1000..4500 rpm with and without Drozdov's friction: the peak dynamic mesh force per
// speed window changes by a few per cent (the seed's Fig. 10: friction is a small damping and a
// small excitation next to the stiffness variation). Two-sided: the change must be small (RMS over
// the windows < 4 %, no window beyond 8 %) AND present (RMS > 0.5 %): friction that did nothing
// (a lost moment or force) gives exactly 0 and fails. Measured: RMS 2.4 %, worst 7.5 % (at the
// resonance's jump, where a small shift of the jump speed moves one window's peak most).
TEST(SeedResults, FrictionChangesTheMeshForceOnlyByAFewPercentOverASweep) {
  sim::SweepOptions sw;
  sw.from_rpm = 1000;
  sw.to_rpm = 4500;
  sw.steps = 14;
  sw.dwell_s = 0.02;
  sw.down = false;
  sw.channels = {"pinion_wheel_force"};
  sim::DynamicsOptions off, on;
  off.friction.law = sim::FrictionLaw::kNone;
  on.friction.law = sim::FrictionLaw::kDrozdov;
  const sim::SweepResult a = sim::run_sweep(seed_pair(), off, sim::RunOptions{}, sw);
  const sim::SweepResult b = sim::run_sweep(seed_pair(), on, sim::RunOptions{}, sw);
  double ss = 0, worst = 0;
  for (std::size_t i = 0; i < a.up.size(); ++i) {
    const double change = b.up[i].peak[0] / a.up[i].peak[0] - 1.0;
    ss += change * change;
    worst = std::max(worst, std::abs(change));
  }
  const double rms_change = std::sqrt(ss / a.up.size());
  EXPECT_LT(rms_change, 0.04);
  EXPECT_GT(rms_change, 0.005);
  EXPECT_LT(worst, 0.08);
  std::cout << "[ result 1 ] friction changes the peak mesh force by " << 100 * rms_change
            << " % RMS, " << 100 * worst << " % at worst\n";
}

// ---- seed result 3: hot oil, less friction-driven vibration ----

// Fig. 11: the spectrum of the acceleration normal to the LOA at the mesh harmonics is lower
// with 95 degC oil than with 25 degC oil. With the EHL friction law of Xu et al. (mu ~ nu0^0.75)
// the first three mesh harmonics fall by more than 2x (the viscosity falls ~14x).
TEST(SeedResults, HotOilLowersTheNormalToLoaMeshHarmonics) {
  const diag::Gearbox gb = seed_pair(2000, 1500);
  sim::DynamicsOptions o;
  o.friction.law = sim::FrictionLaw::kXuKahraman;
  const double fs = 40000;
  o.friction.oil_temperature_c = 25;
  const sim::DynamicResult cold = sim::simulate_dynamic(gb, o, short_run(0.2, fs));
  o.friction.oil_temperature_c = 95;
  const sim::DynamicResult hot = sim::simulate_dynamic(gb, o, short_run(0.2, fs));
  const double fz = gb.mesh_frequency_hz(0);
  for (int h = 1; h <= 3; ++h) {
    const double a = amplitude_at(cold.find("input_bearing1_normal_loa")->samples, fs, h * fz);
    const double b = amplitude_at(hot.find("input_bearing1_normal_loa")->samples, fs, h * fz);
    EXPECT_GT(a, 2.0 * b) << "harmonic " << h << ": 25 degC " << a << ", 95 degC " << b;
  }
}

// ---- seed result 4: the normal-to-LOA level falls as the contact ratio approaches 2 ----

// Fig. 12: at the resonance, the acceleration normal to the LOA falls as the contact ratio goes
// 1.2 -> 1.5 -> 1.8, because the two pairs' friction forces (opposite sides of the pitch point)
// cancel over more of the mesh period. For each contact ratio the resonance is the window of the
// largest mesh force; the normal-direction RMS there must fall strictly from one contact ratio to
// the next. On the default bearings (2e8 N/m each, the mesh's own order) that window is not the
// classic torsional frequency sqrt(k (r1^2/J1 + r2^2/J2)) / 2 pi: it lies at 1.25-1.36 x it, at
// the coupled torsional-translational mode (the mesh spring in series with the bearings, the
// shafts moving along the LOA). Checked: the window's mesh frequency lies within 6 % of the
// model's eigenfrequency of that mode (the eigenvalue of M^-1 K at mean stiffness nearest to it;
// 6 %: the window width, 2.8 % of the frequency, plus the softening by contact loss), and that
// eigenfrequency is 1.2-1.45 x the torsional one.
TEST(SeedResults, NormalToLoaLevelAtResonanceFallsAsContactRatioGrows) {
  sim::SweepOptions sw;
  sw.from_rpm = 1000;
  sw.to_rpm = 4500;
  sw.steps = 35;
  sw.dwell_s = 0.02;
  sw.down = false;
  sim::DynamicsOptions o;
  o.friction.law = sim::FrictionLaw::kConstant;
  o.friction.mu_constant = 0.06;
  std::vector<double> level;
  for (double eps : {1.2, 1.5, 1.8}) {
    const diag::Gearbox gb = seed_pair(2000, 3000, addendum_for_contact_ratio(eps));
    ASSERT_NEAR(gb.meshes()[0].pair.contact_ratio(), eps, 1e-6);
    const sim::SweepResult r = sim::run_sweep(gb, o, sim::RunOptions{}, sw);
    ASSERT_EQ(r.channels[2], "input_bearing1_normal_loa");
    std::size_t best = 0;
    for (std::size_t i = 0; i < r.up.size(); ++i) {
      if (r.up[i].rms[0] > r.up[best].rms[0]) best = i;
    }
    level.push_back(r.up[best].rms[2]);
    const double f_peak = r.up[best].mesh_frequency_hz, f_t = r.mesh_torsional_frequency_hz[0];
    double f_mode = 0;
    for (double f : r.natural_frequencies_hz) {
      if (std::abs(f - f_peak) < std::abs(f_mode - f_peak)) f_mode = f;
    }
    EXPECT_NEAR(f_peak / f_mode, 1.0, 0.06) << "eps " << eps;
    EXPECT_GT(f_mode / f_t, 1.2) << "eps " << eps;
    EXPECT_LT(f_mode / f_t, 1.45) << "eps " << eps;
    std::cout << "[ result 4 ] eps " << eps << ": peak window " << f_peak
              << " Hz = " << f_peak / f_t << " x torsional " << f_t << " Hz; coupled mode "
              << f_mode << " Hz; normal RMS " << level.back() << " m/s^2\n";
  }
  EXPECT_GT(level[0], level[1]);
  EXPECT_GT(level[1], level[2]);
}

// ---- seed result 5: the resonance and its jump ----

// docs/cli/sweep.md's example as written: the seed's pair (testdata/gearbox/seed000_pair.json),
// the scenario testdata/scenario/seed000_sweep_jump.json (bearings 1e10 N/m: the torsional mode
// alone in the band; on the default 2e8 N/m bearings the resonance is the coupled mode of result 4
// and shows no jump in this band), 2000..4500 rpm, 25 windows of 0.03 s, up and down.
//
// Where the peak is, judged against an independent figure: the torsional frequency from ISO
// 6336-1's c_gamma_alpha (not the model's potential-energy stiffness) and disc inertias computed
// here from the drawing (rho pi r^4 b / 2 at the pitch radius), f_iso = sqrt(c b / m_e) / 2 pi
// with m_e = 1 / (r_b1^2/J1 + r_b2^2/J2). The run-up peak must lie at 0.80-1.0 f_iso: below
// it by the PEM's 6 % lower stiffness (3 % in frequency) and by the contact loss's softening (the
// mesh is out of contact part of each period, > 5 % of the time at the peak), never above it.
// The seed's own figure, 1560 Hz, cannot be the check: the paper gives neither its inertias nor
// its FEM stiffness (see docs/validation.md).
// The jump: the run-down stays on the resonant branch below the run-up's peak and leaves it
// later, > 200 rpm (3 windows) lower, with a larger peak; in the window where the run-down peaks
// the two runs differ by more than 30 % of the run-up's largest force (a linear system, or a
// sweep too fast to show hysteresis, gives the same force up and down).
TEST(SeedResults, ResonanceSitsAtTheTorsionalFrequencyAndJumps) {
  const diag::Gearbox gb =
      diag::load_gearbox(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/seed000_pair.json");
  const sim::Scenario sc =
      sim::load_scenario(std::string(GEARDIAG_TESTDATA_DIR) + "/scenario/seed000_sweep_jump.json");
  sim::SweepOptions sw;
  sw.from_rpm = 2000;
  sw.to_rpm = 4500;
  sw.steps = 25;
  sw.dwell_s = 0.03;
  sw.down = true;
  sw.channels = {"pinion_wheel_force"};
  const sim::SweepResult r = sim::run_sweep(gb, sc.dynamics, sc.run, sw);
  // The independent torsional frequency.
  const diag::GearPair& p = gb.meshes()[0].pair;
  const double b = 0.020, rho = 7850;
  auto inertia = [&](double z) {
    const double rp = 0.5 * 0.004 * z;
    return rho * kPi * std::pow(rp, 4) * b / 2;
  };
  const double rb1 = 0.5 * 0.004 * 49 * std::cos(20 * kPi / 180);
  const double rb2 = 0.5 * 0.004 * 51 * std::cos(20 * kPi / 180);
  const double me = 1.0 / (rb1 * rb1 / inertia(49) + rb2 * rb2 / inertia(51));
  const double c_iso = sim::iso6336_method_b(p).c_gamma_alpha_n_per_m2;
  const double f_iso = std::sqrt(c_iso * b / me) / (2 * kPi);
  auto peak_window = [](const std::vector<sim::SweepPoint>& pts) {
    std::size_t best = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (pts[i].peak[0] > pts[best].peak[0]) best = i;
    }
    return best;
  };
  const sim::SweepPoint& up = r.up[peak_window(r.up)];
  EXPECT_GT(up.mesh_frequency_hz, 0.80 * f_iso);
  EXPECT_LT(up.mesh_frequency_hz, 1.0 * f_iso);
  EXPECT_GT(up.contact_loss_fraction, 0.05);  // the peak is the nonlinear one
  const std::size_t d = peak_window(r.down);
  const sim::SweepPoint& down = r.down[d];
  EXPECT_LT(down.rpm, up.rpm - 200.0);  // the run-down peak is further down: the jump moved
  EXPECT_GT(down.peak[0], up.peak[0]);
  const sim::SweepPoint& up_same = r.up[r.up.size() - 1 - d];  // the same speed window
  ASSERT_NEAR(up_same.rpm, down.rpm, 1e-6);
  EXPECT_GT(down.peak[0] - up_same.peak[0], 0.3 * up.peak[0]);
  std::cout << "[ result 5 ] f_iso " << f_iso << " Hz, model torsional "
            << r.mesh_torsional_frequency_hz[0] << " Hz; run-up peak " << up.rpm << " rpm ("
            << up.mesh_frequency_hz << " Hz, " << up.peak[0] << " N, contact loss "
            << up.contact_loss_fraction << "); run-down peak " << down.rpm << " rpm ("
            << down.mesh_frequency_hz << " Hz, " << down.peak[0] << " N); up there "
            << up_same.peak[0] << " N\n";
}

// Light load: contact loss and a jump also show on the default bearings, and the run up and run
// down differ somewhere by more than 30 % of the peak force.
TEST(SeedResults, LightLoadLosesContactAndRunUpDiffersFromRunDown) {
  sim::SweepOptions sw;
  sw.from_rpm = 2000;
  sw.to_rpm = 4500;
  sw.steps = 25;
  sw.dwell_s = 0.03;
  sw.down = true;
  sw.channels = {"pinion_wheel_force"};
  sim::DynamicsOptions o;
  o.bearing_stiffness_x_n_per_m = o.bearing_stiffness_y_n_per_m = 1e10;
  const sim::SweepResult r = sim::run_sweep(seed_pair(200), o, sim::RunOptions{}, sw);
  double lost = 0, differs = 0, top = 0;
  for (std::size_t i = 0; i < r.up.size(); ++i) {
    const sim::SweepPoint& d = r.down[r.up.size() - 1 - i];  // same speed window
    lost = std::max(lost, r.up[i].contact_loss_fraction);
    differs = std::max(differs, std::abs(r.up[i].peak[0] - d.peak[0]));
    top = std::max(top, r.up[i].peak[0]);
  }
  EXPECT_GT(lost, 0.1);
  EXPECT_GT(differs, 0.3 * top);
}

// ---- energy balance ----

// Over a steady stretch (an integer number of mesh periods after the transient), the work of the
// motor equals the load's work plus what the dampers and friction dissipated plus the work of the
// stiffness variation (the pairs entering and leaving), plus the change of the stored energy. The
// powers are integrated by the trapezoidal rule on the RK4 steps: O(h^2) with h = T_mesh / 200,
// and the residual must stay below 1 % of the dissipated energy (which is itself ~1e-2 of the
// transmitted work): a sign error in a friction moment or arm would break it by 100 %.
TEST(GearboxModel, EnergyBalancesOverASteadyStretch) {
  const diag::Gearbox gb = seed_pair(2000, 2000);
  sim::DynamicsOptions o;
  o.friction.law = sim::FrictionLaw::kConstant;
  o.friction.mu_constant = 0.06;
  o.back_flank = true;
  sim::GearboxModel model(gb, o);
  const int n = model.dofs();
  std::vector<double> y = model.equilibrium_state();
  const double f_mesh = gb.mesh_frequency_hz(0);
  const double h = 1.0 / (f_mesh * 200);
  sim::Rk4 rk4(2 * n);
  sim::Observation obs;
  obs.meshes.resize(1);
  double t = 0;
  for (int i = 0; i < 200 * 300; ++i, t += h) rk4.step(model, t, h, y.data());  // settle
  const double e0 = model.total_energy_j(t, y.data());
  double w_motor = 0, w_load = 0, w_damp = 0, w_fric = 0, w_param = 0;
  std::vector<double> prev(y);
  sim::Observation o0, o1;
  o0.meshes.resize(1);
  o1.meshes.resize(1);
  std::vector<double> dy(2 * n);
  model.derivatives(t, y.data(), dy.data(), &o0);
  for (int i = 0; i < 200 * 50; ++i) {
    prev = y;
    rk4.step(model, t, h, y.data());
    model.derivatives(t + h, y.data(), dy.data(), &o1);
    w_motor += 0.5 * h * (o0.motor_power_w + o1.motor_power_w);
    w_load += 0.5 * h * (o0.load_power_w + o1.load_power_w);
    w_damp += 0.5 * h * (o0.damping_power_w + o1.damping_power_w);
    w_fric += 0.5 * h * (o0.friction_power_w + o1.friction_power_w);
    w_param += model.parametric_work_j(t, prev.data(), t + h, y.data());
    t += h;
    o0 = o1;
  }
  const double de = model.total_energy_j(t, y.data()) - e0;
  const double residual = w_motor + w_param - w_load - w_damp - w_fric - de;
  ASSERT_GT(w_fric, 0.0);
  EXPECT_GT(w_fric, 0.005 * w_motor);  // mu = 0.06 loses ~1 % in a spur mesh
  EXPECT_LT(std::abs(residual), 0.01 * (w_damp + w_fric))
      << "motor " << w_motor << " load " << w_load << " damping " << w_damp << " friction "
      << w_fric << " parametric " << w_param << " dE " << de;
}

// ---- integrators ----

// The fixed-step RK4 result at its automatic step and GSL's adaptive Runge-Kutta-Prince-Dormand
// (8,9) at 1e-10 relative tolerance, sampled through the same anti-alias filter, give the same
// dynamic mesh force within 3 % of its fluctuation (RMS of the difference; measured 1.9 %). The
// mesh stiffness steps when a pair enters or leaves contact, and a fixed step straddling a step
// is only first-order accurate there: that, not the smooth dynamics, sets the bound.
TEST(Integrators, Rk4AgreesWithGslAdaptive) {
  const diag::Gearbox gb = seed_pair(2000, 1000);
  sim::DynamicsOptions o;
  o.friction.law = sim::FrictionLaw::kConstant;
  sim::RunOptions r = short_run(0.02, 50000);
  const sim::DynamicResult a = sim::simulate_dynamic(gb, o, r);
  r.method = sim::RunOptions::Method::kGslRk8pd;
  r.gsl_rel_tol = 1e-10;
  r.gsl_abs_tol = 1e-14;
  const sim::DynamicResult b = sim::simulate_dynamic(gb, o, r);
  const auto& fa = a.find("pinion_wheel_force")->samples;
  const auto& fb = b.find("pinion_wheel_force")->samples;
  ASSERT_EQ(fa.size(), fb.size());
  std::vector<double> diff(fa.size());
  for (std::size_t i = 0; i < fa.size(); ++i) diff[i] = fa[i] - fb[i];
  EXPECT_LT(rms(diff), 0.03 * rms(fa));
}

// ---- defaults, determinism and bad input ----

// The foundation's minimal description (no bearings, materials or sensors) simulates with the
// documented defaults: accelerometers along/normal to the LOA and horizontal/vertical at two
// bearings per shaft, a tachometer per shaft, the transmission error, mesh channels; no NaN; the
// same seed gives the same samples.
TEST(Simulate, MinimalGearboxSimulatesWithDefaultsDeterministically) {
  const diag::Gearbox gb =
      diag::load_gearbox(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
  sim::DynamicsOptions o;
  o.speed = sim::SpeedProfile::constant(1500);
  sim::RunOptions r = short_run(0.05, 20000);
  r.accel_noise_m_per_s2 = 0.01;
  const sim::DynamicResult a = sim::simulate_dynamic(gb, o, r);
  EXPECT_EQ(a.tachos.size(), 3u);
  for (const char* name :
       {"input_bearing1_along_loa", "input_bearing2_normal_loa", "counter_bearing1_along_loa_z1_z2",
        "counter_bearing1_normal_loa_z3_z4", "output_bearing2_horizontal",
        "output_bearing1_vertical", "transmission_error", "z1_z2_force", "z3_z4_contact"}) {
    const sim::Channel* c = a.find(name);
    ASSERT_NE(c, nullptr) << name;
    EXPECT_EQ(c->samples.size(), 1000u);
    for (double v : c->samples) ASSERT_TRUE(std::isfinite(v)) << name;
  }
  EXPECT_EQ(a.find("input_bearing1_along_loa")->direction, diag::Direction::kAlongLoa);
  EXPECT_EQ(a.find("input_bearing1_normal_loa")->direction, diag::Direction::kNormalLoa);
  EXPECT_EQ(a.find("transmission_error")->direction, diag::Direction::kAngle);
  // The tachometer of the input pulses once per revolution: 1500 rpm over 0.05 s = 1.25 rev.
  int rising = 0;
  const auto& tach = a.tachos[0].samples;
  for (std::size_t i = 1; i < tach.size(); ++i) rising += tach[i] > 0.5 && tach[i - 1] < 0.5;
  EXPECT_GE(rising, 1);
  EXPECT_LE(rising, 2);
  const sim::DynamicResult b = sim::simulate_dynamic(gb, o, r);
  for (std::size_t c = 0; c < a.channels.size(); ++c) {
    ASSERT_EQ(a.channels[c].samples, b.channels[c].samples) << a.channels[c].name;
  }
}

// A healthy gearbox without pitch errors or runout is periodic with its slowest mesh period,
// so its vibration holds only that mesh's harmonics (every 9th order of the input shaft in the
// two-stage box). At 2000 rpm and fs = 10 kHz one output revolution is exactly 1200 samples,
// so averaging whole output revolutions needs no resampling, and whatever lies between the mesh
// harmonics is numerical. Before the fixes in simulate() (central-difference accelerations and
// sub-steps across contact changes) the 5 us step beat with the mesh period and left lines at
// every 3rd input order at 3.7e-2 of the RMS: a damaged input gear to a TSA. Measured now:
// 5.2e-4 (kinks of the stiffness and friction tables remain). Bound 1e-3.
TEST(Simulate, AHealthyGearboxHoldsOnlyItsMeshHarmonics) {
  const diag::Gearbox gb =
      diag::load_gearbox(std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json");
  sim::DynamicsOptions o;
  o.speed = sim::SpeedProfile::constant(2000);
  o.input_torque_nm = 50;
  sim::RunOptions r;
  r.fs_hz = 10000;
  r.duration_s = 12 * 0.12;  // 12 output revolutions of 0.12 s
  r.mesh_channels = false;
  const sim::DynamicResult res = sim::simulate_dynamic(gb, o, r);
  const auto& x = res.find("input_bearing1_along_loa")->samples;
  constexpr std::size_t kRev = 1200;  // samples per output revolution
  const std::size_t revs = x.size() / kRev;
  ASSERT_GE(revs, 10u);
  std::vector<double> avg(kRev, 0.0);
  for (std::size_t r0 = 0; r0 < revs; ++r0) {
    for (std::size_t j = 0; j < kRev; ++j) avg[j] += x[r0 * kRev + j] / revs;
  }
  // Energy at output orders that are (not) multiples of 36 (the second mesh: 9 input orders).
  double on = 0, off = 0;
  for (std::size_t k = 1; k <= kRev / 2; ++k) {
    double re = 0, im = 0;
    for (std::size_t j = 0; j < kRev; ++j) {
      re += avg[j] * std::cos(2 * std::numbers::pi * k * j / kRev);
      im -= avg[j] * std::sin(2 * std::numbers::pi * k * j / kRev);
    }
    (k % 36 == 0 ? on : off) += re * re + im * im;
  }
  constexpr double kMaxOffMeshRatio = 1e-3;
  EXPECT_LT(std::sqrt(off / on), kMaxOffMeshRatio);
}

TEST(Simulate, AStepBeyondTheStabilityBoundIsReducedAndSaidSo) {
  const diag::Gearbox gb = seed_pair();
  sim::DynamicsOptions o;
  sim::RunOptions r = short_run(0.01, 20000);
  r.step_s = 1e-4;  // h w_max >> 2 for kHz modes
  const sim::DynamicResult a = sim::simulate_dynamic(gb, o, r);
  ASSERT_FALSE(a.warnings.empty());
  EXPECT_NE(a.warnings[0].find("stability"), std::string::npos);
  for (double v : a.find("pinion_wheel_force")->samples) ASSERT_TRUE(std::isfinite(v));
}

TEST(Scenario, BadFieldsAreNamed) {
  const auto expect_error = [](const std::string& text, const std::string& what) {
    try {
      sim::parse_scenario(nlohmann::json::parse(text), "sc.json");
      ADD_FAILURE() << "accepted " << text;
    } catch (const diag::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("sc.json"), std::string::npos) << e.what();
    }
  };
  expect_error(R"({"speed": {"rpm": -5}})", "speed.rpm");
  expect_error(R"({"frcition": {}})", "frcition");
  expect_error(R"({"friction": {"law": "magic"}})", "friction.law");
  expect_error(R"({"faults": [{"gear": "z2", "tooth": 1, "type": "dent"}]})", "faults[0].type");
  expect_error(R"({"faults": [{"gear": "z2", "tooth": 1, "type": "crack"}]})",
               "faults[0].depth_mm");
  expect_error(R"({"sensors": {"casing_frequency_hz": 15000}, "fs_hz": 20000})",
               "casing_frequency_hz");
  expect_error(R"({"mesh_damping_ratio": 3})", "mesh_damping_ratio");
  expect_error(R"({"sensors": {"noise_seed": -1}})", "sensors.noise_seed");
}

// "seed" draws the gears (pitch errors, runout phases) and, without sensors.noise_seed, the sensor
// noise; sensors.noise_seed gives the noise its own seed (two measurements of the same gears).
TEST(Scenario, TheNoiseSeedSeparatesTheSensorNoiseFromTheGears) {
  const sim::Scenario a = sim::parse_scenario(nlohmann::json::parse(R"({"seed": 4})"), "a.json");
  EXPECT_EQ(a.dynamics.seed, 4u);
  EXPECT_EQ(a.run.seed, 4u);
  const sim::Scenario b = sim::parse_scenario(
      nlohmann::json::parse(R"({"seed": 4, "sensors": {"noise_seed": 11}})"), "b.json");
  EXPECT_EQ(b.dynamics.seed, 4u);
  EXPECT_EQ(b.run.seed, 11u);
}

TEST(Scenario, AFaultOnAnUnknownGearIsRefused) {
  const diag::Gearbox gb = seed_pair();
  sim::Scenario sc = sim::parse_scenario(
      nlohmann::json::parse(R"({"faults": [{"gear": "nope", "tooth": 1, "type": "missing"}]})"),
      "sc.json");
  EXPECT_THROW(sim::simulate_dynamic(gb, sc.dynamics, short_run(0.01)), diag::InputError);
}

}  // namespace
