#include "detect/spectral/kurtogram.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <limits>
#include <map>
#include <numbers>
#include <string>

#include "detect/spectral/envelope.hpp"
#include "detect/spectral/fft.hpp"
#include "diag/error.hpp"

namespace detect {
namespace {

void check_finite(std::span<const double> x, const char* where) {
  for (std::size_t j = 0; j < x.size(); ++j) {
    if (!std::isfinite(x[j]))
      diag::fail(where, "x", "sample " + std::to_string(j) + " is not finite");
  }
}

double mean_of(std::span<const double> x) {
  double s = 0.0;
  for (double v : x) s += v;
  return s / static_cast<double>(x.size());
}

// <|c|^4> / <|c|^2>^2 - 2 of the complex signal a + i b; 0 for an empty (all-zero) band.
double complex_kurtosis(const std::vector<double>& a, const std::vector<double>& b) {
  double s2 = 0.0, s4 = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j) {
    const double p = a[j] * a[j] + b[j] * b[j];
    s2 += p;
    s4 += p * p;
  }
  if (s2 == 0.0) return 0.0;
  const double n = static_cast<double>(a.size());
  return n * s4 / (s2 * s2) - 2.0;
}

}  // namespace

void SpectralKurtosisOptions::validate() const {
  const char* w = "spectral_kurtosis";
  if (!(std::isfinite(fs_hz) && fs_hz > 0))
    diag::fail(w, "fs_hz", std::to_string(fs_hz) + " is not finite and > 0");
  if (nperseg < 8 || nperseg > (std::size_t{1} << 24))
    diag::fail(w, "nperseg", std::to_string(nperseg) + " is not in [8, 2^24]");
  if (noverlap < -1 || (noverlap >= 0 && static_cast<std::size_t>(noverlap) >= nperseg))
    diag::fail(w, "noverlap",
               std::to_string(noverlap) + " is not in [0, nperseg) = [0, " +
                   std::to_string(nperseg) + ") or -1 (3 nperseg / 4)");
}

SpectralKurtosis spectral_kurtosis(std::span<const double> x,
                                   const SpectralKurtosisOptions& options) {
  options.validate();
  const std::size_t n = options.nperseg;
  const std::size_t overlap =
      options.noverlap < 0 ? 3 * n / 4 : static_cast<std::size_t>(options.noverlap);
  const std::size_t step = n - overlap;
  const std::size_t needed = n + 3 * step;
  if (x.size() < needed)
    diag::fail("spectral_kurtosis", "x",
               std::to_string(x.size()) +
                   " samples; need at least 4 segments = " + std::to_string(needed));
  check_finite(x, "spectral_kurtosis");
  const double mean = mean_of(x);
  const std::vector<double> w = make_window(options.window, n);
  RealFft fft(n);
  std::vector<double> work(n);
  std::vector<std::complex<double>> X(fft.bins());
  std::vector<double> s2(fft.bins(), 0.0), s4(fft.bins(), 0.0);
  SpectralKurtosis r;
  for (std::size_t start = 0; start + n <= x.size(); start += step) {
    for (std::size_t j = 0; j < n; ++j) work[j] = w[j] * (x[start + j] - mean);
    fft.forward(work, X);
    for (std::size_t k = 0; k < X.size(); ++k) {
      const double p = std::norm(X[k]);
      s2[k] += p;
      s4[k] += p * p;
    }
    ++r.segments;
  }
  const double segs = static_cast<double>(r.segments);
  r.frequency_hz.resize(X.size());
  r.kurtosis.resize(X.size());
  for (std::size_t k = 0; k < X.size(); ++k) {
    r.frequency_hz[k] = static_cast<double>(k) * options.fs_hz / static_cast<double>(n);
    r.kurtosis[k] = s2[k] > 0.0 ? segs * s4[k] / (s2[k] * s2[k]) - 2.0 : 0.0;
  }
  return r;
}

void KurtogramOptions::validate() const {
  if (!(std::isfinite(fs_hz) && fs_hz > 0))
    diag::fail("kurtogram", "fs_hz", std::to_string(fs_hz) + " is not finite and > 0");
  if (max_level < 1 || max_level > 20)
    diag::fail("kurtogram", "max_level", std::to_string(max_level) + " is not in [1, 20]");
  if (!(taper_fraction >= 0 && taper_fraction <= 0.25))
    diag::fail("kurtogram", "taper_fraction",
               std::to_string(taper_fraction) + " is not in [0, 0.25]");
  if (!(std::isfinite(min_bandwidth_hz) && min_bandwidth_hz >= 0))
    diag::fail("kurtogram", "min_bandwidth_hz",
               std::to_string(min_bandwidth_hz) + " is not finite and >= 0");
  if (!(std::isfinite(min_low_hz) && min_low_hz >= 0))
    diag::fail("kurtogram", "min_low_hz", std::to_string(min_low_hz) + " is not finite and >= 0");
}

