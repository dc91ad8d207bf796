// What the user says about a recording's channels and speed, applied before any analysis: a
// channel map file, tachos named one by one, and the input shaft's speed. Shared by every caller
// that prepares a recording (`geardiag analyze`, `batch`, `import`, the Python module) through
// the channel contract (channels.hpp).
#pragma once

#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace diag {

struct ChannelSetup {
  std::string channel_map;  // a channel map file (channels.hpp); empty: none
  std::vector<std::string>
      tachos;      // "CHANNEL=SHAFT[:PPR]", each a tacho of SHAFT (parse_tacho_option)
  double rpm = 0;  // the input shaft's speed [rpm], (0, kMaxSpeedRpm]; 0: not given
};

// Applies the channel map and the tachos (a tacho named by both: the tacho option wins), then
// infers the tachos of channels nobody described (infer_tachos). Returns the notes to report: the
// recording's own (rec.notes) followed by the inference's. Throws InputError naming the option
// ("--tacho") or the map file and the entry.
std::vector<std::string> prepare_channels(Recording& rec, const Gearbox* gb,
                                          const ChannelSetup& setup);

// The gearbox at the speed the data says, with a note: setup.rpm, else the speed recorded with the
// file (Recording::speed_rpm, e.g. CWRU's X105RPM), else the description's own. Throws InputError
// for a speed out of range ("--rpm").
Gearbox gearbox_at_speed(const Gearbox& gb, const Recording& rec, const ChannelSetup& setup,
                         std::vector<std::string>& notes);

}  // namespace diag
