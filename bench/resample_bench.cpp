// Order-tracking resampler speed on one core: resample_by_angle over 10 s at 20 kHz
// (2e5 samples, one channel of the simulated three-shaft recording) of a shaft running up
// 20 -> 30 rev/s, at 256 and 1024 samples per revolution (Z = 16). items_per_second = input
// samples/s per channel.
//   BM_ResampleBefore   the algorithm before the AnglePlan (commit 0b53028), kept here verbatim
//                       as the reference: a search and a Newton per output sample, the kernel
//                       linearly interpolated from a 512-per-zero-crossing table built (8192
//                       Bessel calls) on every call
//   BM_Resample         resample_by_angle(x, fs, pulses, options): builds a plan and applies it
//   BM_MakeAnglePlan    the plan alone
//   BM_ResampleWithPlan one channel through a prebuilt plan
//   BM_ResampleChannels 39 channels through one prebuilt plan (items: all channels' samples)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include "bench_data.hpp"
#include "detect/angular/resample.hpp"

namespace {

constexpr double kFs = 20e3;
constexpr double kDuration = 10.0;
constexpr int kChannels = 39;

// Pulses of a shaft at 20 rev/s accelerating at 1 rev/s^2 from t = 0.
std::vector<double> pulses() {
  std::vector<double> t;
  const double f0 = 20, a = 1;
  for (int k = 1;; ++k) {
    const double tk = (-f0 + std::sqrt(f0 * f0 + 2 * a * k)) / a;
    if (tk > kDuration) break;
    t.push_back(tk);
  }
  return t;
}

std::span<const double> channel(int c) {
  const auto& x = bench_data::noise(static_cast<std::int64_t>(kChannels * kFs * kDuration));
  const auto n = static_cast<std::size_t>(kFs * kDuration);
  return std::span<const double>(x).subspan(static_cast<std::size_t>(c) * n, n);
}

detect::ResampleOptions options(int spr) {
  detect::ResampleOptions o;
  o.samples_per_rev = spr;
  return o;
}

// ---- the algorithm before the AnglePlan, verbatim but for the names ----
class BeforeKernelTable {
 public:
  BeforeKernelTable(int zero_crossings, double beta)
      : size_(512 * zero_crossings), h_(static_cast<std::size_t>(size_) + 2, 0.0) {
    const double norm = std::cyl_bessel_i(0.0, beta);
    for (int i = 0; i <= size_; ++i) {
      const double r = static_cast<double>(i) / size_;
      const double x = std::numbers::pi * zero_crossings * r;
      const double sinc = i == 0 ? 1.0 : std::sin(x) / x;
      h_[i] = sinc * std::cyl_bessel_i(0.0, beta * std::sqrt(std::max(0.0, 1 - r * r))) / norm;
    }
  }
  double operator()(double r) const {
    const double p = r * size_;
    const auto i = static_cast<std::size_t>(p);
    const double f = p - static_cast<double>(i);
    return h_[i] + f * (h_[i + 1] - h_[i]);
  }

