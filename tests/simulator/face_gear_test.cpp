// Face-gear pair torsional model (seed 002): analytic linear case, energy balance, integrator
// agreement, the seed's results 1-3, and bad input.
#include "sim/facegear/face_gear.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "diag/error.hpp"
#include "sim/facegear/description.hpp"

namespace fg = sim::facegear;

namespace {

constexpr double kPi = std::numbers::pi;

fg::Description seed_pair() {
  return fg::parse_description(
      nlohmann::json{{"face_gear_pair", {{"pinion_teeth", 15}, {"gear_teeth", 121}}}}, "test");
}

// The shipped description of the seed's pair (the paper's parameters, the assumptions and the
// inertias fitted to its Fig. 7: docs/face-gear.md).
fg::Description shipped() {
  return fg::load_description(std::string(GEARDIAG_TESTDATA_DIR) +
                              "/gearbox/seed002_face_gear.json");
}

// The seed's Fig. 10 case on the shipped description: 12 N m, 10x stiffness.
fg::Description light_stiff(double rpm) {
  fg::Description d = shipped();
  d.pair.stiffness_scale *= 10.0;
  d.operating.torque_nm = 12.0;
  d.operating.speed_rpm = rpm;
  return d;
}

// A table constant in angle and load with a one-harmonic static TE (identical flanks).
fg::FlankTable constant_table(double k, double te_amp, int teeth) {
  fg::FlankTable t;
  const double period = 2 * kPi / teeth;
  for (int i = 0; i < 64; ++i) {
    t.angle_rad.push_back(period * i / 64);
    t.e0_rad.push_back(te_amp * std::cos(teeth * t.angle_rad.back()));
  }
  t.load_nm = {10.0};
  t.k.assign(64, k);
  return t;
}

double range(const std::vector<double>& x) {
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  return *hi - *lo;
}

fg::Trace steady(const fg::Description& d, int record = 128, int transient = 300) {
  const fg::Model m(d.pair, d.operating);
  fg::RunOptions o;
  o.steps_per_period = fg::rk4_steps_per_period(m, 128);
  o.transient_periods = transient;
  o.record_periods = record;
  return fg::run(m, o);
}

}  // namespace

// Linear case (no backlash, identical flanks, constant stiffness, pinion inertia so large (1e4)
// that theta_p = Omega t): m e'' + c e' + k e = k e0 + c e0' - r T_g with m = r I_g, so the GMF
// amplitude of the DTE is A sqrt(k^2 + (c w)^2) / sqrt((k - m w^2)^2 + (c w)^2). The static TE
// is linear between 64 table points per period (its first harmonic is A times
// sinc^2(pi / 64) = 0.9992 A, used below). Tolerance 2e-4 relative: RK4 at 128+ steps per period
// is accurate to ~1e-8 here; the bound covers the 1e-4 speed ripple the finite pinion inertia
// leaves.
TEST(FaceGear, LinearNoBacklashMatchesAnalyticSteadyState) {
  fg::Description d = seed_pair();
  const double k = 5e5, te = 2e-5;
  d.pair.drive = d.pair.coast = constant_table(k, te, 15);
  d.pair.half_backlash_rad = 0.0;
  d.pair.inertia_p = 1e4;
  d.pair.bearing_damping_p = d.pair.bearing_damping_g = 0.0;
  d.pair.damping_alpha = 0.0;
  // Damping zeta = 0.06 (with the bare face gear's r I_g): the start-up transient decays as
  // exp(-c t / 2m), to below 1e-9 of itself in the 400 transient periods even at 25 000 rpm
  // (0.064 s); a lighter damping leaves a transient whose leakage into the GMF bin is of the size
  // of the tolerance.
  d.pair.damping_beta = 2e-5;
  d.operating.torque_nm = 100.0;
  const double r = d.pair.ratio();
  const double m = r * d.pair.inertia_g, c = d.pair.damping_beta * k;
  const double a1 = te * std::pow(std::sin(kPi / 64) / (kPi / 64), 2);
  for (double rpm : {3000.0, 12000.0, 25000.0}) {
    d.operating.speed_rpm = rpm;
    const fg::Trace tr = steady(d, 64, 400);
    const double w = 2 * kPi * rpm / 60 * 15;
    const double expect = a1 * std::hypot(k, c * w) / std::hypot(k - m * w * w, c * w);
    const double got = fg::amplitude_at(tr.dte, 1.0 / tr.dt, w / (2 * kPi));
    EXPECT_NEAR(got, expect, 2e-4 * expect) << rpm << " rpm";
    // The mean: e = -T_static / k (the whole load on the drive flank).
    double mean = 0;
    for (double v : tr.dte) mean += v;
    mean /= tr.dte.size();
    EXPECT_NEAR(mean, -d.operating.torque_nm / k, 1e-4 * d.operating.torque_nm / k);
  }
}

