// Welch PSD speed on one core: 10^7 samples of Gaussian noise (fixed seed), nperseg 4096, 50 %
// overlap, Hann, constant detrend - the parameters bench/peer_welch.py gives scipy.signal.welch,
// so the two samples/s figures compare as a ratio on the same machine.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <random>
#include <vector>

#include "detect/spectral/welch.hpp"

namespace {

const std::vector<double>& noise(std::int64_t samples) {
  static std::map<std::int64_t, std::vector<double>> cache;
  auto it = cache.find(samples);
  if (it != cache.end()) return it->second;
  std::mt19937_64 rng(20240601);
  std::normal_distribution<double> g;
  std::vector<double> x(static_cast<std::size_t>(samples));
  for (double& v : x) v = g(rng);
  return cache.emplace(samples, std::move(x)).first->second;
}

detect::WelchOptions options() {
  detect::WelchOptions o;
  o.fs_hz = 1.0;
  o.nperseg = 4096;  // noverlap -1: 2048
  return o;
}

void BM_Welch(benchmark::State& state) {
  const auto& x = noise(state.range(0));
  for (auto _ : state) {
    auto psd = detect::welch(x, options());
    benchmark::DoNotOptimize(psd.value.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Welch)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

// The streaming accumulator fed 1 MiB chunks (131072 samples), as a file reader would.
void BM_WelchStreaming(benchmark::State& state) {
  const auto& x = noise(state.range(0));
  const std::size_t chunk = 131072;
  detect::WelchAccumulator acc(options());
  for (auto _ : state) {
    acc.reset();
    for (std::size_t pos = 0; pos < x.size(); pos += chunk)
      acc.push(std::span<const double>(x).subspan(pos, std::min(chunk, x.size() - pos)));
    auto psd = acc.result();
    benchmark::DoNotOptimize(psd.value.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_WelchStreaming)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
