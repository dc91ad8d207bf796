// AnglePlan and resample_by_angle (resample.hpp): the plan of output angles and their kernel
// taps, and the dot products of the records with them. The shaft angle is in shaft_angle.cpp,
// the kernel table in resample_kernel.cpp, the half-band decimation in half_band.cpp.
#include "detect/angular/resample.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>

#include "diag/error.hpp"
#include "resample_internal.hpp"

namespace detect {

using diag::InputError;

namespace {

using diag::fail;
using diag::require;
using namespace resample_internal;

// Polyphase form of the kernel for a plan whose cutoff g is the same for every output (see
// resample.hpp): the taps of an output at u = b + phi (b = floor(u)) are c_j = h(g (phi - j)),
// j = lo .. lo + T - 1 (lo = -floor(K), T = 2 floor(K) + 2: every n with |u - n| <= K), smooth
// functions of phi. The phase range [0, 1) is cut into kPhases cells; in each, c_j(phi) is the
// quadratic through the kernel (the cubic table) at the cell's ends and middle.
constexpr int kPhases = 256;
// Relative spread of the cutoffs below which a plan counts as one cutoff (the taps then move by
// at most this much times max |v h'(v)| < 1: far below the table's own 3e-9).
constexpr double kSameCutoff = 1e-10;
// Largest polyphase table [doubles]; larger (a cutoff far below fs / 2, many taps): per tap.
constexpr std::size_t kMaxPolyphase = std::size_t{1} << 17;

}  // namespace

// ---------------------------------------------------------------------------------------------
// resample_by_angle

void ResampleOptions::validate() const {
  const std::string w = "ResampleOptions";
  require(samples_per_rev >= 8, w, "samples_per_rev",
          std::to_string(samples_per_rev) + " is not >= 8");
  require(pulses_per_rev >= 1, w, "pulses_per_rev",
          std::to_string(pulses_per_rev) + " is not >= 1");
  require(kernel_zero_crossings >= 4 && kernel_zero_crossings <= 64, w, "kernel_zero_crossings",
          std::to_string(kernel_zero_crossings) + " is not in [4, 64]");
  require(decimation >= 0 && decimation <= kMaxStages, w, "decimation",
          std::to_string(decimation) + " is not in [0, " + std::to_string(kMaxStages) + "]");
}

AnglePlan::AnglePlan(const ShaftAngle& angle, double fs_hz, std::size_t n_samples,
                     const ResampleOptions& opt) {
  opt.validate();
  require(fs_hz > 0 && std::isfinite(fs_hz), "make_angle_plan", "fs_hz",
          std::to_string(fs_hz) + " is not > 0");
  require(opt.pulses_per_rev == angle.pulses_per_rev(), "make_angle_plan", "pulses_per_rev",
          "the options say " + std::to_string(opt.pulses_per_rev) + ", the ShaftAngle " +
              std::to_string(angle.pulses_per_rev()));
  for (int s = opt.decimation; s > 0; --s) {
    if (build(angle, fs_hz, n_samples, opt, s)) return;
  }
  build(angle, fs_hz, n_samples, opt, 0);
}

bool AnglePlan::build(const ShaftAngle& angle, double fs_hz, std::size_t n_samples,
                      const ResampleOptions& opt, int stages) {
  spr_ = opt.samples_per_rev;
  z_ = opt.kernel_zero_crossings;
  stages_ = stages;
  poly_.clear();
  poly_taps_ = 0;
  // The record read: decimated `stages` times (resample.hpp), its first and last `edge`
  // samples touched by the zeros beyond the record.
  const double rate = std::ldexp(fs_hz, -stages);
  const std::size_t n_read = decimated_length(n_samples, stages);
  const double edge = static_cast<double>(decimated_edge(stages));
  if (stages > 0) {
    // The angular Nyquist at the fastest speed within the last stage's passband.
    const double pass_hz = kHalfBandEdge * std::ldexp(fs_hz, 1 - stages);
    if (0.5 * spr_ * angle.max_speed_rev_per_s() > pass_hz) return false;
  }
  fs_hz_ = rate;
  n_samples_ = n_read;
  const double guard = 1 + 0.5 * transition_rel(z_);

  // Kernel cutoff g = 2 f_c / fs (cycles per sample x 2) and half-width K = z / g [samples].
  // The speed is floored at a tenth of the record's mean: the monotonicity limiter may set a zero
  // slope at an end pulse, which would ask for an infinitely long kernel.
  const double speed_floor =
      0.1 * angle.total_revs() / (angle.last_pulse_s() - angle.first_pulse_s());
  auto cutoff_at = [&](double speed, double r) {
    const double f = std::max(speed, speed_floor);
    const double f_nyq = std::min(0.5 * spr_ * f, 0.5 * r);
    return 2 * (f_nyq / guard) / r;
  };
  auto cutoff_at_speed = [&](double speed) { return cutoff_at(speed, rate); };

  // Whole revolutions whose boundaries have the kernel inside the record (at rate r, length
  // len, `off` samples kept free at each end).
  struct Whole {
    long first = -1, last = -1;
    double margin_s = 0;
  };
  auto whole = [&](double r, std::size_t len, double off) {
    Whole w;
    const double last_sample = static_cast<double>(len) - 1 - off;
    const auto total = static_cast<long>(std::floor(angle.total_revs() + 1e-9));
    for (long k = 0; k <= total; ++k) {
      const double t = angle.time_at(static_cast<double>(k));
      const double half = z_ / cutoff_at(angle.speed_rev_per_s(t), r);
      w.margin_s = std::max(w.margin_s, half / r);
      if (t * r - half >= off) {
        w.first = k;
        break;
      }
    }
    for (long k = total; k >= 0; --k) {
      const double t = angle.time_at(static_cast<double>(k));
      const double half = z_ / cutoff_at(angle.speed_rev_per_s(t), r);
      w.margin_s = std::max(w.margin_s, half / r);
      if (t * r + half <= last_sample) {
        w.last = k;
        break;
      }
    }
    return w;
  };
  const Whole w = whole(rate, n_read, edge);
  if (stages > 0) {
    // The revolutions of the direct plan, or fewer stages.
    const Whole direct = whole(fs_hz, n_samples, 0);
    if (w.first != direct.first || w.last != direct.last || w.first < 0 || w.last <= w.first) {
      return false;
    }
  }
  require(w.first >= 0 && w.last > w.first, "resample_by_angle", "pulse_times_s",
          "no whole revolution lies inside the record with the interpolation filter's margin of " +
              std::to_string(w.margin_s) + " s on each side");
  first_rev_ = static_cast<double>(w.first);
  revolutions_ = static_cast<int>(w.last - w.first);

  const std::size_t outputs = static_cast<std::size_t>(revolutions_) * spr_;
  position_.resize(outputs);
  cutoff_.resize(outputs);
  angle.times_at_uniform_angles(first_rev_, spr_, position_, cutoff_);
  if (stages > 0) {
    const double pass_hz = kHalfBandEdge * std::ldexp(fs_hz, 1 - stages);
    for (std::size_t m = 0; m < outputs; ++m) {
      if (0.5 * spr_ * std::max(cutoff_[m], speed_floor) > pass_hz) return false;
    }
  }
  for (std::size_t m = 0; m < outputs; ++m) {
    position_[m] *= rate;
    cutoff_[m] = cutoff_at_speed(cutoff_[m]);
  }
  table_ = shared_kernel_table(z_).data();

  // One cutoff for every output (the angular Nyquist above fs / 2 all along, or a constant
  // speed): the polyphase table.
  const auto [g_lo, g_hi] = std::minmax_element(cutoff_.begin(), cutoff_.end());
  if (outputs > 0 && *g_hi - *g_lo <= kSameCutoff * *g_hi) {
    const double g = *g_hi;
    const double k_half = std::floor(z_ / g);
    const auto taps = static_cast<std::size_t>(2 * k_half + 2);
    if (3 * taps * kPhases <= kMaxPolyphase) {
      poly_lo_ = -static_cast<long>(k_half);
      poly_taps_ = taps;
      poly_.resize(3 * taps * kPhases);
      auto h = [&](double phi, std::size_t j) {
        return table_kernel(table_, z_,
                            g * (phi - static_cast<double>(poly_lo_ + static_cast<long>(j))));
      };
      for (int a = 0; a < kPhases; ++a) {
        const double phi0 = static_cast<double>(a) / kPhases;
        const double phim = (a + 0.5) / kPhases, phi1 = static_cast<double>(a + 1) / kPhases;
        double* row = poly_.data() + 3 * taps * static_cast<std::size_t>(a);
        for (std::size_t j = 0; j < taps; ++j) {
          const double y0 = h(phi0, j), ym = h(phim, j), y1 = h(phi1, j);
          const double c2 = 2 * (y0 + y1 - 2 * ym);
          row[j] = y0;
          row[taps + j] = y1 - y0 - c2;
          row[2 * taps + j] = c2;
        }
      }
    }
  }
  return true;
}

double AnglePlan::kernel(double v) const { return table_kernel(table_, z_, v); }

namespace {

// acc += x[0 .. kW) t (by reference: a 32-byte vector by value would be passed differently with
// and without AVX).
template <class V>
[[gnu::always_inline]] inline void multiply_add(V& acc, const double* x, const V& t) {
  V a;
  std::memcpy(&a, x, sizeof(V));
  acc += a * t;
}

// Keeps v in a register: otherwise the compiler may load it again from memory for each use (as
// an operand of each multiply), which costs the loads that sharing it saves.
template <class V>
[[gnu::always_inline]] inline void keep_in_register(V& v) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  asm("" : "+x"(v));
#else
  (void)v;
#endif
}

// sum_k x_i[k] c[k] for G channels i at once (the taps loaded once for all of them), each in
// sixteen interleaved partial sums (lane l takes k = l mod 16 of the whole blocks of 16; then one
// block of 8, if left, into lanes 0..7; then the rest, if any, into lanes 0..), reduced in a
// fixed order: a channel's sum does not depend on G or on the vector width. Sixteen sums keep
// the vector units busy (the adds are not one dependent chain).
template <class V, std::size_t G>
[[gnu::always_inline]] inline void dot16(const double* const* x, const double* c, std::size_t count,
                                         double* out) {
  constexpr std::size_t kW = sizeof(V) / sizeof(double), kRegs = 16 / kW;
  // Zeroed one register at a time: `= {}` on the array was a rep stos on the stack per output.
  V acc[G][kRegs];
#pragma GCC unroll 16
  for (std::size_t i = 0; i < G; ++i) {
#pragma GCC unroll 8
    for (std::size_t r = 0; r < kRegs; ++r) acc[i][r] = V{};
  }
  std::size_t k = 0;
  for (; k + 16 <= count; k += 16) {
#pragma GCC unroll 8
    for (std::size_t r = 0; r < kRegs; ++r) {
      V t;  // the taps loaded once for the G channels
      std::memcpy(&t, c + k + r * kW, sizeof(V));
      keep_in_register(t);
#pragma GCC unroll 4
      for (std::size_t i = 0; i < G; ++i) multiply_add(acc[i][r], x[i] + k + r * kW, t);
    }
  }
  if (k + 8 <= count) {
#pragma GCC unroll 8
    for (std::size_t r = 0; r < kRegs / 2; ++r) {
      V t;  // the taps loaded once for the G channels
      std::memcpy(&t, c + k + r * kW, sizeof(V));
      keep_in_register(t);
#pragma GCC unroll 4
      for (std::size_t i = 0; i < G; ++i) multiply_add(acc[i][r], x[i] + k + r * kW, t);
    }
    k += 8;
  }
  for (std::size_t i = 0; i < G; ++i) {
    if (k < count) {  // the rest into lanes 0..: the other lanes add +0
      double rest[8] = {};
      for (std::size_t j = k; j < count; ++j) rest[j - k] = x[i][j] * c[j];
      for (std::size_t r = 0; r < 8 / kW; ++r) {
        V v;
        std::memcpy(&v, rest + r * kW, sizeof(V));
        acc[i][r] += v;
      }
    }
    // half_l = lane l + lane l + 8, then ((h0 + h4) + (h1 + h5)) + ((h2 + h6) + (h3 + h7)), in
    // the vector registers.
    if constexpr (kW == 4) {
      const V q = (acc[i][0] + acc[i][2]) + (acc[i][1] + acc[i][3]);
      out[i] = (q[0] + q[1]) + (q[2] + q[3]);
    } else {
      static_assert(kW == 2);
      const V q0 = (acc[i][0] + acc[i][4]) + (acc[i][2] + acc[i][6]);
      const V q1 = (acc[i][1] + acc[i][5]) + (acc[i][3] + acc[i][7]);
      out[i] = (q0[0] + q0[1]) + (q1[0] + q1[1]);
    }
  }
}

// c[k] = c0[k] + f (c1[k] + f c2[k]): the polyphase taps of one output.
template <class V>
[[gnu::always_inline]] inline void poly_taps(const double* c0, const double* c1, const double* c2,
                                             double f, double* c, std::size_t count) {
  constexpr std::size_t kW = sizeof(V) / sizeof(double);
  V vf;
  for (std::size_t l = 0; l < kW; ++l) vf[l] = f;
  std::size_t k = 0;
  for (; k + kW <= count; k += kW) {
    V a0, a1, a2;
    std::memcpy(&a0, c0 + k, sizeof(V));
    std::memcpy(&a1, c1 + k, sizeof(V));
    std::memcpy(&a2, c2 + k, sizeof(V));
    const V v = a0 + vf * (a1 + vf * a2);
    std::memcpy(c + k, &v, sizeof(V));
  }
  for (; k < count; ++k) c[k] = c0[k] + f * (c1[k] + f * c2[k]);
}

// c[k] = h(|p0 - k step| / kCellsPerZeroCrossing) from the cubic table, k < count: the taps of
// one output whose cutoff follows the speed.
[[gnu::always_inline]] inline double table_tap(const double* table, int last_cell, double p0,
                                               double step, std::size_t k) {
  const double p = std::abs(p0 - static_cast<double>(k) * step);
  const int i = std::min(static_cast<int>(p), last_cell);
  const double f = p - static_cast<double>(i);
  const double* a = table + 4 * static_cast<std::ptrdiff_t>(i);
  return a[0] + f * (a[1] + f * (a[2] + f * a[3]));
}
void table_taps_scalar(const double* table, int last_cell, double p0, double step, double* c,
                       std::size_t count) {
  for (std::size_t k = 0; k < count; ++k) c[k] = table_tap(table, last_cell, p0, step, k);
}
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
// The same, four taps at a time: the four table cells (4 coefficients each, contiguous) loaded
// and transposed, the same operations per lane as table_tap (the same bytes).
[[gnu::target("avx2")]] void table_taps_avx2(const double* table, int last_cell, double p0,
                                             double step, double* c, std::size_t count) {
  const __m256d vp0 = _mm256_set1_pd(p0), vstep = _mm256_set1_pd(step);
  const __m256d sign = _mm256_set1_pd(-0.0);
  const __m128i vlast = _mm_set1_epi32(last_cell);
  std::size_t k = 0;
  for (; k + 4 <= count; k += 4) {
    const auto kd = static_cast<double>(k);
    const __m256d vk = _mm256_set_pd(kd + 3, kd + 2, kd + 1, kd);
    const __m256d p = _mm256_andnot_pd(sign, _mm256_sub_pd(vp0, _mm256_mul_pd(vk, vstep)));
    const __m128i i = _mm_min_epi32(_mm256_cvttpd_epi32(p), vlast);
    const __m256d f = _mm256_sub_pd(p, _mm256_cvtepi32_pd(i));
    alignas(16) int idx[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(idx), i);
    const __m256d r0 = _mm256_loadu_pd(table + 4 * static_cast<std::ptrdiff_t>(idx[0]));
    const __m256d r1 = _mm256_loadu_pd(table + 4 * static_cast<std::ptrdiff_t>(idx[1]));
    const __m256d r2 = _mm256_loadu_pd(table + 4 * static_cast<std::ptrdiff_t>(idx[2]));
    const __m256d r3 = _mm256_loadu_pd(table + 4 * static_cast<std::ptrdiff_t>(idx[3]));
    const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
    const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    const __m256d a0 = _mm256_permute2f128_pd(t0, t2, 0x20);
    const __m256d a1 = _mm256_permute2f128_pd(t1, t3, 0x20);
    const __m256d a2 = _mm256_permute2f128_pd(t0, t2, 0x31);
    const __m256d a3 = _mm256_permute2f128_pd(t1, t3, 0x31);
    const __m256d v = _mm256_add_pd(
        a0, _mm256_mul_pd(
                f, _mm256_add_pd(a1, _mm256_mul_pd(f, _mm256_add_pd(a2, _mm256_mul_pd(f, a3))))));
    _mm256_storeu_pd(c + k, v);
  }
  for (; k < count; ++k) c[k] = table_tap(table, last_cell, p0, step, k);
}
#endif

}  // namespace

