#include "sim/dynamics/simulate.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>

#include "diag/dsp/fir.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/io/truth.hpp"
#include "diag/util/number_format.hpp"
#include "sim/dynamics/rk4.hpp"

namespace sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDivergenceFactor = 1000.0;  // mesh deflection beyond 1000 static deflections

// Base excitation of a single-degree-of-freedom casing: absolute acceleration of the mass over
// the base acceleration, H(s) = (2 z w s + w^2) / (s^2 + 2 z w s + w^2), bilinear transform with
// the resonance pre-warped.
class Resonator {
 public:
  Resonator(double f_hz, double zeta, double fs_hz) {
    const double w = 2 * kPi * f_hz;
    const double c = w / std::tan(w / (2 * fs_hz));  // pre-warped bilinear constant
    const double a0 = c * c + 2 * zeta * w * c + w * w;
    b0_ = (2 * zeta * w * c + w * w) / a0;
    b1_ = (2 * w * w) / a0;
    b2_ = (w * w - 2 * zeta * w * c) / a0;
    a1_ = (2 * w * w - 2 * c * c) / a0;
    a2_ = (c * c - 2 * zeta * w * c + w * w) / a0;
  }
  double operator()(double x) {
    const double y = b0_ * x + s1_;
    s1_ = b1_ * x - a1_ * y + s2_;
    s2_ = b2_ * x - a2_ * y;
    return y;
  }

 private:
  double b0_, b1_, b2_, a1_, a2_, s1_ = 0, s2_ = 0;
};

enum class Source {
  kAccel,
  kTransmissionError,
  kAngle,
  kMeshForce,
  kMeshFriction,
  kMeshDte,
  kMeshContact
};

struct ChannelPlan {
  Channel channel;
  Source source;
  int index = 0;          // DOF (x DOF for accelerations), gear, or mesh
  double cx = 0, cy = 0;  // projection of (x'', y'')
  bool filtered = true;
  bool casing = false;
};

using diag::mesh_name;

// The integration grid: the step, the steps per output sample and the output window. Refuses
// (InputError) a grid beyond the supported steps per sample or run steps.
struct StepPlan {
  std::vector<double> nat;        // the model's natural frequencies [Hz], ascending
  double w_in_max = 0;            // the highest input speed [rad/s]
  double h = 0;                   // integration step [s]
  int D = 1;                      // steps per output sample
  int delay_out = 0;              // the decimation filter's delay [output samples]
  long long settle_out = 0;       // output samples before the recording starts
  long long n_out = 0;            // output samples recorded
  long long first_push_step = 0;  // the first step whose value enters the decimators
  long long total_steps = 0;
};

