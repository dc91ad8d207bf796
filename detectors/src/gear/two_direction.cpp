#include "detect/gear/two_direction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "diag/error.hpp"

namespace detect {

void TwoDirectionOptions::validate() const {
  if (mesh_harmonics < 1 || mesh_harmonics > 50) {
    throw diag::InputError("two_direction: mesh_harmonics: " + std::to_string(mesh_harmonics) +
                           " is not in [1, 50]");
  }
  if (!(halfwidth_hz >= 0) || !std::isfinite(halfwidth_hz)) {
    throw diag::InputError("two_direction: halfwidth_hz: " + std::to_string(halfwidth_hz) +
                           " is not finite and >= 0");
  }
}

double band_mean_square(const SpectrumView& s, double enbw_bins, double low_hz, double high_hz) {
  const auto& f = s.frequency_hz;
  auto first = std::lower_bound(f.begin(), f.end(), low_hz);
  auto last = std::upper_bound(f.begin(), f.end(), high_hz);
  double sum = 0;
  for (auto it = first; it < last; ++it) {
    const double a = s.value[static_cast<std::size_t>(it - f.begin())];
    sum += a * a;
  }
  return sum / (2.0 * enbw_bins);
}

TwoDirectionComparison compare_two_directions(const SpectrumView& along, const SpectrumView& normal,
                                              double enbw_bins, double mesh_hz,
                                              const TwoDirectionOptions& opt) {
  opt.validate();
  along.validate("compare_two_directions: along");
  normal.validate("compare_two_directions: normal");
  if (!(enbw_bins > 0) || !std::isfinite(enbw_bins)) {
    throw diag::InputError("compare_two_directions: enbw_bins: " + std::to_string(enbw_bins) +
                           " is not finite and > 0");
  }
  if (!(mesh_hz > 0) || !std::isfinite(mesh_hz)) {
    throw diag::InputError("compare_two_directions: mesh_hz: " + std::to_string(mesh_hz) +
                           " is not finite and > 0");
  }
  auto bin_of = [](const SpectrumView& s) {
    return (s.frequency_hz.back() - s.frequency_hz.front()) /
           static_cast<double>(s.frequency_hz.size() - 1);
  };
  const double bin = std::max(bin_of(along), bin_of(normal));
  TwoDirectionComparison r;
  r.mesh_hz = mesh_hz;
  int valid = 0;
  for (int h = 1; h <= opt.mesh_harmonics; ++h) {
    HarmonicEnergy e;
    e.harmonic = h;
    e.frequency_hz = h * mesh_hz;
    const double w =
        opt.halfwidth_hz > 0 ? opt.halfwidth_hz : std::max(4.0 * bin, 0.01 * e.frequency_hz);
    const double lo = e.frequency_hz - w, hi = e.frequency_hz + w;
    e.valid = lo >= along.frequency_hz.front() && hi <= along.frequency_hz.back() &&
              lo >= normal.frequency_hz.front() && hi <= normal.frequency_hz.back();
    if (e.valid) {
      e.along = band_mean_square(along, enbw_bins, lo, hi);
      e.normal = band_mean_square(normal, enbw_bins, lo, hi);
      r.along_energy += e.along;
      r.normal_energy += e.normal;
      ++valid;
    }
    r.harmonics.push_back(e);
  }
  if (valid == 0 || (r.along_energy == 0 && r.normal_energy == 0)) {
    r.normal_to_along_db = std::numeric_limits<double>::quiet_NaN();
  } else if (r.along_energy == 0) {
    r.normal_to_along_db = kMaxProminenceDb;
  } else if (r.normal_energy == 0) {
    r.normal_to_along_db = -kMaxProminenceDb;
  } else {
    r.normal_to_along_db = std::clamp(10.0 * std::log10(r.normal_energy / r.along_energy),
                                      -kMaxProminenceDb, kMaxProminenceDb);
  }
  return r;
}

}  // namespace detect