// The taps of one output sample and the dot products with them: y_m = g_m sum_k x[n0 + k] c_k.
struct AnglePlanAccess {
  struct Taps {
    std::size_t n0 = 0, count = 0;
  };
  using PolyTaps = void (*)(const double*, const double*, const double*, double, double*,
                            std::size_t);
  using TableTaps = void (*)(const double* table, int last_cell, double p0, double step, double* c,
                             std::size_t count);
  // Writes the taps of output m to c[0 .. count) (c holds at least max_taps(plan) values).
  static Taps taps(const AnglePlan& plan, std::size_t m, double* c, PolyTaps poly,
                   TableTaps table_taps) {
    const double u = plan.position_[m], g = plan.cutoff_[m];
    const long n_max = static_cast<long>(plan.n_samples_) - 1;
    if (!plan.poly_.empty()) {
      // Polyphase: the cell of u's phase, quadratic in the position within the cell.
      const double b = std::floor(u);
      const double ph = (u - b) * kPhases;
      const int a = std::min(static_cast<int>(ph), kPhases - 1);
      const double f = ph - a;
      const long first = static_cast<long>(b) + plan.poly_lo_;
      const long last = first + static_cast<long>(plan.poly_taps_) - 1;
      const long n0 = std::max<long>(0, first), n1 = std::min(n_max, last);
      const std::size_t count = n1 >= n0 ? static_cast<std::size_t>(n1 - n0 + 1) : 0;
      const std::size_t t = plan.poly_taps_;
      const double* c0 = plan.poly_.data() + 3 * t * static_cast<std::size_t>(a) +
                         static_cast<std::size_t>(n0 - first);
      poly(c0, c0 + t, c0 + 2 * t, f, c, count);
      return padded(plan, static_cast<std::size_t>(n0), count, c);
    }
    const double half = plan.z_ / g;
    const long n0 = std::max<long>(0, static_cast<long>(std::ceil(u - half)));
    const long n1 = std::min<long>(n_max, static_cast<long>(std::floor(u + half)));
    const std::size_t count = n1 >= n0 ? static_cast<std::size_t>(n1 - n0 + 1) : 0;
    // p_k = g |u - n0 - k| kCellsPerZeroCrossing, the table position of tap k; taps with
    // |u - n| <= K only, so p <= Z kCellsPerZeroCrossing up to rounding (the zero cell).
    const double step = g * kCellsPerZeroCrossing;
    const double p0 = (u - static_cast<double>(n0)) * step;
    // int, not size_t: x86-64 converts a double to a signed integer in one instruction.
    const int last_cell = plan.z_ * kCellsPerZeroCrossing;
    table_taps(plan.table_, last_cell, p0, step, c, count);
    return padded(plan, static_cast<std::size_t>(n0), count, c);
  }
  // The taps padded with zeros to a multiple of 8 where the record goes on that far, so that the
  // dot product has no remainder to take one by one (x[n] 0 adds nothing: x is finite).
  static Taps padded(const AnglePlan& plan, std::size_t n0, std::size_t count, double* c) {
    const std::size_t up = (count + 7) / 8 * 8;
    if (n0 + up > plan.n_samples_) return {n0, count};
    std::fill(c + count, c + up, 0.0);
    return {n0, up};
  }
  static AnglePlan::KeptTaps* kept(const AnglePlan& plan) { return plan.kept_.get(); }
  // An upper bound of the taps of any output of the plan.
  static std::size_t max_taps(const AnglePlan& plan) {
    if (!plan.poly_.empty()) return plan.poly_taps_ + 7;
    const double g_min =
        plan.cutoff_.empty() ? 1.0 : *std::min_element(plan.cutoff_.begin(), plan.cutoff_.end());
    return static_cast<std::size_t>(2 * std::floor(plan.z_ / g_min) + 3) + 7;
  }
};