// Energy balance: W_in - W_out + W_param = dE_kin + dV + D (face_gear.hpp), with a table that
// varies in angle and load, backlash, static TE and torque fluctuation, in a case with impacts.
// Powers are integrated with the trapezoid rule over RK4 steps of 1/512 mesh period; W_param as
// the Stieltjes sums of the stiffness and static TE increments. Tolerance: 1e-3 of the energy
// that went through the mesh (its dissipation + |W_param| + max V; the bearings' dissipation and
// the shaft power are far larger and would hide a mesh error), the first-order quadrature error
// of the steps that contain a contact switch.
TEST(FaceGear, EnergyBalance) {
  fg::Description d = seed_pair();
  d.pair.stiffness_scale = 10.0;
  d.operating.torque_nm = 12.0;
  d.operating.speed_rpm = 28000.0;
  d.operating.input_amp = 0.3;
  d.operating.input_freq_hz = 500.0;
  d.operating.load_amp = 0.2;
  d.operating.load_freq_hz = 130.0;
  const fg::Model model(d.pair, d.operating);
  const double r = d.pair.ratio();
  const int n = 512, periods = 60;
  const double h = 1.0 / model.mesh_frequency_hz() / n;
  std::array<double, 4> ys = model.initial_state();
  double* y = ys.data();
  struct Point {
    double p_in, p_out, p_diss, p_mesh, k, d, e0, torque;
    fg::Contact c;
  };
  auto point = [&](double t) {
    const fg::Model::Mesh m = model.mesh(t, y);
    double dydt[4];
    model.derivatives(t, y, dydt);
    Point p{model.input_torque(t) * y[1],
            model.load_torque(t) * y[3],
            0,
            0,
            m.k,
            m.deflection,
            m.e0,
            m.torque,
            m.contact};
    p.p_diss = d.pair.bearing_damping_p * y[1] * y[1] + d.pair.bearing_damping_g * y[3] * y[3];
    if (m.contact != fg::Contact::kFree) {
      // (T_flank - k d) d' / r with T_flank = T_mesh (drive), -T_mesh (coast): c d'^2 / r in
      // contact, -k d d' / r >= 0 where the clamp holds the torque at 0 (face_gear.hpp).
      const double flank = m.contact == fg::Contact::kDrive ? 1.0 : -1.0;
      p.p_mesh = (flank * m.torque - m.k * m.deflection) * m.deflection_rate / r;
      p.p_diss += p.p_mesh;
    }
    return p;
  };
  auto energy = [&](const Point& p) {
    return 0.5 * d.pair.inertia_p * y[1] * y[1] + 0.5 * d.pair.inertia_g * (y[3]) * (y[3]) +
           0.5 * p.k / r * p.d * p.d;
  };
  Point prev = point(0.0);
  const double e_start = energy(prev);
  double w_in = 0, w_out = 0, diss = 0, diss_mesh = 0, w_param = 0, v_max = 0;
  int free_steps = 0;
  for (int i = 0; i < n * periods; ++i) {
    fg::rk4_step(model, i * h, h, y);
    const Point p = point((i + 1) * h);
    w_in += 0.5 * h * (prev.p_in + p.p_in);
    w_out += 0.5 * h * (prev.p_out + p.p_out);
    diss += 0.5 * h * (prev.p_diss + p.p_diss);
    diss_mesh += 0.5 * h * (prev.p_mesh + p.p_mesh);
    if (p.c == prev.c && p.c != fg::Contact::kFree) {
      w_param += 0.25 * (prev.d * prev.d + p.d * p.d) / r * (p.k - prev.k) +
                 0.5 * (prev.torque + p.torque) / r * (p.e0 - prev.e0);
    }
    free_steps += p.c == fg::Contact::kFree;
    v_max = std::max(v_max, 0.5 * p.k / r * p.d * p.d);
    prev = p;
  }
  const double residual = (w_in - w_out + w_param) - (energy(prev) - e_start) - diss;
  const double scale = diss_mesh + std::abs(w_param) + v_max;
  EXPECT_GT(free_steps, 0) << "the case must contain free flight";
  std::printf("energy [J]: W_in %.6g D %.6g (mesh %.4g) W_param %.4g V_max %.4g residual %.3g\n",
              w_in, diss, diss_mesh, w_param, v_max, residual);
  EXPECT_LT(std::abs(residual), 1e-3 * scale)
      << "residual " << residual << " of " << scale << " (W_in " << w_in << ")";
}

