// The face-gear pair (seed 002) in simulate, sweep and info, and `geardiag bifurcation`.
#include "facegear_cmd.hpp"

#include <unistd.h>

#include <boost/program_options.hpp>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "cli_options.hpp"
#include "commands.hpp"
#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/json_fields.hpp"
#include "output.hpp"
#include "sim/facegear/bifurcation.hpp"
#include "sim/facegear/description.hpp"

namespace po = boost::program_options;
namespace fg = sim::facegear;

namespace geardiag {

namespace {

fg::Description load(const std::string& gearbox, const std::string& scenario) {
  fg::Description d = fg::load_description(gearbox);
  if (!scenario.empty()) fg::apply_scenario(d, diag::load_json_file(scenario), scenario);
  return d;
}

double speed_rpm_checked(double rpm, const char* option) {
  if (!(rpm > 0) || !std::isfinite(rpm) || rpm > 1e5) {
    throw diag::InputError(std::string(option) + ": " + std::to_string(rpm) +
                           " is not a speed in (0, 1e5] rpm");
  }
  return rpm;
}

// Linear interpolation of a trace column at time t (t within the trace).
double at(const fg::Trace& tr, const std::vector<double>& x, double t) {
  const double u = (t - tr.t.front()) / tr.dt;
  const std::size_t i = std::min(static_cast<std::size_t>(u), x.size() - 2);
  const double w = u - static_cast<double>(i);
  return (1.0 - w) * x[i] + w * x[i + 1];
}

double tr_mesh_torque(const nlohmann::json& truth) {
  return truth.at("mean_mesh_torque_nm").get<double>();
}

double range_of(const std::vector<double>& x) {
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  return *hi - *lo;
}

}  // namespace

bool is_face_gear_description(const std::string& path) { return fg::is_face_gear_file(path); }

bool is_face_gear_text(const std::string& json_text, const std::string& where) {
  return fg::is_face_gear(diag::parse_json_text(json_text, where));
}

fg::RunOptions face_gear_run_options(const fg::Description& d, double duration_s, double fs_hz) {
  if (!(duration_s > 0) || duration_s > 600) {
    throw diag::InputError("--duration: must be in (0, 600] s");
  }
  if (!(fs_hz > 0) || fs_hz > 1e7) throw diag::InputError("--fs: must be in (0, 1e7] Hz");
  const fg::Model model(d.pair, d.operating);
  const double gmf = model.mesh_frequency_hz();
  fg::RunOptions ro;
  // The located-event rk8pd integrates; the grid (as fine as RK4's would be, and two points per
  // output sample) is where the trace is recorded and interpolated to --fs.
  ro.integrator = fg::Integrator::kAdaptive;
  ro.steps_per_period =
      std::max(fg::rk4_steps_per_period(model), static_cast<int>(std::ceil(2.0 * fs_hz / gmf)));
  ro.transient_periods = 300;
  // At least 18 mesh periods, what classify_period needs (2 x 8 + 2 Poincare points): a shorter
  // recording's truth classifies the same steady run over its first 18 periods.
  ro.record_periods = std::max(static_cast<int>(std::ceil(duration_s * gmf)) + 2, 18);
  if (static_cast<double>(ro.steps_per_period) * ro.record_periods > 2e9) {
    throw diag::InputError("--duration: too many integration steps; shorten the recording");
  }
  return ro;
}

diag::Recording face_gear_recording(const fg::Description& d, const std::string& gearbox_json,
                                    const FaceGearSimulateArgs& a) {
  const fg::RunOptions ro = face_gear_run_options(d, a.duration_s, a.fs_hz);
  const fg::Model model(d.pair, d.operating);
  const double gmf = model.mesh_frequency_hz();
  const fg::Trace tr = fg::run(model, ro);
  const std::size_t n = static_cast<std::size_t>(std::floor(a.duration_s * a.fs_hz));
  diag::Recording rec;
  // Mesh quantities name the mesh "pinion_face_gear"; the angles name their shaft.
  auto add = [&](const std::string& name, const std::string& unit, diag::Role role,
                 diag::Direction dir, const std::string& shaft, const std::vector<double>& x) {
    diag::Signal s;
    s.name = name;
    s.fs_hz = a.fs_hz;
    s.unit = unit;
    s.role = role;
    s.direction = dir;
    s.shaft = shaft;
    if (shaft.empty()) s.mesh = "pinion_face_gear";
    s.samples.resize(n);
    for (std::size_t i = 0; i < n; ++i) s.samples[i] = at(tr, x, tr.t.front() + i / a.fs_hz);
    rec.signals.push_back(std::move(s));
  };
  std::vector<double> contact(tr.contact.begin(), tr.contact.end());
  add("dte", "rad", diag::Role::kAngle, diag::Direction::kAngle, "", tr.dte);
  // Its rate: (dte, dte_rate) is the phase portrait.
  add("dte_rate", "rad/s", diag::Role::kSpeed, diag::Direction::kUnspecified, "", tr.dte_rate);
  add("mesh_torque", "N m", diag::Role::kOther, diag::Direction::kUnspecified, "", tr.mesh_torque);
  add("mesh_stiffness", "N m/rad", diag::Role::kOther, diag::Direction::kUnspecified, "",
      tr.stiffness);
  add("pinion_angle", "rad", diag::Role::kAngle, diag::Direction::kAngle, "pinion", tr.theta_p);
  add("face_gear_angle", "rad", diag::Role::kAngle, diag::Direction::kAngle, "face_gear",
      tr.theta_g);
  // The contact state is a step function: the state at the step at or before each sample.
  {
    diag::Signal s;
    s.name = "contact_state";
    s.fs_hz = a.fs_hz;
    s.role = diag::Role::kOther;
    s.mesh = "pinion_face_gear";
    s.samples.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(std::floor(i / a.fs_hz / tr.dt + 1e-9));
      s.samples[i] = contact[std::min(k, contact.size() - 1)];
    }
    rec.signals.push_back(std::move(s));
  }
  rec.gearbox_json = gearbox_json;
  rec.speed_rpm = d.operating.speed_rpm;
  nlohmann::json truth;
  truth["kind"] = "face_gear";  // diag::SimulationTruth (diag/io/truth.hpp): the rest is extra
  truth["model"] = "face-gear pair torsional (seed 002)";
  truth["input_speed_rpm"] = d.operating.speed_rpm;
  truth["input_torque_nm"] = d.operating.torque_nm;
  truth["static_mesh_torque_nm"] = model.static_torque();
  truth["mean_mesh_torque_nm"] = tr.mean_mesh_torque;
  truth["mesh_frequency_hz"] = gmf;
  truth["natural_frequency_hz"] = d.pair.natural_frequency_hz(d.operating.torque_nm);
  truth["dlf"] = tr.max_abs_mesh_torque / model.static_torque();
  truth["dte_peak_to_peak_rad"] = range_of(tr.dte);
  truth["impact"] = fg::to_string(fg::classify_impacts(tr.contact_steps));
  truth["period"] = fg::classify_period(tr);
  truth["half_gmf_ratio"] = tr.half_gmf_ratio;
  truth["contact_states"] = "contact_state: 1 drive flank, 0 free flight, -1 coast flank";
  truth["stiffness_table"] = d.table_source;
  truth["stiffness_scale"] = d.pair.stiffness_scale;
  truth["integrator"] = "rk8pd, contact switches located by bisection";
  truth["output_steps_per_mesh_period"] = ro.steps_per_period;
  truth["poincare_rel_tol"] = tr.period_rel_tol;
  rec.truth_json = truth.dump();
  return rec;
}

