// analyze's per-channel spectrogram for the report (stages.hpp; SpectrogramTrace in analyze.hpp).
#include <algorithm>
#include <cmath>

#include "detect/spectral/welch.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

void spectrogram_stage(ChannelWork& w) {
  const diag::Signal& sig = w.signal;
  ChannelAnalysis& c = w.out;
  const std::size_t nperseg = 2 * kSpectrogramRows;
  const std::size_t n = sig.samples.size();
  const std::size_t columns = std::min(kSpectrogramColumns, n / nperseg);
  if (columns < 2) return;  // shorter than two segments: nothing to show over time
  // Each span's column is the Welch PSD of the span (the mean of its segments' periodograms, as
  // the spectrogram's PSD mode gives them, analyze.hpp), from one accumulator reused across the
  // spans: one window, one transform, no per-span allocation of segments.
  WelchOptions wo;
  wo.fs_hz = sig.fs_hz;
  wo.nperseg = nperseg;
  WelchAccumulator acc(wo);
  SpectrogramTrace& t = c.spectrogram;
  t.psd_db.reserve(columns * (nperseg / 2 + 1));
  const std::span<const double> x(sig.samples);
  for (std::size_t j = 0; j < columns; ++j) {
    // Span j: samples [j n / columns, (j + 1) n / columns), at least nperseg long.
    const std::size_t b = j * n / columns, e = (j + 1) * n / columns;
    acc.reset();
    acc.push(x.subspan(b, e - b));
    const Psd p = acc.result();
    if (j == 0) t.frequency_hz = p.frequency_hz;
    t.psd_db.insert(t.psd_db.end(), p.value.begin(), p.value.end());
    t.time_s.push_back(0.5 * static_cast<double>(b + e) / sig.fs_hz);
  }
  const double top = *std::max_element(t.psd_db.begin(), t.psd_db.end());
  const double floor_db = top > 0 ? 10 * std::log10(top) - 200 : -300;
  for (double& v : t.psd_db) v = v > 0 ? std::max(10 * std::log10(v), floor_db) : floor_db;
}

}  // namespace detect::analysis_stages