StepPlan plan_steps(const diag::Gearbox& gb, const GearboxModel& model, const RunOptions& run,
                    std::vector<std::string>& warnings) {
  const DynamicsOptions& opt = model.options();
  const std::vector<double> nat = model.natural_frequencies_hz();
  const double f_max = nat.back();
  double f_low = 0.0;
  for (double f : nat) {
    if (f > 1e-6 * f_max) {
      f_low = f;
      break;
    }
  }
  const double w_in_max = opt.speed.max_rpm() * 2 * kPi / 60.0;
  double f_mesh_max = 0.0;
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    const diag::Mesh& m = gb.meshes()[j];
    f_mesh_max = std::max(f_mesh_max, gb.gears()[m.driver].spec.teeth *
                                          model.gear_speed_ratio(m.driver) * w_in_max / (2 * kPi));
  }
  const double h_needed =
      std::min(1.0 / (f_max * run.steps_per_period), 1.0 / (f_mesh_max * run.steps_per_mesh));
  // Steps per output sample, as a double first: at absurd speeds it is far beyond INT_MAX.
  const double steps_per_sample = std::ceil(1.0 / (run.fs_hz * h_needed) - 1e-9);
  if (!(steps_per_sample <= kMaxStepsPerSample)) {
    std::ostringstream m;
    m << "the model needs " << steps_per_sample << " integration steps per output sample (highest "
      << "mesh frequency " << f_mesh_max << " Hz, highest natural frequency " << f_max
      << " Hz at fs " << run.fs_hz << " Hz); at most " << kMaxStepsPerSample
      << " are supported: raise fs or lower the speed";
    throw diag::InputError(diag::format_error("simulate", "fs_hz", m.str()));
  }
  int D = std::max(4, static_cast<int>(steps_per_sample));
  if (run.step_s > 0.0) {
    const double stability = run.step_s * 2 * kPi * f_max;
    if (stability > 2.0) {
      std::ostringstream w;
      w << "step " << run.step_s << " s is beyond the RK4 stability bound for the highest natural "
        << "frequency " << f_max << " Hz (h w_max = " << stability << " > 2); using "
        << 1.0 / (run.fs_hz * D) << " s";
      warnings.push_back(w.str());
    } else {
      const double d_wanted = std::round(1.0 / (run.fs_hz * run.step_s));
      if (!(d_wanted <= kMaxStepsPerSample)) {
        throw diag::InputError(diag::format_error(
            "simulate", "step_s",
            diag::format_significant(d_wanted, 6) + " steps per output sample; at most " +
                diag::format_significant(kMaxStepsPerSample, 6) + " are supported"));
      }
      const int d_user = std::max(1, static_cast<int>(d_wanted));
      D = d_user;
      if (std::abs(1.0 / (run.fs_hz * D) - run.step_s) > 1e-9 * run.step_s) {
        std::ostringstream w;
        w << "step " << run.step_s << " s rounded to " << 1.0 / (run.fs_hz * D)
          << " s (a whole number of steps per output sample)";
        warnings.push_back(w.str());
      }
    }
  }
  const double h = 1.0 / (run.fs_hz * D);
  double settle = run.settle_s;
  if (settle < 0.0) settle = std::max(0.05, 20.0 / std::max(f_low, 1e-3));
  const diag::Decimator probe(D);
  const int delay_out = probe.delay_out_samples();
  long long settle_out = static_cast<long long>(std::ceil(settle * run.fs_hz));
  settle_out = std::max<long long>(settle_out, delay_out);
  const long long n_out = static_cast<long long>(std::llround(run.duration_s * run.fs_hz));
  if (n_out < 1) throw diag::InputError("run: duration_s: shorter than one sample");
  // Inputs pushed from output index (settle_out - delay_out); total outputs wanted n_out +
  // delay_out (the first delay_out are dropped), which needs delay_out * D more inputs after.
  const long long first_push_step = (settle_out - delay_out) * D;
  const long long total_steps = (settle_out + n_out + delay_out) * D + 1;
  const double settle_steps = static_cast<double>(settle_out + n_out + delay_out) * D;
  const long long budget_steps =
      static_cast<long long>(kMaxRunSteps / std::max(1.0, static_cast<double>(gb.meshes().size())));
  if (settle_steps > static_cast<double>(budget_steps)) {
    std::ostringstream m;
    m << "the request needs " << settle_steps << " integration steps (" << D
      << " per output sample over " << (settle_out + n_out) / run.fs_hz
      << " s including the settling time) for " << gb.meshes().size() << " mesh(es); at most "
      << budget_steps
      << " are accepted (about an hour of run time): shorten duration_s or settle_s, or lower "
         "the speed";
    throw diag::InputError(diag::format_error("simulate", "duration_s", m.str()));
  }

  return {nat, w_in_max, h, D, delay_out, settle_out, n_out, first_push_step, total_steps};
}

// The recorded channels and where each value comes from: bearing accelerations (along and
// normal to each mesh's line of action, horizontal, vertical), the transmission error and the
// input and output angles, and each mesh's force, friction, deflection and contact.
std::vector<ChannelPlan> plan_channels(const diag::Gearbox& gb, const GearboxModel& model,
                                       const RunOptions& run) {
  std::vector<ChannelPlan> plans;
  if (run.bearing_channels) {
    for (std::size_t s = 0; s < gb.shafts().size(); ++s) {
      const int x = model.shaft_x_dof(static_cast<int>(s));
      if (x < 0) continue;
      std::vector<int> shaft_meshes;
      for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
        const diag::Mesh& m = gb.meshes()[j];
        if (gb.shaft_of_gear(m.driver) == static_cast<int>(s) ||
            gb.shaft_of_gear(m.driven) == static_cast<int>(s)) {
          shaft_meshes.push_back(static_cast<int>(j));
        }
      }
      for (int b = 1; b <= 2; ++b) {
        const std::string bearing = bearing_location(gb.shafts()[s].name, b);
        auto add = [&](const std::string& suffix, diag::Direction dir, double cx, double cy,
                       const std::string& mesh) {
          ChannelPlan p;
          p.channel.name = bearing + "_" + suffix;
          p.channel.unit = "m/s^2";
          p.channel.direction = dir;
          p.channel.location = bearing;
          p.channel.role = diag::Role::kVibration;
          p.channel.shaft = gb.shafts()[s].name;
          p.channel.mesh = mesh;
          p.source = Source::kAccel;
          p.index = x;
          p.cx = cx;
          p.cy = cy;
          p.casing = run.casing_frequency_hz > 0.0;
          plans.push_back(p);
        };
        for (int j : shaft_meshes) {
          const std::string suffix = shaft_meshes.size() > 1 ? "_" + mesh_name(gb, j) : "";
          const auto [nx, ny] = model.loa_direction(j);
          const auto [mx, my] = model.normal_direction(j);
          add("along_loa" + suffix, diag::Direction::kAlongLoa, nx, ny, mesh_name(gb, j));
          add("normal_loa" + suffix, diag::Direction::kNormalLoa, mx, my, mesh_name(gb, j));
        }
        add("horizontal", diag::Direction::kHorizontal, 1.0, 0.0, "");
        add("vertical", diag::Direction::kVertical, 0.0, 1.0, "");
      }
    }
  }
  {
    ChannelPlan p;
    auto angle = [&](const char* name, int gear) {
      const std::string shaft = gb.shafts()[gb.shaft_of_gear(gear)].name;
      Channel c;
      c.name = name;
      c.unit = "rad";
      c.direction = diag::Direction::kAngle;
      c.location = shaft;
      c.role = diag::Role::kAngle;
      c.shaft = shaft;
      return c;
    };
    p.channel = angle("transmission_error", model.output_gear());
    p.source = Source::kTransmissionError;
    plans.push_back(p);
    p.channel = angle("input_angle", model.input_gear());
    p.source = Source::kAngle;
    p.index = model.input_gear();
    plans.push_back(p);
    p.channel = angle("output_angle", model.output_gear());
    p.index = model.output_gear();
    plans.push_back(p);
  }
  if (run.mesh_channels) {
    for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
      const std::string mn = mesh_name(gb, static_cast<int>(j));
      ChannelPlan p;
      p.index = static_cast<int>(j);
      auto quantity = [&](const std::string& suffix, const char* unit, diag::Role role) {
        Channel c;
        c.name = mn + suffix;
        c.unit = unit;
        c.location = mn;
        c.role = role;
        c.mesh = mn;
        return c;
      };
      p.channel = quantity("_force", "N", diag::Role::kForce);
      p.source = Source::kMeshForce;
      plans.push_back(p);
      p.channel = quantity("_friction", "N", diag::Role::kForce);
      p.source = Source::kMeshFriction;
      plans.push_back(p);
      p.channel = quantity("_dte", "m", diag::Role::kDisplacement);
      p.source = Source::kMeshDte;
      plans.push_back(p);
      p.channel = quantity("_contact", "", diag::Role::kOther);
      p.source = Source::kMeshContact;
      p.filtered = false;
      plans.push_back(p);
    }
  }
  return plans;
}

