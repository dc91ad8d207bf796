#include "sim/kinematic/sporadic_defects.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "diag/error.hpp"
#include "diag/io/truth.hpp"
#include "diag/units.hpp"

namespace sim {

using diag::InputError;
using diag::units::kTwoPi;
using nlohmann::json;

namespace {

// A defect as the simulation needs it: which path mesh, its gap in down-gear angle, and how its
// own gear's angle follows the input angle.
struct ActiveDefect {
  std::size_t step = 0;         // index into power_path()
  double gap_down_rad = 0.0;    // deficit opened in the contact, in down-gear angle
  double phase_rad = 0.0;       // gear angle at which the defect enters the mesh
  double gear_per_input = 0.0;  // d(gear angle) / d(input angle) = 1 / T_i
  double hold_rad = 0.0;        // gear-angle span at full depth (= the defect's own size)
  double recovery_rad = 0.0;    // gear-angle span over which the gap closes again
};

// Fraction of the gap open at input angle x: 1 while the defect is in contact, then a linear
// close-out over the recovery span, 0 elsewhere.
double open_fraction(const ActiveDefect& d, double x) {
  double y = std::fmod(x * d.gear_per_input - d.phase_rad, kTwoPi);
  if (y < 0) y += kTwoPi;
  if (y < d.hold_rad) return 1.0;
  y -= d.hold_rad;
  if (y < d.recovery_rad) return 1.0 - y / d.recovery_rad;
  return 0.0;
}

// Box-Muller on a 64-bit Mersenne Twister: the same seed gives the same bytes on every platform
// (std::normal_distribution is implementation-defined).
class Gaussian {
 public:
  explicit Gaussian(std::uint64_t seed) : rng_(seed) {}
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = 0;
    do {
      u1 = uniform();
    } while (u1 <= 0);
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(kTwoPi * u2);
    has_spare_ = true;
    return r * std::cos(kTwoPi * u2);
  }
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

 private:
  std::mt19937_64 rng_;
  bool has_spare_ = false;
  double spare_ = 0;
};

double quantise(double angle, std::int64_t counts) {
  if (counts <= 0) return angle;
  const double q = kTwoPi / static_cast<double>(counts);
  return std::floor(angle / q) * q;
}

}  // namespace

void KinematicOptions::validate() const {
  diag::require(step_rad > 0 && step_rad <= 0.1, "kinematic simulation", "step_rad",
                "must be in (0, 0.1] rad");
  diag::require(revolutions >= 0 && std::isfinite(revolutions), "kinematic simulation",
                "revolutions", "must be >= 0");
  diag::require(runout_output_rad >= 0, "kinematic simulation", "runout_output_rad",
                "must be >= 0");
  diag::require(mesh_te_output_rad >= 0, "kinematic simulation", "mesh_te_output_rad",
                "must be >= 0");
  diag::require(noise_output_rad >= 0, "kinematic simulation", "noise_output_rad", "must be >= 0");
  diag::require(noise_input_rad >= 0, "kinematic simulation", "noise_input_rad", "must be >= 0");
  diag::require(encoder_counts_per_rev == 0 || encoder_counts_per_rev >= 16, "kinematic simulation",
                "encoder_counts_per_rev", "must be 0 (no quantisation) or >= 16");
}

