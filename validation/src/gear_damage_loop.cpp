#include "validate/gear_damage_loop.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <memory>
#include <nlohmann/json.hpp>
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

void check_range(const std::string& lo_name, double lo, const std::string& hi_name, double hi,
                 double lower_bound, bool strict) {
  if (!std::isfinite(lo) || (strict ? !(lo > lower_bound) : !(lo >= lower_bound))) {
    diag::fail("GearDamageLoopOptions", lo_name,
               std::to_string(lo) + (strict ? " must be > " : " must be >= ") +
                   std::to_string(lower_bound));
  }
  if (!std::isfinite(hi) || hi < lo)
    diag::fail("GearDamageLoopOptions", hi_name, std::to_string(hi) + " is below " + lo_name);
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
  if (cases < 1)
    diag::fail("GearDamageLoopOptions", "cases", std::to_string(cases) + " is below 1");
  if (!(healthy_share >= 0.0 && healthy_share <= 1.0)) {
    diag::fail("GearDamageLoopOptions", "healthy_share",
               std::to_string(healthy_share) + " is outside [0, 1]");
  }
  check_range("min_rpm", min_rpm, "max_rpm", max_rpm, 0.0, true);
  check_range("min_torque_nm", min_torque_nm, "max_torque_nm", max_torque_nm, 0.0, true);
  check_range("min_noise_m_per_s2", min_noise_m_per_s2, "max_noise_m_per_s2", max_noise_m_per_s2,
              0.0, false);
  if (min_accuracy_grade < 0 || max_accuracy_grade > 12 ||
      max_accuracy_grade < min_accuracy_grade) {
    diag::fail("GearDamageLoopOptions", "min_accuracy_grade/max_accuracy_grade",
               std::to_string(min_accuracy_grade) + ".." + std::to_string(max_accuracy_grade) +
                   " is not a range inside [0, 12]");
  }
  check_range("min_runout_m", min_runout_m, "max_runout_m", max_runout_m, 0.0, false);
  check_range("min_crack_fraction", min_crack_fraction, "max_crack_fraction", max_crack_fraction,
              0.0, true);
  if (max_crack_fraction > 1.0)
    diag::fail("GearDamageLoopOptions", "max_crack_fraction", "must be <= 1");
  check_range("min_chip_modules", min_chip_modules, "max_chip_modules", max_chip_modules, 0.0,
              true);
  if (max_chip_modules > 2.0)
    diag::fail("GearDamageLoopOptions", "max_chip_modules", "must be <= 2");
  check_range("min_spall_modules", min_spall_modules, "max_spall_modules", max_spall_modules, 0.0,
              true);
  if (max_spall_modules > 2.0)
    diag::fail("GearDamageLoopOptions", "max_spall_modules", "must be <= 2");
  check_range("min_spall_depth_m", min_spall_depth_m, "max_spall_depth_m", max_spall_depth_m, 0.0,
              true);
  if (!root_crack && !chip && !missing && !spall) {
    diag::fail("GearDamageLoopOptions", "root_crack/chip/missing/spall", "no fault kind enabled");
  }
  if (!(fs_hz > 0))
    diag::fail("GearDamageLoopOptions", "fs_hz", std::to_string(fs_hz) + " must be > 0");
  if (slowest_shaft_revolutions < detector.min_revolutions + 3) {
    diag::fail(
        "GearDamageLoopOptions", "slowest_shaft_revolutions",
        std::to_string(slowest_shaft_revolutions) + " is below detector.min_revolutions + 3");
  }
  if (steps_per_period < 8)
    diag::fail("GearDamageLoopOptions", "steps_per_period",
               std::to_string(steps_per_period) + " < 8");
  detector.validate();
}

GearDamageLoopReport run_gear_damage_loop(const diag::Gearbox& gb,
                                          const GearDamageLoopOptions& opt) {
  return run_gear_damage_loop(std::span<const diag::Gearbox>(&gb, 1), opt);
}

