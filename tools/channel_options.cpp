#include "channel_options.hpp"

#include <cmath>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/channels.hpp"
#include "diag/util/number_format.hpp"

namespace po = boost::program_options;

namespace geardiag {

void ChannelOptions::add_to(po::options_description& desc, bool with_rpm) {
  desc.add_options()("channels", po::value(&channel_map)->value_name("MAP.json"),
                     "channel map: what each channel is (role, unit, direction, location, shaft, "
                     "mesh, ppr; README \"Channel maps\")")(
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

std::vector<std::string> prepare_channels(diag::Recording& rec, const diag::Gearbox* gb,
                                          const ChannelOptions& opt) {
  diag::ChannelMap map;
  if (!opt.channel_map.empty()) map = diag::load_channel_map(opt.channel_map);
  for (const std::string& t : opt.tachos) {
    diag::ChannelMapEntry e = diag::parse_tacho_option(t, "--tacho");
    std::erase_if(map.channels, [&](const diag::ChannelMapEntry& m) { return m.name == e.name; });
    map.channels.push_back(std::move(e));
  }
  const std::string where =
      opt.channel_map.empty() ? std::string("--tacho") : opt.channel_map + " / --tacho";
  diag::apply_channel_map(rec, map, gb, where);
  std::vector<std::string> described;
  for (const auto& e : map.channels) described.push_back(e.name);
  std::vector<std::string> notes = rec.notes;
  for (std::string& n : diag::infer_tachos(rec, gb, described)) notes.push_back(std::move(n));
  return notes;
}

diag::Gearbox gearbox_at_speed(const diag::Gearbox& gb, const diag::Recording& rec,
                               const ChannelOptions& opt, std::vector<std::string>& notes) {
  const double nominal = gb.input().speed_rpm;
  if (opt.rpm != 0) {
    if (!(opt.rpm > 0) || !std::isfinite(opt.rpm) || opt.rpm > 1e6) {
      throw diag::InputError("--rpm: " + diag::format_significant(opt.rpm, 6) +
                             " is not a speed in (0, 1e6] rpm");
    }
    notes.push_back("input speed " + diag::format_significant(opt.rpm, 6) +
                    " rpm from --rpm (description: " + diag::format_significant(nominal, 6) +
                    " rpm)");
    return gb.with_input_speed_rpm(opt.rpm);
  }
  if (rec.speed_rpm > 0) {
    notes.push_back("input speed " + diag::format_significant(rec.speed_rpm, 6) +
                    " rpm recorded with the file " +
                    "(description: " + diag::format_significant(nominal, 6) + " rpm)");
    return gb.with_input_speed_rpm(rec.speed_rpm);
  }
  return gb;
}

}  // namespace geardiag
