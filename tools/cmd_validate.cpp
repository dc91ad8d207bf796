// geardiag validate --attribution: the closed simulate -> attribute loop on the user's gearbox,
// with the user's rig (runout, noise, encoder); prints the confusion table and the smallest defect
// that is reliably attributed. Exit 1 when the loop misses its targets. --gear-damage and
// --bearings run their own loops (validate_gear_damage.hpp, validate_bearings.hpp).
#include <boost/program_options.hpp>
#include <iostream>
#include <iterator>
#include <string>

#include "cli_options.hpp"
#include "commands.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/units.hpp"
#include "parallel.hpp"
#include "validate/attribution_loop.hpp"
#include "validate_bearings.hpp"
#include "validate_dataset.hpp"
#include "validate_gear_damage.hpp"

namespace po = boost::program_options;
using diag::units::deg_to_rad;
using diag::units::rad_to_deg;

namespace geardiag {

int cmd_validate(int argc, char** argv) {
  // --gear-damage and --bearings: their own loops and options (validate_gear_damage.cpp,
  // validate_bearings.cpp).
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--gear-damage") return validate_gear_damage(argc, argv);
    if (std::string(argv[i]) == "--bearings") return cmd_validate_bearings(argc, argv);
    if (std::string(argv[i]) == "--dataset") return validate_dataset(argc, argv);
    if (std::string(argv[i]) == "--history") return validate_history(argc, argv);
  }
  validate::AttributionLoopOptions opt;
  std::string gearbox;
  double min_deg = rad_to_deg(opt.min_size_output_rad),
         max_deg = rad_to_deg(opt.max_size_output_rad);
  double runout_deg = rad_to_deg(opt.runout_output_rad),
         te_deg = rad_to_deg(opt.mesh_te_output_rad);
  double noise_deg = rad_to_deg(opt.noise_output_rad);
  int ladder_cases = 40;
  po::options_description desc(
      "geardiag validate --attribution --gearbox GB.json [options]\n\n"
      "Simulates random sporadic defects (0-3, on different and on the same shafts) on your\n"
      "gearbox with your rig's runout, noise and encoder, attributes them, and compares with the\n"
      "truth. Prints the confusion table and the smallest defect reliably attributed.\n\noptions");
  desc.add_options()("help,h", "this help")("attribution", "validate defect attribution")(
      "gearbox", po::value(&gearbox)->required(), "gearbox description (JSON)")(
      "cases", po::value(&opt.cases)->default_value(opt.cases), "random cases")(
      "seed", po::value(&opt.seed)->default_value(opt.seed), "random seed")(
      "min-size-deg", po::value(&min_deg)->default_value(min_deg),
      "smallest defect at the output [deg]")("max-size-deg",
                                             po::value(&max_deg)->default_value(max_deg),
                                             "largest defect at the output [deg]")(
      "runout-deg", po::value(&runout_deg)->default_value(runout_deg),
      "runout at the output [deg]")("mesh-te-deg", po::value(&te_deg)->default_value(te_deg),
                                    "mesh TE at the output [deg]")(
      "noise-deg", po::value(&noise_deg)->default_value(noise_deg), "angle noise RMS [deg]")(
      "encoder-counts",
      po::value(&opt.encoder_counts_per_rev)->default_value(opt.encoder_counts_per_rev),
      "encoder counts per revolution (0 = exact angles)")(
      "ladder-cases", po::value(&ladder_cases)->default_value(ladder_cases),
      "single-defect cases per size when searching the smallest reliable size (0 = skip)");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  if (!vm.count("attribution"))
    throw diag::InputError(
        "say what to validate: --attribution, --gear-damage, --bearings, --dataset or --history");
  if (opt.cases < 1) throw diag::InputError("--cases: must be >= 1");
  if (!(min_deg > 0 && max_deg >= min_deg)) {
    throw diag::InputError("--min-size-deg/--max-size-deg: need 0 < min <= max");
  }
  if (runout_deg < 0 || te_deg < 0 || noise_deg < 0) {
    throw diag::InputError("--runout-deg/--mesh-te-deg/--noise-deg: must be >= 0");
  }
  opt.min_size_output_rad = deg_to_rad(min_deg);
  opt.max_size_output_rad = deg_to_rad(max_deg);
  opt.runout_output_rad = deg_to_rad(runout_deg);
  opt.mesh_te_output_rad = deg_to_rad(te_deg);
  opt.noise_output_rad = deg_to_rad(noise_deg);
  const diag::Gearbox gb = diag::load_gearbox(gearbox);
  if (gb.power_path().empty()) {
    throw diag::InputError(
        gearbox + ": no mesh between the input and the output shaft: nothing to attribute");
  }
  // Progress on a terminal's stderr (parallel.hpp): the loop and the ladder take minutes.
  validate::LoopReport r;
  {
    Progress progress("validate --attribution", static_cast<std::size_t>(opt.cases), true);
    opt.on_case_done = [&] { progress.tick(); };
    r = validate::run_attribution_loop(gb, opt);
  }
  std::cout << validate::format_report(r) << std::flush;
  if (ladder_cases > 0) {
    std::vector<std::pair<double, double>> ladder;
    // The count is the whole ladder's; it stops early at the first size that is not reliable.
    Progress progress("validate --attribution, size ladder",
                      std::size(validate::kSizeLadderDeg) * static_cast<std::size_t>(ladder_cases),
                      true);
    opt.on_case_done = [&] { progress.tick(); };
    const double smallest = validate::smallest_reliable_size(gb, opt, ladder_cases, 0.95, &ladder);
    progress.finish();
    std::cout << "\nsingle defect, share attributed right with size within "
              << 100 * opt.size_tolerance << " %, by size at the output:\n";
    for (const auto& [size, share] : ladder) {
      std::cout << "  " << rad_to_deg(size) << " deg: " << 100 * share << " %\n";
    }
    if (smallest > 0) {
      std::cout << "smallest defect reliably attributed (>= 95 %): " << rad_to_deg(smallest)
                << " deg at the output shaft\n";
    } else {
      std::cout << "no size on the ladder is attributed reliably (>= 95 %) with this rig\n";
    }
  }
  const bool ok = r.single_correct >= 0.98 * r.single_total &&
                  r.two_defects_attributed >= 0.95 * (r.two_defects_total - r.two_defects_hidden) &&
                  r.healthy_clean == r.healthy_total;
  return ok ? 0 : 1;
}

}  // namespace geardiag