// Every channel is held at the output rate twice (raw and filtered) before it is written:
// refused beyond the documented limit or half of this machine's memory.
void check_output_memory(std::size_t n_channels, long long n_out, int delay_out) {
  const double channels = static_cast<double>(n_channels);
  const double bytes = 2.0 * 8.0 * channels * static_cast<double>(n_out + 2 * delay_out + 2);
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  const double machine = pages > 0 && page > 0 ? 0.5 * double(pages) * double(page) : 1e300;
  const double limit = std::min(kMaxOutputBytes, machine);
  if (bytes > limit) {
    std::ostringstream m;
    m << "the recording would need " << bytes / (1 << 20) << " MiB (" << n_out << " samples x "
      << channels << " channels x 8 bytes, twice); at most " << limit / (1 << 20)
      << " MiB are accepted: shorten duration_s or lower fs_hz";
    throw diag::InputError(diag::format_error("simulate", "duration_s", m.str()));
  }
}

// Tachometers: one per shaft with gears, from the first gear's total angle; `tachos` gets their
// (empty) channels, the plan each one's gear and pulse duty (a share of the revolution).
struct TachoPlan {
  std::vector<int> gear;
  std::vector<double> duty;
};

TachoPlan plan_tachos(const diag::Gearbox& gb, const GearboxModel& model, const RunOptions& run,
                      double w_in_max, long long n_out, std::vector<Channel>& tachos) {
  TachoPlan plan;
  for (std::size_t s = 0; s < gb.shafts().size(); ++s) {
    if (gb.shafts()[s].gears.empty()) continue;
    const int g = gb.shafts()[s].gears.front();
    plan.gear.push_back(g);
    const double f_shaft = model.gear_speed_ratio(g) * w_in_max / (2 * kPi);
    plan.duty.push_back(std::clamp(3.0 * f_shaft / run.fs_hz, 0.02, 0.25));
    Channel c;
    c.name = gb.shafts()[s].name;
    c.fs_hz = run.fs_hz;
    c.direction = diag::Direction::kTacho;
    c.location = gb.shafts()[s].name;
    c.role = diag::Role::kTacho;
    c.shaft = gb.shafts()[s].name;
    c.ppr = 1;
    c.samples.reserve(static_cast<std::size_t>(n_out));
    tachos.push_back(c);
  }
  return plan;
}

// Each mesh's static deflection under the input torque: the scale of the divergence check.
std::vector<double> static_deflections(const diag::Gearbox& gb, const GearboxModel& model) {
  std::vector<double> static_delta(gb.meshes().size());
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    const diag::Mesh& m = gb.meshes()[j];
    const double torque_driver = model.input_torque_nm() / model.gear_speed_ratio(m.driver);
    const double f = torque_driver / diag::Gear(gb.gears()[m.driver].spec).base_radius_m();
    static_delta[j] = std::max(f / model.mean_mesh_stiffness_n_per_m(static_cast<int>(j)), 1e-9);
  }
  return static_delta;
}

