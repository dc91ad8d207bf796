#include "detect/angular/speed_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "detect/spectral/fft.hpp"
#include "detect/spectral/welch.hpp"
#include "detect/spectral/window.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/channels.hpp"
#include "diag/util/number_format.hpp"

namespace detect {

namespace {

using diag::fail;
using diag::require;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// Orders equal to this relative tolerance are one line (products of tooth-count ratios differ
// only by round-off).
constexpr double kSameOrderTol = 1e-9;
// Candidates whose band reaches above this fraction of Nyquist are dropped (anti-aliasing filters
// of acquisition systems roll off there).
constexpr double kMaxNyquistFraction = 0.8;
// Frames averaged around nominal_time_s to choose the line of a run-up.
constexpr std::ptrdiff_t kSelectionHalfFrames = 1;
// Peaks closer than this many frame bins (fs / frame length; 2: the Hann mainlobe half-width)
// are one peak.
constexpr double kDistinctPeakBins = 2.0;
// Lowest ridge frequency followed, in frame bins (fs / frame length).
constexpr double kMinRidgeBins = 4.0;
// Frames whose least-squares line extrapolates the ridge beyond the first and last frame centres.
constexpr std::size_t kEndFitFrames = 5;
// The harmonic-set check: a bin's floor is the median of the bins within kFloorHalfBins of it,
// taken every kFloorStride bins and interpolated; speeds are scanned over [1/kScanRange,
// kScanRange] x the nominal.
constexpr std::size_t kFloorHalfBins = 64;
constexpr std::size_t kFloorStride = 16;
constexpr double kScanRange = 2.0;

std::size_t next_pow2(std::size_t n) {
  std::size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Peak position between bins: Gaussian interpolation (a parabola through the logarithms of the
// three values around the maximum bin k), in bins, |offset| <= 0.5.
double interpolated_bin(std::span<const double> p, std::size_t k) {
  if (k == 0 || k + 1 >= p.size()) return static_cast<double>(k);
  constexpr double kTiny = 1e-300;
  const double a = std::log(p[k - 1] + kTiny), b = std::log(p[k] + kTiny),
               c = std::log(p[k + 1] + kTiny);
  const double den = a - 2.0 * b + c;
  if (!(den < 0.0)) return static_cast<double>(k);
  return static_cast<double>(k) + std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
}

// Bins [lo, hi] covering [f_lo, f_hi], clipped to the spectrum.
struct BinRange {
  std::size_t lo = 0, hi = 0;
};
BinRange bins_of(double f_lo, double f_hi, double df, std::size_t nbins) {
  BinRange r;
  r.lo = static_cast<std::size_t>(std::max(0.0, std::ceil(f_lo / df)));
  r.hi = std::min(nbins - 1, static_cast<std::size_t>(std::max(0.0, std::floor(f_hi / df))));
  r.lo = std::min(r.lo, r.hi);  // a band outside the spectrum: its nearest bin
  return r;
}

// Local maxima of p inside [r.lo, r.hi] (ends excluded unless the band is at the spectrum's
// edge), strongest first.
std::vector<std::size_t> local_maxima(std::span<const double> p, BinRange r) {
  std::vector<std::size_t> m;
  for (std::size_t k = r.lo; k <= r.hi; ++k) {
    const bool left = k == 0 || p[k] > p[k - 1];
    const bool right = k + 1 >= p.size() || p[k] >= p[k + 1];
    if (left && right) m.push_back(k);
  }
  std::sort(m.begin(), m.end(), [&](std::size_t a, std::size_t b) { return p[a] > p[b]; });
  return m;
}

struct Candidate {
  SpeedLine line;
  double lo_hz = 0, hi_hz = 0;  // search band
};

struct Choice {
  bool found = false;
  Candidate cand;
  std::size_t channel = 0;
  double frequency_hz = 0;
  double prominence_db = -1e300;
  double floor_psd = 0;  // median PSD of the band [x^2/Hz]
};

// Each bin's height over the median of its neighbourhood [dB] (the floor every kFloorStride bins,
// linear between): where a line stands out, for the harmonic-set check.
std::vector<float> prominence_db(std::span<const double> p) {
  const std::size_t n = p.size();
  std::vector<float> out(n, 0.0f);
  if (n < 2 * kFloorHalfBins + 1) return out;
  std::vector<double> knots_at, knots;
  std::vector<double> buf;
  for (std::size_t k = 0;; k += kFloorStride) {
    const std::size_t c = std::min(k, n - 1);
    const std::size_t lo = c > kFloorHalfBins ? c - kFloorHalfBins : 0;
    const std::size_t hi = std::min(n, c + kFloorHalfBins + 1);
    buf.assign(p.begin() + static_cast<std::ptrdiff_t>(lo),
               p.begin() + static_cast<std::ptrdiff_t>(hi));
    knots_at.push_back(static_cast<double>(c));
    knots.push_back(median_of(std::move(buf)));
    if (c == n - 1) break;
  }
  std::size_t j = 0;
  for (std::size_t k = 0; k < n; ++k) {
    while (j + 2 < knots_at.size() && knots_at[j + 1] < static_cast<double>(k)) ++j;
    const double u = (static_cast<double>(k) - knots_at[j]) / (knots_at[j + 1] - knots_at[j]);
    const double floor = knots[j] + std::clamp(u, 0.0, 1.0) * (knots[j + 1] - knots[j]);
    out[k] = floor > 0.0 && p[k] > 0.0 ? static_cast<float>(10.0 * std::log10(p[k] / floor)) : 0.0f;
  }
  return out;
}

struct LineCount {
  int found = 0, counted = 0;
  double score = 0;  // the found lines' prominences [dB], each at most kMaxLineScoreDb
};
// A line's share of the score: the lines of the true speed are the mesh's or shaft's own, far
// stronger than the sidebands or harmonics another speed's candidates may fall on, but one
// very strong line must not outweigh several.
constexpr double kMaxLineScoreDb = 60.0;

// How many of the orders, at speed f_hz, have a bin within tol_hz standing min_db over its floor
// (orders whose line is above max_hz are not counted), and their score.
LineCount lines_at(const std::vector<double>& orders, std::span<const float> prom, double df,
                   double f_hz, double tol_hz, double min_db, double max_hz) {
  LineCount c;
  for (double o : orders) {
    const double f = o * f_hz;
    if (f > max_hz) continue;
    ++c.counted;
    const BinRange r = bins_of(f - tol_hz, f + tol_hz, df, prom.size());
    float top = 0.0f;
    for (std::size_t k = r.lo; k <= r.hi; ++k) top = std::max(top, prom[k]);
    if (top >= min_db) {
      ++c.found;
      c.score += std::min<double>(top, kMaxLineScoreDb);
    }
  }
  return c;
}

// Searches one group of mutually overlapping candidates (size 1: a plain band) on spectrum p.
// Returns a choice, or sets *ambiguous when a prominent peak cannot be attributed.
Choice search_group(const std::vector<Candidate>& group, std::span<const double> p, double df,
                    double peak_sep_hz, double min_db, bool* ambiguous) {
  Choice c;
  double lo = group.front().lo_hz, hi = group.front().hi_hz;
  for (const auto& g : group) lo = std::min(lo, g.lo_hz), hi = std::max(hi, g.hi_hz);
  const BinRange r = bins_of(lo, hi, df, p.size());
  if (r.hi <= r.lo + 2) return c;
  // The floor: median over the band widened by its width on each side, so that a line smeared
  // over much of a narrow band (a run-up's low speeds) does not raise it.
  const BinRange wide = bins_of(2.0 * lo - hi, 2.0 * hi - lo, df, p.size());
  const double floor =
      median_of(std::vector<double>(p.begin() + static_cast<std::ptrdiff_t>(wide.lo),
                                    p.begin() + static_cast<std::ptrdiff_t>(wide.hi) + 1));
  if (!(floor > 0.0)) return c;
  const auto maxima = local_maxima(p, r);
  if (maxima.empty()) return c;
  auto db = [&](std::size_t k) { return 10.0 * std::log10(p[k] / floor); };
  auto freq = [&](std::size_t k) { return interpolated_bin(p, k) * df; };
  const std::size_t k1 = maxima.front();
  if (db(k1) < min_db) return c;
  const double f1 = freq(k1);
  c.frequency_hz = f1;
  c.prominence_db = db(k1);
  c.floor_psd = floor;
  if (group.size() == 1) {
    c.found = true;
    c.cand = group.front();
    return c;
  }
  // Two prominent peaks in the ratio of two orders of the group name the stronger one.
  constexpr std::size_t kPeaksTried = 6;
  for (std::size_t j = 1; j < std::min(maxima.size(), kPeaksTried); ++j) {
    const std::size_t k2 = maxima[j];
    if (db(k2) < min_db) break;
    const double f2 = freq(k2);
    if (std::abs(f2 - f1) < peak_sep_hz) continue;
    const double tol = 0.5 * df * (1.0 / f2 + f1 / (f2 * f2));  // ratio error of +-df/2 each
    for (const auto& a : group) {
      for (const auto& b : group) {
        if (&a == &b || f1 < a.lo_hz || f1 > a.hi_hz || f2 < b.lo_hz || f2 > b.hi_hz) continue;
        if (std::abs(f1 / f2 - a.line.order / b.line.order) <= tol) {
          c.found = true;
          c.cand = a;
          return c;
        }
      }
    }
  }
  *ambiguous = true;
  return c;
}

// The demodulation of step 3: z(t) = x(t) exp(-i phi(t)) low-passed (zero-phase raised cosine,
// 1 up to pass_hz, 0 from stop_hz; real and imaginary parts by real FFTs of the zero-padded
// record), theta = phi + the unwrapped phase of the result, amp = its modulus. The FFT, the
// filter's response and the buffers are made once for both passes.
class Demodulator {
 public:
  Demodulator(std::size_t n, double fs_hz, double pass_hz, double stop_hz)
      // The response's tails decay as 1/t^3 on the scale 1 / (stop - pass): 4 of those keep the
      // circular wrap-around under 1e-4 of the line.
      : n_(n),
        fft_(next_pow2(n + static_cast<std::size_t>(std::ceil(4.0 * fs_hz / (stop_hz - pass_hz))))),
        response_(fft_.bins()),
        re_(n),
        im_(n),
        buf_(fft_.size()),
        spec_(fft_.bins()) {
    const double df = fs_hz / static_cast<double>(fft_.size());
    for (std::size_t k = 0; k < response_.size(); ++k) {
      const double f = static_cast<double>(k) * df;
      double h = 0.0;
      if (f <= pass_hz) {
        h = 1.0;
      } else if (f < stop_hz) {
        h = 0.5 * (1.0 + std::cos(std::numbers::pi * (f - pass_hz) / (stop_hz - pass_hz)));
      }
      response_[k] = h;
    }
  }

  // One pass: phi += unwrapped phase of LP{x exp(-i phi)}; amp = |LP{...}|.
  void pass(std::span<const double> x, std::vector<double>& phi, std::vector<double>& amp) {
    for (std::size_t i = 0; i < n_; ++i) {
      double s = 0.0, c = 0.0;
      sincos(phi[i], &s, &c);  // the same values as std::sin, std::cos (glibc)
      re_[i] = x[i] * c;
      im_[i] = -x[i] * s;
    }
    lowpass(re_);
    lowpass(im_);
    amp.resize(n_);
    double prev = 0.0, unwrapped = 0.0;
    for (std::size_t i = 0; i < n_; ++i) {
      const double a = std::atan2(im_[i], re_[i]);
      if (i == 0) {
        unwrapped = a;
      } else {
        // remainder(d, 2 pi) for d in [-2 pi, 2 pi] (a, prev in [-pi, pi]): the same value,
        // exactly (Sterbenz: d -+ 2 pi is exact for |d| in [pi, 2 pi]).
        double d = a - prev;
        if (d > std::numbers::pi) {
          d -= kTwoPi;
        } else if (d < -std::numbers::pi) {
          d += kTwoPi;
        }
        unwrapped += d;
      }
      prev = a;
      amp[i] = std::sqrt(re_[i] * re_[i] + im_[i] * im_[i]);  // signal-sized: no overflow
      phi[i] += unwrapped;
    }
  }

 private:
  void lowpass(std::vector<double>& part) {
    std::copy(part.begin(), part.end(), buf_.begin());
    std::fill(buf_.begin() + static_cast<std::ptrdiff_t>(n_), buf_.end(), 0.0);
    fft_.forward(buf_, spec_);
    for (std::size_t k = 0; k < spec_.size(); ++k) spec_[k] *= response_[k];
    fft_.inverse(spec_, buf_);
    std::copy(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(n_), part.begin());
  }

  std::size_t n_;
  RealFft fft_;
  std::vector<double> response_;
  std::vector<double> re_, im_, buf_;
  std::vector<std::complex<double>> spec_;
};

}  // namespace

void SpeedEstimateOptions::validate() const {
  if (!(search_fraction > 0.0 && search_fraction < 0.5))
    fail("SpeedEstimateOptions", "search_fraction",
         diag::format_significant(search_fraction, 6) + " is not in (0, 0.5)");
  if (!(frame_s > 0.0 && std::isfinite(frame_s)))
    fail("SpeedEstimateOptions", "frame_s",
         diag::format_significant(frame_s, 6) + " is not a finite time > 0");
  if (!(hop_s > 0.0 && hop_s <= frame_s))
    fail("SpeedEstimateOptions", "hop_s",
         diag::format_significant(hop_s, 6) +
             " is not in (0, frame_s = " + diag::format_significant(frame_s, 6) + "]");
  if (zero_padding < 1 || zero_padding > 16)
    fail("SpeedEstimateOptions", "zero_padding",
         std::to_string(zero_padding) + " is not in [1, 16]");
  if (!(min_prominence_db >= 3.0 && min_prominence_db <= 60.0))
    fail("SpeedEstimateOptions", "min_prominence_db",
         diag::format_significant(min_prominence_db, 6) + " is not in [3, 60]");
  if (!(max_step_fraction > 0.0 && max_step_fraction < 0.5))
    fail("SpeedEstimateOptions", "max_step_fraction",
         diag::format_significant(max_step_fraction, 6) + " is not in (0, 0.5)");
  if (!std::isfinite(nominal_time_s))
    fail("SpeedEstimateOptions", "nominal_time_s", "is NaN or Inf (< 0 means: the whole record)");
  if (!(demod_passband > 0.0 && demod_passband < 0.5))
    fail("SpeedEstimateOptions", "demod_passband",
         diag::format_significant(demod_passband, 6) + " is not in (0, 0.5)");
  if (!(min_line_snr > 0.0 && std::isfinite(min_line_snr)))
    fail("SpeedEstimateOptions", "min_line_snr",
         diag::format_significant(min_line_snr, 6) + " is not a finite ratio > 0");
  if (!(max_fade_fraction >= 0.0 && max_fade_fraction <= 1.0))
    fail("SpeedEstimateOptions", "max_fade_fraction",
         diag::format_significant(max_fade_fraction, 6) + " is not in [0, 1]");
  if (!(stationary_tolerance > 0.0 && std::isfinite(stationary_tolerance)))
    fail("SpeedEstimateOptions", "stationary_tolerance",
         diag::format_significant(stationary_tolerance, 6) + " is not a finite ratio > 0");
  if (points_per_rev < 8)
    fail("SpeedEstimateOptions", "points_per_rev", std::to_string(points_per_rev) + " is < 8");
}

std::string_view to_string(SpeedStatus s) {
  switch (s) {
    case SpeedStatus::kTracked:
      return "tracked";
    case SpeedStatus::kLowConfidence:
      return "low_confidence";
    case SpeedStatus::kNoLine:
      return "no_line";
    case SpeedStatus::kAmbiguous:
      return "ambiguous";
    case SpeedStatus::kUnconfirmed:
      return "unconfirmed";
    case SpeedStatus::kElsewhere:
      return "elsewhere";
  }
  return "?";
}

double SpeedEstimate::angle_rev_at(double t_s) const {
  require(has_speed() && !angle_rev.empty(), "SpeedEstimate::angle_rev_at", "status",
          std::string(to_string(status)) + ": the estimate holds no angle");
  const double u = std::clamp(t_s / angle_step_s, 0.0, static_cast<double>(angle_rev.size() - 1));
  const auto j = std::min(static_cast<std::size_t>(u), angle_rev.size() - 1);
  if (j + 1 >= angle_rev.size()) return angle_rev.back();
  const double w = u - static_cast<double>(j);
  return angle_rev[j] + w * (angle_rev[j + 1] - angle_rev[j]);
}

SpeedEstimate estimate_speed(std::span<const double> x, double fs_hz, double nominal_speed_hz,
                             const std::vector<SpeedLine>& lines,
                             const SpeedEstimateOptions& options) {
  return estimate_speed(std::vector<std::span<const double>>{x}, fs_hz, nominal_speed_hz, lines,
                        options);
}

SpeedEstimate estimate_speed(const std::vector<std::span<const double>>& channels, double fs_hz,
                             double nominal_speed_hz, const std::vector<SpeedLine>& lines,
                             const SpeedEstimateOptions& options) {
  const std::string where = "estimate_speed";
  options.validate();
  require(fs_hz > 0.0 && std::isfinite(fs_hz), where, "fs_hz",
          diag::format_significant(fs_hz, 6) + " is not > 0");
  require(nominal_speed_hz > 0.0 && std::isfinite(nominal_speed_hz), where, "nominal_speed_hz",
          diag::format_significant(nominal_speed_hz, 6) + " is not a finite speed > 0");
  require(!channels.empty(), where, "channels", "none given");
  const std::size_t n = channels.front().size();
  const auto nperseg = static_cast<std::size_t>(std::llround(options.frame_s * fs_hz));
  const auto hop = std::max<std::size_t>(
      1, std::min(nperseg, static_cast<std::size_t>(std::llround(options.hop_s * fs_hz))));
  require(nperseg >= 16, where, "frame_s",
          diag::format_significant(options.frame_s, 6) + " s is " + std::to_string(nperseg) +
              " samples, < 16");
  for (std::size_t c = 0; c < channels.size(); ++c) {
    require(channels[c].size() == n, where, "channels",
            "channel " + std::to_string(c) + " has " + std::to_string(channels[c].size()) +
                " samples, channel 0 has " + std::to_string(n));
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(channels[c][i]))
        fail(where, "channels",
             "channel " + std::to_string(c) + " sample " + std::to_string(i) + " is NaN or Inf");
    }
  }
  require(n >= nperseg, where, "channels",
          std::to_string(n) + " samples, fewer than one frame (frame_s = " +
              diag::format_significant(options.frame_s, 6) + " s: " + std::to_string(nperseg) +
              ")");
  require(!lines.empty(), where, "lines", "no candidate line");
  for (std::size_t i = 0; i < lines.size(); ++i) {
    require(lines[i].order > 0.0 && std::isfinite(lines[i].order), where,
            "lines[" + std::to_string(i) + "].order",
            diag::format_significant(lines[i].order, 6) + " is not > 0");
    require(lines[i].modulation_order > 0.0 && std::isfinite(lines[i].modulation_order), where,
            "lines[" + std::to_string(i) + "].modulation_order",
            diag::format_significant(lines[i].modulation_order, 6) + " is not > 0");
  }

