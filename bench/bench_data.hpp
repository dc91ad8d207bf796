// Inputs shared by the benchmarks and matched by the peer scripts (bench/peer_*.py): Gaussian
// noise of a fixed seed, and the Welch parameters they give scipy.signal.welch.
#pragma once

#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "detect/spectral/welch.hpp"

namespace bench_data {

// `samples` values of unit Gaussian noise, seed 20240601; made once per length.
inline const std::vector<double>& noise(std::int64_t samples) {
  static std::map<std::int64_t, std::vector<double>> cache;
  auto it = cache.find(samples);
  if (it != cache.end()) return it->second;
  std::mt19937_64 rng(20240601);
  std::normal_distribution<double> g;
  std::vector<double> x(static_cast<std::size_t>(samples));
  for (double& v : x) v = g(rng);
  return cache.emplace(samples, std::move(x)).first->second;
}

// nperseg 4096, 50 % overlap (noverlap -1), Hann, constant detrend, density; fs 1.
inline detect::WelchOptions welch_options() {
  detect::WelchOptions o;
  o.fs_hz = 1.0;
  o.nperseg = 4096;
  return o;
}

}  // namespace bench_data
