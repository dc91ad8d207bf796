// geardiag wear: the wear history of one mesh (seed 004 / Archard), worn profiles and the
// transmission error they give, as an HDF5 file.
#include <boost/program_options.hpp>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli_options.hpp"
#include "commands.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/hdf5_arrays.hpp"
#include "output.hpp"
#include "sim/dynamics/scenario.hpp"
#include "sim/wear/wear.hpp"

namespace po = boost::program_options;

namespace geardiag {

namespace {

// The mesh named DRIVER_DRIVEN (gear names joined by '_').
int find_mesh(const diag::Gearbox& gb, const std::string& name, const std::string& file) {
  std::string names;
  for (std::size_t i = 0; i < gb.meshes().size(); ++i) {
    const auto& m = gb.meshes()[i];
    const std::string n = gb.gears()[static_cast<std::size_t>(m.driver)].name + "_" +
                          gb.gears()[static_cast<std::size_t>(m.driven)].name;
    if (n == name) return static_cast<int>(i);
    names += (names.empty() ? "" : ", ") + n;
  }
  throw diag::InputError(
      diag::format_error(file, "--mesh", "unknown mesh '" + name + "' (meshes: " + names + ")"));
}

std::vector<double> flatten(const std::vector<std::vector<double>>& rows, double scale) {
  std::vector<double> out;
  for (const auto& r : rows) {
    for (double v : r) out.push_back(v * scale);
  }
  return out;
}

std::vector<double> scaled(const std::vector<double>& v, double scale) {
  std::vector<double> out(v);
  for (double& x : out) x *= scale;
  return out;
}

// What --record-every needs besides the history: the dynamic run's scenario and overrides.
struct RecordRequest {
  int every = 0;  // 0: no recordings
  std::string scenario;
  double rpm = 0, torque = -1, duration_s = 0, fs_hz = 0;
};

// The scenario of the recordings (as `geardiag simulate` builds it from the same options).
sim::Scenario record_scenario(const RecordRequest& r) {
  sim::Scenario sc;
  if (!r.scenario.empty()) sc = sim::load_scenario(r.scenario);
  if (r.duration_s > 0) sc.run.duration_s = r.duration_s;
  if (r.fs_hz > 0) sc.run.fs_hz = r.fs_hz;
  if (r.rpm > 0) sc.dynamics.speed = sim::SpeedProfile::constant(r.rpm);
  if (r.torque >= 0) sc.dynamics.input_torque_nm = r.torque;
  sc.run.validate();
  return sc;
}

// "<dir>/<stem>_step<k>.h5" beside OUT.h5, k zero-padded to the width of the last step.
std::string recording_path(const std::string& out, int step, int last) {
  const std::filesystem::path p(out);
  const int width = static_cast<int>(std::to_string(last).size());
  std::ostringstream name;
  name << p.stem().string() << "_step" << std::setw(width) << std::setfill('0') << step << ".h5";
  return (p.parent_path() / name.str()).string();
}

// One dynamic recording per recorded point of life (step 0: the new pair), the worn state as
// truth (sim::MeshWear, the same path as the scenario's wear fault). Returns the steps and paths.
std::vector<std::pair<int, std::string>> record_life(
    const diag::Gearbox& gb, int mesh, const std::string& mesh_label, const sim::WearHistory& h,
    sim::WearLaw law, const sim::Scenario& sc, const RecordRequest& r, const std::string& out) {
  std::vector<std::pair<int, std::string>> done;
  const int last = static_cast<int>(h.cycles.size());
  for (int k = 0; k <= last; k += r.every) {
    sim::MeshWear w;
    w.mesh = diag::mesh_name(gb, mesh);
    w.where = "wear step " + std::to_string(k);
    w.law = law;
    if (k == 0) {
      w.state = sim::worn_pair(h, 0);
      w.state.cycles = 0;
      w.state.te_peak_to_peak_rad = h.te_peak_to_peak_new_rad;
      std::fill(w.state.depth_driver_m.begin(), w.state.depth_driver_m.end(), 0.0);
      std::fill(w.state.depth_driven_m.begin(), w.state.depth_driven_m.end(), 0.0);
    } else {
      w.state = sim::worn_pair(h, static_cast<std::size_t>(k - 1));
    }
    sim::DynamicsOptions dyn = sc.dynamics;
    dyn.wear.push_back(w);
    const sim::DynamicResult res = sim::simulate_dynamic(gb, dyn, sc.run);
    print_warnings(res.warnings, "wear");
    const std::string path = recording_path(out, k, last);
    diag::write_recording(path, sim::to_recording(gb, res));
    std::cout << mesh_label << " step " << k << " (" << w.state.cycles << " cycles) -> " << path
              << "\n";
    done.emplace_back(k, path);
  }
  return done;
}

}  // namespace

int cmd_wear(int argc, char** argv) {
  sim::WearOptions o;
  std::string gearbox, mesh, out, law = "archard";
  RecordRequest rec;
  double depth_limit_um = o.depth_limit_m * 1e6;
  po::options_description desc(
      "geardiag wear --gearbox GB.json --mesh DRIVER_DRIVEN --cycles N --steps K\n"
      "              [--law archard|seed004] [--depth-limit-um D] -o OUT.h5\n"
      "              [--record-every M [--scenario SC.json] [--rpm R] [--torque T]\n"
      "               [--duration S] [--fs HZ]]\n\n"
      "Wears the mesh's flanks over N driver revolutions in K blocks (docs/wear.md): each "
      "block\n"
      "wears both flanks by the chosen law at the input torque of the gearbox, then recomputes "
      "load\n"
      "sharing, the loaded contact ratio, the mesh stiffness and the unloaded transmission error "
      "of\n"
      "the worn profiles; the history stops early once a point has worn D deep. Writes "
      "/wear/cycles\n"
      "(K), /wear/<gear>/radius_mm and /wear/<gear>/depth_um (K x points) for both gears,\n"
      "/wear/te_peak_to_peak_rad and /wear/te_harmonics_rad (K x 3: the unloaded TE of the gap\n"
      "the dynamic simulator runs), /wear/te_rolled_peak_to_peak_rad (the worn flanks rolled,\n"
      "corner contact included), /wear/loaded_contact_ratio,\n"
      "/wear/mesh_stiffness_n_per_m and /wear/max_pressure_mpa (K each), the sharing's pair\n"
      "stiffness /wear/<driver>/pair_stiffness_n_per_m and the load /wear/normal_force_n.\n"
      "With --record-every M, the dynamic simulator (as `geardiag simulate`, the scenario and\n"
      "options alike) runs the worn pair at steps 0 (new), M, 2M, ... and writes one recording\n"
      "per point of life beside OUT, OUT_step<k>.h5, its truth's \"wear\" entry the state "
      "(cycles,\n"
      "deepest wear per gear, unloaded TE, law); /wear/recorded_steps lists them. The torque of\n"
      "the history is the run's (--torque, else the scenario's, else the "
      "description's).\n\noptions");
  desc.add_options()("help,h", "this help")("gearbox", po::value(&gearbox)->required(),
                                            "gearbox description (JSON)")(
      "mesh", po::value(&mesh)->required(), "the mesh, as DRIVER_DRIVEN gear names")(
      "cycles", po::value(&o.cycles)->required(), "driver revolutions over the history, > 0")(
      "steps", po::value(&o.steps)->required(), "blocks (history entries), >= 1")(
      "law", po::value(&law)->default_value(law), "archard | seed004")(
      "archard-k",
      po::value(&o.archard_coefficient_m2_per_n)->default_value(o.archard_coefficient_m2_per_n),
      "Archard wear coefficient [m^2/N]")(
      "seed-m", po::value(&o.seed_exponent_m)->default_value(o.seed_exponent_m),
      "seed004: exponent m of the reduced radius")(
      "seed-n", po::value(&o.seed_exponent_n)->default_value(o.seed_exponent_n),
      "seed004: exponent n of the sliding speed")(
      "depth-limit-um", po::value(&depth_limit_um)->default_value(depth_limit_um),
      "stop once a flank point has worn this deep [um]")(
      "profile-points", po::value(&o.profile_points)->default_value(o.profile_points),
      "points on each active flank")("output,o", po::value(&out)->required(), "output HDF5 file")(
      "record-every", po::value(&rec.every), "a vibration recording every M steps (and at 0)")(
      "scenario", po::value(&rec.scenario), "recordings: scenario description (JSON)")(
      "rpm", po::value(&rec.rpm), "recordings: constant input speed [rpm]")(
      "torque", po::value(&rec.torque), "input torque [N m] of the history and the recordings")(
      "duration", po::value(&rec.duration_s), "recordings: duration [s] (default 1)")(
      "fs", po::value(&rec.fs_hz), "recordings: sampling rate [Hz] (default 20000)");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  o.law = sim::parse_wear_law(law, "--law");
  if (!(o.cycles > 0)) throw diag::InputError(diag::format_error("--cycles", "", "must be > 0"));
  if (o.steps < 1) throw diag::InputError(diag::format_error("--steps", "", "must be >= 1"));
  o.depth_limit_m = depth_limit_um * 1e-6;
  o.validate();
  const bool recording = vm.count("record-every") > 0;
  for (const char* opt : {"scenario", "rpm", "duration", "fs"}) {
    if (vm.count(opt) && !recording) {
      throw diag::InputError(diag::format_error(
          std::string("--") + opt, "", "is an option of the recordings: give --record-every"));
    }
  }
  if (recording && rec.every < 1) {
    throw diag::InputError(diag::format_error("--record-every", "", "must be >= 1"));
  }
  if (vm.count("rpm") && (!(rec.rpm > 0) || !(rec.rpm <= diag::kMaxSpeedRpm))) {
    throw diag::InputError(
        diag::format_error("--rpm", "",
                           "must be a speed in (0, " +
                               std::to_string(static_cast<long>(diag::kMaxSpeedRpm)) + "] rpm"));
  }
  if (vm.count("torque") && !(rec.torque >= 0 && std::isfinite(rec.torque))) {
    throw diag::InputError(diag::format_error("--torque", "", "must be >= 0"));
  }
  if (vm.count("duration") && !(rec.duration_s > 0)) {
    throw diag::InputError(diag::format_error("--duration", "", "must be > 0"));
  }
  if (vm.count("fs") && !(rec.fs_hz > 0)) {
    throw diag::InputError(diag::format_error("--fs", "", "must be > 0"));
  }
  check_output(out, "--output");
  if (recording && std::filesystem::path(out).extension() != ".h5") {
    throw diag::InputError(diag::format_error(
        "--output", "",
        "with --record-every, OUT must end in .h5 (recordings are OUT_step<k>.h5)"));
  }
  const diag::Gearbox gb = diag::load_gearbox(gearbox);
  const int mi = find_mesh(gb, mesh, gearbox);
  sim::Scenario sc;
  if (recording) sc = record_scenario(rec);
  o.input_torque_nm = vm.count("torque") ? rec.torque : sc.dynamics.input_torque_nm;
  const sim::WearHistory h = sim::simulate_wear(gb, mi, o);
  std::vector<std::pair<int, std::string>> recorded;
  if (recording) recorded = record_life(gb, mi, mesh, h, o.law, sc, rec, out);
  std::vector<double> recorded_steps;
  std::string recorded_files;
  for (const auto& [k, path] : recorded) {
    recorded_steps.push_back(k);
    recorded_files +=
        (recorded_files.empty() ? "" : ";") + std::filesystem::path(path).filename().string();
  }
  const auto& m = gb.meshes()[static_cast<std::size_t>(mi)];
  const std::string n1 = gb.gears()[static_cast<std::size_t>(m.driver)].name;
  const std::string n2 = gb.gears()[static_cast<std::size_t>(m.driven)].name;
  const std::size_t k = h.cycles.size(), np = h.roll_driver_m.size();
  std::vector<double> harm;
  for (const auto& a : h.te_harmonics_rad) harm.insert(harm.end(), a.begin(), a.end());
  const std::vector<diag::Hdf5Array> arrays = {
      {"/wear/cycles", {}, h.cycles, "driver revolutions"},
      {"/wear/" + n1 + "/radius_mm", {}, scaled(h.radius_driver_m, 1e3), "mm"},
      {"/wear/" + n1 + "/roll_mm", {}, scaled(h.roll_driver_m, 1e3), "mm"},
      {"/wear/" + n1 + "/depth_um", {k, np}, flatten(h.depth_driver_m, 1e6), "um"},
      {"/wear/" + n2 + "/radius_mm", {}, scaled(h.radius_driven_m, 1e3), "mm"},
      {"/wear/" + n2 + "/roll_mm", {}, scaled(h.roll_driven_m, 1e3), "mm"},
      {"/wear/" + n2 + "/depth_um", {k, np}, flatten(h.depth_driven_m, 1e6), "um"},
      {"/wear/te_peak_to_peak_rad",
       {},
       h.te_peak_to_peak_rad,
       "rad (driven gear), the gap the dynamic simulator runs"},
      {"/wear/te_harmonics_rad", {k, 3}, harm, "rad (driven gear), mesh harmonics 1..3"},
      {"/wear/te_rolled_peak_to_peak_rad",
       {},
       h.te_rolled_peak_to_peak_rad,
       "rad (driven gear), the worn flanks rolled (corner contact included)"},
      {"/wear/loaded_contact_ratio", {}, h.loaded_contact_ratio, ""},
      {"/wear/mesh_stiffness_n_per_m", {}, h.mesh_stiffness_n_per_m, "N/m"},
      {"/wear/max_pressure_mpa", {}, scaled(h.max_pressure_pa, 1e-6), "MPa"},
      {"/wear/" + n1 + "/pair_stiffness_n_per_m",
       {},
       h.pair_stiffness_n_per_m,
       "N/m, unworn pair stiffness k(s) with the contact at these driver points"},
      {"/wear/normal_force_n", {}, {h.normal_force_n}, "N, total normal force on the mesh"}};
  std::vector<diag::Hdf5Array> all = arrays;
  if (recording) {
    all.push_back({"/wear/recorded_steps", {}, recorded_steps, "steps (0: the new pair)"});
  }
  write_hdf5_arrays(
      out, all,
      {{"creator", "geardiag wear"},
       {"law", law},
       {"recordings", recorded_files},
       {"input_torque_nm",
        std::to_string(o.input_torque_nm >= 0 ? o.input_torque_nm : gb.input().torque_nm)},
       {"mesh", mesh},
       {"gearbox", gb.description_json()},
       {"stopped_at_depth_limit", h.stopped_at_limit ? "true" : "false"},
       {"te_points_per_mesh", std::to_string(o.te_points_per_mesh)}});
  const double te_end = h.te_peak_to_peak_rad.back();
  double deepest = 0;
  for (double v : h.depth_driver_m.back()) deepest = std::max(deepest, v);
  for (double v : h.depth_driven_m.back()) deepest = std::max(deepest, v);
  std::cout << std::setprecision(4) << mesh << " (" << law << "): " << k << " steps to "
            << h.cycles.back() << " cycles" << (h.stopped_at_limit ? " (depth limit reached)" : "")
            << "; deepest wear " << deepest * 1e6 << " um; unloaded TE peak-to-peak "
            << h.te_peak_to_peak_new_rad << " -> " << te_end << " rad; loaded contact ratio "
            << h.loaded_contact_ratio_new << " -> " << h.loaded_contact_ratio.back() << " -> "
            << out << "\n";
  return 0;
}

}  // namespace geardiag
