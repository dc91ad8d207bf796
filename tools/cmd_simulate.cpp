// geardiag simulate: a gearbox description with defects in, a recording with ground truth out.
// Modes: dynamic (seed 000 generalised: meshes, shafts, bearings, sensors) and kinematic (seed 003:
// slow rotation, shaft angles).
#include <boost/program_options.hpp>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli_options.hpp"
#include "commands.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/units.hpp"
#include "facegear_cmd.hpp"
#include "output.hpp"
#include "sim/dynamics/scenario.hpp"
#include "sim/kinematic/sporadic_defects.hpp"

namespace po = boost::program_options;

namespace geardiag {

namespace {

// CSV "input_angle_rad,output_angle_rad", written as every output is (output.hpp).
void write_angles_csv(const std::string& path, const sim::KinematicResult& r) {
  std::ostringstream out;
  out.precision(17);
  out << "input_angle_rad,output_angle_rad\n";
  for (std::size_t i = 0; i < r.input_angle_rad.size(); ++i) {
    out << r.input_angle_rad[i] << ',' << r.output_angle_rad[i] << '\n';
  }
  write_output(path, out.str(), "--output");
}

}  // namespace

namespace {

int simulate_kinematic_mode(const std::string& gearbox, const std::string& output,
                            sim::KinematicOptions k, double step_deg, double runout_deg,
                            double te_deg, double noise_deg) {
  k.step_rad = diag::units::deg_to_rad(step_deg);
  k.runout_output_rad = diag::units::deg_to_rad(runout_deg);
  k.mesh_te_output_rad = diag::units::deg_to_rad(te_deg);
  k.noise_output_rad = diag::units::deg_to_rad(noise_deg);
  const diag::Gearbox gb = diag::load_gearbox(gearbox);
  print_warnings(gb.warnings(), "simulate");
  const sim::KinematicResult r = sim::simulate_kinematic(gb, k);
  if (std::filesystem::path(output).extension() == ".csv") {
    write_angles_csv(output, r);
  } else {
    diag::write_recording(output, sim::to_recording(gb, r));
  }
  std::cout << "simulated " << r.input_angle_rad.size() << " samples over "
            << r.truth["revolutions"].get<double>() << " input revolutions, " << gb.defects().size()
            << " defect(s) -> " << output << "\n";
  return 0;
}

}  // namespace

int cmd_simulate(int argc, char** argv) {
  sim::KinematicOptions k;
  std::string gearbox, output, scenario, mode = "dynamic";
  double step_deg = diag::units::rad_to_deg(k.step_rad), runout_deg = 0, te_deg = 0, noise_deg = 0;
  double duration_s = 0, fs_hz = 0, rpm = 0, torque = -1, oil_c = -300;
  std::string friction;
  po::options_description desc(
      "geardiag simulate --gearbox GB.json [--scenario SC.json] --duration S --fs HZ -o OUT.h5\n"
      "geardiag simulate --mode kinematic --gearbox GB.json -o OUT.h5|OUT.csv [options]\n\n"
      "Dynamic mode (default; docs/physics.md): the gearbox's meshes with time-varying stiffness,\n"
      "friction, backlash and tooth faults, its shafts on bearings; writes bearing accelerations\n"
      "along and normal to each line of action and horizontal/vertical, the transmission error,\n"
      "mesh forces, tachometers and the ground truth. The scenario (JSON, docs/formats.md) sets\n"
      "the operating point, friction, oil, faults, sensors; the options below override it.\n"
      "Kinematic mode (seed 003): output angle vs input angle at slow speed with the gearbox's\n"
      "sporadic defects, over six recurrences of the longest defect period.\n\noptions");
  desc.add_options()("help,h", "this help")("gearbox", po::value(&gearbox)->required(),
                                            "gearbox description (JSON)")(
      "output,o", po::value(&output)->required(),
      "output file (.h5; kinematic mode also .csv; '-': HDF5 to stdout)")(
      "mode", po::value(&mode)->default_value(mode), "dynamic | kinematic")(
      "scenario", po::value(&scenario), "dynamic: scenario description (JSON)")(
      "duration", po::value(&duration_s), "dynamic: recorded duration [s] (default 1)")(
      "fs", po::value(&fs_hz), "dynamic: output sampling rate [Hz] (default 20000)")(
      "rpm", po::value(&rpm), "dynamic: constant input speed [rpm] (default: the gearbox's)")(
      "torque", po::value(&torque), "dynamic: input torque [N m] (default: the gearbox's)")(
      "friction", po::value(&friction), "dynamic: none | constant | drozdov | benedict_kelley")(
      "oil-temp", po::value(&oil_c), "dynamic: oil temperature [degC]")(
      "step-deg", po::value(&step_deg)->default_value(step_deg),
      "kinematic: input-angle step [deg]")(
      "revolutions", po::value(&k.revolutions)->default_value(0.0),
      "kinematic: input revolutions; 0 = six recurrences of the longest period")(
      "runout-deg", po::value(&runout_deg)->default_value(0.0),
      "kinematic: once-per-rev runout of every path shaft, amplitude at the output [deg]")(
      "mesh-te-deg", po::value(&te_deg)->default_value(0.0),
      "kinematic: mesh-harmonic transmission error, amplitude at the output [deg]")(
      "noise-deg", po::value(&noise_deg)->default_value(0.0),
      "kinematic: Gaussian noise on the output angle, RMS [deg]")(
      "encoder-counts", po::value(&k.encoder_counts_per_rev)->default_value(0),
      "kinematic: encoder counts per revolution for both angles (0 = no quantisation)")(
      "seed", po::value(&k.seed)->default_value(k.seed), "random seed");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  // Checked before the simulation; with "-" the recording goes to stdout and the summary to
  // stderr.
  const diag::OutputTarget target = diag::check_output_path(output, "--output");
  const CoutToStderr summary_to_stderr(target.kind == diag::OutputKind::kStdout);
  if (mode == "kinematic") {
    return simulate_kinematic_mode(gearbox, output, k, step_deg, runout_deg, te_deg, noise_deg);
  }
  if (mode != "dynamic") {
    throw diag::InputError("--mode: '" + mode + "' is not dynamic or kinematic");
  }
  // A FIFO, device or stdout has no meaningful extension.
  if (target.kind == diag::OutputKind::kRegular &&
      std::filesystem::path(output).extension() != ".h5") {
    throw diag::InputError("--output: '" + output +
                           "': the dynamic mode writes an HDF5 recording (.h5)");
  }
  if (is_face_gear_description(gearbox)) {
    return simulate_face_gear({gearbox, output, scenario, vm.count("duration") ? duration_s : 1.0,
                               vm.count("fs") ? fs_hz : 20000.0, vm.count("rpm") ? rpm : 0.0,
                               vm.count("torque") ? torque : -1.0});
  }
  const diag::Gearbox gb = diag::load_gearbox(gearbox);
  print_warnings(gb.warnings(), "simulate");
  sim::Scenario sc;
  if (!scenario.empty()) sc = sim::load_scenario(scenario);
  if (vm.count("duration")) sc.run.duration_s = duration_s;
  if (vm.count("fs")) sc.run.fs_hz = fs_hz;
  if (vm.count("rpm")) {
    // 0 would mean "the description's speed" inside the options: refused here, not ignored.
    if (!(rpm > 0) || !std::isfinite(rpm) || rpm > diag::kMaxSpeedRpm) {
      throw diag::InputError("--rpm: " + std::to_string(rpm) + " is not a speed in (0, " +
                             std::to_string(static_cast<long>(diag::kMaxSpeedRpm)) + "] rpm");
    }
    sc.dynamics.speed = sim::SpeedProfile::constant(rpm);
  }
  if (vm.count("torque")) {
    if (!(torque >= 0)) throw diag::InputError("--torque: must be >= 0");
    sc.dynamics.input_torque_nm = torque;
  }
  if (vm.count("friction")) sc.dynamics.friction.law = sim::friction_law_from_string(friction);
  if (vm.count("oil-temp")) sc.dynamics.friction.oil_temperature_c = oil_c;
  // Only an explicit --seed replaces the scenario's "seed" and sensors.noise_seed: vm.count is 1
  // for the defaulted option too.
  if (vm.count("seed") && !vm["seed"].defaulted()) sc.dynamics.seed = sc.run.seed = k.seed;
  const sim::DynamicResult r = sim::simulate_dynamic(gb, sc.dynamics, sc.run);
  print_warnings(r.warnings, "simulate");
  diag::write_recording(output, sim::to_recording(gb, r));
  std::cout << "simulated " << sc.run.duration_s << " s at " << sc.run.fs_hz << " Hz ("
            << r.channels.size() << " channels, " << r.tachos.size() << " tachometers; RK step "
            << r.step_s * 1e6 << " us, " << r.decimation << " steps per sample) -> " << output
            << "\n";
  return 0;
}

}  // namespace geardiag
