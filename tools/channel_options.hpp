// The options that say what a measured file's channels are, shared by `import` and `analyze`:
// --channels MAP.json, --tacho CHANNEL=SHAFT[:PPR] (repeatable) and --rpm, applied through the
// channel contract (diag/io/channels.hpp).
#pragma once

#include <boost/program_options.hpp>
#include <optional>
#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace geardiag {

struct ChannelOptions {
  std::string channel_map;          // --channels: a channel map file; empty: none
  std::vector<std::string> tachos;  // --tacho CHANNEL=SHAFT[:PPR]
  double rpm = 0;                   // --rpm: the input shaft's speed [rpm]; 0: not given

  void add_to(boost::program_options::options_description& desc, bool with_rpm);
};

// Applies --channels and --tacho (the latter wins for a channel named by both), then infers the
// tachos of channels nobody described (diag::infer_tachos). Returns the notes to report. Throws
// diag::InputError naming the option or file.
std::vector<std::string> prepare_channels(diag::Recording& rec, const diag::Gearbox* gb,
                                          const ChannelOptions& opt);

// The gearbox at the speed the data says, with a note: --rpm, else the speed recorded with the
// file (Recording::speed_rpm, e.g. CWRU's X105RPM), else the description's own. Throws
// diag::InputError for --rpm out of range.
diag::Gearbox gearbox_at_speed(const diag::Gearbox& gb, const diag::Recording& rec,
                               const ChannelOptions& opt, std::vector<std::string>& notes);

}  // namespace geardiag