// Steady response with the located-event rk8pd (what the CLI runs), on the RK4 step grid.
fg::Trace steady_adaptive(const fg::Description& d, int record = 128, int transient = 300) {
  const fg::Model m(d.pair, d.operating);
  fg::RunOptions o;
  o.integrator = fg::Integrator::kAdaptive;
  o.steps_per_period = fg::rk4_steps_per_period(m, 64);
  o.transient_periods = transient;
  o.record_periods = record;
  return fg::run(m, o);
}

// RK4 (fixed step) and GSL rk8pd with located contact switches agree on a steady response with
// impacts (the shipped pair in the seed's Fig. 10 case at 8000 rpm: period-2 with free flight):
// the DTE traces on the same time grid differ by at most 1 % of the DTE range (RK4 at 32 steps
// per mesh-mode period loses order at the unlocated switches); four times more RK4 steps must at
// least halve the difference (first to second order with unlocated kinks).
TEST(FaceGear, Rk4AndAdaptiveAgree) {
  const fg::Description d = light_stiff(8000.0);
  const fg::Model model(d.pair, d.operating);
  fg::RunOptions o;
  o.transient_periods = 300;
  o.record_periods = 20;
  o.steps_per_period = fg::rk4_steps_per_period(model);
  const fg::Trace a = fg::run(model, o);
  o.steps_per_period *= 4;
  o.decimation = 4;
  const fg::Trace a4 = fg::run(model, o);
  o.integrator = fg::Integrator::kAdaptive;
  const fg::Trace b = fg::run(model, o);
  ASSERT_EQ(a.dte.size(), b.dte.size());
  ASSERT_GT(b.events, 0) << "the case must switch contact";
  double diff = 0, diff4 = 0;
  for (std::size_t i = 0; i < a.dte.size(); ++i) {
    diff = std::max(diff, std::abs(a.dte[i] - b.dte[i]));
    diff4 = std::max(diff4, std::abs(a4.dte[i] - b.dte[i]));
  }
  std::printf("rk4 vs adaptive: %.3g (x4 steps: %.3g) of range %.3g, %d events\n", diff, diff4,
              range(b.dte), b.events);
  EXPECT_LT(diff, 1e-2 * range(b.dte));
  EXPECT_LT(diff4, 0.5 * diff);
  // The period label: the located-event run gives the bifurcation's period-2 at this speed; RK4's
  // Poincare jitter (its difference above is 0.6 % of the range, above its 1e-3 tolerance) may not.
  std::printf("period: rk4 %s, rk4 x4 %s, adaptive %s\n", fg::classify_period(a).c_str(),
              fg::classify_period(a4).c_str(), fg::classify_period(b).c_str());
  EXPECT_EQ(fg::classify_period(b), "period-2");
}

// The description: L1, L2 of the seed's table 1 are radii. The face gear's mean radius is
// (L1 + L2) / 2 = 175.28 mm; the ratio of the arms, mean radius over pinion pitch radius, must then
// be the gear ratio 121/15 = 8.07 within the helix and face-gear geometry (8.21: 2 %; read as
// diameters it would be 4.1). The old diameter keys are refused naming the field.
TEST(FaceGear, GearRadiiNotDiameters) {
  const fg::Description d = shipped();
  EXPECT_NEAR(d.geometry.gear_mean_radius_m(), 0.17528, 1e-9);
  const double arms = d.geometry.gear_mean_radius_m() / d.geometry.pinion_pitch_radius_m();
  EXPECT_NEAR(arms, 121.0 / 15.0, 0.03 * 121.0 / 15.0);
  // Face width b2 = L2 - L1.
  EXPECT_NEAR(d.geometry.gear_outer_radius_m - d.geometry.gear_inner_radius_m,
              d.geometry.gear_face_width_m, 1e-12);
  nlohmann::json j = {
      {"face_gear_pair",
       {{"pinion_teeth", 15}, {"gear_teeth", 121}, {"gear_inner_diameter_mm", 160}}}};
  try {
    fg::parse_description(j, "fg.json");
    ADD_FAILURE() << "diameter key accepted";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("face_gear_pair.gear_inner_diameter_mm"),
              std::string::npos)
        << e.what();
  }
}