  SpeedEstimate est;
  const double s = options.search_fraction;
  const double nyquist = 0.5 * fs_hz;

  // Candidates: drop those too high, merge equal orders.
  std::vector<Candidate> cands;
  for (const auto& l : lines) {
    const double lo = l.order * nominal_speed_hz * (1.0 - s);
    const double hi = l.order * nominal_speed_hz * (1.0 + s);
    if (hi > kMaxNyquistFraction * nyquist) {
      est.notes.push_back("candidate '" + l.label + "' (order " +
                          diag::format_significant(l.order, 6) + ", up to " +
                          diag::format_significant(hi, 6) + " Hz) dropped: above 0.8 x Nyquist");
      continue;
    }
    bool merged = false;
    for (auto& c : cands) {
      if (std::abs(c.line.order - l.order) <= kSameOrderTol * l.order) {
        c.line.label += " = " + l.label;
        c.line.modulation_order = std::min(c.line.modulation_order, l.modulation_order);
        merged = true;
        break;
      }
    }
    if (!merged) cands.push_back({l, lo, hi});
  }
  // Groups of overlapping bands (connected by overlap, in order of frequency).
  std::sort(cands.begin(), cands.end(),
            [](const Candidate& a, const Candidate& b) { return a.line.order < b.line.order; });
  std::vector<std::vector<Candidate>> groups;
  for (const auto& c : cands) {
    if (!groups.empty() && c.lo_hz <= groups.back().back().hi_hz) {
      groups.back().push_back(c);
    } else {
      groups.push_back({c});
    }
  }

