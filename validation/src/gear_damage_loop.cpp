#include "validate/gear_damage_loop.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <random>
#include <sstream>

#include "diag/error.hpp"
#include "diag/geometry/gear.hpp"
#include "sim/dynamics/simulate.hpp"

namespace validate {

namespace {

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
}

void fail(const std::string& field, const std::string& reason) {
  throw diag::InputError(diag::format_error("GearDamageLoopOptions", field, reason));
}

void check_range(const std::string& lo_name, double lo, const std::string& hi_name, double hi,
                 double lower_bound, bool strict) {
  if (!std::isfinite(lo) || (strict ? !(lo > lower_bound) : !(lo >= lower_bound))) {
    fail(lo_name, std::to_string(lo) + (strict ? " must be > " : " must be >= ") +
                      std::to_string(lower_bound));
  }
  if (!std::isfinite(hi) || hi < lo) fail(hi_name, std::to_string(hi) + " is below " + lo_name);
}

// Half thickness of the tooth at the root circle, perpendicular to its centre line: the h_root of
// sim/mesh/mesh_stiffness (the limit of a root crack is 1.8 h_root / sin(crack angle)).
double root_half_thickness_m(const diag::Gear& g, const diag::GearSpec& sp) {
  const double a = sp.pressure_angle_rad;
  const double inv_a = std::tan(a) - a;
  const double alpha2 =
      std::numbers::pi / (2.0 * sp.teeth) + inv_a + 2.0 * sp.profile_shift * std::tan(a) / sp.teeth;
  const double rb = g.base_radius_m(), rf = g.root_radius_m();
  if (rf < rb) return rb * std::sin(alpha2);
  const double ar = std::acos(rb / rf);
  return rf * std::sin(alpha2 - (std::tan(ar) - ar));
}

}  // namespace

void GearDamageLoopOptions::validate() const {
  if (cases < 1) fail("cases", std::to_string(cases) + " is below 1");
  if (!(healthy_share >= 0.0 && healthy_share <= 1.0)) {
    fail("healthy_share", std::to_string(healthy_share) + " is outside [0, 1]");
  }
  check_range("min_rpm", min_rpm, "max_rpm", max_rpm, 0.0, true);
  check_range("min_torque_nm", min_torque_nm, "max_torque_nm", max_torque_nm, 0.0, true);
  check_range("min_noise_m_per_s2", min_noise_m_per_s2, "max_noise_m_per_s2", max_noise_m_per_s2,
              0.0, false);
  check_range("min_crack_fraction", min_crack_fraction, "max_crack_fraction", max_crack_fraction,
              0.0, true);
  if (max_crack_fraction > 1.0) fail("max_crack_fraction", "must be <= 1");
  check_range("min_chip_modules", min_chip_modules, "max_chip_modules", max_chip_modules, 0.0,
              true);
  if (max_chip_modules > 2.0) fail("max_chip_modules", "must be <= 2");
  if (!root_crack && !chip && !missing) fail("root_crack/chip/missing", "no fault kind enabled");
  if (!(fs_hz > 0)) fail("fs_hz", std::to_string(fs_hz) + " must be > 0");
  if (slowest_shaft_revolutions < detector.min_revolutions + 3) {
    fail("slowest_shaft_revolutions",
         std::to_string(slowest_shaft_revolutions) + " is below detector.min_revolutions + 3");
  }
  if (steps_per_period < 8) fail("steps_per_period", std::to_string(steps_per_period) + " < 8");
  detector.validate();
}

