// geardiag wear: the wear history of one mesh (seed 004 / Archard), worn profiles and the
// transmission error they give, as an HDF5 file.
#include <boost/program_options.hpp>
#include <iomanip>
#include <iostream>

#include "cli_options.hpp"
#include "commands.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/hdf5_arrays.hpp"
#include "output.hpp"
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

}  // namespace

int cmd_wear(int argc, char** argv) {
  sim::WearOptions o;
  std::string gearbox, mesh, out, law = "archard";
  double depth_limit_um = o.depth_limit_m * 1e6;
  po::options_description desc(
      "geardiag wear --gearbox GB.json --mesh DRIVER_DRIVEN --cycles N --steps K\n"
      "              [--law archard|seed004] [--depth-limit-um D] -o OUT.h5\n\n"
      "Wears the mesh's flanks over N driver revolutions in K blocks (README \"Wear\"): each "
      "block\n"
      "wears both flanks by the chosen law at the input torque of the gearbox, then recomputes "
      "load\n"
      "sharing, the loaded contact ratio, the mesh stiffness and the unloaded transmission error "
      "of\n"
      "the worn profiles; the history stops early once a point has worn D deep. Writes "
      "/wear/cycles\n"
      "(K), /wear/<gear>/radius_mm and /wear/<gear>/depth_um (K x points) for both gears,\n"
      "/wear/te_peak_to_peak_rad, /wear/te_harmonics_rad (K x 3), /wear/loaded_contact_ratio,\n"
      "/wear/mesh_stiffness_n_per_m and /wear/max_pressure_mpa (K each).\n\noptions");
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
      "points on each active flank")("output,o", po::value(&out)->required(), "output HDF5 file");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  if (law == "archard") {
    o.law = sim::WearLaw::kArchard;
  } else if (law == "seed004") {
    o.law = sim::WearLaw::kSeed004;
  } else {
    throw diag::InputError(
        diag::format_error("--law", "", "must be archard or seed004 (got '" + law + "')"));
  }
  if (!(o.cycles > 0)) throw diag::InputError(diag::format_error("--cycles", "", "must be > 0"));
  if (o.steps < 1) throw diag::InputError(diag::format_error("--steps", "", "must be >= 1"));
  o.depth_limit_m = depth_limit_um * 1e-6;
  o.validate();
  check_output(out, "--output");
  const diag::Gearbox gb = diag::load_gearbox(gearbox);
  const int mi = find_mesh(gb, mesh, gearbox);
  const sim::WearHistory h = sim::simulate_wear(gb, mi, o);
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
      {"/wear/te_peak_to_peak_rad", {}, h.te_peak_to_peak_rad, "rad (driven gear)"},
      {"/wear/te_harmonics_rad", {k, 3}, harm, "rad (driven gear), mesh harmonics 1..3"},
      {"/wear/loaded_contact_ratio", {}, h.loaded_contact_ratio, ""},
      {"/wear/mesh_stiffness_n_per_m", {}, h.mesh_stiffness_n_per_m, "N/m"},
      {"/wear/max_pressure_mpa", {}, scaled(h.max_pressure_pa, 1e-6), "MPa"}};
  write_hdf5_arrays(out, arrays,
                    {{"creator", "geardiag wear"},
                     {"law", law},
                     {"mesh", mesh},
                     {"gearbox", gb.description_json()},
                     {"stopped_at_depth_limit", h.stopped_at_limit ? "true" : "false"}});
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
