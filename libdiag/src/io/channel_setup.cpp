#include "diag/io/channel_setup.hpp"

#include <algorithm>
#include <cmath>

#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "diag/util/number_format.hpp"

namespace diag {

namespace {

std::string fmt(double v) { return format_significant(v, 6); }

}  // namespace

std::vector<std::string> prepare_channels(Recording& rec, const Gearbox* gb,
                                          const ChannelSetup& setup) {
  ChannelMap map;
  if (!setup.channel_map.empty()) map = load_channel_map(setup.channel_map);
  for (const std::string& t : setup.tachos) {
    ChannelMapEntry e = parse_tacho_option(t, "--tacho");
    std::erase_if(map.channels, [&](const ChannelMapEntry& m) { return m.name == e.name; });
    map.channels.push_back(std::move(e));
  }
  const std::string where =
      setup.channel_map.empty() ? std::string("--tacho") : setup.channel_map + " / --tacho";
  apply_channel_map(rec, map, gb, where);
  std::vector<std::string> described;
  for (const auto& e : map.channels) described.push_back(e.name);
  std::vector<std::string> notes = rec.notes;
  for (std::string& n : infer_tachos(rec, gb, described)) notes.push_back(std::move(n));
  return notes;
}

namespace {
// How far a given speed may be from the one recorded with the data before it is a contradiction.
constexpr double kGivenSpeedTolerance = 0.01;
}  // namespace

Gearbox gearbox_at_speed(const Gearbox& gb, const Recording& rec, const ChannelSetup& setup,
                         std::vector<std::string>& notes) {
  const double nominal = gb.input().speed_rpm;
  if (setup.rpm != 0) {
    if (!(setup.rpm > 0) || !std::isfinite(setup.rpm) || setup.rpm > kMaxSpeedRpm) {
      throw InputError("--rpm: " + fmt(setup.rpm) + " is not a speed in (0, " + fmt(kMaxSpeedRpm) +
                       "] rpm");
    }
    // The speed recorded with the data is a measurement: a --rpm that contradicts it (beyond
    // the 1 % a speed drifts with load) is a warning naming both, and the measurement is used.
    if (rec.speed_rpm > 0 && std::abs(setup.rpm / rec.speed_rpm - 1) > kGivenSpeedTolerance) {
      notes.push_back("warning: --rpm " + fmt(setup.rpm) + " contradicts the input speed " +
                      fmt(rec.speed_rpm) + " rpm recorded with the file (" +
                      fmt(100 * std::abs(setup.rpm / rec.speed_rpm - 1)) +
                      " % apart): the recorded speed is used");
      return gb.with_input_speed_rpm(rec.speed_rpm);
    }
    notes.push_back("input speed " + fmt(setup.rpm) +
                    " rpm from --rpm (description: " + fmt(nominal) + " rpm)");
    return gb.with_input_speed_rpm(setup.rpm);
  }
  if (rec.speed_rpm > 0) {
    notes.push_back("input speed " + fmt(rec.speed_rpm) + " rpm recorded with the file " +
                    "(description: " + fmt(nominal) + " rpm)");
    return gb.with_input_speed_rpm(rec.speed_rpm);
  }
  return gb;
}

}  // namespace diag
