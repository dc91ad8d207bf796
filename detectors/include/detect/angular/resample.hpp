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
// input sample, whatever the speed.
#pragma once

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
  double total_revs() const;                 // angle of the last pulse [rev]
  double first_pulse_s() const { return t_.front(); }
  double last_pulse_s() const { return t_.back(); }
  int pulses_per_rev() const { return ppr_; }

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

  void validate() const;  // throws diag::InputError naming the field
};

struct AngleResampled {
  std::vector<double> samples;  // x at angles first_rev + m / samples_per_rev
  int samples_per_rev = 0;
  double first_rev = 0;  // angle of samples[0] [rev], from the first pulse; an integer
  int revolutions = 0;   // whole revolutions held: samples.size() / samples_per_rev
};

// Resamples whole revolutions: those whose interpolation kernels lie inside the record. Throws
// diag::InputError for bad options, fs_hz <= 0, non-finite samples, bad pulse times, or when not
// one whole revolution fits (the message names the margin the filter needs).
AngleResampled resample_by_angle(std::span<const double> x, double fs_hz,
                                 std::span<const double> pulse_times_s,
                                 const ResampleOptions& options = {});

}  // namespace detect
