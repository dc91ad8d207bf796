#include "channel_options.hpp"

#include <cmath>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/util/number_format.hpp"

namespace po = boost::program_options;

namespace geardiag {

void ChannelOptions::add_to(po::options_description& desc, bool with_rpm) {
  desc.add_options()("channels", po::value(&channel_map)->value_name("MAP.json"),
                     "channel map: what each channel is (role, unit, direction, location, shaft, "
                     "mesh, ppr; docs/channels.md)")(
      "tacho", po::value(&tachos)->value_name("CHANNEL=SHAFT[:PPR]")->composing(),
      "CHANNEL is the tacho of SHAFT with PPR pulses per revolution (default 1); repeatable");
  if (with_rpm) {
    // Checked when given: 0 is "not given" inside the struct, so --rpm 0 must not pass silently.
    desc.add_options()("rpm", po::value(&rpm)->value_name("RPM")->notifier([](double v) {
      if (!(v > 0) || !std::isfinite(v) || v > diag::kMaxSpeedRpm) {
        throw diag::InputError("--rpm: " + diag::format_significant(v, 6) +
                               " is not a speed in (0, " +
                               diag::format_significant(diag::kMaxSpeedRpm, 6) + "] rpm");
      }
    }),
                       "input shaft speed [rpm], (0, 1e5]: overrides the description's and the "
                       "file's");
  }
}

}  // namespace geardiag
