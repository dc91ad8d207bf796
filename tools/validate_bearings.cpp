// geardiag validate --bearings [options]: simulates bearing faults of every class from the bearing
// kinematics (sim/bearing/bearing_signal.hpp) on a grid of speeds, sizes and SNRs, diagnoses them
// and prints right / silent / wrong by class and SNR.
#include "validate_bearings.hpp"

#include <algorithm>
#include <boost/program_options.hpp>
#include <iostream>
#include <sstream>

#include "cli_options.hpp"
#include "diag/error.hpp"
#include "parallel.hpp"
#include "validate/bearing_loop.hpp"

namespace po = boost::program_options;

namespace geardiag {

namespace {

std::vector<double> parse_list(const std::string& s, const std::string& option) {
  std::vector<double> v;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw diag::InputError("--" + option + ": '" + item + "' is not a number");
    }
  }
  if (v.empty()) throw diag::InputError("--" + option + ": empty list");
  return v;
}

std::string join(const std::vector<double>& v) {
  std::ostringstream o;
  for (std::size_t i = 0; i < v.size(); ++i) o << (i ? "," : "") << v[i];
  return o.str();
}

}  // namespace

int cmd_validate_bearings(int argc, char** argv) {
  validate::BearingLoopOptions opt;
  std::string speeds = join(opt.shaft_hz), sizes = join(opt.sizes), snrs = join(opt.snr_db);
  po::options_description desc(
      "geardiag validate --bearings [options]\n\n"
      "Simulates outer-race, inner-race, rolling-element and cage faults and healthy bearings\n"
      "(CWRU's SKF 6205, 12 kHz) from the bearing kinematics, with load-zone modulation, slip,\n"
      "a structural resonance, shaft and gear-mesh interference and noise; diagnoses each and\n"
      "prints right / silent / wrong by fault class and SNR.\n\noptions");
  desc.add_options()("help,h", "this help")("bearings", "validate the bearing diagnosis")(
      "speeds", po::value(&speeds)->default_value(speeds), "shaft speeds [Hz], comma-separated")(
      "sizes", po::value(&sizes)->default_value(sizes),
      "impact amplitudes (fault sizes; shaft and mesh interference at 2), comma-separated")(
      "snr", po::value(&snrs)->default_value(snrs), "fault-over-noise power [dB], comma-separated")(
      "cases", po::value(&opt.seeds)->default_value(opt.seeds), "seeds per grid point")(
      "seed", po::value(&opt.first_seed)->default_value(opt.first_seed), "first seed")(
      "duration", po::value(&opt.duration_s)->default_value(opt.duration_s), "record length [s]");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  opt.shaft_hz = parse_list(speeds, "speeds");
  opt.sizes = parse_list(sizes, "sizes");
  opt.snr_db = parse_list(snrs, "snr");
  // Progress on a terminal's stderr (parallel.hpp): one case per class, speed, size, SNR and seed.
  Progress progress("validate --bearings",
                    opt.classes.size() * opt.shaft_hz.size() * opt.sizes.size() *
                        opt.snr_db.size() * static_cast<std::size_t>(std::max(opt.seeds, 0)),
                    true);
  opt.on_case_done = [&] { progress.tick(); };
  const validate::BearingLoopReport r = validate::run_bearing_loop(opt);
  progress.finish();
  std::cout << validate::format_report(r);
  int wrong = 0;
  for (const auto& c : r.by_class) wrong += c.wrong;
  return wrong == 0 ? 0 : 1;
}

}  // namespace geardiag