// A channel's value at step time t. `obs` is the observation at t; `y` the state at t + h (RK4,
// advanced in place) or at t (GSL), `before` the state at t and `prev` at t - h (RK4).
double sample_value(const ChannelPlan& p, const GearboxModel& model, const Observation& obs,
                    const std::vector<double>& y, const std::vector<double>& before,
                    const std::vector<double>& prev, double h, double t, bool gsl, bool first_step,
                    Resonator& casing) {
  const int n = model.dofs();
  switch (p.source) {
    case Source::kAccel: {
      double value = 0.0;
      if (!gsl && !first_step) {
        // Mean acceleration over [t - h, t + h] with triangular weight: the central
        // difference of the velocity. Why not the point value: the bearing force jumps
        // when a tooth pair enters or leaves a mesh, and a point-sampled step is placed
        // at the nearest fine-grid sample; that timing error (up to h / 2) cycles with
        // the beat between step and mesh period and survives the decimation filter as
        // spurious periodic lines (3.6 % of the vibration RMS in the two-stage box at
        // 2000 rpm with a 5 us step). The difference integrates the jump exactly; its
        // own response, sinc^2(f h), is 0.999 at 0.4 fs for D >= 4 steps per sample.
        const double ax = (y[n + p.index] - prev[n + p.index]) / (2.0 * h);
        const double ay = (y[n + p.index + 1] - prev[n + p.index + 1]) / (2.0 * h);
        value = p.cx * ax + p.cy * ay;
      } else {
        value = p.cx * obs.acceleration[p.index] + p.cy * obs.acceleration[p.index + 1];
      }
      return p.casing ? casing(value) : value;
    }
    case Source::kTransmissionError:
    case Source::kAngle: {
      // State at t: for RK4 y is already at t + h; the pre-step copy is `before`.
      const double* ys = gsl ? y.data() : before.data();
      if (p.source == Source::kAngle) return model.gear_angle_rad(p.index, t, ys);
      return ys[model.input_gear()] * model.gear_speed_ratio(model.output_gear()) /
                 model.gear_speed_ratio(model.input_gear()) -
             ys[model.output_gear()];
    }
    case Source::kMeshForce:
      return obs.meshes[p.index].force_n;
    case Source::kMeshFriction:
      return obs.meshes[p.index].friction_n;
    case Source::kMeshDte:
      return obs.meshes[p.index].delta_m;
    case Source::kMeshContact:
      return obs.meshes[p.index].contact;
  }
  return 0.0;  // every Source is a case above
}

