#include "detect/baseline/mesh_harmonic_growth.hpp"

#include <algorithm>
#include <cmath>

#include "detect/spectral/spectrum.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"

namespace detect {

namespace {

const char* const kWhere = "mesh_harmonic_growth";

// A_h, h = 1..harmonics, of one channel (header).
std::vector<double> harmonic_amplitudes(const diag::Signal& s, double mesh_hz,
                                        const MeshHarmonicGrowthOptions& o) {
  if (o.harmonics * mesh_hz >= 0.5 * s.fs_hz) {
    diag::fail(kWhere, "channel " + s.name,
               "harmonic " + std::to_string(o.harmonics) + " of the mesh (" +
                   std::to_string(o.harmonics * mesh_hz) +
                   " Hz) is not below fs / 2 = " + std::to_string(0.5 * s.fs_hz));
  }
  SpectrumOptions so;
  so.fs_hz = s.fs_hz;
  so.window = WindowType::kHann;
  so.remove_mean = true;
  const Spectrum sp = amplitude_spectrum(s.samples, so);
  const auto last = static_cast<long>(sp.amplitude.size()) - 1;
  std::vector<double> a;
  for (int h = 1; h <= o.harmonics; ++h) {
    const long k = std::lround(h * mesh_hz / sp.resolution_hz);
    const long lo = std::clamp(k - o.search_bins, 0L, last);
    const long hi = std::clamp(k + o.search_bins, 0L, last);
    a.push_back(*std::max_element(sp.amplitude.begin() + lo, sp.amplitude.begin() + hi + 1));
  }
  return a;
}

double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

void MeshHarmonicGrowthOptions::validate() const {
  if (harmonics < 1 || harmonics > 20) diag::fail(kWhere, "harmonics", "must be in [1, 20]");
  if (search_bins < 0 || search_bins > 50) diag::fail(kWhere, "search_bins", "must be in [0, 50]");
  if (!(threshold_db > 0) || !std::isfinite(threshold_db))
    diag::fail(kWhere, "threshold_db", "must be > 0");
}

MeshHarmonicGrowth mesh_harmonic_growth(const diag::Recording& rec, double mesh_hz,
                                        std::span<const diag::Recording> baseline,
                                        std::span<const double> baseline_mesh_hz,
                                        const MeshHarmonicGrowthOptions& o) {
  o.validate();
  if (baseline.empty()) diag::fail(kWhere, "baseline", "no recording given");
  if (baseline_mesh_hz.size() != baseline.size()) {
    diag::fail(kWhere, "baseline_mesh_hz",
               std::to_string(baseline_mesh_hz.size()) + " frequencies for " +
                   std::to_string(baseline.size()) + " baseline recordings");
  }
  auto check_hz = [](double f, const std::string& field) {
    if (!(f > 0) || !std::isfinite(f)) diag::fail(kWhere, field, "must be > 0 Hz");
  };
  check_hz(mesh_hz, "mesh_hz");
  for (std::size_t i = 0; i < baseline_mesh_hz.size(); ++i) {
    check_hz(baseline_mesh_hz[i], "baseline_mesh_hz[" + std::to_string(i) + "]");
  }
  MeshHarmonicGrowth out;
  out.threshold_db = o.threshold_db;
  for (std::size_t idx : diag::sensor_channels(rec)) {
    const diag::Signal& s = rec.signals[idx];
    std::vector<const diag::Signal*> theirs;
    for (const auto& b : baseline) {
      if (const diag::Signal* t = b.find(s.name)) theirs.push_back(t);
    }
    if (theirs.size() != baseline.size()) continue;
    const std::vector<double> a = harmonic_amplitudes(s, mesh_hz, o);
    std::vector<std::vector<double>> per_h(a.size());
    for (std::size_t i = 0; i < theirs.size(); ++i) {
      const std::vector<double> b = harmonic_amplitudes(*theirs[i], baseline_mesh_hz[i], o);
      for (std::size_t h = 0; h < b.size(); ++h) per_h[h].push_back(b[h]);
    }
    std::vector<double> ref;
    for (const auto& v : per_h) ref.push_back(median(v));
    if (!(rms(ref) > 0))
      diag::fail(kWhere, "channel " + s.name, "the baseline has no level at the mesh harmonics");
    out.channels.push_back(s.name);
    out.channel_db.push_back(20.0 * std::log10(rms(a) / rms(ref)));
  }
  if (out.channels.empty()) {
    diag::fail(kWhere, "recording", "no vibration channel found in every baseline recording");
  }
  double sum = 0;
  for (double g : out.channel_db) sum += g;
  out.growth_db = sum / static_cast<double>(out.channel_db.size());
  out.flagged = out.growth_db > o.threshold_db;
  return out;
}

}  // namespace detect