namespace {

// y_i[m] = g[m] dot(x_i + n0_m, taps_m) for a block of outputs, channels i < G.
template <class V, std::size_t G>
[[gnu::always_inline]] inline void block_dot(const double* const* x, const double* t,
                                             const AnglePlanAccess::Taps* where, const double* g,
                                             double* const* y, std::size_t outputs) {
  for (std::size_t m = 0; m < outputs; ++m) {
    const double* xs[G];
    for (std::size_t i = 0; i < G; ++i) xs[i] = x[i] + where[m].n0;
    double d[G];
    dot16<V, G>(xs, t, where[m].count, d);
    for (std::size_t i = 0; i < G; ++i) y[i][m] = g[m] * d[i];
    t += where[m].count;
  }
}
// Channels [0, n) through a block: in pairs where the vector registers hold two channels'
// partial sums (AVX2: 8 of 16), else one by one.
using BlockDot = void (*)(const double* const* x, std::size_t n, const double* taps,
                          const AnglePlanAccess::Taps* where, const double* g, double* const* y,
                          std::size_t outputs);
void block_dot_sse2(const double* const* x, std::size_t n, const double* t,
                    const AnglePlanAccess::Taps* where, const double* g, double* const* y,
                    std::size_t outputs) {
  for (std::size_t i = 0; i < n; ++i) block_dot<V2, 1>(x + i, t, where, g, y + i, outputs);
}
void poly_taps_sse2(const double* c0, const double* c1, const double* c2, double f, double* c,
                    std::size_t count) {
  poly_taps<V2>(c0, c1, c2, f, c, count);
}
struct Kernels {
  BlockDot dot;
  AnglePlanAccess::PolyTaps poly;
  AnglePlanAccess::TableTaps table;
};
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
[[gnu::target("avx2")]] void block_dot_avx2(const double* const* x, std::size_t n, const double* t,
                                            const AnglePlanAccess::Taps* where, const double* g,
                                            double* const* y, std::size_t outputs) {
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) block_dot<V4, 2>(x + i, t, where, g, y + i, outputs);
  for (; i < n; ++i) block_dot<V4, 1>(x + i, t, where, g, y + i, outputs);
}
[[gnu::target("avx2")]] void poly_taps_avx2(const double* c0, const double* c1, const double* c2,
                                            double f, double* c, std::size_t count) {
  poly_taps<V4>(c0, c1, c2, f, c, count);
}
#endif
Kernels kernels() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (use_avx2()) return {block_dot_avx2, poly_taps_avx2, table_taps_avx2};
#endif
  return {block_dot_sse2, poly_taps_sse2, table_taps_scalar};
}

}  // namespace

