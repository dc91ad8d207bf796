// Computed order tracking: shaft angle from tacho pulse times, and a signal resampled at uniform
// shaft-angle increments with a speed-tracking anti-aliasing filter.
//
// Shaft angle vs time (ShaftAngle). Pulse i is at angle i / pulses_per_rev revolutions. Between
// pulses the angle is a cubic Hermite polynomial whose slopes (the speed at each pulse) are those
// of the parabola through the pulse and its two neighbours (non-uniform three-point formula),
// limited to [0, 3 x the smaller adjacent secant] (Fritsch & Carlson 1980, SIAM J. Numer. Anal.
// 17(2), the monotonicity condition). Why this model:
//  - it is exact for a constant angular acceleration (the phase model of Fyfe & Munck 1997,
//    Mech. Syst. Signal Process. 11(2), "Analysis of computed order tracking"), because the
//    three-point slope of a parabola is exact;
//  - the angle never runs backwards, so time_at(angle) has one answer (a global cubic spline can
//    overshoot after an abrupt speed change); the limiter only acts when the speed changes by more
//    than 3x between neighbouring pulse intervals;
//  - it is local: a bad pulse disturbs two intervals, not the whole record;
//  - it is C1, so the speed (used to set the anti-aliasing cutoff) is continuous.
// Outside the pulses the angle is extrapolated linearly with the end slopes.
//
// Resampling (resample_by_angle). Each output sample at angle theta_m = first_rev + m /
// samples_per_rev is the band-limited interpolation of the time signal at t = time_at(theta_m):
//   y_m = sum_n x[n] g sinc(g (u - n)) w((u - n) / K),   u = t fs,  g = 2 f_c / fs,
//   K = Z / g (Z zero crossings each side),  w = Kaiser window (beta 8, stopband ~ -80 dB).
// The cutoff f_c tracks the local speed f(t) [rev/s] so that nothing above the angular Nyquist
// order samples_per_rev / 2 survives at any speed:
//   f_c = min(samples_per_rev f(t) / 2, fs / 2) / (1 + delta / 2),  delta = 5 / Z (the Kaiser
//   transition width relative to f_c for 80 dB),
// so the stopband starts at the angular Nyquist (or fs/2) and the passband (ripple < 1e-3) ends
// at (1 - delta/2) f_c: for Z = 16, orders up to 0.72 x samples_per_rev / 2 pass unchanged.
// A fixed time-domain low-pass set for the highest speed would let orders between the Nyquist
// orders of the lowest and highest speeds alias; one set for the lowest speed would cut orders
// the high-speed part holds. Tracking the speed avoids both. Cost: about 2.3 Z multiply-adds per
// input sample while the output rate is below fs (2 Z per output sample above it).
//
// Implementation (AnglePlan). Design is kept apart from processing: the plan holds, per output
// sample, u_m = t_m fs and g_m, found once per shaft (the output angles are monotone, so the
// inverse of the angle walks the pulse intervals with a warm-started Newton instead of a search
// per sample, and the speed for g_m comes from the same Hermite segment), and it holds the
// kernel h(v) = sinc(v) w(v / Z), v = g (u - n) in [0, Z] zero crossings: since the cutoff enters
// only through v, one table serves every g. The table is piecewise cubic Hermite (value and slope
// exact at 64 points per zero crossing): error <= max|h''''| / (384 x 64^4), the maximum at
// v = 0: h''''(0) = pi^4 / 5 + 2 pi^2 beta I1(beta) / (I0(beta) Z^2) + 3 beta^2 I2(beta) /
// (I0(beta) Z^4), so 4.5e-9 of the kernel's peak per tap at Z = 4, 3.1e-9 at Z = 16,
// far below the -80 dB (1e-4) stopband; no Bessel function per tap (the table is built once per
// Z and process). Applying a plan computes the taps of one output sample into a contiguous
// buffer and takes dot products with it, once per channel: the per-channel work is a plain dot
// product when many channels share a plan. The result does not depend on whether channels are
// resampled together or one by one (same bytes), nor on the instruction set (the dot product's
// sixteen partial sums are the same with 2- or 4-wide vectors; no fused multiply-add).
// Polyphase kernel. When every output has the same cutoff g (to 1e-10 relative: the angular
// Nyquist above fs / 2 all along, the case of the TSA resolutions of pulse_refine.hpp and the
// damaged-shaft locator at a steady speed; or an exactly constant speed), the taps of an output
// at u = b + phi (b = floor(u)) depend on the phase phi only: c_j(phi) = h(g (phi - j)),
// j = -floor(K) .. floor(K) + 1. The plan then tabulates them over 256 phase cells, per cell the
// quadratic through the table's values at the cell's ends and middle (two multiply-adds per tap
// on contiguous rows, instead of a table look-up per tap). Its error in a cell of width
// D = g / 256 (in v) is at most max|h'''| D^3 / (72 sqrt 3) = 3.6e-9 of the peak for g <= 1 at
// Z = 16 (max|h'''| = 7.5, computed; the sinc alone has (2 pi)^3 / 32 = 7.75; 13.7 and 6.5e-9 at
// Z = 4), on top of the table's 3.1e-9; at the two taps where |u - n| crosses K (the kernel's
// kink: h falls to 0 with slope |h'(Z)| = 1 / (Z I0(beta)) = 1.7e-4 at Z = 16) at most
// 2.25 |h'(Z)| D = 1.5e-6 (the quadratic's Lebesgue constant is 1.25). In an output: at most
// 2 g (K + 1) 7e-9 + 2 g 1.5e-6 <= 3.3e-6 of max|x| (-110 dB), far below the -80 dB stopband.
// Otherwise (a cutoff that follows the speed, or a table above 2^17 values: g < 0.19 at Z = 16)
// the taps come from the table.
//
// Decimation first (ResampleOptions::decimation, AnglePlan::decimation, decimate_half_band).
// While the output rate is below fs the cost is ~2.3 Z multiply-adds per INPUT sample whatever
// the output rate, so a plan whose angular Nyquist f_N = samples_per_rev f / 2 stays far below
// fs / 2 pays for a bandwidth it throws away. Such a plan may read the record decimated by 2^s
// (s stages of one half-band filter, each halving the rate): the kernel (the same f_c in Hz, so
// the same continuous-time filter) then spans 2^s times fewer input samples. Half-band filter
// (Vaidyanathan 1993, "Multirate Systems and Filter Banks", half-band filters; the window
// design of Kaiser 1974, "Nonrecursive digital filter design using the I0-sinh window
// function", Proc. IEEE ISCAS): h[n] = sinc(n / 2) w(n / 55) / 2, n = -55 .. 55, w the Kaiser
// window of beta 0.1102 (100 - 8.7) = 10.06 (100 dB); h[0] = 1/2 and every other even tap is 0 (28
// symmetric pairs: 14 multiply-adds per input sample for the first stage, half that for the next).
// Computed on a 20 000-point grid (resample_decimation_test.cpp checks it on tones):
// passband [0, 0.22 fs_in] ripple 9.8e-6, stopband [0.28 fs_in, fs_in / 2] below -100 dB
// (|H| < 9.8e-6). A decimated sample is y[k] = (h * x)[2k]: at the time of x[2k] exactly
// (linear phase, no delay to compensate). A plan takes the most stages s <=
// ResampleOptions::decimation for which f_N <= 0.22 fs / 2^(s-1) at every output (the
// passband edge of the last stage): then the band that aliases onto [0, f_N] lies in the
// stopband of every stage, and what the stages leave between f_N and the decimated Nyquist
// lies in the resampling kernel's stopband as it does without decimation. An output of the
// decimated plan therefore equals the direct one to s x 1e-5 of the content below f_N
// (passband ripple, and stopband residue aliased onto it) plus the difference of the two
// discrete kernels' stopband leakage (each <= 1e-4 of the content above the cutoff, -80 dB):
// tested on tones and a chirp (resample_decimation_test.cpp: 8.9e-6 of the in-band content
// after two stages). The samples within 29 of a once-decimated record's ends (43 after two
// stages) see the zeros beyond the record: a decimated plan keeps its kernels off them, and it
// takes fewer stages where that would cost a revolution, so it holds exactly the revolutions
// of the direct plan. The stages run SSE2 or AVX2 with the same operations per lane (the same
// bytes, tested).
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

