// analyze's per-channel spectrogram for the report (stages.hpp; SpectrogramTrace in analyze.hpp).
#include <algorithm>
#include <cmath>

#include "detect/spectral/spectrogram.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

void spectrogram_stage(const diag::Signal& sig, ChannelAnalysis& c) {
  const std::size_t nperseg = 2 * kSpectrogramRows;
  const std::size_t n = sig.samples.size();
  const std::size_t columns = std::min(kSpectrogramColumns, n / nperseg);
  if (columns < 2) return;  // shorter than two segments: nothing to show over time
  SpectrogramOptions so;
  so.fs_hz = sig.fs_hz;
  so.nperseg = nperseg;
  SpectrogramTrace& t = c.spectrogram;
  const std::span<const double> x(sig.samples);
  for (std::size_t j = 0; j < columns; ++j) {
    // Span j: samples [j n / columns, (j + 1) n / columns), at least nperseg long.
    const std::size_t b = j * n / columns, e = (j + 1) * n / columns;
    const Spectrogram s = spectrogram(x.subspan(b, e - b), so);
    if (j == 0) t.frequency_hz = s.frequency_hz;
    const std::size_t bins = s.frequency_hz.size(), segs = s.time_s.size();
    for (std::size_t k = 0; k < bins; ++k) {
      double mean = 0;
      for (std::size_t m = 0; m < segs; ++m) mean += s.at(m, k);
      t.psd_db.push_back(mean / static_cast<double>(segs));
    }
    t.time_s.push_back(0.5 * static_cast<double>(b + e) / sig.fs_hz);
  }
  const double top = *std::max_element(t.psd_db.begin(), t.psd_db.end());
  const double floor_db = top > 0 ? 10 * std::log10(top) - 200 : -300;
  for (double& v : t.psd_db) v = v > 0 ? std::max(10 * std::log10(v), floor_db) : floor_db;
}

}  // namespace detect::analysis_stages