// Load-dependent stiffness solved consistently: the elastic torque returned satisfies
// T = k(angle, T) d to round-off at every angle and at deflections spanning the table (below the
// first load, between grid loads, above the last); the analytic table's Hertz law gives
// T ~ d^(3/2) between its grid loads (the secant k ~ T^(1/3)): T(8 d) / T(d) = 22.6 within the
// piecewise-linear interpolation of the table (its chords of T^(1/3) between loads a factor 2
// apart: measured +3.3 %, bound 5 %).
TEST(FaceGear, LoadDependentStiffnessIsSolvedConsistently) {
  const fg::Description d = shipped();
  const fg::FlankTable& t = d.pair.drive;
  const double period = d.pair.mesh_period_rad();
  for (double a : {0.0, 0.1 * period, 0.55 * period, 0.97 * period}) {
    for (double defl : {1e-9, 1e-7, 1e-6, 1e-5, 5e-5, 1e-4, 2e-4, 1e-3}) {
      for (double scale : {1.0, 10.0}) {
        const fg::FlankTable::Elastic el = t.elastic_torque(a, defl, period, scale);
        const double k = scale * t.stiffness(a, el.torque, period);
        EXPECT_NEAR(el.torque, k * defl, 1e-12 * el.torque + 1e-15) << a << " " << defl;
        EXPECT_NEAR(el.k, k, 1e-12 * k);
      }
    }
    const double d12 = t.elastic_torque(a, 1e-6, period, 1.0).torque;
    const double d96 = t.elastic_torque(a, 8e-6, period, 1.0).torque;
    EXPECT_NEAR(d96 / d12, std::pow(8.0, 1.5), 0.05 * std::pow(8.0, 1.5));
  }
}

// Contact only pushes: in an impacting case (the seed's Fig. 11 point, 12 N m, 10x, 12 000 rpm)
// the drive flank's torque is never negative and the coast flank's never positive, and the clamp
// acts (some contact samples have k d + c d' < 0: without it they would transmit tension).
TEST(FaceGear, ContactTransmitsNoTension) {
  const fg::Description d = light_stiff(12000.0);
  const fg::Trace tr = steady_adaptive(d, 100, 200);
  const fg::Model m(d.pair, d.operating);
  long clamped = 0, contact = 0;
  for (std::size_t i = 0; i < tr.dte.size(); ++i) {
    if (tr.contact[i] == 1) {
      EXPECT_GE(tr.mesh_torque[i], 0.0);
    } else if (tr.contact[i] == -1) {
      EXPECT_LE(tr.mesh_torque[i], 0.0);
    }
  }
  // Re-evaluate the mesh at the recorded states (angle, DTE and their rates).
  const double r = d.pair.ratio();
  for (std::size_t i = 0; i < tr.dte.size(); ++i) {
    if (tr.contact[i] == 0) continue;
    const double omega_p = 2 * kPi * d.operating.speed_rpm / 60;  // its ripple is small here
    const double y[4] = {tr.theta_p[i], omega_p, tr.dte[i], tr.dte_rate[i] + r * omega_p};
    const fg::Model::Mesh me = m.mesh(tr.t[i], y, static_cast<fg::Contact>(tr.contact[i]));
    ++contact;
    clamped += me.clamped;
  }
  std::printf("contact samples %ld, clamped %ld\n", contact, clamped);
  EXPECT_GT(contact, 0);
  EXPECT_GT(clamped, 0) << "the case must exercise the clamp";
}

