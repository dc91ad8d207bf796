#include "validate_gear_damage.hpp"

#include <boost/program_options.hpp>
#include <iostream>
#include <string>
#include <vector>

#include "cli_options.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "parallel.hpp"
#include "validate/gear_damage_loop.hpp"

namespace po = boost::program_options;

namespace geardiag {

int validate_gear_damage(int argc, char** argv) {
  validate::GearDamageLoopOptions opt;
  std::vector<std::string> files;
  double min_runout_um = opt.min_runout_m * 1e6, max_runout_um = opt.max_runout_m * 1e6;
  po::options_description desc(
      "geardiag validate --gear-damage --gearbox GB.json [--gearbox GB2.json ...] [options]\n\n"
      "Simulates random tooth faults (root crack, chip, missing tooth, spall) and healthy\n"
      "cases on your gearbox(es), with ISO 1328 pitch errors of a random grade and random\n"
      "runout on every gear, locates the damaged shaft and compares with the truth. Prints\n"
      "right / silent / wrong shaft per fault kind and size, false alarms, and the ROC as the\n"
      "score threshold moves.\n\n"
      "options");
  desc.add_options()("help,h", "this help")("gear-damage", "validate the damaged-shaft locator")(
      "gearbox", po::value(&files)->required(), "gearbox description (JSON), repeatable")(
      "cases", po::value(&opt.cases)->default_value(opt.cases), "random cases")(
      "seed", po::value(&opt.seed)->default_value(opt.seed), "random seed")(
      "healthy-share", po::value(&opt.healthy_share)->default_value(opt.healthy_share),
      "share of healthy cases")(
      "min-grade", po::value(&opt.min_accuracy_grade)->default_value(opt.min_accuracy_grade),
      "lowest ISO 1328 accuracy grade (0: perfect gears)")(
      "max-grade", po::value(&opt.max_accuracy_grade)->default_value(opt.max_accuracy_grade),
      "highest ISO 1328 accuracy grade")("min-runout-um",
                                         po::value(&min_runout_um)->default_value(min_runout_um),
                                         "smallest runout of every gear [um]")(
      "max-runout-um", po::value(&max_runout_um)->default_value(max_runout_um),
      "largest runout of every gear [um]")(
      "min-rpm", po::value(&opt.min_rpm)->default_value(opt.min_rpm), "lowest input speed [rpm]")(
      "max-rpm", po::value(&opt.max_rpm)->default_value(opt.max_rpm), "highest input speed [rpm]")(
      "min-noise", po::value(&opt.min_noise_m_per_s2)->default_value(opt.min_noise_m_per_s2),
      "lowest sensor noise RMS [m/s^2]")(
      "max-noise", po::value(&opt.max_noise_m_per_s2)->default_value(opt.max_noise_m_per_s2),
      "highest sensor noise RMS [m/s^2]")(
      "baseline", po::bool_switch(&opt.baseline),
      "compare each case with a healthy baseline of the same gears (NA4-style)");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  opt.min_runout_m = min_runout_um * 1e-6;
  opt.max_runout_m = max_runout_um * 1e-6;
  opt.validate();
  std::vector<diag::Gearbox> gbs;
  for (const auto& f : files) gbs.push_back(diag::load_gearbox(f));
  // Progress on a terminal's stderr (parallel.hpp): each case is a dynamic simulation.
  Progress progress("validate --gear-damage", static_cast<std::size_t>(opt.cases), true);
  opt.on_case_done = [&] { progress.tick(); };
  const validate::GearDamageLoopReport r = validate::run_gear_damage_loop(gbs, opt);
  progress.finish();
  std::cout << validate::format_report(r);
  const bool ok = r.healthy_false_alarms <= 0.05 * r.healthy_total &&
                  r.faulty_wrong_shaft <= 0.05 * r.faulty_total;
  return ok ? 0 : 1;
}

}  // namespace geardiag
