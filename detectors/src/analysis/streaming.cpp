#include "detect/analysis/streaming.hpp"

#include <algorithm>
#include <span>
#include <vector>

#include "diag/error.hpp"

namespace detect {
namespace {

constexpr std::size_t kMaxBlockSamples = std::size_t{1} << 27;  // 1 GiB of doubles

}  // namespace

void StreamingOptions::validate() const {
  if (block_samples < 1 || block_samples > kMaxBlockSamples) {
    throw diag::InputError(diag::format_error("analyze_streaming", "block_samples",
                                              std::to_string(block_samples) + " is not in [1, " +
                                                  std::to_string(kMaxBlockSamples) + "]"));
  }
  welch.validate();
}

StreamingSummary analyze_streaming(diag::RecordingReader& reader, const std::string& channel,
                                   const StreamingOptions& options) {
  options.validate();
  const diag::ChannelInfo& info = reader.channel(channel);
  if (info.length < options.welch.nperseg) {
    throw diag::InputError(diag::format_error(
        "analyze_streaming", "channel '" + channel + "'",
        std::to_string(info.length) +
            " samples is shorter than welch.nperseg = " + std::to_string(options.welch.nperseg)));
  }
  WelchOptions welch = options.welch;
  welch.fs_hz = info.fs_hz;
  WelchAccumulator psd(welch);
  MomentAccumulator moments;

  // Read by the explicit "group/name" so a signal and a tacho of the same name cannot mix.
  const std::string path = info.group + "/" + info.name;
  const std::size_t block =
      static_cast<std::size_t>(std::min<std::uint64_t>(options.block_samples, info.length));
  std::vector<double> buffer(block);
  StreamingSummary out;
  out.channel = path;
  out.fs_hz = info.fs_hz;
  for (std::uint64_t offset = 0; offset < info.length; offset += block) {
    const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(block, info.length - offset));
    const std::span<double> chunk(buffer.data(), n);
    reader.read_block(path, offset, chunk);
    psd.push(chunk);
    moments.add(chunk);
    ++out.blocks;
  }
  out.samples = info.length;
  out.psd = psd.result();
  out.moments = moments.result();
  return out;
}

}  // namespace detect