// Seed result 1 (Fig. 6): at the rated point (4000 rpm, 300 N m) the response is period-1
// without impact and the GMF is the largest line of the DTE spectrum. Predicted (the description
// is fitted on Fig. 10 only): the point is in the dynamic regime, GMF / f_n = 1000 / 1066 = 0.94,
// on the high-speed flank of the primary resonance (Fig. 7's peak, 3750-3800 rpm here). Bounds:
// DLF above 1.5 (the quasi-static side, 3000 rpm, gives 1.17) and below the resonance peak's
// 2.35 (measured 2.08).
TEST(FaceGear, RatedPointIsPeriodOneWithoutImpact) {
  const fg::Description d = shipped();
  const fg::Trace tr = steady_adaptive(d);
  EXPECT_EQ(fg::classify_period(tr), "period-1");
  EXPECT_EQ(fg::classify_impacts(tr.contact), fg::ImpactClass::kNoImpact);
  const double gmf = 4000.0 / 60 * 15;
  const double fn = d.pair.natural_frequency_hz(300.0);
  EXPECT_GT(gmf / fn, 0.7);
  EXPECT_LT(gmf / fn, 0.95);
  const auto spec = fg::amplitude_spectrum(tr.dte, 1.0 / tr.dt, 3.5 * gmf);
  const auto top =
      std::max_element(spec.begin(), spec.end(), [](auto& x, auto& y) { return x[1] < y[1]; });
  EXPECT_NEAR((*top)[0], gmf, 1.0);
  const double dlf = tr.max_abs_mesh_torque / fg::Model(d.pair, d.operating).static_torque();
  EXPECT_GT(dlf, 1.5);
  EXPECT_LT(dlf, 2.35);
}

// Fig. 7 (300 N m): the largest DTE over the input speed lies in 4000-5000 rpm. Predicted by the
// description fitted on Fig. 10 (docs/face-gear.md): 9 speeds 3500-5500 rpm, each from static
// equilibrium; the peak must be within the paper's band widened by 10 % (3600-5500 rpm; the
// paper reads it off a plot) and at least twice the DTE at 3500 and 5500 rpm (measured: 366 urad
// at 3750 rpm, 93 and 45 urad).
TEST(FaceGear, Fig7PrimaryResonanceNearThePapersBand) {
  fg::Description d = shipped();
  double best = 0, best_rpm = 0, first = 0, last = 0;
  for (int i = 0; i <= 8; ++i) {
    d.operating.speed_rpm = 3500.0 + 250.0 * i;
    const fg::Trace tr = steady_adaptive(d, 40, 200);
    const double pp = range(tr.dte);
    if (pp > best) best = pp, best_rpm = d.operating.speed_rpm;
    if (i == 0) first = pp;
    if (i == 8) last = pp;
  }
  std::printf("DTE peak %.4g rad at %.0f rpm (%.4g, %.4g at the ends)\n", best, best_rpm, first,
              last);
  EXPECT_GE(best_rpm, 3600.0);
  EXPECT_LE(best_rpm, 5500.0);
  EXPECT_GT(best, 2 * first);
  EXPECT_GT(best, 2 * last);
}