  // STFT frames as the spectrogram's (spectrogram.hpp): frame m starts at m hop, centre
  // t_m = (m hop + nperseg / 2) / fs. Only a Welch PSD per channel (the average of the selection
  // frames) and one frame at a time of the followed channel are held: memory O(nfft), not
  // O(frames x nfft), for long records.
  WelchOptions wo;
  wo.fs_hz = fs_hz;
  wo.nperseg = nperseg;
  wo.noverlap = static_cast<long long>(nperseg - hop);
  wo.nfft = next_pow2(nperseg * static_cast<std::size_t>(options.zero_padding));
  wo.window = WindowType::kHann;
  wo.detrend = Detrend::kConstant;
  const std::size_t frames = (n - nperseg) / hop + 1;
  std::vector<double> frame_t(frames);
  for (std::size_t m = 0; m < frames; ++m)
    frame_t[m] = (static_cast<double>(m * hop) + 0.5 * static_cast<double>(nperseg)) / fs_hz;
  const std::size_t nbins = wo.nfft / 2 + 1;
  const double df = fs_hz / static_cast<double>(wo.nfft);
  const double frame_bin_hz = fs_hz / static_cast<double>(nperseg);

  // Frames the line is chosen on, and the one the ridge starts from.
  std::size_t sel_lo = 0, sel_hi = frames - 1, start = frames / 2;
  if (options.nominal_time_s >= 0.0) {
    const double u = (options.nominal_time_s * fs_hz - 0.5 * static_cast<double>(nperseg)) /
                     static_cast<double>(hop);
    start =
        static_cast<std::size_t>(std::clamp(std::round(u), 0.0, static_cast<double>(frames - 1)));
    sel_lo = static_cast<std::size_t>(
        std::max<std::ptrdiff_t>(0, static_cast<std::ptrdiff_t>(start) - kSelectionHalfFrames));
    sel_hi = std::min(frames - 1, start + static_cast<std::size_t>(kSelectionHalfFrames));
  }