namespace resample_internal {

// SimdPath::kAuto: AVX2 where the CPU has it.
std::atomic<SimdPath> g_simd{SimdPath::kAuto};
bool use_avx2() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool has = __builtin_cpu_supports("avx2");
  const SimdPath p = g_simd.load(std::memory_order_relaxed);
  return p == SimdPath::kAuto ? has : p == SimdPath::kAvx2;
#else
  return false;
#endif
}

}  // namespace resample_internal

bool set_resample_simd(SimdPath path) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (path == SimdPath::kAvx2 && !__builtin_cpu_supports("avx2")) return false;
#else
  if (path == SimdPath::kAvx2) return false;
#endif
  g_simd.store(path, std::memory_order_relaxed);
  return true;
}

struct AnglePlan::KeptTaps {
  std::size_t max_values = 0;
  std::once_flag once;
  std::unique_ptr<double[]> taps;            // every output's, one after the other
  std::size_t count = 0;                     // of them
  std::vector<AnglePlanAccess::Taps> where;  // per output; empty: none kept
};

void AnglePlan::keep_taps(std::size_t max_values) {
  kept_ = std::make_shared<KeptTaps>();
  kept_->max_values = max_values;
}

std::size_t AnglePlan::kept_taps() const { return kept_ ? kept_->count : 0; }