// Seed result 2 (4000 rpm, 300 N m: the resonant regime, GMF / f_n = 0.94). Stiffer mesh ->
// smaller DTE (mean and peak-to-peak), as the paper says. Its DLF "basically does not change with
// the mean stiffness" holds for the resonance's peak (Fig. 7's curve of the largest DLF), not at
// one speed: the mesh is excited mainly by its stiffness ripple, a torque Delta k * (T / k) that
// does not depend on k, amplified at resonance by 1 / (2 zeta), zeta fixed; so the peak DLF stays
// (measured 2.35 -> 2.21, -6 %: asserted within 15 %) while the peak moves up by sqrt 2 in speed
// (3750 -> 5300 rpm) and the DTE, T / k, halves. At the one speed 4000 rpm, just above the x1
// peak, the DLF falls (2.08 -> 1.16): the x2 mode has moved away.
// Backlash (paper: 3x backlash -> more points in free flight): in a single-sided case (12 N m, 10x,
// 7000 rpm: the coast flank is never reached) the backlash cannot matter and the free-flight share
// is the same to 1e-9; in a double-sided case (12 000 rpm with 5x static TE) the wider backlash
// adds free flight. Larger static TE -> larger DTE fluctuation and mesh torque.
TEST(FaceGear, StiffnessBacklashAndStaticTeTrends) {
  fg::Description d = shipped();
  const fg::Model m0(d.pair, d.operating);
  const fg::Trace base = steady_adaptive(d);
  fg::Description stiff = d;
  stiff.pair.stiffness_scale = 2.0;
  const fg::Trace s = steady_adaptive(stiff);
  auto mean_abs = [](const std::vector<double>& x) {
    double a = 0;
    for (double v : x) a += std::abs(v);
    return a / x.size();
  };
  EXPECT_LT(mean_abs(s.dte), 0.9 * mean_abs(base.dte));
  EXPECT_LT(range(s.dte), range(base.dte));
  const double dlf0 = base.max_abs_mesh_torque / m0.static_torque();
  const double dlf_s = s.max_abs_mesh_torque / m0.static_torque();
  std::printf("DLF at 4000 rpm: x1 %.4f, x2 stiffness %.4f\n", dlf0, dlf_s);
  EXPECT_LT(dlf_s, dlf0);
  // The resonance peaks: 50 rpm steps over each mode's band, each from static equilibrium.
  struct Peak {
    double dlf = 0, dlf_rpm = 0, dte = 0;
  };
  auto peak = [](fg::Description x, double from_rpm, double to_rpm) {
    Peak p;
    for (double rpm = from_rpm; rpm <= to_rpm + 1e-9; rpm += 50.0) {
      x.operating.speed_rpm = rpm;
      const fg::Trace tr = steady_adaptive(x, 40, 200);
      const double dlf = tr.max_abs_mesh_torque / fg::Model(x.pair, x.operating).static_torque();
      if (dlf > p.dlf) p.dlf = dlf, p.dlf_rpm = rpm;
      p.dte = std::max(p.dte, range(tr.dte));
    }
    return p;
  };
  const Peak p1 = peak(d, 3500.0, 4300.0), p2 = peak(stiff, 5000.0, 6000.0);
  std::printf(
      "resonance peak: x1 DLF %.4f at %.0f rpm (DTE %.4g), x2 DLF %.4f at %.0f rpm (%.4g)\n",
      p1.dlf, p1.dlf_rpm, p1.dte, p2.dlf, p2.dlf_rpm, p2.dte);
  EXPECT_NEAR(p2.dlf, p1.dlf, 0.15 * p1.dlf);
  EXPECT_NEAR(p2.dlf_rpm / p1.dlf_rpm, std::sqrt(2.0), 0.05 * std::sqrt(2.0));
  EXPECT_NEAR(p2.dte / p1.dte, 0.5, 0.1);

  fg::Description te = d;
  for (double& e : te.pair.drive.e0_rad) e *= 3;
  const fg::Trace t3 = steady_adaptive(te);
  EXPECT_GT(range(t3.dte), range(base.dte));
  EXPECT_GT(t3.max_abs_mesh_torque, base.max_abs_mesh_torque);

  auto free_share = [](const fg::Trace& tr) {
    return std::count(tr.contact.begin(), tr.contact.end(), 0) / double(tr.contact.size());
  };
  auto widened = [](fg::Description x) {
    x.pair.half_backlash_rad *= 3;
    return x;
  };
  const fg::Description single = light_stiff(7000.0);
  const fg::Trace s1 = steady_adaptive(single);
  EXPECT_EQ(fg::classify_impacts(s1.contact_steps), fg::ImpactClass::kSingleSided);
  EXPECT_GT(free_share(s1), 0.0);
  EXPECT_NEAR(free_share(steady_adaptive(widened(single))), free_share(s1), 1e-9);
  fg::Description dbl = light_stiff(12000.0);
  for (fg::FlankTable* t : {&dbl.pair.drive, &dbl.pair.coast}) {
    for (double& e : t->e0_rad) e *= 5;
  }
  const fg::Trace d1 = steady_adaptive(dbl);
  EXPECT_EQ(fg::classify_impacts(d1.contact_steps), fg::ImpactClass::kDoubleSided);
  const double f1 = free_share(d1), f3 = free_share(steady_adaptive(widened(dbl)));
  std::printf("free flight, double-sided: %.4f -> %.4f with 3x backlash\n", f1, f3);
  EXPECT_GT(f3, f1);
}