  // Step 1: the most prominent line over channels and candidate groups.
  Choice best;
  std::vector<Choice> found;
  bool ambiguous = false;
  const bool steady = options.nominal_time_s < 0.0;
  std::vector<std::vector<float>> prominence;  // per channel, for the harmonic-set check
  for (std::size_t c = 0; c < channels.size(); ++c) {
    // Welch over exactly the selection frames: the mean of their PSDs.
    const std::vector<double> avg =
        welch(channels[c].subspan(sel_lo * hop, nperseg + (sel_hi - sel_lo) * hop), wo).value;
    if (steady) prominence.push_back(prominence_db(avg));
    for (const auto& g : groups) {
      bool amb = false;
      Choice ch = search_group(g, avg, df, kDistinctPeakBins * frame_bin_hz,
                               options.min_prominence_db, &amb);
      if (amb) {
        ambiguous = true;
        std::string labels;
        for (const auto& x : g) labels += (labels.empty() ? "'" : ", '") + x.line.label + "'";
        est.notes.push_back("channel " + std::to_string(c) + ": overlapping candidates " + labels +
                            " hold a line that fits more than one of them: left out");
      }
      if (!ch.found) continue;
      ch.channel = c;
      found.push_back(ch);
      if (ch.prominence_db > best.prominence_db) best = ch;
    }
  }
  // The harmonic-set check (steady records): all the candidate lines together at the speed found
  // in the band and at every speed in [nominal / 2, 2 x nominal]. A nominal speed far off can put
  // a harmonic of the true speed's lines into a candidate's band (4/3 off: the third mesh
  // harmonic's band holds the fourth's line, for every mesh at once, so the lines even confirm
  // each other) or no line at all into any band; the true speed shows all its lines.
  if (steady && lines.size() >= 3) {
    // The candidates and their doubles (a mesh's harmonics 1-3 give 1-4 and 6): with orders
    // that are multiples of one another (one mesh's first harmonic the other's second) the
    // first three alone fit 3/2 or 2 x the speed nearly as well as the speed; their doubles
    // tell them apart.
    std::vector<double> orders;
    for (const double m : {1.0, 2.0}) {
      for (const SpeedLine& l : lines) {
        const double order = m * l.order;
        if (std::none_of(orders.begin(), orders.end(),
                         [&](double o) { return std::abs(o - order) <= kSameOrderTol * o; })) {
          orders.push_back(order);
        }
      }
    }
    const double max_hz = kMaxNyquistFraction * nyquist, tol_hz = frame_bin_hz;
    const auto count_of = [&](const std::vector<double>& set, double f) {
      LineCount most;
      for (const std::vector<float>& prom : prominence) {
        const LineCount c = lines_at(set, prom, df, f, tol_hz, options.min_prominence_db, max_hz);
        if (c.score > most.score) most = c;
        if (most.counted == 0) most.counted = c.counted;
      }
      return most;
    };
    const auto count_at = [&](double f) { return count_of(orders, f); };
    const double top_order = *std::max_element(orders.begin(), orders.end());
    LineCount here;  // the best of the speeds the lines found in the band imply
    for (const Choice& ch : found) {
      const LineCount c = count_at(ch.frequency_hz / ch.cand.line.order);
      if (c.score > here.score || here.counted == 0) here = c;
    }
    est.lines_found = here.found;
    est.lines_counted = here.counted;
    // Speeds a step apart that moves the highest line by a frame bin at most.
    LineCount better;
    double better_hz = 0;
    for (double f = nominal_speed_hz / kScanRange; f <= kScanRange * nominal_speed_hz;
         f *= 1.0 + tol_hz / (top_order * f + tol_hz)) {
      const LineCount c = count_at(f);
      if (c.score > better.score) better = c, better_hz = f;
    }
    // An octave (or twelfth) error: the true speed's harmonics are the lines of twice (three
    // times) it too, and may score more when its higher harmonics are strong and its first
    // weak. The lines a half (third) predicts that the speed does not (its odd multiples) tell:
    // when a third of them stand out, the half is the speed; when none do, the half has no line
    // of its own.
    for (bool lower = true; lower;) {
      lower = false;
      for (const double k : {2.0, 3.0}) {
        const double f = better_hz / k;
        if (f < nominal_speed_hz / kScanRange) continue;
        std::vector<double> own;  // orders whose line at f is no line of better_hz
        for (double o : orders) {
          if (o * f > max_hz) continue;
          const bool shared = std::any_of(orders.begin(), orders.end(), [&](double q) {
            return std::abs(q * better_hz - o * f) <= tol_hz;
          });
          if (!shared) own.push_back(o);
        }
        if (own.empty()) continue;
        const int own_found = count_of(own, f).found;
        if (3 * own_found >= static_cast<int>(own.size()) && own_found >= 1) {
          better = count_at(f), better_hz = f, lower = true;
          break;
        }
      }
    }
    est.better_speed_hz = better_hz;
    est.better_lines_found = better.found;
    est.better_lines_counted = better.counted;
    const bool outside = std::abs(better_hz / nominal_speed_hz - 1.0) > s;
    // Outside the band, more of the lines and stronger than at any speed the band's lines imply
    // (the band's best speed is among those scanned: a true speed there scores the most).
    const bool clearly = better.found >= std::max(3, here.found + 1) && better.score > here.score &&
                         2 * better.found >= better.counted;
    if (outside && clearly) {
      est.status = SpeedStatus::kElsewhere;
      est.notes.push_back(
          "the candidate lines fit " + diag::format_significant(better_hz, 6) + " Hz (" +
          std::to_string(better.found) + " of " + std::to_string(better.counted) +
          " stand out) better than the band around the nominal " +
          diag::format_significant(nominal_speed_hz, 6) + " Hz (" +
          (best.found ? std::to_string(here.found) + " of " + std::to_string(here.counted) +
                            " at the line found there"
                      : std::string("no line found there")) +
          "): no speed claimed in the band");
      return est;
    }
  }
  if (!best.found) {
    est.status = ambiguous ? SpeedStatus::kAmbiguous : SpeedStatus::kNoLine;
    est.notes.push_back(ambiguous ? "only ambiguous lines: no speed claimed"
                                  : "no candidate line stands " +
                                        diag::format_significant(options.min_prominence_db, 6) +
                                        " dB over its band: no speed claimed");
    return est;
  }
  // The other prominent lines of the same channel should imply the same speed as the line
  // followed, to a frame bin (the averaged peaks are far better placed; a sideband followed
  // instead of its carrier is off by a whole shaft order).
  const auto agree = [&](const Choice& a, const Choice& b) {
    const double implied = b.frequency_hz / b.cand.line.order * a.cand.line.order;
    return std::abs(implied - a.frequency_hz) <=
           frame_bin_hz * a.cand.line.order / b.cand.line.order;
  };
  const auto confirmations = [&](const Choice& a) {
    int n = 0;
    for (const Choice& o : found) {
      if (o.channel == a.channel && o.cand.line.order != a.cand.line.order && agree(a, o)) ++n;
    }
    return n;
  };
  // A foreign line (an electrical or structural line, a fault line) may stand out more than the
  // shaft's or mesh's own in one band: when the most prominent line is confirmed by no other,
  // the most prominent line that others confirm is followed instead (the CWRU outer-race record
  // told 1977 rpm: a line at 107.7 Hz in the third shaft harmonic's band, contradicted by the
  // first and second at 29.9 and 59.9 Hz, which confirm each other).
  if (confirmations(best) == 0) {
    const Choice* confirmed = nullptr;
    for (const Choice& o : found) {
      if (confirmations(o) > 0 && (!confirmed || o.prominence_db > confirmed->prominence_db)) {
        confirmed = &o;
      }
    }
    if (confirmed) {
      est.notes.push_back("line '" + best.cand.line.label + "' at " +
                          diag::format_significant(best.frequency_hz, 6) +
                          " Hz, the most "
                          "prominent, is confirmed by no other: not followed");
      best = *confirmed;
    }
  }
  est.line = best.cand.line;
  est.line_frequency_hz = best.frequency_hz;
  est.prominence_db = best.prominence_db;
  est.channel = best.channel;
  est.notes.push_back("line '" + est.line.label + "' (order " +
                      diag::format_significant(est.line.order, 6) + ") at " +
                      diag::format_significant(best.frequency_hz, 6) + " Hz, " +
                      diag::format_significant(best.prominence_db, 6) +
                      " dB over its band, channel " + std::to_string(best.channel));
  const double order = est.line.order;
  // Cross-check: the other prominent lines of the same channel.
  for (const Choice& o : found) {
    if (o.channel != best.channel || o.cand.line.order == order) continue;
    if (agree(best, o)) {
      ++est.confirmations;
    } else {
      ++est.contradictions;
      est.notes.push_back(
          "line '" + o.cand.line.label + "' at " + diag::format_significant(o.frequency_hz, 6) +
          " Hz implies " + diag::format_significant(o.frequency_hz / o.cand.line.order, 6) +
          " Hz, the line followed " + diag::format_significant(best.frequency_hz / order, 6) +
          " Hz: one of them may be a sideband or a foreign line");
    }
  }