 private:
  int size_;
  std::vector<double> h_;
};

std::vector<double> resample_before(std::span<const double> x, double fs_hz,
                                    std::span<const double> pulse_times_s,
                                    const detect::ResampleOptions& opt) {
  const detect::ShaftAngle angle(pulse_times_s, opt.pulses_per_rev);
  const int spr = opt.samples_per_rev;
  const int z = opt.kernel_zero_crossings;
  const double guard = 1 + 0.5 * (80.0 - 8.0) / (2.285 * 2 * std::numbers::pi * z);
  const double last_sample = static_cast<double>(x.size()) - 1;
  const double speed_floor =
      0.1 * angle.total_revs() / (angle.last_pulse_s() - angle.first_pulse_s());
  auto cutoff = [&](double t) {
    const double f = std::max(angle.speed_rev_per_s(t), speed_floor);
    const double f_nyq = std::min(0.5 * spr * f, 0.5 * fs_hz);
    return 2 * (f_nyq / guard) / fs_hz;
  };
  const auto total = static_cast<long>(std::floor(angle.total_revs() + 1e-9));
  long first = -1, last = -1;
  for (long k = 0; k <= total; ++k) {
    const double t = angle.time_at(static_cast<double>(k));
    if (t * fs_hz - z / cutoff(t) >= 0) {
      first = k;
      break;
    }
  }
  for (long k = total; k >= 0; --k) {
    const double t = angle.time_at(static_cast<double>(k));
    if (t * fs_hz + z / cutoff(t) <= last_sample) {
      last = k;
      break;
    }
  }
  std::vector<double> out(static_cast<std::size_t>(last - first) * spr);
  const BeforeKernelTable kernel(z, 0.1102 * (80.0 - 8.7));
  const long n_max = static_cast<long>(x.size()) - 1;
  for (std::size_t m = 0; m < out.size(); ++m) {
    const double theta = static_cast<double>(first) + static_cast<double>(m) / spr;
    const double t = angle.time_at(theta);
    const double g = cutoff(t);
    const double half = z / g;
    const double inv_half = g / z;
    const double u = t * fs_hz;
    const long n0 = std::max<long>(0, static_cast<long>(std::ceil(u - half)));
    const long n1 = std::min<long>(n_max, static_cast<long>(std::floor(u + half)));
    double acc = 0;
    for (long n = n0; n <= n1; ++n) {
      const double r = std::abs(u - static_cast<double>(n)) * inv_half;
      if (r < 1) acc += x[static_cast<std::size_t>(n)] * kernel(r);
    }
    out[m] = g * acc;
  }
  return out;
}

void BM_ResampleBefore(benchmark::State& state) {
  const auto p = pulses();
  const auto x = channel(0);
  for (auto _ : state) {
    auto y = resample_before(x, kFs, p, options(static_cast<int>(state.range(0))));
    benchmark::DoNotOptimize(y.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(x.size()));
}
BENCHMARK(BM_ResampleBefore)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

void BM_Resample(benchmark::State& state) {
  const auto p = pulses();
  const auto x = channel(0);
  for (auto _ : state) {
    auto y = detect::resample_by_angle(x, kFs, p, options(static_cast<int>(state.range(0))));
    benchmark::DoNotOptimize(y.samples.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(x.size()));
}
BENCHMARK(BM_Resample)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

void BM_MakeAnglePlan(benchmark::State& state) {
  const auto p = pulses();
  const auto n = channel(0).size();
  for (auto _ : state) {
    auto plan = detect::make_angle_plan(p, kFs, n, options(static_cast<int>(state.range(0))));
    benchmark::DoNotOptimize(plan.positions().data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_MakeAnglePlan)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

void BM_ResampleWithPlan(benchmark::State& state) {
  const auto x = channel(0);
  const auto plan =
      detect::make_angle_plan(pulses(), kFs, x.size(), options(static_cast<int>(state.range(0))));
  for (auto _ : state) {
    auto y = detect::resample_by_angle(x, plan);
    benchmark::DoNotOptimize(y.samples.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(x.size()));
}
BENCHMARK(BM_ResampleWithPlan)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

void BM_ResampleChannels(benchmark::State& state) {
  std::vector<std::span<const double>> xs;
  for (int c = 0; c < kChannels; ++c) xs.push_back(channel(c));
  const auto plan = detect::make_angle_plan(pulses(), kFs, xs[0].size(),
                                            options(static_cast<int>(state.range(0))));
  for (auto _ : state) {
    auto y = detect::resample_by_angle(xs, plan);
    benchmark::DoNotOptimize(y.data());
  }
  state.SetItemsProcessed(state.iterations() * kChannels * static_cast<std::int64_t>(xs[0].size()));
}
BENCHMARK(BM_ResampleChannels)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