int simulate_face_gear(const FaceGearSimulateArgs& a) {
  fg::Description d = load(a.gearbox, a.scenario);
  if (a.rpm > 0) d.operating.speed_rpm = speed_rpm_checked(a.rpm, "--rpm");
  if (a.torque_nm >= 0) {
    if (!(a.torque_nm > 0)) throw diag::InputError("--torque: a face-gear pair needs > 0 N m");
    d.operating.torque_nm = a.torque_nm;
  }
  const diag::Recording rec = face_gear_recording(d, diag::load_json_file(a.gearbox).dump(2), a);
  const nlohmann::json truth = nlohmann::json::parse(rec.truth_json);
  diag::write_recording(a.output, rec);
  std::cout << "simulated face-gear pair " << d.name << ": " << a.duration_s << " s at " << a.fs_hz
            << " Hz, " << d.operating.speed_rpm << " rpm, " << d.operating.torque_nm
            << " N m input (" << std::setprecision(4) << tr_mesh_torque(truth)
            << " N m at the mesh); DLF " << std::setprecision(4) << truth["dlf"].get<double>()
            << ", " << truth["period"].get<std::string>() << ", "
            << truth["impact"].get<std::string>() << " -> " << a.output << "\n";
  return 0;
}

int sweep_face_gear(const FaceGearSweepArgs& a) {
  const fg::Description d = load(a.gearbox, a.scenario);
  fg::BifurcationOptions check;
  check.from_rpm = a.from_rpm;
  check.to_rpm = a.to_rpm;
  check.steps = a.steps;
  check.validate();
  nlohmann::json out;
  out["natural_frequency_hz"] = d.pair.natural_frequency_hz(d.operating.torque_nm);
  out["torque_nm"] = d.operating.torque_nm;
  std::cout << "face-gear pair " << d.name << ", " << d.operating.torque_nm
            << " N m input; mesh-mode natural frequency " << std::setprecision(5)
            << out["natural_frequency_hz"].get<double>()
            << " Hz (mesh_Nm: the mean mesh torque, the input less the pinion bearing's c_p "
               "Omega)\n";
  // Each speed continues from the previous speed's final state (run up, then down).
  auto pass = [&](bool up, fg::RunOptions& ro) {
    nlohmann::json j = nlohmann::json::array();
    std::cout << (up ? "run up\n" : "run down\n") << std::setw(10) << "rpm" << std::setw(14)
              << "DTE_pp_urad" << std::setw(10) << "mesh_Nm" << std::setw(10) << "DLF"
              << std::setw(10) << "free" << std::setw(12) << "period"
              << "  impact\n";
    for (int s = 0; s < a.steps; ++s) {
      const int i = up ? s : a.steps - 1 - s;
      fg::Operating op = d.operating;
      op.speed_rpm = a.from_rpm + (a.to_rpm - a.from_rpm) * i / (a.steps - 1);
      const fg::Model model(d.pair, op);
      ro.integrator = fg::Integrator::kAdaptive;  // switches located (bifurcation.hpp)
      ro.steps_per_period = 32;                   // the output grid only
      if (ro.has_start) {
        // Keep the angles, the DTE and its rate; set the rigid-body momentum
        // L = I_p w_p + r I_g w_g to its value at the new speed, (I_p + r^2 I_g) Omega. (Setting
        // w_p = Omega at an arbitrary phase of its mesh-frequency ripple would leave a rigid-body
        // offset that decays only through the bearings, drifting the mesh phase for seconds.)
        const double r = d.pair.ratio(), ip = d.pair.inertia_p, ig = d.pair.inertia_g;
        const double omega = op.speed_rpm * 2.0 * std::numbers::pi / 60.0;
        const double e_rate = ro.start[3] - r * ro.start[1];
        ro.start[1] = omega - r * ig * e_rate / (ip + r * r * ig);
        ro.start[3] = r * ro.start[1] + e_rate;
      }
      const fg::Trace tr = fg::run(model, ro);
      ro.has_start = true;
      ro.start = tr.final_state;
      const double dlf = tr.max_abs_mesh_torque / model.static_torque();
      const double free =
          static_cast<double>(tr.contact_steps[1]) /
          static_cast<double>(tr.contact_steps[0] + tr.contact_steps[1] + tr.contact_steps[2]);
      const std::string period = fg::classify_period(tr);
      const char* impact = fg::to_string(fg::classify_impacts(tr.contact_steps));
      std::cout << std::setw(10) << std::fixed << std::setprecision(1) << op.speed_rpm
                << std::setw(14) << std::setprecision(3) << range_of(tr.dte) * 1e6 << std::setw(10)
                << tr.mean_mesh_torque << std::setw(10) << dlf << std::setw(10) << free
                << std::defaultfloat << std::setw(12) << period << "  " << impact << "\n";
      j.push_back({{"rpm", op.speed_rpm},
                   {"dte_peak_to_peak_rad", range_of(tr.dte)},
                   {"dlf", dlf},
                   {"mean_mesh_torque_nm", tr.mean_mesh_torque},
                   {"static_mesh_torque_nm", model.static_torque()},
                   {"free_flight_share", free},
                   {"period", period},
                   {"half_gmf_ratio", tr.half_gmf_ratio},
                   {"impact", impact}});
    }
    return j;
  };
  fg::RunOptions ro;
  ro.transient_periods = 200;
  ro.record_periods = 100;
  out["up"] = pass(true, ro);
  if (a.down) out["down"] = pass(false, ro);
  if (!a.json_out.empty()) write_output(a.json_out, out.dump(2) + "\n", "--json");
  return 0;
}