  if (est.confirmations == 0 && groups.size() > 1) {
    est.notes.push_back(
        "no other candidate confirms the speed: with a nominal speed off by more than "
        "search_fraction, a neighbouring line of the same family can be taken for the candidate");
  }
  if (est.confirmations == 0 && options.require_confirmation) {
    est.status = SpeedStatus::kUnconfirmed;
    est.notes.push_back("unconfirmed line not followed (require_confirmation): no speed claimed");
    return est;
  }

  // Step 2: the ridge, forward and backward from `start`.
  const std::span<const double> x = channels[best.channel];
  std::vector<double> ridge_hz(frames, 0.0);
  const std::vector<double> window = make_window(WindowType::kHann, nperseg);
  RealFft frame_fft(wo.nfft);
  std::vector<double> seg(wo.nfft, 0.0), row(nbins);
  std::vector<std::complex<double>> bins(nbins);
  auto peak_near = [&](std::size_t m, double f_pred) {
    const auto first = x.begin() + static_cast<std::ptrdiff_t>(m * hop);
    std::copy(first, first + static_cast<std::ptrdiff_t>(nperseg), seg.begin());
    detrend(std::span<double>(seg.data(), nperseg), Detrend::kConstant);
    for (std::size_t j = 0; j < nperseg; ++j) seg[j] *= window[j];
    frame_fft.forward(seg, bins);
    // A ridge extrapolated towards 0 Hz or Nyquist (a machine stopping, a wrong line) is held
    // a few frame bins inside, so that the demodulation band stays > 0.
    f_pred = std::clamp(f_pred, kMinRidgeBins * frame_bin_hz, kMaxNyquistFraction * nyquist);
    const double w = options.max_step_fraction * f_pred;
    const BinRange r = bins_of(f_pred - w, f_pred + w, df, nbins);
    // Unscaled |X|^2 where it is read: the range and a bin either side (the interpolation).
    for (std::size_t k = r.lo > 0 ? r.lo - 1 : 0; k <= std::min(r.hi + 1, nbins - 1); ++k)
      row[k] = std::norm(bins[k]);
    std::size_t k = r.lo;
    for (std::size_t j = r.lo; j <= r.hi; ++j) {
      if (row[j] > row[k]) k = j;
    }
    return interpolated_bin(row, k) * df;
  };
  ridge_hz[start] = peak_near(start, best.frequency_hz);
  for (int dir : {+1, -1}) {
    std::ptrdiff_t m = static_cast<std::ptrdiff_t>(start) + dir;
    for (; m >= 0 && m < static_cast<std::ptrdiff_t>(frames); m += dir) {
      const auto prev = static_cast<std::size_t>(m - dir);
      double pred = ridge_hz[prev];
      const std::ptrdiff_t prev2 = m - 3 * dir;  // the trend over two frames
      if (prev2 >= 0 && prev2 < static_cast<std::ptrdiff_t>(frames) &&
          std::abs(static_cast<std::ptrdiff_t>(start) - m) >= 3) {
        pred += 0.5 * (ridge_hz[prev] - ridge_hz[static_cast<std::size_t>(prev2)]);
      }
      ridge_hz[static_cast<std::size_t>(m)] = peak_near(static_cast<std::size_t>(m), pred);
    }
  }

