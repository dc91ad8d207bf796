// Analysis speed on one core over 10^7 samples of Gaussian noise (fixed seed; the same length and
// parameters bench/peer_analysis.py gives scipy): the Welch PSD (nperseg 4096, 50 % overlap, Hann,
// constant detrend, density) and the time-domain statistics (mean, variance, skewness, kurtosis,
// min, max, RMS, crest factor) by detect::moments (two passes) and detect::MomentAccumulator
// (1 MiB chunks, as a file reader feeds it), and both together: items_per_second = samples/s.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <span>
#include <vector>

#include "bench_data.hpp"
#include "detect/indicators/indicators.hpp"
#include "detect/spectral/welch.hpp"

namespace {

using bench_data::noise;
using bench_data::welch_options;

constexpr std::size_t kChunk = 131072;  // 1 MiB of doubles

// Everything a condition report reads from the moments: forces their evaluation.
double statistics(const detect::Moments& m) {
  return m.mean + m.variance() + m.skewness() + m.kurtosis() + m.rms() + m.crest_factor() +
         m.peak_to_peak();
}

void BM_Moments(benchmark::State& state) {
  const auto& x = noise(state.range(0));
  for (auto _ : state) {
    const detect::Moments m = detect::moments(x);
    benchmark::DoNotOptimize(statistics(m));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Moments)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

void BM_MomentAccumulator(benchmark::State& state) {
  const auto& x = noise(state.range(0));
  for (auto _ : state) {
    detect::MomentAccumulator acc;
    for (std::size_t pos = 0; pos < x.size(); pos += kChunk)
      acc.add(std::span<const double>(x).subspan(pos, std::min(kChunk, x.size() - pos)));
    benchmark::DoNotOptimize(statistics(acc.result()));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_MomentAccumulator)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

void BM_WelchPsd(benchmark::State& state) {
  const auto& x = noise(state.range(0));
  for (auto _ : state) {
    auto psd = detect::welch(x, welch_options());
    benchmark::DoNotOptimize(psd.value.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_WelchPsd)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

// Welch + moments in one chunked pass: what analyze_streaming does after reading each block.
void BM_WelchAndMomentsChunked(benchmark::State& state) {
  const auto& x = noise(state.range(0));
  detect::WelchAccumulator psd(welch_options());
  for (auto _ : state) {
    psd.reset();
    detect::MomentAccumulator acc;
    for (std::size_t pos = 0; pos < x.size(); pos += kChunk) {
      const auto chunk = std::span<const double>(x).subspan(pos, std::min(kChunk, x.size() - pos));
      psd.push(chunk);
      acc.add(chunk);
    }
    auto p = psd.result();
    benchmark::DoNotOptimize(p.value.data());
    benchmark::DoNotOptimize(statistics(acc.result()));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_WelchAndMomentsChunked)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