AnglePlan make_angle_plan(const ShaftAngle& angle, double fs_hz, std::size_t n_samples,
                          const ResampleOptions& options) {
  return AnglePlan(angle, fs_hz, n_samples, options);
}

AnglePlan make_angle_plan(std::span<const double> pulse_times_s, double fs_hz,
                          std::size_t n_samples, const ResampleOptions& options) {
  options.validate();
  return AnglePlan(ShaftAngle(pulse_times_s, options.pulses_per_rev), fs_hz, n_samples, options);
}

std::vector<AngleResampled> resample_by_angle(std::span<const std::span<const double>> channels,
                                              const AnglePlan& plan) {
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const auto& x = channels[c];
    require(
        x.size() == plan.n_samples(), "resample_by_angle", "x",
        "channel " + std::to_string(c) + " has " + std::to_string(x.size()) +
            " samples; the plan is for " + std::to_string(plan.n_samples()) +
            (plan.decimation() > 0 ? " (the record decimated " + std::to_string(plan.decimation()) +
                                         " times: decimate_half_band)"
                                   : ""));
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (!std::isfinite(x[i]))
        fail("resample_by_angle", "x",
             "channel " + std::to_string(c) + " sample " + std::to_string(i) + " is NaN or Inf");
    }
  }
  std::vector<AngleResampled> out(channels.size());
  for (AngleResampled& o : out) {
    o.samples_per_rev = plan.samples_per_rev();
    o.first_rev = plan.first_rev();
    o.revolutions = plan.revolutions();
    o.samples.resize(plan.size());
  }
  // Outputs in blocks whose taps fill ~32 KiB (L1/L2): the taps of a block are computed once,
  // then each channel streams through its part of the record for the whole block (one channel
  // at a time keeps the hardware prefetcher on one stream).
  constexpr std::size_t kBlockTaps = 4096;
  const std::span<const double> g = plan.cutoffs();
  const std::size_t most = AnglePlanAccess::max_taps(plan);
  const Kernels kern = kernels();
  std::vector<const double*> x(channels.size());
  std::vector<double*> y(channels.size());
  for (std::size_t c = 0; c < channels.size(); ++c) x[c] = channels[c].data();
  if (auto* kept_taps = AnglePlanAccess::kept(plan)) {
    auto& kept = *kept_taps;
    std::call_once(kept.once, [&] {
      // Room for max_values taps (only the pages written are touched); an output that might not
      // fit (max_taps of it) keeps none.
      auto bound = [&](std::size_t m) {
        return plan.polyphase() ? most
                                : static_cast<std::size_t>(
                                      2 * std::floor(plan.kernel_zero_crossings() / g[m]) + 10);
      };
      std::size_t room = 0;
      for (std::size_t m = 0; m < plan.size() && room <= kept.max_values; ++m) room += bound(m);
      room = std::min(room, kept.max_values);
      kept.taps.reset(new double[room]);
      kept.where.resize(plan.size());
      std::size_t used = 0;
      for (std::size_t m = 0; m < plan.size(); ++m) {
        if (used + bound(m) > room) {
          kept.taps.reset();
          kept.where = {};
          return;
        }
        kept.where[m] =
            AnglePlanAccess::taps(plan, m, kept.taps.get() + used, kern.poly, kern.table);
        used += kept.where[m].count;
      }
      kept.count = used;
    });
    if (!kept.where.empty()) {
      const double* t = kept.taps.get();
      for (std::size_t m0 = 0; m0 < plan.size();) {
        std::size_t used = 0, m1 = m0;
        for (; m1 < plan.size() && (m1 == m0 || used < kBlockTaps); ++m1)
          used += kept.where[m1].count;
        for (std::size_t c = 0; c < channels.size(); ++c) y[c] = out[c].samples.data() + m0;
        kern.dot(x.data(), x.size(), t, kept.where.data() + m0, g.data() + m0, y.data(), m1 - m0);
        t += used;
        m0 = m1;
      }
      return out;
    }
  }
  std::vector<double> taps(kBlockTaps + most);
  std::vector<AnglePlanAccess::Taps> where;
  for (std::size_t m0 = 0; m0 < plan.size();) {
    where.clear();
    std::size_t used = 0, m1 = m0;
    for (; m1 < plan.size() && (m1 == m0 || used < kBlockTaps); ++m1) {
      if (taps.size() < used + most) taps.resize(used + most);
      const AnglePlanAccess::Taps w =
          AnglePlanAccess::taps(plan, m1, taps.data() + used, kern.poly, kern.table);
      where.push_back(w);
      used += w.count;
    }
    for (std::size_t c = 0; c < channels.size(); ++c) y[c] = out[c].samples.data() + m0;
    kern.dot(x.data(), x.size(), taps.data(), where.data(), g.data() + m0, y.data(), m1 - m0);
    m0 = m1;
  }
  return out;
}

AngleResampled resample_by_angle(std::span<const double> x, const AnglePlan& plan) {
  return std::move(resample_by_angle(std::span<const std::span<const double>>(&x, 1), plan)[0]);
}

AngleResampled resample_by_angle(std::span<const double> x, double fs_hz,
                                 std::span<const double> pulse_times_s,
                                 const ResampleOptions& opt) {
  const AnglePlan plan = make_angle_plan(pulse_times_s, fs_hz, x.size(), opt);
  if (plan.decimation() == 0) return resample_by_angle(x, plan);
  return resample_by_angle(decimate_half_band(x, plan.decimation()), plan);
}

}  // namespace detect
