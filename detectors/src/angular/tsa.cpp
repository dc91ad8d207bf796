#include "detect/angular/tsa.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <string>

#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace detect {

using diag::InputError;

namespace {

using diag::fail;
using diag::require;

bool power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

// keep_regular: the regular lines pass; otherwise they are removed (residual, difference).
std::vector<double> filter_orders(std::span<const double> x, std::span<const int> mesh_orders,
                                  int sidebands, const TsaOrderOptions& opt, bool keep_regular,
                                  const char* where) {
  const std::vector<bool> regular = tsa_regular_orders(x.size(), mesh_orders, sidebands, opt);
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]))
      fail(where, "one_rev", "sample " + std::to_string(i) + " is NaN or Inf");
  }
  RealFft fft(x.size());
  std::vector<std::complex<double>> spec(fft.bins());
  fft.forward(x, spec);
  for (std::size_t k = 0; k < spec.size(); ++k) {
    if (regular[k] != keep_regular) spec[k] = 0.0;
  }
  std::vector<double> out(x.size());
  fft.inverse(spec, out);
  return out;
}

}  // namespace

void TsaOptions::validate() const {
  const std::string w = "TsaOptions";
  require(samples_per_rev >= 64 && power_of_two(samples_per_rev), w, "samples_per_rev",
          std::to_string(samples_per_rev) + " is not a power of two >= 64");
  require(min_revolutions >= 1, w, "min_revolutions",
          std::to_string(min_revolutions) + " is not >= 1");
  require(pulses_per_rev >= 1, w, "pulses_per_rev",
          std::to_string(pulses_per_rev) + " is not >= 1");
  require(kernel_zero_crossings >= 4 && kernel_zero_crossings <= 64, w, "kernel_zero_crossings",
          std::to_string(kernel_zero_crossings) + " is not in [4, 64]");
}

void TsaOrderOptions::validate() const {
  require(shaft_orders >= 0, "TsaOrderOptions", "shaft_orders",
          std::to_string(shaft_orders) + " is not >= 0");
  require(mesh_harmonics >= 0, "TsaOrderOptions", "mesh_harmonics",
          std::to_string(mesh_harmonics) + " is not >= 0");
}

Tsa tsa(const AngleResampled& r, int min_revolutions) {
  require(power_of_two(r.samples_per_rev) && r.samples_per_rev >= 64, "tsa", "samples_per_rev",
          std::to_string(r.samples_per_rev) + " is not a power of two >= 64");
  require(min_revolutions >= 1, "tsa", "min_revolutions",
          std::to_string(min_revolutions) + " is not >= 1");
  require(r.samples.size() == static_cast<std::size_t>(r.revolutions) * r.samples_per_rev, "tsa",
          "resampled",
          "holds " + std::to_string(r.samples.size()) + " samples, not revolutions x " +
              "samples_per_rev");
  require(r.revolutions >= min_revolutions, "tsa", "min_revolutions",
          "the record holds " + std::to_string(r.revolutions) +
              " whole revolutions of this shaft, fewer than the " +
              std::to_string(min_revolutions) + " required");
  const auto spr = static_cast<std::size_t>(r.samples_per_rev);
  Tsa out;
  out.samples_per_rev = r.samples_per_rev;
  out.revolutions = r.revolutions;
  out.first_rev = r.first_rev;
  out.samples.assign(spr, 0.0);
  for (int rev = 0; rev < r.revolutions; ++rev) {
    const double* p = r.samples.data() + static_cast<std::size_t>(rev) * spr;
    for (std::size_t j = 0; j < spr; ++j) out.samples[j] += p[j];
  }
  for (double& v : out.samples) v /= r.revolutions;
  return out;
}

ResampleOptions TsaOptions::resample_options() const {
  ResampleOptions ro;
  ro.samples_per_rev = samples_per_rev;
  ro.pulses_per_rev = pulses_per_rev;
  ro.kernel_zero_crossings = kernel_zero_crossings;
  return ro;
}

Tsa tsa(std::span<const double> x, double fs_hz, std::span<const double> pulse_times_s,
        const TsaOptions& opt) {
  opt.validate();
  return tsa(resample_by_angle(x, fs_hz, pulse_times_s, opt.resample_options()),
             opt.min_revolutions);
}

Tsa tsa(std::span<const double> x, const AnglePlan& plan, int min_revolutions) {
  return tsa(resample_by_angle(x, plan), min_revolutions);
}

std::vector<bool> tsa_regular_orders(std::size_t n, std::span<const int> mesh_orders,
                                     int sideband_orders, const TsaOrderOptions& opt) {
  opt.validate();
  require(n >= 8, "tsa order filter", "one_rev",
          "has " + std::to_string(n) + " samples; at least 8 needed");
  require(sideband_orders >= 0, "tsa order filter", "sideband_orders",
          std::to_string(sideband_orders) + " is not >= 0");
  const long nyq = static_cast<long>(n / 2);
  std::vector<bool> keep(static_cast<std::size_t>(nyq) + 1, false);
  keep[0] = true;
  for (long k = 1; k <= std::min<long>(opt.shaft_orders, nyq); ++k)
    keep[static_cast<std::size_t>(k)] = true;
  for (int z : mesh_orders) {
    require(z >= 1 && z <= nyq, "tsa order filter", "mesh_orders",
            "order " + std::to_string(z) + " is not in [1, " + std::to_string(nyq) +
                "] (the Nyquist order of " + std::to_string(n) + " samples per revolution)");
    const long h_max = opt.mesh_harmonics == 0 ? nyq / z : opt.mesh_harmonics;
    for (long h = 1; h <= h_max && h * z <= nyq; ++h) {
      const long c = h * z;
      for (long j = -sideband_orders; j <= sideband_orders; ++j) {
        const long k = c + j;
        if (k >= 1 && k <= nyq) keep[static_cast<std::size_t>(k)] = true;
      }
    }
  }
  return keep;
}

std::vector<double> tsa_regular(std::span<const double> x, std::span<const int> mesh_orders,
                                int sideband_orders, const TsaOrderOptions& opt) {
  return filter_orders(x, mesh_orders, sideband_orders, opt, true, "tsa_regular");
}
std::vector<double> tsa_residual(std::span<const double> x, std::span<const int> mesh_orders,
                                 int sideband_orders, const TsaOrderOptions& opt) {
  return filter_orders(x, mesh_orders, sideband_orders, opt, false, "tsa_residual");
}
std::vector<double> tsa_difference(std::span<const double> x, std::span<const int> mesh_orders,
                                   int extra_sideband_orders, const TsaOrderOptions& opt) {
  require(extra_sideband_orders >= 0, "tsa_difference", "extra_sideband_orders",
          std::to_string(extra_sideband_orders) + " is not >= 0");
  return filter_orders(x, mesh_orders, 1 + extra_sideband_orders, opt, false, "tsa_difference");
}

std::vector<double> tsa_regular(const Tsa& t, std::span<const int> m, int s,
                                const TsaOrderOptions& o) {
  return tsa_regular(std::span<const double>(t.samples), m, s, o);
}
std::vector<double> tsa_residual(const Tsa& t, std::span<const int> m, int s,
                                 const TsaOrderOptions& o) {
  return tsa_residual(std::span<const double>(t.samples), m, s, o);
}
std::vector<double> tsa_difference(const Tsa& t, std::span<const int> m, int e,
                                   const TsaOrderOptions& o) {
  return tsa_difference(std::span<const double>(t.samples), m, e, o);
}

}  // namespace detect