  // Step 3: phase refinement. Reference phase from the ridge: line frequency linear between
  // frame centres and extrapolated along the least-squares line of the end frames beyond them
  // (held, a run-up's first half frame would be off by more than the demodulation band),
  // integrated by the trapezoid rule.
  std::vector<double> phi(n);
  {
    const auto& t = frame_t;
    const std::size_t fit = std::min<std::size_t>(frames, kEndFitFrames);
    auto end_slope = [&](std::size_t first) {
      if (fit < 2) return 0.0;
      double tm = 0.0, fm = 0.0;
      for (std::size_t m = first; m < first + fit; ++m) tm += t[m] / fit, fm += ridge_hz[m] / fit;
      double sxy = 0.0, sxx = 0.0;
      for (std::size_t m = first; m < first + fit; ++m) {
        sxy += (t[m] - tm) * (ridge_hz[m] - fm);
        sxx += (t[m] - tm) * (t[m] - tm);
      }
      return sxy / sxx;
    };
    const double slope_start = end_slope(0), slope_end = end_slope(frames - fit);
    std::size_t m = 0;
    double f_prev = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double ti = static_cast<double>(i) / fs_hz;
      while (m + 1 < frames && t[m + 1] <= ti) ++m;
      double f = 0.0;
      if (ti < t.front()) {
        f = ridge_hz.front() + slope_start * (ti - t.front());
      } else if (m + 1 >= frames) {
        f = ridge_hz.back() + slope_end * (ti - t.back());
      } else {
        f = ridge_hz[m] + (ridge_hz[m + 1] - ridge_hz[m]) * (ti - t[m]) / (t[m + 1] - t[m]);
      }
      phi[i] = i == 0 ? 0.0 : phi[i - 1] + kTwoPi * 0.5 * (f + f_prev) / fs_hz;
      f_prev = f;
    }
  }
  double min_ridge = *std::min_element(ridge_hz.begin(), ridge_hz.end());
  double max_ridge = *std::max_element(ridge_hz.begin(), ridge_hz.end());
  const double mod_hz = est.line.modulation_order * min_ridge / order;
  const double pass_hz = options.demod_passband * mod_hz;
  const double stop_hz = 2.0 * pass_hz;
  std::vector<double> amp;
  Demodulator demodulator(n, fs_hz, pass_hz, stop_hz);
  for (int pass = 0; pass < 2; ++pass) demodulator.pass(x, phi, amp);