namespace detect {

// Shaft angle vs time from pulse times (see above). Immutable once built.
class ShaftAngle {
 public:
  // pulse_times_s strictly increasing and finite, at least pulses_per_rev + 1 of them (one whole
  // revolution). Throws diag::InputError otherwise.
  ShaftAngle(std::span<const double> pulse_times_s, int pulses_per_rev = 1);

  double revs_at(double t_s) const;          // angle [rev], 0 at the first pulse
  double time_at(double revs) const;         // inverse of revs_at [s]
  double speed_rev_per_s(double t_s) const;  // d(revs)/dt [rev/s]
  double max_speed_rev_per_s() const;        // the largest d(revs)/dt anywhere [rev/s]
  double total_revs() const;                 // angle of the last pulse [rev]
  double first_pulse_s() const { return t_.front(); }
  double last_pulse_s() const { return t_.back(); }
  int pulses_per_rev() const { return ppr_; }

  // time_at(theta_m) and speed_rev_per_s there, for the uniform angles theta_m = first_revs +
  // m / samples_per_rev, m = 0 .. times_s.size() - 1 (speeds_rev_per_s: same size, or empty to
  // skip them). Walks the pulse intervals with a warm-started Newton instead of a search per
  // angle: equals time_at() and speed_rev_per_s() to a few ulps. samples_per_rev >= 1.
  void times_at_uniform_angles(double first_revs, int samples_per_rev, std::span<double> times_s,
                               std::span<double> speeds_rev_per_s) const;

