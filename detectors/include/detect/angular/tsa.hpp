// Time-synchronous averaging per shaft and the signals derived from it (MATLAB tsa, tsaregular,
// tsaresidual, tsadifference).
//
// TSA (McFadden 1987, Mech. Syst. Signal Process. 1(2), "A revised model for the extraction of
// periodic waveforms by time domain averaging"): the signal is resampled at samples_per_rev
// uniform angle steps of THIS shaft (resample.hpp, speed-tracking anti-aliasing; works under
// slowly varying speed) and the N whole revolutions are averaged sample by sample:
//   tsa[j] = (1/N) sum_r x(theta = first_rev + r + j / samples_per_rev).
// Components locked to the shaft (integer orders) are kept; a component at order q is multiplied
// by the comb response |sin(pi N q) / (N sin(pi q))|, which for a non-integer q falls as 1/N;
// random noise falls as 1/sqrt(N) in RMS.
//
// Order sets (orders are cycles per revolution of this shaft; z = a gear's tooth count on this
// shaft, its mesh order; H = mesh harmonics; s = sideband orders):
//   shaft orders      1 .. shaft_orders           (MATLAB: the "primary frequency" and its
//                                                   harmonics)
//   mesh orders       h z, h = 1 .. H             (H = 0: every harmonic below the Nyquist order)
//   sidebands         h z +- j, j = 1 .. s
//   regular(s)   = order 0 + shaft orders + mesh orders + their sidebands up to s   (tsaregular)
//   residual(s)  = TSA - regular(s)        (tsaresidual: shaft and mesh orders removed, and
//                                           s sidebands on request; MATLAB's NumSidebands)
//   difference(e) = TSA - regular(1 + e)   (tsadifference: the first-order sidebands always go,
//                                           e more on request; Stewart 1977 / McFadden's FM4
//                                           input)
// so regular(s) + residual(s) = TSA exactly and difference(e) = residual(1 + e). MATLAB's
// NumHarmonics = H corresponds to shaft_orders = H and mesh_harmonics = H. The mean (order 0)
// belongs to the regular signal, so residual and difference have zero mean. Implemented by one
// real FFT of the one-revolution TSA and zeroing lines; orders above samples_per_rev / 2 cannot
// be represented (an error), and orders above ~0.72 x samples_per_rev / 2 were attenuated by the
// resampling filter (resample.hpp): choose samples_per_rev >= 2.8 x the highest order of
// interest.
#pragma once

#include <span>
#include <vector>

#include "detect/angular/resample.hpp"

namespace detect {

struct TsaOptions {
  int samples_per_rev = 1024;      // angular resolution [samples/rev], power of two >= 64
  int min_revolutions = 10;        // fewer revolutions than this is an error, not a noisy answer
  int pulses_per_rev = 1;          // tacho pulses per revolution of THIS shaft, >= 1
  int kernel_zero_crossings = 16;  // resampling kernel, see ResampleOptions, [4, 64]

  void validate() const;  // throws diag::InputError naming the field
  // The resampling these options ask for: build the shaft's AnglePlan from it to share the plan
  // with other channels (tsa(x, plan, min_revolutions)).
  ResampleOptions resample_options() const;
};

struct Tsa {
  std::vector<double> samples;  // one revolution, samples_per_rev values, sample j at angle j/spr
  int revolutions = 0;          // revolutions averaged
  int samples_per_rev = 0;
  double first_rev = 0;  // angle (from the first pulse) of the first revolution averaged
};

// pulse_times_s: pulses of THIS shaft (scale_pulses() derives them from another shaft's tacho).
// Throws diag::InputError for bad options or inputs, or fewer than min_revolutions whole
// revolutions in the record.
Tsa tsa(std::span<const double> x, double fs_hz, std::span<const double> pulse_times_s,
        const TsaOptions& options = {});
// x resampled through a plan shared with other channels (make_angle_plan with
// TsaOptions::resample_options()): equals tsa(x, fs, pulses, options) to the byte.
Tsa tsa(std::span<const double> x, const AnglePlan& plan, int min_revolutions = 10);
// Averages an already resampled record (its samples_per_rev must be a power of two >= 64).
Tsa tsa(const AngleResampled& resampled, int min_revolutions = 10);

struct TsaOrderOptions {
  int shaft_orders = 1;    // shaft orders 1 .. shaft_orders belong to the regular signal, >= 0
  int mesh_harmonics = 0;  // harmonics h z, h = 1 .. mesh_harmonics, of each mesh order; 0: all
                           // below the Nyquist order; >= 0

  void validate() const;  // throws diag::InputError naming the field
};

// mesh_orders: tooth counts of the gears on this shaft, each in [1, samples_per_rev / 2].
// The span forms take one revolution of any length >= 8.
std::vector<double> tsa_regular(std::span<const double> one_rev, std::span<const int> mesh_orders,
                                int sideband_orders = 0, const TsaOrderOptions& options = {});
std::vector<double> tsa_residual(std::span<const double> one_rev, std::span<const int> mesh_orders,
                                 int sideband_orders = 0, const TsaOrderOptions& options = {});
std::vector<double> tsa_difference(std::span<const double> one_rev,
                                   std::span<const int> mesh_orders, int extra_sideband_orders = 0,
                                   const TsaOrderOptions& options = {});

std::vector<double> tsa_regular(const Tsa& tsa, std::span<const int> mesh_orders,
                                int sideband_orders = 0, const TsaOrderOptions& options = {});
std::vector<double> tsa_residual(const Tsa& tsa, std::span<const int> mesh_orders,
                                 int sideband_orders = 0, const TsaOrderOptions& options = {});
std::vector<double> tsa_difference(const Tsa& tsa, std::span<const int> mesh_orders,
                                   int extra_sideband_orders = 0,
                                   const TsaOrderOptions& options = {});

// The order lines (0 .. n/2) the regular signal keeps for a one-revolution record of n samples:
// true at line k when order k is regular. Exposed so that reports and tests can name them.
std::vector<bool> tsa_regular_orders(std::size_t n, std::span<const int> mesh_orders,
                                     int sideband_orders, const TsaOrderOptions& options = {});

}  // namespace detect