// The recorded window of every channel (the decimation filter's delay dropped), with the
// accelerometers' noise (RunOptions::accel_noise_m_per_s2, seeded by RunOptions::seed).
std::vector<Channel> assemble_channels(const std::vector<ChannelPlan>& plans,
                                       const std::vector<std::vector<double>>& raw, int delay_out,
                                       long long n_out, const RunOptions& run) {
  std::vector<Channel> channels;
  std::mt19937_64 rng(run.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (std::size_t c = 0; c < plans.size(); ++c) {
    Channel ch = plans[c].channel;
    ch.fs_hz = run.fs_hz;
    const auto& r = raw[c];
    const std::size_t first = static_cast<std::size_t>(delay_out);
    if (r.size() < first + static_cast<std::size_t>(n_out)) {
      throw std::logic_error("simulate_dynamic: channel " + ch.name + " is short");
    }
    ch.samples.assign(r.begin() + first, r.begin() + first + n_out);
    if (plans[c].source == Source::kAccel && run.accel_noise_m_per_s2 > 0) {
      for (double& v : ch.samples) v += run.accel_noise_m_per_s2 * gauss(rng);
    }
    channels.push_back(std::move(ch));
  }

  return channels;
}

// RunOptions::bearing_faults resolved against the gearbox and the channel plan before the run
// (so that a bad one is refused before the integration), then each defect's impacts added to the
// accelerometers at its bearing. What the truth records of each: the bearing's shaft and rate,
// the impacts.
struct AppliedBearingFault {
  const BearingFault* fault = nullptr;
  const diag::BearingSpec* spec = nullptr;
  std::string shaft;
  double shaft_hz = 0, fault_rms = 0;
  int impacts = 0;
  BearingSignalOptions options;  // the impacts' model; duration set from the recorded window
};

std::vector<AppliedBearingFault> resolve_bearing_faults(const diag::Gearbox& gb,
                                                        const DynamicsOptions& opt,
                                                        const RunOptions& run,
                                                        const std::vector<ChannelPlan>& plans) {
  std::vector<AppliedBearingFault> out;
  for (std::size_t i = 0; i < run.bearing_faults.size(); ++i) {
    const BearingFault& f = run.bearing_faults[i];
    const std::string where =
        f.where.empty() ? "simulate: bearing_faults[" + std::to_string(i) + "]" : f.where;
    const auto spec = std::find_if(gb.bearings().begin(), gb.bearings().end(),
                                   [&](const diag::BearingSpec& b) { return b.name == f.bearing; });
    if (spec == gb.bearings().end()) {
      throw diag::InputError(diag::format_error(
          where, "bearing", "'" + f.bearing + "' is not a bearing of the gearbox description"));
    }
    if (opt.speed.min_rpm() != opt.speed.max_rpm()) {
      throw diag::InputError(
          diag::format_error(where, "bearing", "a bearing defect needs a constant speed"));
    }
    const bool sensed = std::any_of(plans.begin(), plans.end(), [&](const ChannelPlan& p) {
      return p.source == Source::kAccel && p.channel.location == f.bearing;
    });
    if (!sensed) {
      throw diag::InputError(diag::format_error(where, "bearing",
                                                "no accelerometer at '" + f.bearing +
                                                    "' (the simulator's bearings are named " +
                                                    "<shaft>_bearing1 and <shaft>_bearing2, e.g. " +
                                                    bearing_location(spec->shaft, 1) + ")"));
    }
    AppliedBearingFault a;
    a.fault = &f;
    a.spec = &*spec;
    a.shaft = spec->shaft;
    a.shaft_hz =
        std::abs(gb.shafts()[static_cast<std::size_t>(gb.shaft_index(spec->shaft))].speed_ratio) *
        opt.speed.max_rpm() / 60.0;
    BearingSignalOptions& o = a.options;
    o.fs_hz = run.fs_hz;
    o.duration_s = run.duration_s;
    o.shaft_hz = a.shaft_hz;
    o.fault = f.kind;
    o.impact_amplitude = f.amplitude_m_per_s2;
    o.resonance_hz = f.resonance_hz;
    o.damping_ratio = f.damping_ratio;
    o.mean_slip = f.mean_slip;
    o.jitter = f.jitter;
    // Its own stream, from the run's noise seed and the defect's index.
    o.seed = (run.seed ^ (0x9E3779B97F4A7C15ULL * (i + 1))) % 1000000007ULL;
    // The model's own checks (resonance below 0.45 fs, slip, geometry) before the run.
    try {
      o.validate();
      diag::bearing_rates(*spec, a.shaft_hz);
    } catch (const diag::InputError& e) {
      throw diag::InputError(where + ": " + e.what());
    }
    out.push_back(a);
  }
  return out;
}

void add_bearing_faults(const RunOptions& run, std::vector<AppliedBearingFault>& faults,
                        std::vector<Channel>& channels) {
  for (AppliedBearingFault& a : faults) {
    const BearingFault& f = *a.fault;
    std::vector<Channel*> at;
    for (Channel& c : channels) {
      if (c.location == f.bearing && c.unit == "m/s^2") at.push_back(&c);
    }
    BearingSignalOptions o = a.options;
    o.duration_s = static_cast<double>(at.front()->samples.size()) / run.fs_hz;
    const std::vector<double> x = bearing_fault_samples(*a.spec, o, a.impacts);
    double p = 0;
    for (double v : x) p += v * v;
    a.fault_rms = x.empty() ? 0.0 : std::sqrt(p / static_cast<double>(x.size()));
    for (Channel* c : at) {
      const std::size_t n = std::min(c->samples.size(), x.size());
      for (std::size_t j = 0; j < n; ++j) c->samples[j] += x[j];
    }
  }
}

// The ground truth of a run (diag/io/truth.hpp): speeds, torques, defects, the model and its
// integration, and the seeds that reproduce it.
nlohmann::json dynamic_truth(const diag::Gearbox& gb, const GearboxModel& model,
                             const RunOptions& run, const StepPlan& steps,
                             const std::vector<std::string>& warnings,
                             const std::vector<AppliedBearingFault>& bearing_faults) {
  const DynamicsOptions& opt = model.options();
  const auto& [nat, w_in_max, h, D, delay_out, settle_out, n_out, first_push_step, total_steps] =
      steps;
  diag::SimulationTruth st;
  st.kind = "dynamic";
  st.input_speed_rpm_max = opt.speed.max_rpm();
  st.input_speed_rpm_min = opt.speed.min_rpm();
  st.input_torque_nm = model.input_torque_nm();
  st.load_torque_nm = model.load_torque_nm();
  for (const GearFault& f : opt.faults) {
    const int g = gb.gear_index(f.gear);
    diag::TruthDefect d;
    d.kind = f.profile_json.empty() ? fault_kind(f.fault.kind) : diag::FaultKind::kProfile;
    d.gear = f.gear;
    d.shaft = gb.shafts()[gb.shaft_of_gear(g)].name;
    d.tooth = f.fault.tooth;
    d.size_m = f.fault.size_m;
    d.depth_m = f.fault.depth_m;
    d.width_fraction = f.fault.width_fraction;
    // At the run's speed (the description's input speed is only its nominal: --rpm and a
    // scenario's speed replace it); left out at a varying speed (no one value).
    if (opt.speed.min_rpm() == opt.speed.max_rpm()) {
      d.shaft_frequency_hz =
          std::abs(gb.shafts()[gb.shaft_of_gear(g)].speed_ratio) * opt.speed.max_rpm() / 60.0;
    }
    st.defects.push_back(std::move(d));
  }
  nlohmann::json bearing_json = nlohmann::json::array();
  for (const AppliedBearingFault& a : bearing_faults) {
    diag::TruthDefect d;
    d.kind = fault_kind(a.fault->kind);
    d.bearing = a.fault->bearing;
    d.shaft = a.shaft;
    d.shaft_frequency_hz = a.shaft_hz;
    st.defects.push_back(std::move(d));
    bearing_json.push_back({{"bearing", a.fault->bearing},
                            {"fault", to_string(a.fault->kind)},
                            {"amplitude_m_per_s2", a.fault->amplitude_m_per_s2},
                            {"resonance_hz", a.fault->resonance_hz},
                            {"damping_ratio", a.fault->damping_ratio},
                            {"mean_slip", a.fault->mean_slip},
                            {"jitter", a.fault->jitter},
                            {"impacts", a.impacts},
                            {"fault_rms_m_per_s2", a.fault_rms}});
  }
  nlohmann::json& truth = st.extra;
  if (!bearing_faults.empty()) truth["bearing_faults"] = bearing_json;
  truth["model"] = "lumped gearbox dynamics (seed 000 generalised): rotations + shaft translations";
  truth["friction_law"] = static_cast<int>(opt.friction.law);
  truth["oil_temperature_c"] = opt.friction.oil_temperature_c;
  truth["mesh_damping_ratio"] = opt.mesh_damping_ratio;
  truth["natural_frequencies_hz"] = nat;
  // Mesh frequencies at the run's mean input speed over the recorded window (the description's
  // input.speed_rpm is only its nominal: --rpm and a scenario's speed replace it).
  const double t_first = static_cast<double>(settle_out) / run.fs_hz;
  const double t_last = static_cast<double>(settle_out + n_out) / run.fs_hz;
  const double run_rpm = opt.speed.min_rpm() == opt.speed.max_rpm()
                             ? opt.speed.max_rpm()
                             : (opt.speed.angle_rad(t_last) - opt.speed.angle_rad(t_first)) /
                                   (t_last - t_first) * 60.0 / (2 * kPi);
  const double speed_scale = run_rpm / gb.input().speed_rpm;
  nlohmann::json meshes = nlohmann::json::array();
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    const int jj = static_cast<int>(j);
    meshes.push_back({{"name", mesh_name(gb, jj)},
                      {"mean_stiffness_n_per_m", model.mean_mesh_stiffness_n_per_m(jj)},
                      {"torsional_frequency_hz", model.mesh_torsional_frequency_hz(jj)},
                      {"backlash_m", model.mesh_backlash_m(jj)},
                      {"contact_ratio", gb.meshes()[j].pair.contact_ratio()},
                      {"mesh_frequency_hz", gb.mesh_frequency_hz(jj) * speed_scale}});
  }
  truth["meshes"] = meshes;
  nlohmann::json wear = nlohmann::json::array();
  for (const AppliedWear& a : model.applied_wear()) {
    const diag::Mesh& me = gb.meshes()[static_cast<std::size_t>(a.mesh)];
    wear.push_back({{"mesh", mesh_name(gb, a.mesh)},
                    {"law", wear_law_name(a.law)},
                    {"cycles", a.state.cycles},
                    {"max_depth_um",
                     {{gb.gears()[static_cast<std::size_t>(me.driver)].name,
                       a.state.max_depth_driver_m() * 1e6},
                      {gb.gears()[static_cast<std::size_t>(me.driven)].name,
                       a.state.max_depth_driven_m() * 1e6}}},
                    {"max_gap_um", a.max_gap_m * 1e6},
                    {"te_peak_to_peak_rad", a.state.te_peak_to_peak_rad},
                    {"mesh_frequency_hz", gb.mesh_frequency_hz(a.mesh) * speed_scale}});
  }
  truth["wear"] = wear;
  truth["accuracy_grade"] = opt.accuracy_grade;
  truth["runout_m"] = opt.runout_m;
  truth["integrator"] = {{"method", run.method == RunOptions::Method::kRk4 ? "rk4" : "gsl_rk8pd"},
                         {"step_s", h},
                         {"decimation", D},
                         {"settle_s", static_cast<double>(settle_out) / run.fs_hz}};
  truth["warnings"] = warnings;
  // Provenance: the seeds that drew the pitch errors and runout phases (dynamics) and the sensor
  // noise (run), so that the recording can be reproduced.
  truth["seed"] = run.seed;
  truth["dynamics_seed"] = opt.seed;
  return st.to_json();
}

}  // namespace

