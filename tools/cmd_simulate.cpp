// geardiag simulate: a gearbox description with defects in, a recording with ground truth out.
// Modes: kinematic (seed 003: slow rotation, shaft angles). The dynamic mode (seed 000 6-DOF
// pairs, bearing accelerations) is not built yet and says so.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <unistd.h>

#include <boost/program_options.hpp>

#include "commands.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/units.hpp"
#include "sim/kinematic/sporadic_defects.hpp"

namespace po = boost::program_options;

namespace geardiag {

namespace {

// CSV "input_angle_rad,output_angle_rad", written to a temporary name and renamed into place.
void write_angles_csv(const std::filesystem::path& path, const sim::KinematicResult& r) {
  const std::filesystem::path tmp = path.string() + ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw diag::InputError(path.string() + ": cannot write the file");
    out.precision(17);
    out << "input_angle_rad,output_angle_rad\n";
    for (std::size_t i = 0; i < r.input_angle_rad.size(); ++i) {
      out << r.input_angle_rad[i] << ',' << r.output_angle_rad[i] << '\n';
    }
    if (!out) {
      out.close();
      std::filesystem::remove(tmp);
      throw diag::InputError(path.string() + ": write failed");
    }
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace

int cmd_simulate(int argc, char** argv) {
  sim::KinematicOptions k;
  std::string gearbox, output, mode = "kinematic";
  double step_deg = diag::units::rad_to_deg(k.step_rad), runout_deg = 0, te_deg = 0, noise_deg = 0;
  po::options_description desc(
      "geardiag simulate --gearbox GB.json -o OUT.h5|OUT.csv [options]\n\n"
      "Simulates the defects listed in the gearbox description. Kinematic mode (seed 003): the\n"
      "output shaft's angle vs the input shaft's angle at slow speed, over six recurrences of the\n"
      "longest defect period unless --revolutions is given. Output: HDF5 recording with the truth,\n"
      "or CSV input_angle_rad,output_angle_rad.\n\noptions");
  desc.add_options()("help,h", "this help")(
      "gearbox", po::value(&gearbox)->required(), "gearbox description (JSON) with defects")(
      "output,o", po::value(&output)->required(), "output file (.h5 recording or .csv angles)")(
      "mode", po::value(&mode)->default_value(mode), "kinematic (dynamic: not built yet)")(
      "step-deg", po::value(&step_deg)->default_value(step_deg), "input-angle step [deg]")(
      "revolutions", po::value(&k.revolutions)->default_value(0.0),
      "input revolutions; 0 = six recurrences of the longest period")(
      "runout-deg", po::value(&runout_deg)->default_value(0.0),
      "once-per-rev runout of every path shaft, amplitude at the output [deg]")(
      "mesh-te-deg", po::value(&te_deg)->default_value(0.0),
      "mesh-harmonic transmission error, amplitude at the output [deg]")(
      "noise-deg", po::value(&noise_deg)->default_value(0.0),
      "Gaussian noise on the output angle, RMS [deg]")(
      "encoder-counts", po::value(&k.encoder_counts_per_rev)->default_value(0),
      "encoder counts per revolution for both angles (0 = no quantisation)")(
      "seed", po::value(&k.seed)->default_value(k.seed), "random seed (phases, noise)");
  po::variables_map vm;
  po::store(po::command_line_parser(argc, argv).options(desc).run(), vm);
  if (vm.count("help")) {
    std::cout << desc << "\n";
    return 0;
  }
  po::notify(vm);
  if (mode != "kinematic") {
    throw diag::InputError("--mode: '" + mode +
                           "' is not available; this build simulates the kinematic mode only");
  }
  k.step_rad = diag::units::deg_to_rad(step_deg);
  k.runout_output_rad = diag::units::deg_to_rad(runout_deg);
  k.mesh_te_output_rad = diag::units::deg_to_rad(te_deg);
  k.noise_output_rad = diag::units::deg_to_rad(noise_deg);
  const diag::Gearbox gb = diag::load_gearbox(gearbox);
  const sim::KinematicResult r = sim::simulate_kinematic(gb, k);
  const std::filesystem::path out(output);
  if (out.extension() == ".csv") {
    write_angles_csv(out, r);
  } else {
    diag::write_recording(out, sim::to_recording(gb, r));
  }
  std::cout << "simulated " << r.input_angle_rad.size() << " samples over "
            << r.truth["revolutions"].get<double>() << " input revolutions, "
            << gb.defects().size() << " defect(s) -> " << output << "\n";
  return 0;
}

}  // namespace geardiag