  // Fades: amplitude vs the noise the band lets through. The PSD floor P [x^2/Hz] (one-sided) of
  // real noise becomes P/2 two-sided at baseband; the raised-cosine band passes
  // 2 (pass + 3/8 (stop - pass)) Hz of it. A line of amplitude A reads A/2.
  const double b_eff = pass_hz + 0.375 * (stop_hz - pass_hz);
  const double noise_rms = std::sqrt(best.floor_psd * b_eff);
  std::size_t faded = 0;
  for (double a : amp) faded += a < options.min_line_snr * noise_rms ? 1 : 0;
  est.faded_fraction = static_cast<double>(faded) / static_cast<double>(n);
  {
    std::vector<double> sorted = amp;
    const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
    std::nth_element(sorted.begin(), mid, sorted.end());
    est.phase_jitter_deg =
        *mid > 0 ? 180.0 / std::numbers::pi * noise_rms / (std::sqrt(2.0) * *mid) : 180.0;
  }
  est.status = est.faded_fraction > options.max_fade_fraction ? SpeedStatus::kLowConfidence
                                                              : SpeedStatus::kTracked;
  if (faded > 0) {
    est.notes.push_back("the line is under " + diag::format_significant(options.min_line_snr, 6) +
                        " x the noise in its band for " +
                        diag::format_significant(100.0 * est.faded_fraction, 6) +
                        " % of the record: phase slips of 1/order rev possible there");
  }

