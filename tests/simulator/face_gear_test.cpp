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

// Linear case (no backlash, identical flanks, constant stiffness, pinion inertia so large that
// theta_p = Omega t): m e'' + c e' + k e = k e0 + c e0' - r T_g with m = r I_g, so the GMF
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
  d.pair.inertia_p = 1e3;
  d.pair.bearing_damping_p = d.pair.bearing_damping_g = 0.0;
  d.pair.damping_alpha = 0.0;
  d.pair.damping_beta = 1e-6;
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
      // c d'^2 / r with c d' = T_mesh - k d (drive), -T_mesh - k d (coast).
      const double flank = m.contact == fg::Contact::kDrive ? 1.0 : -1.0;
      const double cdd = flank * m.torque - m.k * m.deflection;
      const double c = d.pair.damping_alpha * d.pair.reduced_inertia() + d.pair.damping_beta * m.k;
      p.p_mesh = cdd * cdd / c / r;
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

// RK4 (fixed step) and GSL rk8pd with located contact switches agree on a steady response with
// impacts: the DTE traces on the same time grid differ by at most 0.1 % of the DTE range (RK4 at
// 32 steps per mesh-mode period loses order at the unlocated switches; measured 0.02 %, 40
// switches in 20 mesh periods); four times more RK4 steps must at least halve the difference
// (measured: / 7.7, between first and second order, as expected with unlocated kinks).
TEST(FaceGear, Rk4AndAdaptiveAgree) {
  fg::Description d = seed_pair();
  d.pair.stiffness_scale = 0.24;
  d.operating.torque_nm = 12.0;
  d.operating.speed_rpm = 13000.0;
  const fg::Model model(d.pair, d.operating);
  fg::RunOptions o;
  o.transient_periods = 150;
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
  EXPECT_LT(diff, 1e-3 * range(b.dte));
  EXPECT_LT(diff4, 0.5 * diff);
  EXPECT_EQ(fg::classify_period(a), fg::classify_period(b));
}

// Seed result 1: at the rated point (4000 rpm, 300 N m) the response is period-1 without impact
// and the GMF is the largest line of the DTE spectrum.
TEST(FaceGear, RatedPointIsPeriodOneWithoutImpact) {
  const fg::Description d = seed_pair();
  const fg::Trace tr = steady(d);
  EXPECT_EQ(fg::classify_period(tr), "period-1");
  EXPECT_EQ(fg::classify_impacts(tr.contact), fg::ImpactClass::kNoImpact);
  const double gmf = 4000.0 / 60 * 15;
  const auto spec = fg::amplitude_spectrum(tr.dte, 1.0 / tr.dt, 3.5 * gmf);
  const auto top =
      std::max_element(spec.begin(), spec.end(), [](auto& x, auto& y) { return x[1] < y[1]; });
  EXPECT_NEAR((*top)[0], gmf, 1.0);
  const double dlf = tr.max_abs_mesh_torque / fg::Model(d.pair, d.operating).static_torque();
  EXPECT_GT(dlf, 1.0);
  EXPECT_LT(dlf, 1.2);
}

// Seed result 2 (4000 rpm, 300 N m unless said): stiffer mesh -> smaller DTE (mean and
// peak-to-peak), DLF changes by < 5 %; 3x backlash at light load -> more free-flight points;
// larger static TE -> larger DTE fluctuation and DLF.
TEST(FaceGear, StiffnessBacklashAndStaticTeTrends) {
  fg::Description d = seed_pair();
  const fg::Model m0(d.pair, d.operating);
  const fg::Trace base = steady(d);
  fg::Description stiff = d;
  stiff.pair.stiffness_scale = 2.0;
  const fg::Trace s = steady(stiff);
  auto mean_abs = [](const std::vector<double>& x) {
    double a = 0;
    for (double v : x) a += std::abs(v);
    return a / x.size();
  };
  EXPECT_LT(mean_abs(s.dte), 0.9 * mean_abs(base.dte));
  EXPECT_LT(range(s.dte), range(base.dte));
  const double dlf0 = base.max_abs_mesh_torque / m0.static_torque();
  const double dlf_s = s.max_abs_mesh_torque / m0.static_torque();
  EXPECT_NEAR(dlf_s, dlf0, 0.05 * dlf0);

  fg::Description te = d;
  for (double& e : te.pair.drive.e0_rad) e *= 3;
  const fg::Trace t3 = steady(te);
  EXPECT_GT(range(t3.dte), range(base.dte));
  EXPECT_GT(t3.max_abs_mesh_torque, base.max_abs_mesh_torque);

  // Backlash at light load (12 N m) and 10x stiffness beyond the separation speed.
  fg::Description light = seed_pair();
  light.pair.stiffness_scale = 10.0;
  light.operating.torque_nm = 12.0;
  light.operating.speed_rpm = 26000.0;
  fg::Description wide = light;
  wide.pair.half_backlash_rad *= 3;
  auto free_share = [](const fg::Trace& tr) {
    return std::count(tr.contact.begin(), tr.contact.end(), 0) / double(tr.contact.size());
  };
  const double f1 = free_share(steady(light)), f3 = free_share(steady(wide));
  EXPECT_GT(f1, 0.0);
  EXPECT_GT(f3, f1);
}