 private:
  std::size_t interval_of_time(double t) const;
  std::vector<double> t_;      // pulse times [s]
  std::vector<double> slope_;  // d(revs)/dt at each pulse [rev/s]
  int ppr_ = 1;
};

// Once-per-revolution times of shaft B from the pulse times of shaft A, ratio = f_B / f_A (speed
// ratio, e.g. z_A / z_B for a gear pair). B's revolutions start where A's angle is k / ratio
// revolutions, k = 0, 1, ...; they fall between A's pulses when the ratio is not an integer and
// are placed by A's angle model. CAUTION: B's angle zero is A's first pulse, not B's own keyway:
// B's TSA is correct up to a constant rotation. Throws diag::InputError for ratio <= 0.
std::vector<double> scale_pulses(std::span<const double> pulse_times_s, double ratio,
                                 int pulses_per_rev = 1);

struct ResampleOptions {
  int samples_per_rev = 256;       // angular sampling [samples/rev], >= 8
  int pulses_per_rev = 1;          // tacho pulses per revolution of the shaft, >= 1
  int kernel_zero_crossings = 16;  // Z, zero crossings of the sinc on each side, [4, 64]; more:
                                   // a passband closer to the Nyquist order, more work
  int decimation = 0;  // at most this many half-band stages before the resampling (see above),
                       // [0, 4]; the plan takes as many as its angular Nyquist allows

  void validate() const;  // throws diag::InputError naming the field
};

struct AngleResampled {
  std::vector<double> samples;  // x at angles first_rev + m / samples_per_rev
  int samples_per_rev = 0;
  double first_rev = 0;  // angle of samples[0] [rev], from the first pulse; an integer
  int revolutions = 0;   // whole revolutions held: samples.size() / samples_per_rev
};

// The angle grid of one shaft for records of n_samples samples at fs_hz: the whole revolutions
// whose interpolation kernels lie inside the record, the time of every output angle and the
// kernel cutoff there (see above). Immutable once built; share it across the channels of a
// recording (they share the tacho) and across threads. Build it once per shaft and
// samples_per_rev: it costs about as much as applying it to one channel (bench/RESULTS.md), so
// a plan built per channel (the one-call resample_by_angle) gains nothing.
class AnglePlan {
 public:
  // options.pulses_per_rev must equal angle.pulses_per_rev(). Throws diag::InputError for bad
  // options, fs_hz <= 0, or when not one whole revolution fits in n_samples (the message names
  // the margin the filter needs).
  AnglePlan(const ShaftAngle& angle, double fs_hz, std::size_t n_samples,
            const ResampleOptions& options = {});

  int samples_per_rev() const { return spr_; }
  double first_rev() const { return first_rev_; }  // angle of output 0 [rev]; an integer
  int revolutions() const { return revolutions_; }
  std::size_t size() const { return position_.size(); }  // output samples: revolutions x spr
  // The record the plan reads: the one given to the constructor decimated decimation() times
  // (decimate_half_band): its rate and length.
  double fs_hz() const { return fs_hz_; }
  std::size_t n_samples() const { return n_samples_; }  // input length the plan is for
  int decimation() const { return stages_; }            // half-band stages taken, 0 = none
  int kernel_zero_crossings() const { return z_; }
  // u_m = t_m fs_hz(): time of output m in samples of the record read (t = 0 at its sample 0).
  std::span<const double> positions() const { return position_; }
  // g_m = 2 f_c / fs_hz of output m, in (0, 1).
  std::span<const double> cutoffs() const { return cutoff_; }