GearDamageLoopReport run_gear_damage_loop(const diag::Gearbox& gb,
                                          const GearDamageLoopOptions& opt) {
  opt.validate();
  std::mt19937_64 rng(opt.seed);
  std::vector<std::string> kinds;
  if (opt.root_crack) kinds.push_back("root_crack");
  if (opt.chip) kinds.push_back("chip");
  if (opt.missing) kinds.push_back("missing");
  double slowest_ratio = 1e300;
  for (const auto& s : gb.shafts()) {
    if (!s.gears.empty()) slowest_ratio = std::min(slowest_ratio, std::abs(s.speed_ratio));
  }
  const sim::StiffnessOptions stiffness;
  GearDamageLoopReport rep;
  const int n_healthy = static_cast<int>(std::lround(opt.healthy_share * opt.cases));
  for (int i = 0; i < opt.cases; ++i) {
    GearDamageCase c;
    // Healthy cases are spread evenly through the run (every k-th case).
    c.faulty = n_healthy == 0 || (i * n_healthy) / opt.cases == ((i + 1) * n_healthy) / opt.cases;
    c.rpm = uniform(rng, opt.min_rpm, opt.max_rpm);
    c.torque_nm = uniform(rng, opt.min_torque_nm, opt.max_torque_nm);
    c.noise_m_per_s2 = uniform(rng, opt.min_noise_m_per_s2, opt.max_noise_m_per_s2);
    sim::DynamicsOptions dyn;
    dyn.speed = sim::SpeedProfile::constant(c.rpm);
    dyn.input_torque_nm = c.torque_nm;
    dyn.seed = rng();
    if (c.faulty) {
      const int g = static_cast<int>(rng() % gb.gears().size());
      const diag::GearEntry& ge = gb.gears()[g];
      const diag::Gear gear(ge.spec);
      c.gear = ge.name;
      c.truth_shaft = ge.shaft;
      c.kind = kinds[rng() % kinds.size()];
      c.tooth = static_cast<int>(rng() % ge.spec.teeth);
      sim::GearFault f;
      f.gear = ge.name;
      f.fault.tooth = c.tooth;
      if (c.kind == "root_crack") {
        f.fault.kind = sim::ToothFault::Kind::kRootCrack;
        const double max_crack =
            1.8 * root_half_thickness_m(gear, ge.spec) / std::sin(stiffness.crack_angle_rad);
        f.fault.size_m = max_crack * uniform(rng, opt.min_crack_fraction, opt.max_crack_fraction);
      } else if (c.kind == "chip") {
        f.fault.kind = sim::ToothFault::Kind::kChip;
        f.fault.size_m =
            ge.spec.module_m * uniform(rng, opt.min_chip_modules, opt.max_chip_modules);
      } else {
        f.fault.kind = sim::ToothFault::Kind::kMissing;
      }
      c.size_m = f.fault.size_m;
      dyn.faults.push_back(f);
    }
    sim::RunOptions run;
    const double slowest_hz = c.rpm / 60.0 * slowest_ratio;
    run.duration_s = opt.slowest_shaft_revolutions / slowest_hz;
    run.fs_hz = opt.fs_hz;
    run.accel_noise_m_per_s2 = c.noise_m_per_s2;
    run.seed = rng();
    run.mesh_channels = false;
    run.steps_per_period = opt.steps_per_period;
    const sim::DynamicResult sr = sim::simulate_dynamic(gb, dyn, run);
    c.result = detect::locate_gear_damage(sim::to_recording(gb, sr), gb, opt.detector);
    if (!c.result.findings.empty()) c.found_shaft = c.result.findings[0].shaft;
    if (c.faulty) {
      ++rep.faulty_total;
      c.correct = c.result.status == "damaged" && c.found_shaft == c.truth_shaft;
      if (c.correct)
        ++rep.faulty_correct;
      else if (c.result.status == "healthy")
        ++rep.faulty_missed;
      else if (c.result.status == "ambiguous")
        ++rep.faulty_ambiguous;
      else
        ++rep.faulty_wrong_shaft;
    } else {
      ++rep.healthy_total;
      c.correct = c.result.findings.empty();
      if (!c.correct) ++rep.healthy_false_alarms;
    }
    rep.cases.push_back(std::move(c));
  }
  return rep;
}

std::string format_report(const GearDamageLoopReport& r) {
  std::ostringstream o;
  o << std::setprecision(4);
  for (std::size_t i = 0; i < r.cases.size(); ++i) {
    const GearDamageCase& c = r.cases[i];
    if (c.correct) continue;
    o << "case " << i << ": "
      << (c.faulty ? c.kind + " on " + c.gear + " tooth " + std::to_string(c.tooth) + " (" +
                         c.truth_shaft + ")"
                   : std::string("healthy"))
      << " size " << c.size_m * 1e3 << " mm, " << c.rpm << " rpm, " << c.torque_nm << " N m, noise "
      << c.noise_m_per_s2 << " -> " << c.result.status << " " << c.found_shaft << "; scores";
    for (const auto& s : c.result.shafts) o << " " << s.shaft << "=" << s.score << "/snr " << s.snr;
    o << "\n";
  }
  o << "faulty: " << r.faulty_correct << "/" << r.faulty_total << " right shaft ("
    << 100.0 * r.faulty_accuracy() << " %), missed " << r.faulty_missed << ", wrong shaft "
    << r.faulty_wrong_shaft << ", ambiguous " << r.faulty_ambiguous << "\n"
    << "healthy: " << r.healthy_false_alarms << " false alarms in " << r.healthy_total << "\n";
  return o.str();
}

}  // namespace validate