void RunOptions::validate() const {
  const std::string where = "run";
  auto positive = [&](double v, const char* field) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw diag::InputError(diag::format_error(where, field, std::to_string(v) + " is not > 0"));
    }
  };
  positive(duration_s, "duration_s");
  positive(fs_hz, "fs_hz");
  auto at_most = [&](double v, double limit, const char* field, const char* unit) {
    if (v > limit) {
      throw diag::InputError(diag::format_error(where, field,
                                                diag::format_significant(v, 6) + unit +
                                                    " exceeds the limit " +
                                                    diag::format_significant(limit, 6) + unit));
    }
  };
  at_most(duration_s, kMaxDurationS, "duration_s", " s");
  at_most(fs_hz, kMaxFsHz, "fs_hz", " Hz");
  at_most(settle_s, kMaxSettleS, "settle_s", " s");
  at_most(steps_per_period, kMaxStepsPerPeriod, "steps_per_period", "");
  at_most(steps_per_mesh, kMaxStepsPerPeriod, "steps_per_mesh", "");
  at_most(contact_substeps, kMaxContactSubsteps, "contact_substeps", "");
  if (!(step_s >= 0.0)) throw diag::InputError(diag::format_error(where, "step_s", "must be >= 0"));
  if (steps_per_period < 8)
    throw diag::InputError(diag::format_error(where, "steps_per_period", "must be >= 8"));
  if (steps_per_mesh < 8)
    throw diag::InputError(diag::format_error(where, "steps_per_mesh", "must be >= 8"));
  if (contact_substeps < 1) {
    throw diag::InputError(diag::format_error(where, "contact_substeps", "must be >= 1"));
  }
  positive(gsl_rel_tol, "gsl_rel_tol");
  positive(gsl_abs_tol, "gsl_abs_tol");
  if (!(accel_noise_m_per_s2 >= 0.0)) {
    throw diag::InputError(diag::format_error(where, "accel_noise_m_per_s2", "must be >= 0"));
  }
  if (!(casing_frequency_hz >= 0.0)) {
    throw diag::InputError(diag::format_error(where, "casing_frequency_hz", "must be >= 0"));
  }
  if (casing_frequency_hz > 0.0 && casing_frequency_hz >= 0.45 * fs_hz) {
    throw diag::InputError(
        diag::format_error(where, "casing_frequency_hz",
                           std::to_string(casing_frequency_hz) +
                               " Hz is not below 0.45 fs = " + std::to_string(0.45 * fs_hz)));
  }
  if (!(casing_damping_ratio > 0.0 && casing_damping_ratio < 1.0)) {
    throw diag::InputError(diag::format_error(where, "casing_damping_ratio", "must be in (0, 1)"));
  }
}