int info_face_gear(const std::string& gearbox, bool json) {
  const fg::Description d = fg::load_description(gearbox);
  const fg::Model model(d.pair, d.operating);
  nlohmann::json j;
  j["name"] = d.name;
  j["type"] = "face_gear_pair";
  j["pinion_teeth"] = d.pair.pinion_teeth;
  j["gear_teeth"] = d.pair.gear_teeth;
  j["ratio"] = static_cast<double>(d.pair.gear_teeth) / d.pair.pinion_teeth;
  j["input_speed_rpm"] = d.operating.speed_rpm;
  j["input_torque_nm"] = d.operating.torque_nm;
  j["mesh_frequency_hz"] = model.mesh_frequency_hz();
  j["pinion_inertia_kg_m2"] = d.pair.inertia_p;
  j["gear_inertia_kg_m2"] = d.pair.inertia_g;
  j["half_backlash_pinion_urad"] = d.pair.half_backlash_rad * 1e6;
  j["static_mesh_torque_nm"] = model.static_torque();
  j["mean_stiffness_nm_per_rad"] = d.pair.mean_stiffness(d.operating.torque_nm);
  j["mean_tangent_stiffness_nm_per_rad"] = d.pair.mean_tangent_stiffness(d.operating.torque_nm);
  j["gear_mean_radius_mm"] = d.geometry.gear_mean_radius_m() * 1e3;
  j["natural_frequency_hz"] = d.pair.natural_frequency_hz(d.operating.torque_nm);
  j["stiffness_table"] = d.table_source;
  j["stiffness_scale"] = d.pair.stiffness_scale;
  if (json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "face-gear pair '" << d.name << "' (seed 002 torsional model)\n";
  for (const auto& [k, v] : j.items()) {
    if (k != "name") std::cout << "  " << std::left << std::setw(28) << k << v.dump() << "\n";
  }
  std::cout << "  (simulate, sweep and bifurcation apply; analyze, attribute and validate need a "
               "shafts/gears/meshes gearbox)\n";
  return 0;
}

int cmd_bifurcation(int argc, char** argv) {
  fg::BifurcationOptions opt;
  std::string gearbox, scenario, json_out, svg_out;
  double torque = -1;
  po::options_description desc(
      "geardiag bifurcation --gearbox FG.json [--scenario SC.json] [--torque NM]\n"
      "                     --from-rpm A --to-rpm B --steps N --json OUT.json [--svg OUT.svg]\n\n"
      "Bifurcation diagram of a face-gear pair (seed 002): at each of N speeds from A to B an\n"
      "independent run from static equilibrium; after the transients the DTE once per mesh\n"
      "period (Poincare section) and its class (period-1, period-2, period-n, chaos), the impact\n"
      "class, the DLF and half_gmf_ratio, A(GMF/2) / A(GMF) of the DTE spectrum (the period\n"
      "doubling's subharmonic line). Speeds run on all cores; the output does not depend on their\n"
      "number; a terminal shows the progress.\n"
      "The scenario accepts stiffness_scale, torque_nm, backlash_um, static_te_scale.\n\noptions");
  desc.add_options()("help,h", "this help")("gearbox", po::value(&gearbox)->required(),
                                            "face-gear pair description (JSON)")(
      "scenario", po::value(&scenario), "scenario (JSON)")(
      "torque", po::value(&torque), "input torque [N m] (default: the description's)")(
      "from-rpm", po::value(&opt.from_rpm)->required(), "first speed [rpm], > 0")(
      "to-rpm", po::value(&opt.to_rpm)->required(), "last speed [rpm]")(
      "steps", po::value(&opt.steps)->default_value(opt.steps), "number of speeds")(
      "transient", po::value(&opt.transient_periods)->default_value(opt.transient_periods),
      "mesh periods discarded per speed")(
      "periods", po::value(&opt.record_periods)->default_value(opt.record_periods),
      "Poincare points (mesh periods) per speed")(
      "threads", po::value(&opt.threads)->default_value(0), "worker threads (0: all cores)")(
      "json", po::value(&json_out)->required(), "output JSON ('-': stdout)")(
      "svg", po::value(&svg_out), "output SVG plot");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  const CoutToStderr summary_to_stderr(check_output(json_out, "--json"));
  if (!svg_out.empty()) check_output(svg_out, "--svg");
  opt.validate();
  if (!is_face_gear_description(gearbox)) {
    throw diag::InputError(diag::format_error(gearbox, "face_gear_pair",
                                              "bifurcation needs a face-gear pair description"));
  }
  fg::Description d = load(gearbox, scenario);
  if (vm.count("torque")) {
    if (!(torque > 0) || !std::isfinite(torque)) throw diag::InputError("--torque: must be > 0");
    d.operating.torque_nm = torque;
  }
  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  auto progress = [&](int done, int total) {
    if (terminal) std::cerr << "\rbifurcation: " << done << "/" << total << " speeds" << std::flush;
  };
  const fg::Bifurcation b = fg::bifurcation(d.pair, d.operating, opt, progress);
  if (terminal) std::cerr << "\n";
  nlohmann::json j = b.to_json();
  j["gearbox"] = gearbox;
  j["torque_nm"] = d.operating.torque_nm;
  j["stiffness_scale"] = d.pair.stiffness_scale;
  j["transient_periods"] = opt.transient_periods;
  j["integrator"] = "rk8pd, contact switches located by bisection";
  write_output(json_out, j.dump(1) + "\n", "--json");
  if (!svg_out.empty()) {
    std::ostringstream title;
    title << d.name << ": " << d.operating.torque_nm << " N m, stiffness x"
          << d.pair.stiffness_scale;
    write_output(svg_out, b.to_svg(title.str()), "--svg");
  }
  int counts[4] = {0, 0, 0, 0};
  for (const auto& p : b.speeds) {
    const char* names[] = {"period-1", "period-2", "period-n", "chaos"};
    for (int c = 0; c < 4; ++c) counts[c] += p.period_class == names[c];
  }
  std::cout << "bifurcation: " << b.speeds.size() << " speeds " << opt.from_rpm << ".."
            << opt.to_rpm << " rpm: period-1 " << counts[0] << ", period-2 " << counts[1]
            << ", period-n " << counts[2] << ", chaos " << counts[3] << " on " << b.threads
            << " threads -> " << json_out << "\n";
  return 0;
}

}  // namespace geardiag