GearDamageLoopReport run_gear_damage_loop(std::span<const diag::Gearbox> gearboxes,
                                          const GearDamageLoopOptions& opt) {
  opt.validate();
  if (gearboxes.empty()) diag::fail("GearDamageLoopOptions", "gearboxes", "none given");
  std::mt19937_64 rng(opt.seed);
  std::vector<std::string> kinds;
  if (opt.root_crack) kinds.push_back("crack");
  if (opt.chip) kinds.push_back("chip");
  if (opt.missing) kinds.push_back("missing");
  if (opt.spall) kinds.push_back("spall");
  const sim::StiffnessOptions stiffness;
  GearDamageLoopReport rep;
  const int n_healthy = static_cast<int>(std::lround(opt.healthy_share * opt.cases));
  for (int i = 0; i < opt.cases; ++i) {
    const diag::Gearbox& gb = gearboxes[static_cast<std::size_t>(i) % gearboxes.size()];
    double slowest_ratio = 1e300;
    for (const auto& s : gb.shafts()) {
      if (!s.gears.empty()) slowest_ratio = std::min(slowest_ratio, std::abs(s.speed_ratio));
    }
    GearDamageCase c;
    c.gearbox = gb.name();
    // Healthy cases are spread evenly through the run (every k-th case).
    c.faulty = n_healthy == 0 || (i * n_healthy) / opt.cases == ((i + 1) * n_healthy) / opt.cases;
    c.rpm = uniform(rng, opt.min_rpm, opt.max_rpm);
    c.torque_nm = uniform(rng, opt.min_torque_nm, opt.max_torque_nm);
    c.noise_m_per_s2 = uniform(rng, opt.min_noise_m_per_s2, opt.max_noise_m_per_s2);
    c.accuracy_grade =
        opt.min_accuracy_grade +
        static_cast<int>(rng() % static_cast<std::uint64_t>(opt.max_accuracy_grade -
                                                            opt.min_accuracy_grade + 1));
    c.runout_m = uniform(rng, opt.min_runout_m, opt.max_runout_m);
    sim::DynamicsOptions dyn;
    dyn.speed = sim::SpeedProfile::constant(c.rpm);
    dyn.input_torque_nm = c.torque_nm;
    dyn.accuracy_grade = c.accuracy_grade;
    dyn.runout_m = c.runout_m;
    dyn.seed = rng();
    // Drawn for every case (healthy ones too), so that the draws of a case do not depend on
    // whether the one before was faulty.
    const int g = static_cast<int>(rng() % gb.gears().size());
    const std::string kind = kinds[rng() % kinds.size()];
    const double u = uniform(rng, 0.0, 1.0), u2 = uniform(rng, 0.0, 1.0);
    const std::uint64_t tooth_draw = rng();
    if (c.faulty) {
      const diag::GearEntry& ge = gb.gears()[static_cast<std::size_t>(g)];
      const diag::Gear gear(ge.spec);
      c.gear = ge.name;
      c.truth_shaft = ge.shaft;
      c.kind = kind;
      c.tooth = static_cast<int>(tooth_draw % static_cast<std::uint64_t>(ge.spec.teeth));
      c.severity = u;
      sim::GearFault f;
      f.gear = ge.name;
      f.fault.tooth = c.tooth;
      auto lerp = [u](double lo, double hi) { return lo + u * (hi - lo); };
      if (c.kind == "crack") {
        f.fault.kind = sim::ToothFault::Kind::kRootCrack;
        const double max_crack =
            1.8 * root_half_thickness_m(gear, ge.spec) / std::sin(stiffness.crack_angle_rad);
        f.fault.size_m = max_crack * lerp(opt.min_crack_fraction, opt.max_crack_fraction);
      } else if (c.kind == "chip") {
        f.fault.kind = sim::ToothFault::Kind::kChip;
        f.fault.size_m = ge.spec.module_m * lerp(opt.min_chip_modules, opt.max_chip_modules);
      } else if (c.kind == "spall") {
        f.fault.kind = sim::ToothFault::Kind::kSpall;
        f.fault.size_m = ge.spec.module_m * lerp(opt.min_spall_modules, opt.max_spall_modules);
        f.fault.depth_m =
            opt.min_spall_depth_m + u2 * (opt.max_spall_depth_m - opt.min_spall_depth_m);
      } else {
        f.fault.kind = sim::ToothFault::Kind::kMissing;
        c.severity = 1.0;
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
    const std::uint64_t baseline_noise_seed = rng();
    const double baseline_delay = uniform(rng, 0.3, 1.3);
    const sim::DynamicResult sr = sim::simulate_dynamic(gb, dyn, run);
    detect::GearDamageOptions det = opt.detector;
    if (opt.baseline) {
      // The baseline is recorded later in the run (0.3-1.3 slowest-shaft revolutions more
      // settling), as a real one is on another day: the shafts stand at other relative angles
      // at its first tacho pulse, so the slower shafts' averages are rotated against the
      // record's and what is not synchronous with a shaft does not cancel in the difference.
      sim::DynamicsOptions healthy = dyn;
      healthy.faults.clear();
      sim::RunOptions run_b = run;
      run_b.seed = baseline_noise_seed;
      run_b.settle_s =
          sr.truth["integrator"]["settle_s"].get<double>() + baseline_delay / slowest_hz;
      const diag::Recording rb = sim::to_recording(gb, sim::simulate_dynamic(gb, healthy, run_b));
      det.baseline = std::make_shared<const detect::GearDamageBaseline>(
          detect::gear_damage_baseline(rb, gb, opt.detector));
    }
    c.result = detect::locate_gear_damage(sim::to_recording(gb, sr), gb, det);
    for (const auto& s : c.result.shafts) {
      c.evidence.push_back({s.shaft, s.frequency_hz, s.score, s.significant});
    }
    if (!c.result.findings.empty()) c.found_shaft = c.result.findings[0].shaft;
    if (c.faulty) {
      ++rep.faulty_total;
      if (c.result.status == "damaged" && c.found_shaft == c.truth_shaft) {
        c.outcome = "right";
        ++rep.faulty_correct;
      } else if (c.result.status == "healthy") {
        c.outcome = "silent";
        ++rep.faulty_missed;
      } else if (c.result.status == "ambiguous") {
        c.outcome = "silent";
        ++rep.faulty_ambiguous;
      } else {
        c.outcome = "wrong";
        ++rep.faulty_wrong_shaft;
      }
    } else {
      ++rep.healthy_total;
      c.outcome = c.result.findings.empty() ? "right" : "false_alarm";
      if (!c.result.findings.empty()) ++rep.healthy_false_alarms;
    }
    c.correct = c.outcome == "right";
    rep.cases.push_back(std::move(c));
    if (opt.on_case_done) opt.on_case_done();
  }
  return rep;
}

std::string decide_at(const GearDamageCase& c, double threshold) {
  const ShaftEvidence* best = nullptr;
  for (const auto& e : c.evidence) {
    if (!e.gates_passed || !(e.score > threshold)) continue;
    if (!best || e.frequency_hz < best->frequency_hz) best = &e;
  }
  return best ? best->shaft : std::string();
}

namespace {

std::string group_of(const GearDamageCase& c) {
  if (!c.faulty) return "healthy";
  if (c.kind == "missing") return c.kind;
  const char* third = c.severity < 1.0 / 3.0   ? "small"
                      : c.severity < 2.0 / 3.0 ? "medium"
                                               : "large";
  return c.kind + " " + third;
}

}  // namespace

std::vector<std::pair<std::string, OutcomeCounts>> outcome_table(const GearDamageLoopReport& r) {
  std::vector<std::pair<std::string, OutcomeCounts>> t;
  for (const char* kind : {"crack", "chip", "spall"}) {
    for (const char* third : {"small", "medium", "large"}) {
      t.emplace_back(std::string(kind) + " " + third, OutcomeCounts{});
    }
  }
  t.emplace_back("missing", OutcomeCounts{});
  t.emplace_back("healthy", OutcomeCounts{});
  for (const auto& c : r.cases) {
    const std::string g = group_of(c);
    auto it = std::find_if(t.begin(), t.end(), [&](const auto& p) { return p.first == g; });
    OutcomeCounts& n = it->second;
    ++n.total;
    if (c.outcome == "right") {
      ++n.right;
    } else if (c.outcome == "silent") {
      ++n.silent;
    } else {
      ++n.wrong;
    }
  }
  std::erase_if(t, [](const auto& p) { return p.second.total == 0; });
  return t;
}

std::vector<RocPoint> roc(const GearDamageLoopReport& r, std::span<const double> thresholds) {
  std::vector<RocPoint> out;
  for (double th : thresholds) {
    RocPoint p;
    p.threshold = th;
    int healthy = 0, alarms = 0, faulty = 0, right = 0, wrong = 0;
    std::vector<std::pair<std::string, std::pair<int, int>>> by_kind;
    for (const auto& c : r.cases) {
      const std::string found = decide_at(c, th);
      if (!c.faulty) {
        ++healthy;
        alarms += !found.empty();
        continue;
      }
      ++faulty;
      const bool ok = found == c.truth_shaft;
      right += ok;
      wrong += !found.empty() && !ok;
      auto it = std::find_if(by_kind.begin(), by_kind.end(),
                             [&](const auto& k) { return k.first == c.kind; });
      if (it == by_kind.end()) it = by_kind.insert(by_kind.end(), {c.kind, {0, 0}});
      ++it->second.first;
      it->second.second += ok;
    }
    p.false_alarm_rate = healthy ? double(alarms) / healthy : 0.0;
    p.detection_rate = faulty ? double(right) / faulty : 0.0;
    p.wrong_rate = faulty ? double(wrong) / faulty : 0.0;
    for (const auto& [k, n] : by_kind) {
      p.detection_by_kind.emplace_back(k, double(n.second) / n.first);
    }
    out.push_back(std::move(p));
  }
  return out;
}

std::string format_report(const GearDamageLoopReport& r) {
  std::ostringstream o;
  o << std::setprecision(4);
  for (std::size_t i = 0; i < r.cases.size(); ++i) {
    const GearDamageCase& c = r.cases[i];
    if (c.correct) continue;
    o << "case " << i << " [" << c.gearbox << "]: "
      << (c.faulty ? c.kind + " on " + c.gear + " tooth " + std::to_string(c.tooth) + " (" +
                         c.truth_shaft + ")"
                   : std::string("healthy"))
      << " size " << c.size_m * 1e3 << " mm, grade " << c.accuracy_grade << ", runout "
      << c.runout_m * 1e6 << " um, " << c.rpm << " rpm, " << c.torque_nm << " N m, noise "
      << c.noise_m_per_s2 << " -> " << c.result.status << " " << c.found_shaft << "; scores";
    for (const auto& s : c.result.shafts) {
      o << " " << s.shaft << "=" << s.score << (s.significant ? "" : "(gated)") << "/snr " << s.snr;
    }
    o << "\n";
  }
  o << "\n"
    << std::left << std::setw(20) << "class" << std::right << std::setw(7) << "cases"
    << std::setw(7) << "right" << std::setw(8) << "silent" << std::setw(7) << "wrong"
    << "\n";
  for (const auto& [g, n] : outcome_table(r)) {
    o << std::left << std::setw(20) << (g == "healthy" ? "healthy (wrong: alarm)" : g) << std::right
      << std::setw(7) << n.total << std::setw(7) << n.right << std::setw(8) << n.silent
      << std::setw(7) << n.wrong << "\n";
  }
  o << "faulty: " << r.faulty_correct << "/" << r.faulty_total << " right shaft ("
    << 100.0 * r.faulty_accuracy() << " %), silent " << r.faulty_missed + r.faulty_ambiguous
    << " (ambiguous " << r.faulty_ambiguous << "), wrong shaft " << r.faulty_wrong_shaft << "\n"
    << "healthy: " << r.healthy_false_alarms << " false alarms in " << r.healthy_total << "\n";
  std::vector<double> th;
  for (double x = 2.0; x <= 200.0; x *= 1.25) th.push_back(x);
  o << "\nROC (score threshold: false-alarm rate, detection rate, wrong-shaft rate; detection "
       "by kind)\n";
  o << std::fixed << std::setprecision(2);
  for (const RocPoint& p : roc(r, th)) {
    o << "  " << std::setw(5) << p.threshold << ": FA " << p.false_alarm_rate << "  det "
      << p.detection_rate << "  wrong " << p.wrong_rate << " |";
    for (const auto& [k, d] : p.detection_by_kind) o << " " << k << " " << d;
    o << "\n";
  }
  return o.str();
}

}  // namespace validate
