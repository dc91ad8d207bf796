// analyze's spectral helpers (detectors/src/analysis/stages.hpp) against their plain definitions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "../../detectors/src/analysis/stages.hpp"

namespace {

// The plain definition: every local maximum a[k] > a[k-1], a[k] >= a[k+1] of bins 1 .. n-2 up to
// max_hz, sorted by descending amplitude, equal amplitudes by ascending frequency, the first
// `count`.
std::vector<detect::SpectralPeak> plain_peaks(const detect::Spectrum& s, int count, double max_hz) {
  std::vector<detect::SpectralPeak> c;
  const auto& a = s.amplitude;
  for (std::size_t k = 1; k + 1 < a.size(); ++k) {
    if (s.frequency_hz[k] > max_hz) break;
    if (a[k] > a[k - 1] && a[k] >= a[k + 1]) c.push_back({s.frequency_hz[k], a[k]});
  }
  std::stable_sort(c.begin(), c.end(),
                   [](const auto& l, const auto& r) { return l.amplitude > r.amplitude; });
  c.resize(std::min<std::size_t>(c.size(), static_cast<std::size_t>(std::max(count, 0))));
  return c;
}

// On noise (a third of the bins are local maxima), on quantised noise (many equal amplitudes,
// plateaus), with every count from 0 to past the number of maxima and several limits: the same
// peaks in the same order.
TEST(LargestPeaks, MatchesTheFullSortOfEveryLocalMaximum) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  for (int quantised = 0; quantised < 2; ++quantised) {
    for (std::size_t n : {0u, 1u, 2u, 3u, 5u, 100u, 4001u}) {
      detect::Spectrum s;
      for (std::size_t k = 0; k < n; ++k) {
        const double v = std::abs(g(rng));
        s.frequency_hz.push_back(0.5 * static_cast<double>(k));
        s.amplitude.push_back(quantised ? std::round(4 * v) : v);
      }
      for (int count : {0, 1, 3, 8, 100, 5000}) {
        for (double max_hz : {0.0, 1.0, 37.25, 1e9}) {
          const auto got = detect::analysis_stages::largest_peaks(s, count, max_hz);
          const auto want = plain_peaks(s, count, max_hz);
          ASSERT_EQ(got.size(), want.size()) << n << " " << count << " " << max_hz;
          for (std::size_t i = 0; i < got.size(); ++i) {
            EXPECT_EQ(got[i].frequency_hz, want[i].frequency_hz) << n << " " << count << " " << i;
            EXPECT_EQ(got[i].amplitude, want[i].amplitude);
          }
        }
      }
    }
  }
}

}  // namespace