std::string bearing_location(const std::string& shaft, int index) {
  return shaft + "_bearing" + std::to_string(index);
}

bool at_bearing_location(const diag::BearingSpec& bearing) {
  return bearing.name == bearing_location(bearing.shaft, 1) ||
         bearing.name == bearing_location(bearing.shaft, 2);
}

const Channel* DynamicResult::find(const std::string& name) const {
  for (const Channel& c : channels) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

DynamicResult simulate_dynamic(const diag::Gearbox& gb, const DynamicsOptions& dynamics,
                               const RunOptions& run) {
  run.validate();
  GearboxModel model(gb, dynamics);
  const DynamicsOptions& opt = model.options();
  DynamicResult result;
  result.fs_hz = run.fs_hz;
  const StepPlan steps = plan_steps(gb, model, run, result.warnings);
  const auto& [nat, w_in_max, h, D, delay_out, settle_out, n_out, first_push_step, total_steps] =
      steps;
  result.step_s = h;
  result.decimation = D;

  const std::vector<ChannelPlan> plans = plan_channels(gb, model, run);
  std::vector<AppliedBearingFault> bearing_faults = resolve_bearing_faults(gb, opt, run, plans);
  std::vector<diag::Decimator> decimators;
  std::vector<Resonator> casings;
  for (const ChannelPlan& p : plans) {
    decimators.emplace_back(p.filtered ? D : 1);
    casings.emplace_back(run.casing_frequency_hz > 0 ? run.casing_frequency_hz : 1.0,
                         run.casing_damping_ratio, run.fs_hz * D);
  }
  check_output_memory(plans.size() + gb.shafts().size(), n_out, delay_out);
  std::vector<std::vector<double>> raw(plans.size());
  for (auto& r : raw) r.reserve(static_cast<std::size_t>(n_out + 2 * delay_out + 2));

  const auto [tacho_gear, tacho_duty] = plan_tachos(gb, model, run, w_in_max, n_out, result.tachos);
  const std::vector<double> static_delta = static_deflections(gb, model);

  // ---- integration ----
  std::vector<double> y = model.equilibrium_state();
  const int n = model.dofs();
  Observation obs;
  obs.meshes.resize(gb.meshes().size());
  obs.acceleration.resize(n);
  Rk4 rk4(2 * n);

  struct GslParams {
    const GearboxModel* model;
  } params{&model};
  gsl_odeiv2_system sys{[](double t, const double* yy, double* dy, void* p) -> int {
                          static_cast<GslParams*>(p)->model->derivatives(t, yy, dy);
                          return GSL_SUCCESS;
                        },
                        nullptr, static_cast<std::size_t>(2 * n), &params};
  gsl_odeiv2_driver* driver = nullptr;
  if (run.method == RunOptions::Method::kGslRk8pd) {
    driver = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, h, run.gsl_abs_tol,
                                           run.gsl_rel_tol);
  }
  struct DriverGuard {
    gsl_odeiv2_driver* d;
    ~DriverGuard() {
      if (d) gsl_odeiv2_driver_free(d);
    }
  } guard{driver};

  // The state at the start of the current step (RK4 advances y in place; the angle channels and
  // tachometers need the state at t, like the observation).
  std::vector<double> scratch = y;
  std::vector<double> prev = y;  // the state at t - h (RK4 only)
  std::vector<double> dydt(2 * n);
  std::vector<double> one(1);
  const bool speed_varies = opt.speed.kind != SpeedProfile::Kind::kConstant;
  long long out_index = -1;  // output samples emitted after the first push (incl. dropped ones)
  double t = 0.0;
  for (long long k = 0; k < total_steps; ++k) {
    t = k * h;
    if (speed_varies) model.update_speed(t);
    const bool record = k >= first_push_step;
    if (driver) {
      if (record) model.derivatives(t, y.data(), dydt.data(), &obs);
    } else {
      const std::uint64_t before = model.contact_signature(t, y.data());
      rk4.step(model, t, h, y.data(), record ? &obs : nullptr);
      // (the observation is at t, the state is now at t + h)
      if (run.contact_substeps > 1 && model.contact_signature(t + h, y.data()) != before) {
        // A pair entered or left a mesh within the step: redo it in sub-steps (RunOptions).
        y.assign(scratch.begin(), scratch.end());
        const double hs = h / run.contact_substeps;
        for (int j = 0; j < run.contact_substeps; ++j) {
          rk4.step(model, t + j * hs, hs, y.data(), (j == 0 && record) ? &obs : nullptr);
        }
      }
    }
    if (record) {
      const long long rel = k - first_push_step;
      const bool at_output = rel % D == 0;
      for (std::size_t c = 0; c < plans.size(); ++c) {
        const ChannelPlan& p = plans[c];
        const double value = sample_value(p, model, obs, y, scratch, prev, h, t, driver != nullptr,
                                          k == 0, casings[c]);
        if (!p.filtered) {
          if (at_output) raw[c].push_back(value);
        } else {
          one[0] = value;
          decimators[c].push(one, raw[c]);
        }
      }
      if (at_output) {
        ++out_index;
        if (out_index >= delay_out && out_index < delay_out + n_out) {
          const double* ys = driver ? y.data() : scratch.data();
          for (std::size_t i = 0; i < tacho_gear.size(); ++i) {
            const double a = model.gear_angle_rad(tacho_gear[i], t, ys);
            const double frac = a / (2 * kPi) - std::floor(a / (2 * kPi));
            result.tachos[i].samples.push_back(frac < tacho_duty[i] ? 1.0 : 0.0);
          }
        }
      }
      for (std::size_t j = 0; j < obs.meshes.size(); ++j) {
        if (!std::isfinite(obs.meshes[j].force_n) ||
            std::abs(obs.meshes[j].delta_m) > kDivergenceFactor * static_delta[j]) {
          std::ostringstream msg;
          msg << "simulation diverged at t = " << t << " s: mesh "
              << mesh_name(gb, static_cast<int>(j)) << " deflection " << obs.meshes[j].delta_m
              << " m exceeds " << kDivergenceFactor
              << " static deflections; the scenario is not physical (check stiffness, damping, "
              << "speed) or the step " << h << " s is too large";
          throw diag::InputError(msg.str());
        }
      }
    }
    if (driver) {
      double tt = t;
      const int status = gsl_odeiv2_driver_apply(driver, &tt, t + h, y.data());
      if (status != GSL_SUCCESS) {
        throw diag::InputError("simulation: GSL odeiv2 failed at t = " + std::to_string(t) +
                               " s: " + gsl_strerror(status));
      }
    }
    prev.swap(scratch);  // the state at t (the next step's t - h)
    scratch.assign(y.begin(), y.end());
    for (double v : y) {
      if (!std::isfinite(v)) {
        throw diag::InputError(
            "simulation diverged at t = " + std::to_string(t) +
            " s: the state is not finite; reduce the step or check the scenario");
      }
    }
  }

  result.channels = assemble_channels(plans, raw, delay_out, n_out, run);
  add_bearing_faults(run, bearing_faults, result.channels);
  for (Channel& tc : result.tachos) tc.samples.resize(static_cast<std::size_t>(n_out), 0.0);
  result.truth = dynamic_truth(gb, model, run, steps, result.warnings, bearing_faults);
  return result;
}

diag::Recording to_recording(const diag::Gearbox& gb, const DynamicResult& r) {
  diag::Recording rec;
  rec.signals = r.channels;
  rec.tachos = r.tachos;
  rec.gearbox_json = gb.description_json();
  rec.truth_json = r.truth.dump();
  rec.metadata["simulator"] = "dynamic";
  // The speed the run was made at, as a measured file records its own: the description's
  // input.speed_rpm is only its nominal (simulate --rpm or a scenario's speed replace it). A
  // varying speed has no one value: the tachos carry it.
  const double lo = r.truth.value("input_speed_rpm_min", 0.0);
  const double hi = r.truth.value("input_speed_rpm_max", 0.0);
  if (lo > 0 && lo == hi) rec.speed_rpm = lo;
  return rec;
}

}  // namespace sim
