#include "detect/spectral/window.hpp"

#include <array>
#include <cmath>
#include <deque>
#include <mutex>
#include <numbers>
#include <string>

#include "diag/error.hpp"

namespace detect {
namespace {

struct CosineSum {
  std::array<double, 5> a{};
  int terms = 1;
};

CosineSum coefficients(WindowType type) {
  switch (type) {
    case WindowType::kRectangular:
      return {{1.0}, 1};
    case WindowType::kHann:
      return {{0.5, 0.5}, 2};
    case WindowType::kHamming:
      return {{0.54, 0.46}, 2};
    case WindowType::kBlackmanHarris:
      return {{0.35875, 0.48829, 0.14128, 0.01168}, 4};
    case WindowType::kFlatTop: {
      constexpr double c[] = {1.0, 1.9383379, 1.3045202, 0.4028270, 0.0350665};
      constexpr double peak = c[0] + c[1] + c[2] + c[3] + c[4];
      return {{c[0] / peak, c[1] / peak, c[2] / peak, c[3] / peak, c[4] / peak}, 5};
    }
    case WindowType::kFlatTopMatlab:
      return {{0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368}, 5};
  }
  throw diag::InputError("window: type: unknown window type");
}

}  // namespace

std::vector<double> make_window(WindowType type, std::size_t n, WindowSymmetry symmetry) {
  if (n == 0) throw diag::InputError(diag::format_error("window", "n", "0 is not >= 1"));
  const CosineSum c = coefficients(type);
  std::vector<double> w(n, 1.0);
  if (n == 1) return w;
  const double d =
      symmetry == WindowSymmetry::kPeriodic ? static_cast<double>(n) : static_cast<double>(n - 1);
  for (std::size_t j = 0; j < n; ++j) {
    const double z = 2.0 * std::numbers::pi * static_cast<double>(j) / d;
    double v = 0.0;
    double sign = 1.0;
    for (int k = 0; k < c.terms; ++k, sign = -sign) v += sign * c.a[k] * std::cos(k * z);
    w[j] = v;
  }
  return w;
}

SharedWindow shared_window_sums(WindowType type, std::size_t n, WindowSymmetry symmetry) {
  struct Entry {
    WindowType type;
    std::size_t n;
    WindowSymmetry symmetry;
    SharedWindow w;
  };
  // Windows kept, most recent first: a channel's spectra use a handful of lengths (the record,
  // its envelope, Welch and spectrogram segments), the same for every channel of a recording.
  constexpr std::size_t kKept = 6;
  static std::mutex mutex;
  static std::deque<Entry> kept;
  {
    std::lock_guard<std::mutex> lock(mutex);
    for (const Entry& e : kept) {
      if (e.type == type && e.n == n && e.symmetry == symmetry) return e.w;
    }
  }
  SharedWindow w;
  w.values = std::make_shared<const std::vector<double>>(make_window(type, n, symmetry));
  for (double v : *w.values) {
    w.sum += v;
    w.sum_sq += v * v;
  }
  std::lock_guard<std::mutex> lock(mutex);
  kept.push_front({type, n, symmetry, w});
  if (kept.size() > kKept) kept.pop_back();
  return w;
}

std::shared_ptr<const std::vector<double>> shared_window(WindowType type, std::size_t n,
                                                         WindowSymmetry symmetry) {
  return shared_window_sums(type, n, symmetry).values;
}

double coherent_gain(std::span<const double> w) {
  if (w.empty()) throw diag::InputError("coherent_gain: w: empty window");
  double s = 0.0;
  for (double v : w) s += v;
  return s / static_cast<double>(w.size());
}

double enbw_bins(std::span<const double> w) {
  if (w.empty()) throw diag::InputError("enbw_bins: w: empty window");
  double s = 0.0, s2 = 0.0;
  for (double v : w) {
    s += v;
    s2 += v * v;
  }
  if (s == 0.0) throw diag::InputError("enbw_bins: w: window sums to zero");
  return static_cast<double>(w.size()) * s2 / (s * s);
}

std::string_view to_string(WindowType type) {
  switch (type) {
    case WindowType::kRectangular:
      return "rectangular";
    case WindowType::kHann:
      return "hann";
    case WindowType::kHamming:
      return "hamming";
    case WindowType::kBlackmanHarris:
      return "blackmanharris";
    case WindowType::kFlatTop:
      return "flattop";
    case WindowType::kFlatTopMatlab:
      return "flattop-matlab";
  }
  return "unknown";
}

WindowType parse_window(std::string_view name, std::string_view field) {
  for (WindowType t :
       {WindowType::kRectangular, WindowType::kHann, WindowType::kHamming,
        WindowType::kBlackmanHarris, WindowType::kFlatTop, WindowType::kFlatTopMatlab}) {
    if (name == to_string(t)) return t;
  }
  throw diag::InputError(diag::format_error(
      "window", std::string(field),
      "'" + std::string(name) +
          "' is not one of rectangular, hann, hamming, blackmanharris, flattop, flattop-matlab"));
}

}  // namespace detect