  // The kernel h(v) = sinc(v) w(v / Z) at v in [0, Z] zero crossings, from the table: exposed so
  // the tests can check the table against the formula.
  double kernel(double v) const;
  // Whether the taps come from the polyphase table (one cutoff for every output, see above).
  bool polyphase() const { return !poly_.empty(); }

  // Keeps the taps of every output once the plan is first applied, for a plan applied again one
  // channel at a time (each application then only takes the dot products; the same bytes as
  // computing the taps again): at most max_values taps (8 bytes each); a plan with more keeps
  // none. Call before the plan is shared; copies share what is kept. Thread-safe applications.
  void keep_taps(std::size_t max_values);
  // The taps kept (0 until the first application, or when there were more than max_values).
  std::size_t kept_taps() const;

 private:
  friend struct AnglePlanAccess;
  int spr_ = 0, z_ = 0, revolutions_ = 0, stages_ = 0;
  // Builds the plan reading the record decimated `stages` times; false (stages > 0) when the
  // angular Nyquist exceeds the last stage's passband edge or no revolution fits.
  bool build(const ShaftAngle& angle, double fs_hz, std::size_t n_samples,
             const ResampleOptions& opt, int stages);
  double first_rev_ = 0, fs_hz_ = 0;
  std::size_t n_samples_ = 0;
  std::vector<double> position_, cutoff_;
  const double* table_ = nullptr;  // kernel: 4 cubic coefficients per cell, 64 cells per unit v
                                   // (one table per Z, shared by every plan)
  // Polyphase kernel (one cutoff for every output): per phase cell, 3 x poly_taps_ quadratic
  // coefficients of the taps at offsets poly_lo_ .. poly_lo_ + poly_taps_ - 1 from floor(u).
  // Empty: the taps from table_.
  long poly_lo_ = 0;
  std::size_t poly_taps_ = 0;
  std::vector<double> poly_;
  struct KeptTaps;  // resample.cpp
  std::shared_ptr<KeptTaps> kept_;
};

// Builds the plan from pulse times (pulses_per_rev from the options). Throws like AnglePlan().
AnglePlan make_angle_plan(std::span<const double> pulse_times_s, double fs_hz,
                          std::size_t n_samples, const ResampleOptions& options = {});
AnglePlan make_angle_plan(const ShaftAngle& angle, double fs_hz, std::size_t n_samples,
                          const ResampleOptions& options = {});

// x decimated `stages` times by the half-band filter above (y[k] = (h * x)[2k], zeros beyond x;
// each stage takes n samples to (n + 1) / 2): what a plan with decimation() = stages reads.
// stages in [0, 4] (0: a copy). Throws diag::InputError otherwise.
std::vector<double> decimate_half_band(std::span<const double> x, int stages = 1);

// The vector instructions of the resampler's inner loops: kAuto (the default) takes AVX2 where
// the CPU has it, else SSE2 (the x86-64 baseline); the others force one, for the tests that
// check that both give the same bytes. Returns false (and changes nothing) for AVX2 on a CPU
// without it. Process-wide; not for use while another thread resamples.
enum class SimdPath { kAuto, kSse2, kAvx2 };
bool set_resample_simd(SimdPath path);

// Applies a plan: x.size() must equal plan.n_samples() (the record decimated as the plan says:
// decimate_half_band(record, plan.decimation())). Throws diag::InputError for a length
// mismatch or non-finite samples.
AngleResampled resample_by_angle(std::span<const double> x, const AnglePlan& plan);
// Every channel through the same plan: the kernel taps of each output sample are computed once
// for all channels. Equals one call per channel, to the byte.
std::vector<AngleResampled> resample_by_angle(std::span<const std::span<const double>> channels,
                                              const AnglePlan& plan);

// Resamples whole revolutions: those whose interpolation kernels lie inside the record. Throws
// diag::InputError for bad options, fs_hz <= 0, non-finite samples, bad pulse times, or when not
// one whole revolution fits (the message names the margin the filter needs). With
// options.decimation, decimates x as the plan says (decimate_half_band). Builds a plan and
// applies it: when several channels share the tacho, build the plan once (make_angle_plan).
AngleResampled resample_by_angle(std::span<const double> x, double fs_hz,
                                 std::span<const double> pulse_times_s,
                                 const ResampleOptions& options = {});

}  // namespace detect
