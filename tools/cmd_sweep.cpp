// geardiag sweep: the input speed ramped slowly up and down through a range; peak and RMS of the
// chosen channels per speed window, contact loss, natural frequencies and the speeds where the
// first mesh's frequency meets each mesh's torsional natural frequency.
#include <boost/program_options.hpp>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_options.hpp"
#include "commands.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "facegear_cmd.hpp"
#include "output.hpp"
#include "sim/dynamics/scenario.hpp"
#include "sim/dynamics/sweep.hpp"

namespace po = boost::program_options;

namespace geardiag {

int cmd_sweep(int argc, char** argv) {
  sim::SweepOptions sw;
  std::string gearbox, scenario, json_out;
  po::options_description desc(
      "geardiag sweep --gearbox GB.json --from-rpm A --to-rpm B [--steps N] [--down]\n"
      "               [--scenario SC.json] [--channel NAME ...] [--json OUT.json]\n\n"
      "Ramps the input speed slowly from A to B (and back with --down) and reports the peak and\n"
      "RMS of each channel per speed window (default: every mesh force and the first bearing's\n"
      "accelerations along and normal to the line of action), the share of time out of contact,\n"
      "and the natural frequencies. A nonlinear resonance shows as a jump at different speeds up\n"
      "and down.\n\noptions");
  bool down = false;
  desc.add_options()("help,h", "this help")("gearbox", po::value(&gearbox)->required(),
                                            "gearbox description (JSON)")(
      "scenario", po::value(&scenario), "scenario description (JSON); its speed is ignored")(
      "from-rpm", po::value(&sw.from_rpm)->required(), "start speed [rpm]")(
      "to-rpm", po::value(&sw.to_rpm)->required(), "end speed [rpm]")(
      "steps", po::value(&sw.steps)->default_value(sw.steps), "speed windows per run")(
      "down", po::bool_switch(&down), "also run down from B to A")(
      "dwell", po::value(&sw.dwell_s)->default_value(0.0),
      "time per window [s]; 0 = 200 mesh periods at the start speed")(
      "channel", po::value(&sw.channels)->multitoken(), "channel(s) to report")(
      "json", po::value(&json_out), "write the sweep as JSON ('-': stdout, the tables to stderr)");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  sw.down = down;
  // Checked before the sweep; with "-" the JSON goes to stdout and the tables to stderr.
  const CoutToStderr tables_to_stderr(!json_out.empty() && check_output(json_out, "--json"));
  if (is_face_gear_description(gearbox)) {
    return sweep_face_gear({gearbox, scenario, json_out, sw.from_rpm, sw.to_rpm, sw.steps, down});
  }
  const diag::Gearbox gb = diag::load_gearbox(gearbox);
  sim::Scenario sc;
  if (!scenario.empty()) sc = sim::load_scenario(scenario);
  const sim::SweepResult r = sim::run_sweep(gb, sc.dynamics, sc.run, sw);
  std::cout << "natural frequencies [Hz]:";
  for (double f : r.natural_frequencies_hz) std::cout << ' ' << std::setprecision(5) << f;
  std::cout << "\nmesh torsional resonance at input speed [rpm]:";
  for (double v : r.resonance_rpm) std::cout << ' ' << std::setprecision(5) << v;
  std::cout << "\n\n";
  auto table = [&](const char* title, const std::vector<sim::SweepPoint>& pts) {
    std::cout << title << "\n" << std::setw(10) << "rpm" << std::setw(12) << "f_mesh_Hz";
    for (const std::string& c : r.channels) std::cout << std::setw(24) << (c + " pk");
    std::cout << std::setw(10) << "lost"
              << "\n";
    for (const sim::SweepPoint& p : pts) {
      std::cout << std::setw(10) << std::fixed << std::setprecision(1) << p.rpm << std::setw(12)
                << p.mesh_frequency_hz << std::defaultfloat;
      for (double v : p.peak) std::cout << std::setw(24) << std::setprecision(5) << v;
      std::cout << std::setw(10) << std::setprecision(3) << p.contact_loss_fraction << "\n";
    }
  };
  table("run up", r.up);
  if (sw.down) table("run down", r.down);
  if (!json_out.empty()) write_output(json_out, r.to_json().dump(2) + "\n", "--json");
  return 0;
}

}  // namespace geardiag