  // The angle, kept every `dec` samples (points_per_rev per revolution at the top speed).
  const double top_speed_hz = max_ridge / order;
  const auto dec = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::floor(fs_hz / (options.points_per_rev * top_speed_hz))));
  est.angle_step_s = static_cast<double>(dec) / fs_hz;
  const double theta0 = phi[0];
  const double per_rev = kTwoPi * order;
  for (std::size_t i = 0; i < n; i += dec) est.angle_rev.push_back((phi[i] - theta0) / per_rev);

  // Mean speed: least-squares slope of the angle (every sample).
  {
    const double nn = static_cast<double>(n);
    const double tm = 0.5 * (nn - 1.0) / fs_hz;
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double dt = static_cast<double>(i) / fs_hz - tm;
      sxy += dt * (phi[i] - theta0);
      sxx += dt * dt;
    }
    est.mean_speed_hz = sxy / sxx / per_rev;
  }
  // Per frame: the angle's increase over the frame (clipped symmetrically at the record's ends).
  const double t_end = static_cast<double>(n - 1) / fs_hz;
  est.time_s = frame_t;
  est.speed_hz.resize(frames);
  est.ridge_speed_hz.resize(frames);
  for (std::size_t m = 0; m < frames; ++m) {
    const double t = frame_t[m];
    const double h = std::min({0.5 * options.frame_s, t, t_end - t});
    const auto i0 = static_cast<std::size_t>(std::llround(std::clamp(t - h, 0.0, t_end) * fs_hz));
    const auto i1 = static_cast<std::size_t>(std::llround(std::clamp(t + h, 0.0, t_end) * fs_hz));
    est.speed_hz[m] = i1 > i0 ? (phi[i1] - phi[i0]) / per_rev * fs_hz / static_cast<double>(i1 - i0)
                              : ridge_hz[m] / order;
    est.ridge_speed_hz[m] = ridge_hz[m] / order;
  }
  est.min_speed_hz = *std::min_element(est.speed_hz.begin(), est.speed_hz.end());
  est.max_speed_hz = *std::max_element(est.speed_hz.begin(), est.speed_hz.end());
  est.stationary =
      (est.max_speed_hz - est.min_speed_hz) <= options.stationary_tolerance * est.mean_speed_hz;
  return est;
}

std::vector<SpeedLine> gearbox_speed_lines(const diag::Gearbox& gb, int reference_shaft,
                                           int harmonics) {
  const std::string where = "gearbox_speed_lines";
  const int shafts = static_cast<int>(gb.shafts().size());
  require(reference_shaft >= 0 && reference_shaft < shafts, where, "reference_shaft",
          std::to_string(reference_shaft) + " is not in [0, " + std::to_string(shafts) + ")");
  require(harmonics >= 1, where, "harmonics", std::to_string(harmonics) + " is < 1");
  const double ref = std::abs(gb.shafts()[static_cast<std::size_t>(reference_shaft)].speed_ratio);
  require(ref > 0.0, where, "reference_shaft", "the shaft does not turn");
  auto rel = [&](int shaft) {
    return std::abs(gb.shafts()[static_cast<std::size_t>(shaft)].speed_ratio) / ref;
  };
  std::vector<SpeedLine> lines;
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    const diag::Mesh& m = gb.meshes()[j];
    const int sd = gb.shaft_of_gear(m.driver), sn = gb.shaft_of_gear(m.driven);
    const double mesh_order = gb.gears()[static_cast<std::size_t>(m.driver)].spec.teeth * rel(sd);
    const std::string name = diag::mesh_name(gb, static_cast<int>(j));
    for (int h = 1; h <= harmonics; ++h) {
      lines.push_back(
          {h * mesh_order, "mesh " + name + " h" + std::to_string(h), std::min(rel(sd), rel(sn))});
    }
  }
  if (lines.empty()) {
    for (int s = 0; s < shafts; ++s) {
      for (int h = 1; h <= harmonics; ++h) {
        lines.push_back(
            {h * rel(s),
             "shaft " + gb.shafts()[static_cast<std::size_t>(s)].name + " x" + std::to_string(h),
             rel(s) / harmonics});
      }
    }
  }
  return lines;
}

std::vector<double> revolution_times_s(const SpeedEstimate& estimate, double first_angle_rev) {
  require(estimate.has_speed() && estimate.angle_rev.size() >= 2, "revolution_times_s", "estimate",
          std::string(to_string(estimate.status)) + ": no speed to take pulses from");
  require(std::isfinite(first_angle_rev), "revolution_times_s", "first_angle_rev", "is NaN or Inf");
  const auto& a = estimate.angle_rev;
  std::vector<double> t;
  double target = first_angle_rev;
  // Skip whole revolutions before the record.
  if (target < a.front()) target += std::ceil(a.front() - target);
  for (std::size_t j = 0; j + 1 < a.size(); ++j) {
    // A backward step (noise) that passed the target places it at the step's start.
    while (a[j + 1] > a[j] && target < a[j + 1]) {
      const double w = std::max(0.0, target - a[j]) / (a[j + 1] - a[j]);
      t.push_back((static_cast<double>(j) + w) * estimate.angle_step_s);
      target += 1.0;
    }
  }
  return t;
}

}  // namespace detect
