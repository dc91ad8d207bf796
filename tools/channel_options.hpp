// The options that say what a measured file's channels are, shared by `import`, `analyze` and
// `batch`: --channels MAP.json, --tacho CHANNEL=SHAFT[:PPR] (repeatable) and --rpm, applied by
// diag::prepare_channels and diag::gearbox_at_speed (diag/io/channel_setup.hpp).
#pragma once

#include <boost/program_options.hpp>
#include <optional>
#include <string>
#include <vector>

#include "diag/io/channel_setup.hpp"

namespace geardiag {

// The CLI's face of diag::ChannelSetup (diag/io/channel_setup.hpp): the options that fill it.
struct ChannelOptions : diag::ChannelSetup {
  void add_to(boost::program_options::options_description& desc, bool with_rpm);
};

}  // namespace geardiag
