// analyze's whole-record stage (stages.hpp): a long HDF5 recording is analysed on its first part
// (diag::ReadLimits) by every stage that needs one contiguous record (amplitude spectrum and
// sidebands: lines 1/T apart; kurtogram; TSA; order spectra; bearing diagnosis; the locator).
// What is a mean over time is accumulated over the whole file instead, one block at a time, so
// that memory stays that of the excerpt whatever the length:
//   - time indicators from running moments (MomentAccumulator: Pebay 2008's one-pass update,
//     indicators.hpp): RMS, peak, crest factor, kurtosis and skewness of every sample;
//   - the Welch PSD (WelchAccumulator, welch.hpp): the same segments, window and overlap as the
//     excerpt's, over every whole segment of the file (Welch 1967 is itself a mean over
//     segments; a segment is never split by a block boundary);
//   - at a steady speed, the envelope spectrum: the file cut in blocks as long as the excerpt,
//     each demodulated in the band the kurtogram chose on the excerpt, the amplitude spectra
//     averaged (the same frequency grid; the lines of a periodic fault add coherently in every
//     block, the noise floor's scatter shrinks as 1/sqrt(blocks)). The first block is the
//     excerpt, so its spectrum is the excerpt's. At varying speed the envelope and PSD stay the
//     excerpt's (they are order spectra through angle plans of the excerpt's tacho).
// The excerpt's envelope peaks, trace and bearing band metrics are replaced by the averaged
// spectrum's; the bearing diagnosis (its own kurtogram and decision) stays the excerpt's.
#include <mutex>
#include <span>
#include <vector>

#include "detect/indicators/indicators.hpp"
#include "detect/spectral/envelope.hpp"
#include "detect/spectral/welch.hpp"
#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

namespace {

const diag::ChannelInfo* find_signal(const diag::RecordingReader& reader, const std::string& name) {
  for (const diag::ChannelInfo& c : reader.channels()) {
    if (c.group == "signals" && c.name == name) return &c;
  }
  return nullptr;
}

struct WholeChannel {
  std::uint64_t samples = 0;        // read over the whole file
  std::size_t envelope_blocks = 0;  // envelope spectra averaged
};

// One channel of the file: the blocks read in order under `read_lock` (HDF5 calls one at a
// time), the accumulation outside it.
WholeChannel whole_channel(const AnalysisContext& ctx, const diag::RecordingReader& reader,
                           const diag::ChannelInfo& info, std::mutex& read_lock,
                           ChannelAnalysis& c) {
  const AnalyzeOptions& opt = ctx.opt;
  const std::size_t block = c.samples;  // the excerpt's length
  WholeChannel w;
  MomentAccumulator mo;
  const bool spectra = c.vibration && !ctx.order_domain && c.psd_segments > 0;
  std::optional<WelchAccumulator> psd;
  WelchOptions wo;
  wo.fs_hz = info.fs_hz;
  wo.nperseg = welch_segment(opt, block);
  if (spectra && opt.traces) psd.emplace(wo);
  // The envelope stage ran on the excerpt (it sets the band's upper edge, > 0).
  const bool envelope = spectra && c.envelope_high_hz > 0;
  EnvelopeSpectrumOptions eo;
  eo.fs_hz = info.fs_hz;
  eo.band_low_hz = c.envelope_low_hz;
  eo.band_high_hz = c.envelope_high_hz >= 0.5 * info.fs_hz ? 0.0 : c.envelope_high_hz;
  Spectrum env_sum;
  std::vector<double> buffer(block);
  const std::string path = info.group + "/" + info.name;
  for (std::uint64_t offset = 0; offset < info.length; offset += block) {
    const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(block, info.length - offset));
    const std::span<double> x(buffer.data(), n);
    {
      const std::lock_guard<std::mutex> lock(read_lock);
      reader.read_block(path, offset, x);
    }
    mo.add(x);
    if (psd) psd->push(x);
    if (envelope && n == block) {
      Spectrum e = envelope_spectrum(x, eo);
      if (w.envelope_blocks == 0) {
        env_sum = std::move(e);
      } else {
        for (std::size_t k = 0; k < e.amplitude.size(); ++k) env_sum.amplitude[k] += e.amplitude[k];
      }
      ++w.envelope_blocks;
    }
  }
  w.samples = info.length;
  c.time = time_indicators(mo.result());
  if (psd) {
    const Psd p = psd->result();
    c.psd = decimate_for_plot(p.frequency_hz, p.value, ctx.plot_points, Decimation::kMax);
    c.psd_resolution_hz = p.resolution_hz;
    c.psd_segments = p.segments;
  } else if (spectra) {  // only drawn (AnalyzeOptions::traces): its layout over the whole file
    c.psd_resolution_hz = info.fs_hz / static_cast<double>(wo.fft_length());
    c.psd_segments = wo.segments(static_cast<std::size_t>(info.length));
  }
  if (w.envelope_blocks > 0) {
    for (double& a : env_sum.amplitude) a /= static_cast<double>(w.envelope_blocks);
    envelope_results(ctx, env_sum, info.fs_hz, c);
  }
  return w;
}

}  // namespace

void whole_record_stage(const AnalysisContext& ctx, AnalysisResult& r) {
  const std::filesystem::path& file = ctx.opt.whole_recording;
  if (file.empty()) return;
  const diag::RecordingReader reader(file);
  std::mutex read_lock;
  std::vector<WholeChannel> done(r.channels.size());
  diag::parallel_for(r.channels.size(), ctx.opt.threads, [&](std::size_t ci) {
    ChannelAnalysis& c = r.channels[ci];
    const diag::ChannelInfo* info = find_signal(reader, c.name);
    // A channel the file does not hold as read (another rate), or read whole: as it is.
    if (!info || info->fs_hz != c.fs_hz || info->length <= c.samples || c.samples == 0) return;
    done[ci] = whole_channel(ctx, reader, *info, read_lock, c);
  });
  double whole_s = 0, excerpt_s = 0;
  std::size_t channels = 0, blocks = 0, block = 0;
  for (std::size_t ci = 0; ci < done.size(); ++ci) {
    if (done[ci].samples == 0) continue;
    ++channels;
    whole_s = std::max(whole_s, static_cast<double>(done[ci].samples) / r.channels[ci].fs_hz);
    excerpt_s =
        std::max(excerpt_s, static_cast<double>(r.channels[ci].samples) / r.channels[ci].fs_hz);
    if (done[ci].envelope_blocks > blocks) {
      blocks = done[ci].envelope_blocks;
      block = r.channels[ci].samples;
    }
  }
  if (channels == 0) return;
  // At varying speed the PSD and envelope spectra are order spectra through the first part's
  // angle plans: only the indicators cover the whole file.
  std::string note = "whole recording read by blocks (" + fmt(whole_s, 5) + " s, " +
                     std::to_string(channels) + " channels): the time indicators " +
                     (ctx.order_domain ? "cover" : "and Welch PSD cover") + " all of it";
  if (blocks > 0) {
    note += ", the envelope spectra are the mean of " + std::to_string(blocks) + " blocks of " +
            std::to_string(block) + " samples in the band the kurtogram chose on the first part";
  }
  note += std::string("; the ") + (ctx.order_domain ? "PSD, envelope spectra, " : "") +
          "amplitude spectrum, kurtogram, sidebands, order spectrum, TSA, bearing diagnosis and "
          "damaged-shaft locator cover the first " +
          fmt(excerpt_s, 4) + " s";
  r.notes.push_back(note);
}

}  // namespace detect::analysis_stages
