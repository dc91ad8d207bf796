// Welch PSD speed on one core: 10^7 samples of Gaussian noise (fixed seed), nperseg 4096, 50 %
// overlap, Hann, constant detrend - the parameters bench/peer_welch.py gives scipy.signal.welch,
// so the two samples/s figures compare as a ratio on the same machine.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include "bench_data.hpp"
#include "detect/spectral/welch.hpp"

namespace {

using bench_data::noise;
using bench_data::welch_options;

void BM_Welch(benchmark::State& state) {
  const auto& x = noise(state.range(0));
  for (auto _ : state) {
    auto psd = detect::welch(x, welch_options());
    benchmark::DoNotOptimize(psd.value.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Welch)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

// The streaming accumulator fed 1 MiB chunks (131072 samples), as a file reader would.
void BM_WelchStreaming(benchmark::State& state) {
  const auto& x = noise(state.range(0));
  const std::size_t chunk = 131072;
  detect::WelchAccumulator acc(welch_options());
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