// Seed result 3 (Fig. 9): with input and load torque fluctuation (a = b = 0.5) the two largest
// lines of the DTE spectrum are the input-torque frequency and the GMF. The seed's explanation is
// that the face gear's inertia is much larger than the pinion's: a torque fluctuation splits
// between the mesh and the rigid-body acceleration in the ratio of the inertias (input:
// r^2 I_g / (I_p + r^2 I_g) reaches the mesh, load: I_p / (I_p + r^2 I_g)). The shipped pair has
// r^2 I_g = 20.6 I_p (the bare gears' ratio, kept by the fit), the seed's condition; no inertia is
// set here. The fluctuation frequencies (the seed gives none): f_p = 200 Hz, f_g = 400 Hz.
TEST(FaceGear, TorqueFluctuationLines) {
  fg::Description d = shipped();
  EXPECT_GT(d.pair.ratio() * d.pair.ratio() * d.pair.inertia_g, 10 * d.pair.inertia_p);
  const double gmf = 1000.0, fp = 200.0, fg_hz = 400.0;
  d.operating.input_amp = 0.5;
  d.operating.input_freq_hz = fp;
  d.operating.load_amp = 0.5;
  d.operating.load_freq_hz = fg_hz;
  const fg::Trace tr = steady(d, 200);  // 0.2 s: 40 periods of f_p, 80 of f_g
  auto spec = fg::amplitude_spectrum(tr.dte, 1.0 / tr.dt, 3 * gmf);
  std::sort(spec.begin(), spec.end(), [](auto& x, auto& y) { return x[1] > y[1]; });
  const double df = 1.0 / (tr.dt * tr.dte.size());
  std::vector<double> top = {spec[0][0], spec[1][0]};
  std::sort(top.begin(), top.end());
  EXPECT_NEAR(top[0], fp, df);
  EXPECT_NEAR(top[1], gmf, df);
}

namespace {

struct HalfGmfLine {
  std::string period;  // classify_period (the Poincare section)
  fg::ImpactClass impact = fg::ImpactClass::kNoImpact;
  double half = 0, gmf = 0;  // A(GMF / 2), A(GMF) of the DTE
  double library_ratio = 0;  // Trace::half_gmf_ratio
};

// A steady response of description d (located-event rk8pd, as the CLI), and the DTE spectrum
// at GMF / 2 and GMF over 200 whole mesh periods (an even count: both fall on DFT bins).
HalfGmfLine half_gmf_line(const fg::Description& d) {
  const fg::Model m(d.pair, d.operating);
  const fg::Trace tr = steady_adaptive(d, 200, 300);
  const double gmf = m.mesh_frequency_hz(), fs = 1.0 / tr.dt;
  const std::vector<double> x(tr.dte.begin(), tr.dte.end() - 1);  // the 200 periods exactly
  HalfGmfLine out;
  out.period = fg::classify_period(tr);
  out.impact = fg::classify_impacts(tr.contact_steps);
  out.half = fg::amplitude_at(x, fs, 0.5 * gmf);
  out.gmf = fg::amplitude_at(x, fs, gmf);
  out.library_ratio = tr.half_gmf_ratio;
  return out;
}

}  // namespace

// Fig. 10 and 11 (12 N m, 10x stiffness). Fig. 10 is the figure the inertias and the static TE
// were fitted to (docs/face-gear.md), so this guards the fit at the paper's speeds; Fig. 11 is a
// prediction:
//  - 5000 rpm, between the paper's windows: period-1, no GMF / 2 line (ratio < 1e-3);
//  - 8000 rpm, in the paper's 7500-9500 rpm window (period-1 -> period-2 -> chaos): not
//    period-1, GMF / 2 line >= 0.1 of the GMF's;
//  - 18 000 rpm, past the paper's return to period-1 at 16 500 rpm: period-1;
//  - 12 000 rpm, Fig. 11: the GMF / 2 line (half_gmf_ratio >= 0.1, the criterion), single-
//    sided impacts (the paper: "between the backlash and the working flank"), not period-1.
// The library's half_gmf_ratio equals the DFT of the recorded trace (1e-9).
TEST(FaceGear, Fig10And11AtThePapersSpeeds) {
  const HalfGmfLine p1 = half_gmf_line(light_stiff(5000.0));
  EXPECT_EQ(p1.period, "period-1");
  EXPECT_LT(p1.half / p1.gmf, 1e-3);
  const HalfGmfLine w = half_gmf_line(light_stiff(8000.0));
  EXPECT_NE(w.period, "period-1");
  EXPECT_GE(w.half / w.gmf, 0.1);
  EXPECT_EQ(half_gmf_line(light_stiff(18000.0)).period, "period-1");
  const HalfGmfLine f11 = half_gmf_line(light_stiff(12000.0));
  std::printf("5000: %s %.3g; 8000: %s %.3g; 12000: %s %.3g %s\n", p1.period.c_str(),
              p1.half / p1.gmf, w.period.c_str(), w.half / w.gmf, f11.period.c_str(),
              f11.half / f11.gmf, fg::to_string(f11.impact));
  EXPECT_NE(f11.period, "period-1");
  EXPECT_GE(f11.library_ratio, 0.1);
  EXPECT_EQ(f11.impact, fg::ImpactClass::kSingleSided);
  for (const HalfGmfLine* h : {&p1, &w, &f11}) {
    EXPECT_NEAR(h->library_ratio, h->half / h->gmf, 1e-9 * h->half / h->gmf + 1e-15);
  }
}