Kurtogram fast_kurtogram(std::span<const double> x, const KurtogramOptions& options) {
  options.validate();
  const std::size_t needed = std::size_t{1} << (options.max_level + 7);
  if (x.size() < needed)
    diag::fail("kurtogram", "x",
               std::to_string(x.size()) + " samples; max_level " +
                   std::to_string(options.max_level) + " needs at least 2^(max_level + 7) = " +
                   std::to_string(needed) + " (lower max_level or give a longer record)");
  check_finite(x, "kurtogram");
  const std::size_t n = x.size();
  const double mean = mean_of(x);
  RealFft fft(n);
  const std::span<double> centred = fft.input();  // transformed in place (no copies)
  for (std::size_t j = 0; j < n; ++j) centred[j] = x[j] - mean;
  // The DFT sees the record as periodic: a steady tone that does not fit a whole number of
  // periods jumps at the wrap, and that one impulse per record leaks into the bands next to the
  // tone as a spuriously impulsive signal. Half-cosine ramps at both ends remove the jump.
  const std::size_t ramp = static_cast<std::size_t>(options.taper_fraction * double(n));
  for (std::size_t j = 0; j < ramp; ++j) {
    const double g = 0.5 - 0.5 * std::cos(std::numbers::pi * (double(j) + 0.5) / double(ramp));
    centred[j] *= g;
    centred[n - 1 - j] *= g;
  }
  const std::span<const std::complex<double>> X = fft.forward_input();
  // (level, band count): 0:1, then k: 2^k and k + log2(3) - 1: 3 2^(k-1) for k < max_level.
  std::vector<std::pair<double, std::size_t>> layout{{0.0, 1}};
  for (int k = 1; k <= options.max_level; ++k) {
    layout.push_back({static_cast<double>(k), std::size_t{1} << k});
    if (k < options.max_level)
      layout.push_back({k + std::log2(3.0) - 1.0, 3 * (std::size_t{1} << (k - 1))});
  }

  std::map<std::size_t, RealFft> ffts;  // by band signal length, reused across bands
  std::vector<std::complex<double>> A, B;
  std::vector<double> a, b;
  Kurtogram r;
  r.kurtosis = -1e300;
  for (const auto& [level, bands] : layout) {
    KurtogramLevel row;
    row.level = level;
    row.bandwidth_hz = 0.5 * options.fs_hz / static_cast<double>(bands);
    if (row.bandwidth_hz < options.min_bandwidth_hz) continue;
    row.kurtosis.resize(bands);
    // Bins with i B <= k df < (i + 1) B, B / df = n / (2 bands): half-open bands, as the
    // paper's; the Nyquist bin k = n/2 of an even n (fs/2, the top band's upper edge) is in none.
    auto first_bin = [&](std::size_t i) { return (i * n + 2 * bands - 1) / (2 * bands); };
    std::size_t m_max = 0;
    for (std::size_t i = 0; i < bands; ++i)
      m_max = std::max(m_max, first_bin(i + 1) - first_bin(i));
    // The complex band signal c(t) = sum_{q<m} Z_q e^{2 pi i q t / len}, sampled at len >= 2m
    // points (oversampled by at least 2, as the paper's complex decimated signals). The kurtosis
    // is the ratio of the means of |c|^4 and |c|^2 over the samples; |c|^4 is a trigonometric
    // polynomial of degree 2(m - 1), so any len >= 2m - 1 equispaced points give its exact mean
    // over a period (and of |c|^2's): K does not depend on len beyond 2m - 1, and len is taken as
    // the smallest fast FFT length >= 2m of the row's widest band (smooth_length_at_least; one
    // length per row: every FFTW plan costs 1-30 ms to make, ~100 executions of the band's
    // transform). Same value as len = 2m up to round-off.
    const std::size_t len = smooth_length_at_least(2 * m_max);
    auto it = ffts.find(len);
    if (it == ffts.end()) it = ffts.emplace(len, RealFft(len)).first;
    RealFft* f = &it->second;
    A.assign(f->bins(), 0.0);
    B.assign(f->bins(), 0.0);
    a.resize(len);
    b.resize(len);
    std::size_t filled = 0;  // A and B hold nonzero bins below `filled`
    for (std::size_t i = 0; i < bands; ++i) {
      if (static_cast<double>(i) * row.bandwidth_hz < options.min_low_hz) {
        row.kurtosis[i] = std::numeric_limits<double>::quiet_NaN();
        continue;
      }
      const std::size_t k_lo = first_bin(i);
      const std::size_t m = first_bin(i + 1) - k_lo;
      // Z_q = X_{k_lo + q} for q < m, 0 for m <= q < len. The complex inverse DFT of Z is
      // IDFT(A) + i IDFT(B) with the Hermitian parts A_q = (Z_q + conj Z_{-q}) / 2 and
      // B_q = (Z_q - conj Z_{-q}) / (2 i), each a real inverse DFT. As len >= 2m, Z_{-q} =
      // Z_{len - q} = 0 for 0 < q <= len / 2: A_q = Z_q / 2, B_q = -i Z_q / 2, and at q = 0
      // A_0 = Re Z_0, B_0 = Im Z_0.
      for (std::size_t q = m; q < filled; ++q) A[q] = B[q] = 0.0;
      filled = m;
      if (m > 0) {
        A[0] = X[k_lo].real();
        B[0] = X[k_lo].imag();
      }
      for (std::size_t q = 1; q < m; ++q) {
        const std::complex<double> zq = X[k_lo + q];
        A[q] = 0.5 * zq;
        B[q] = {0.5 * zq.imag(), -0.5 * zq.real()};
      }
      f->inverse(A, a);
      f->inverse(B, b);
      const double k = complex_kurtosis(a, b);
      row.kurtosis[i] = k;
      if (k > r.kurtosis) {
        r.kurtosis = k;
        r.level = level;
        r.bandwidth_hz = row.bandwidth_hz;
        r.centre_hz = (static_cast<double>(i) + 0.5) * row.bandwidth_hz;
      }
    }
    r.levels.push_back(std::move(row));
  }
  return r;
}

}  // namespace detect