// Seed result 3: with input and load torque fluctuation (a = b = 0.5) the two largest lines of
// the DTE spectrum are the input-torque frequency and the GMF. The seed's explanation is that the
// face gear's inertia is much larger than the pinion's: a torque fluctuation splits between the
// mesh and the rigid-body acceleration in the ratio of the inertias (input: r^2 I_g / (I_p +
// r^2 I_g) reaches the mesh, load: I_p / (I_p + r^2 I_g)). The default inertias are the bare
// gears (r^2 I_g = 1.3 I_p); here the face gear carries its output shaft and hub, I_g = 0.1 kg m^2
// (r^2 I_g = 17 I_p), which is the seed's condition. The fluctuations also modulate the speed, so
// the mesh phase: its deviation N_p dT / (I (2 pi f)^2 omega) ... stays below 1 rad (carrier
// J0 > 0.75) for f_p = 200 Hz, f_g = 400 Hz; at a few tens of Hz the rigid-body speed swing of
// these small inertias spreads the GMF line over many sidebands (the seed gives no frequencies).
TEST(FaceGear, TorqueFluctuationLines) {
  fg::Description d = seed_pair();
  d.pair.inertia_g = 0.1;
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
  std::string period;        // classify_period (the Poincare section)
  double half = 0, gmf = 0;  // A(GMF / 2), A(GMF) of the DTE
  double neighbourhood = 0;  // largest other bin in [0.25, 0.75] GMF
  double library_ratio = 0;  // Trace::half_gmf_ratio
};

// A steady response at (rpm, torque) with 10x stiffness, and the DTE spectrum around GMF / 2
// over 200 whole mesh periods (an even count: GMF / 2 and GMF fall on DFT bins).
HalfGmfLine half_gmf_line(double rpm, double torque) {
  fg::Description d = seed_pair();
  d.pair.stiffness_scale = 10.0;
  d.operating.speed_rpm = rpm;
  d.operating.torque_nm = torque;
  const fg::Model m(d.pair, d.operating);
  fg::RunOptions o;  // the step count simulate and bifurcation use
  o.steps_per_period = fg::rk4_steps_per_period(m);
  o.transient_periods = 400;
  o.record_periods = 200;
  const fg::Trace tr = fg::run(m, o);
  const double gmf = m.mesh_frequency_hz(), fs = 1.0 / tr.dt;
  const std::vector<double> x(tr.dte.begin(), tr.dte.end() - 1);  // the 200 periods exactly
  const double df = fs / static_cast<double>(x.size());           // GMF / 200
  HalfGmfLine out;
  out.period = fg::classify_period(tr);
  out.half = fg::amplitude_at(x, fs, 0.5 * gmf);
  out.gmf = fg::amplitude_at(x, fs, gmf);
  const int k_half = static_cast<int>(std::lround(0.5 * gmf / df));
  for (int k = static_cast<int>(0.25 * gmf / df); k <= static_cast<int>(0.75 * gmf / df); ++k) {
    if (std::abs(k - k_half) > 2) {
      out.neighbourhood = std::max(out.neighbourhood, fg::amplitude_at(x, fs, k * df));
    }
  }
  out.library_ratio = tr.half_gmf_ratio;
  return out;
}

}  // namespace

// Period doubling in the DTE spectrum (a line at 0.5 GMF when period-2). At light load
// (12 N m) with 10x stiffness the analytical default pair is period-2 from 75 750 to 76 750 rpm
// (geardiag bifurcation, 70 000-80 000 rpm in 250 rpm steps: chaos and period-n around it, with
// double-sided impacts); 76 250 rpm stays period-2 at 64, 128 and 256 RK4 steps per period and
// 300-1000 transient periods (76 000 rpm does not: its class changes with the step count). The
// nearest period-1 speed at that load is 22 000 rpm (period-1 up to 22 000 rpm, then chaos,
// period-n and this window up to 100 000 rpm); at 76 000 rpm the rated 300 N m keeps it period-1.
// Criterion for "a line": A(GMF / 2) at least 20x (26 dB) the largest other bin within
// [0.25, 0.75] GMF. Over whole periods of a steady periodic response those bins hold only what
// is left of the transient and the integration jitter: measured 5.5e4x for period-2, 0.6x and
// 0.3x for the period-1 cases; 26 dB, a usual peak-picking prominence, is two decades from
// both. In the period-2 window the gear rattles from flank to flank once every two mesh periods,
// so the subharmonic dominates: A(GMF / 2) / A(GMF) = 46.1 measured, asserted > 1. Period-1:
// A(GMF / 2) / A(GMF) < 1e-3 (measured 1e-6 and 3e-9).
TEST(FaceGear, PeriodTwoHasHalfGmfLinePeriodOneHasNone) {
  const HalfGmfLine p2 = half_gmf_line(76250.0, 12.0);
  EXPECT_EQ(p2.period, "period-2");
  EXPECT_GT(p2.half, 20.0 * p2.neighbourhood);
  EXPECT_GT(p2.half / p2.gmf, 1.0);
  EXPECT_NEAR(p2.library_ratio, p2.half / p2.gmf, 1e-9 * p2.half / p2.gmf);
  for (const auto& [rpm, torque] : {std::pair{22000.0, 12.0}, std::pair{76000.0, 300.0}}) {
    const HalfGmfLine p1 = half_gmf_line(rpm, torque);
    EXPECT_EQ(p1.period, "period-1") << rpm << " rpm, " << torque << " N m";
    EXPECT_LT(p1.half, 20.0 * p1.neighbourhood) << rpm << " rpm, " << torque << " N m";
    EXPECT_LT(p1.half / p1.gmf, 1e-3) << rpm << " rpm, " << torque << " N m";
    EXPECT_LT(p1.library_ratio, 1e-3) << rpm << " rpm, " << torque << " N m";
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
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("fg_bad_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
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