TEST(FaceGear, PeriodClassification) {
  std::vector<double> p1(40, 1.0), p2, pn, chaos;
  for (int i = 0; i < 40; ++i) {
    p2.push_back(i % 2 ? 1.0 : 2.0);
    pn.push_back(i % 3);
    chaos.push_back(std::sin(1.0 + i * i * 0.37));
  }
  EXPECT_EQ(fg::classify_period(p1, 1.0), "period-1");
  EXPECT_EQ(fg::classify_period(p2, 1.0), "period-2");
  EXPECT_EQ(fg::classify_period(pn, 1.0), "period-n");
  EXPECT_EQ(fg::classify_period(chaos, 1.0), "chaos");
  EXPECT_EQ(fg::classify_impacts(std::vector<int>{1, 1, 1}), fg::ImpactClass::kNoImpact);
  EXPECT_EQ(fg::classify_impacts(std::vector<int>{1, 0, 1}), fg::ImpactClass::kSingleSided);
  EXPECT_EQ(fg::classify_impacts(std::vector<int>{1, 0, -1}), fg::ImpactClass::kDoubleSided);
}

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const diag::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(FaceGear, BadInputNamesTheField) {
  const std::filesystem::path dir = geardiag_test::scratch_dir("fg_bad");
  auto pair_with = [](const char* key, nlohmann::json v) {
    nlohmann::json j = {{"face_gear_pair", {{"pinion_teeth", 15}, {"gear_teeth", 121}}}};
    j["face_gear_pair"][key] = v;
    return j;
  };
  EXPECT_NE(error_of([&] {
              fg::parse_description(pair_with("backlash_um", -1), "fg.json");
            }).find("face_gear_pair.backlash_um"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              fg::parse_description(pair_with("stiffnes", 1), "fg.json");
            }).find("unknown field"),
            std::string::npos);
  auto table_error = [&](const std::string& rows) {
    std::ofstream(dir / "t.csv") << "flank,angle_deg,load_nm,stiffness_nm_per_rad,e0_urad\n"
                                 << rows;
    return error_of([&] {
      fg::parse_description(pair_with("stiffness_table", "t.csv"), (dir / "fg.json").string());
    });
  };
  const std::string ok_coast = "coast,0,10,1e6,0\ncoast,10,10,1e6,0\n";
  EXPECT_EQ(table_error("drive,0,10,1e6,0\ndrive,10,10,1e6,0\n" + ok_coast), "");
  EXPECT_NE(
      table_error("drive,0,10,-1e6,0\ndrive,10,10,1e6,0\n" + ok_coast).find("stiffness_nm_per_rad"),
      std::string::npos);
  // 30 deg is beyond one mesh period (24 deg for 15 teeth).
  EXPECT_NE(table_error("drive,0,10,1e6,0\ndrive,30,10,1e6,0\n" + ok_coast).find("drive.angle"),
            std::string::npos);
  EXPECT_NE(table_error("drive,0,10,1e6,0\ndrive,10,20,1e6,0\n" + ok_coast).find("incomplete"),
            std::string::npos);
  EXPECT_NE(table_error("drive,0,10,1e6,0\n").find("coast"), std::string::npos);
  EXPECT_NE(table_error("drive,0,10,1e6,0\ndrive,x,10,1e6,0\n" + ok_coast).find("angle_deg"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}
