// Streaming analysis of one channel of a recording on disk: the Welch PSD and the time-domain
// moments computed block by block, so a recording larger than memory (a 4 GB HDF5 file) is
// analysed in O(block_samples + nperseg + nfft) memory.
//
// The channel is read with diag::RecordingReader::read_block in blocks of block_samples, in
// order; each block is pushed into a detect::WelchAccumulator (welch.hpp: bit-identical to
// detect::welch on the whole record, whatever the blocking) and added to a
// detect::MomentAccumulator (indicators.hpp: Pebay's pairwise update of exact per-block central
// sums, equal to detect::moments up to round-off). The result is what welch() and moments()
// give on the channel loaded in one go.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "detect/indicators/indicators.hpp"
#include "detect/spectral/welch.hpp"
#include "diag/io/hdf5.hpp"

namespace detect {

struct StreamingOptions {
  WelchOptions welch;  // PSD parameters; welch.fs_hz is ignored and set to
                       // the channel's sampling rate
  std::size_t block_samples = std::size_t{1} << 20;  // samples read per block [samples],
                                                     // [1, 2^27] (8 MiB of doubles by default)

  // Throws diag::InputError "analyze_streaming: <field>: ..." (the Welch fields through
  // WelchOptions::validate).
  void validate() const;
};

struct StreamingSummary {
  std::string channel;        // as found in the recording ("signals" group first, then "tacho")
  double fs_hz = 0;           // the channel's sampling rate [Hz]
  std::uint64_t samples = 0;  // samples read (the channel's length)
  std::uint64_t blocks = 0;   // read_block calls made
  Psd psd;                    // Welch PSD of the whole channel
  Moments moments;            // mean, central sums, min, max of the whole channel
};

// Reads `channel` of `reader` from start to end in blocks. Throws diag::InputError for bad
// options, an unknown channel, a channel shorter than welch.nperseg, or a non-finite sample
// (from read_block, naming the file, the channel and the sample index).
StreamingSummary analyze_streaming(diag::RecordingReader& reader, const std::string& channel,
                                   const StreamingOptions& options);

}  // namespace detect