KinematicResult simulate_kinematic(const diag::Gearbox& gb, const KinematicOptions& opt) {
  opt.validate();
  const auto& path = gb.power_path();
  const double u_total = gb.total_ratio();

  // Shafts on the power path and the longest period among them.
  std::vector<int> path_shafts{gb.input_shaft()};
  for (const auto& st : path) path_shafts.push_back(gb.shaft_of_gear(st.down_gear));
  double longest_rev = 1.0;
  for (int s : path_shafts) longest_rev = std::max(longest_rev, gb.shaft_period_input_rev(s));

  KinematicResult out;
  out.step_rad = opt.step_rad;
  diag::SimulationTruth truth;  // diag/io/truth.hpp
  truth.kind = "kinematic";

  std::vector<ActiveDefect> active;
  for (const auto& d : gb.defects()) {
    const int g = gb.gear_index(d.gear);
    const int shaft = gb.shaft_of_gear(g);
    const double u_i = gb.ratio_to_output(g);
    const double period_rev = gb.recurrence_period_input_rev(g);
    diag::TruthDefect t;
    t.kind = diag::parse_fault_kind(d.type, "simulate_kinematic", "defects.type");
    t.gear = d.gear;
    t.shaft = gb.shafts()[shaft].name;
    t.size_gear_rad = d.size_rad;
    t.size_output_rad = d.size_rad / u_i;
    t.phase_rad = d.phase_rad;
    t.period_input_rev = period_rev;
    t.first_event_input_rad = d.phase_rad * period_rev;
    for (int o : gb.gears_sharing_shaft(g)) t.gears_on_shaft.push_back(gb.gears()[o].name);
    t.on_power_path = gb.on_power_path(g);
    truth.defects.push_back(std::move(t));
    for (std::size_t k = 0; k < path.size(); ++k) {
      const auto& st = path[k];
      if (st.up_gear != g && st.down_gear != g) continue;
      const double z_up = gb.gears()[st.up_gear].spec.teeth;
      const double z_down = gb.gears()[st.down_gear].spec.teeth;
      ActiveDefect a;
      a.step = k;
      // A loss D of the up gear's rotation is a gap D r_b,up along the LOA, i.e. D z_up / z_down
      // of the down gear's rotation; a loss on the down gear is already in its angle.
      a.gap_down_rad = (st.up_gear == g) ? d.size_rad * z_up / z_down : d.size_rad;
      a.phase_rad = d.phase_rad;
      a.gear_per_input = 1.0 / period_rev;
      a.hold_rad = d.size_rad;
      a.recovery_rad = d.size_rad;
      // The pulse spans (hold + recovery) of gear angle, i.e. that times T_i of input angle.
      const double pulse_input_rad = (a.hold_rad + a.recovery_rad) * period_rev;
      constexpr double kStepsPerPulse = 20.0;  // resolves the pulse's peak within 5 %
      if (opt.step_rad > pulse_input_rad / kStepsPerPulse) {
        std::ostringstream m;
        m << "too coarse for the defect on gear '" << d.gear << "': its pulse spans "
          << pulse_input_rad
          << " rad of input angle; use step_rad <= " << pulse_input_rad / kStepsPerPulse;
        diag::require(false, "kinematic simulation", "step_rad", m.str());
      }
      active.push_back(a);
    }
  }

  // Six periods of the longest recurrence: five complete ones follow any initial phase.
  const double revs = opt.revolutions > 0 ? opt.revolutions : 6.0 * longest_rev;
  // Three vectors of n doubles are held (input, output, irregularity): bounded before allocation.
  constexpr double kMaxSamples = 5e7;
  const double n_wanted = std::ceil(revs * kTwoPi / opt.step_rad) + 1;
  if (!(n_wanted <= kMaxSamples)) {
    std::ostringstream m;
    m << revs << " input revolutions at a step of " << opt.step_rad << " rad need " << n_wanted
      << " samples (" << 24.0 * n_wanted / (1 << 20) << " MiB); at most " << kMaxSamples
      << " are accepted: fewer revolutions or a coarser step";
    diag::require(false, "kinematic simulation", "revolutions", m.str());
  }
  const auto n = static_cast<std::size_t>(n_wanted);

  out.input_angle_rad.resize(n);
  out.output_angle_rad.resize(n);
  out.irregularity_rad.resize(n);

  // Per-step ratios and the defects grouped by path step.
  std::vector<double> ratio(path.size());
  for (std::size_t k = 0; k < path.size(); ++k) {
    ratio[k] = static_cast<double>(gb.gears()[path[k].up_gear].spec.teeth) /
               gb.gears()[path[k].down_gear].spec.teeth;
  }
  std::vector<double> theta(path.size(), 0.0);  // down-gear angles, previous step

  // Measurement effects: phases drawn once from the seed.
  Gaussian gauss(opt.seed);
  std::vector<double> runout_phase(path_shafts.size()), mesh_phase(3 * path.size());
  for (double& p : runout_phase) p = kTwoPi * gauss.uniform();
  for (double& p : mesh_phase) p = kTwoPi * gauss.uniform();
  const double mesh_amp[3] = {1.0, 0.5, 0.25};

  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i) * opt.step_rad;
    double up = x;
    for (std::size_t k = 0; k < path.size(); ++k) {
      double gap = 0.0;
      for (const auto& a : active) {
        if (a.step == k) gap += a.gap_down_rad * open_fraction(a, x);
      }
      const double follow = up * ratio[k] - gap;
      theta[k] = (i == 0) ? follow : std::max(theta[k], follow);
      up = theta[k];
    }
    double measured_out = up;
    if (opt.runout_output_rad > 0) {
      for (std::size_t s = 0; s < path_shafts.size(); ++s) {
        const double shaft_angle = x / gb.shaft_period_input_rev(path_shafts[s]);
        measured_out += opt.runout_output_rad * std::sin(shaft_angle + runout_phase[s]);
      }
    }
    if (opt.mesh_te_output_rad > 0) {
      for (std::size_t k = 0; k < path.size(); ++k) {
        const int up_shaft = gb.shaft_of_gear(path[k].up_gear);
        const double mesh_angle =
            gb.gears()[path[k].up_gear].spec.teeth * x / gb.shaft_period_input_rev(up_shaft);
        for (int h = 0; h < 3; ++h) {
          measured_out += opt.mesh_te_output_rad * mesh_amp[h] *
                          std::sin((h + 1) * mesh_angle + mesh_phase[3 * k + h]);
        }
      }
    }
    double measured_in = x;
    if (opt.noise_input_rad > 0) measured_in += opt.noise_input_rad * gauss();
    if (opt.noise_output_rad > 0) measured_out += opt.noise_output_rad * gauss();
    measured_in = quantise(measured_in, opt.encoder_counts_per_rev);
    measured_out = quantise(measured_out, opt.encoder_counts_per_rev);
    out.input_angle_rad[i] = measured_in;
    out.output_angle_rad[i] = measured_out;
    out.irregularity_rad[i] = measured_in / u_total - measured_out;
  }

  json& extra = truth.extra;
  extra["step_rad"] = opt.step_rad;
  extra["revolutions"] = revs;
  extra["total_ratio"] = u_total;
  extra["runout_output_rad"] = opt.runout_output_rad;
  extra["mesh_te_output_rad"] = opt.mesh_te_output_rad;
  extra["noise_output_rad"] = opt.noise_output_rad;
  extra["noise_input_rad"] = opt.noise_input_rad;
  extra["encoder_counts_per_rev"] = opt.encoder_counts_per_rev;
  extra["seed"] = opt.seed;
  out.truth = truth.to_json();
  return out;
}

diag::Recording to_recording(const diag::Gearbox& gb, const KinematicResult& r) {
  diag::Recording rec;
  const double fs = diag::units::rpm_to_hz(gb.input().speed_rpm) * kTwoPi / r.step_rad;
  auto add = [&](const char* name, const std::vector<double>& v, int shaft) {
    diag::Signal s;
    s.name = name;
    s.fs_hz = fs;
    s.unit = "rad";
    s.direction = diag::Direction::kAngle;
    s.location = shaft >= 0 ? gb.shafts()[shaft].name : "";
    s.samples = v;
    s.role = diag::Role::kAngle;
    s.shaft = s.location;
    rec.signals.push_back(std::move(s));
  };
  add("input_angle_rad", r.input_angle_rad, gb.input_shaft());
  add("output_angle_rad", r.output_angle_rad, gb.output_shaft());
  add("transmission_error_rad", r.irregularity_rad, gb.output_shaft());
  rec.gearbox_json = gb.description_json();
  rec.truth_json = r.truth.dump(2);
  rec.metadata["mode"] = "kinematic";
  return rec;
}

}  // namespace sim
