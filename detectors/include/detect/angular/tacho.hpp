// Tachometer processing: pulse times from a sampled tacho signal, repair of missed and extra
// pulses (reported, never silent), and the speed profile (MATLAB tachorpm's job).
//
// Pulses: rising crossings of a threshold with hysteresis. The detector arms when the signal
// falls below threshold - band/2 and fires when it next rises above threshold + band/2; the pulse
// time is the crossing of the threshold itself, placed between the two samples that straddle it
// by linear interpolation. Sample n is at time n / fs_hz.
//   CAUTION: linear interpolation puts an ideal 0/1 edge (our simulator's pulse trains) at the
//   midpoint between the samples, so each pulse time is uncertain by up to half a sampling
//   period. For a smooth edge the error is at most |x''| T^2 / (8 |x'|) (T = 1/fs_hz) at the
//   crossing.
// Auto threshold: the midpoint of the robust minimum and maximum (the 10th smallest and 10th
// largest samples, fewer in records under 200 samples, so that up to 9 isolated spikes or
// dropouts do not move it).
//
// Repair. Intervals d_i between pulses are compared with the median m_i of the intervals in a
// window centred on them (local, so a run-up or run-down is fine; it shrinks to 3 intervals at
// the ends of the record to stay centred), r_i = d_i / m_i:
//  - |r - 1| <= tol                    a normal interval;
//  - |r - k| <= tol, k = round(r) >= 2 k - 1 missed pulses: inserted where a quadratic phase
//                                      (constant angular acceleration) fitted to the two pulses
//                                      on each side reaches them;
//  - r < 1 - tol and r plus a neighbouring interval's r is within tol of 1: an extra pulse,
//                                      dropped (the neighbour that completes the interval best);
//  - anything else                     reported as an irregular interval and left as it is.
// Every repair is listed in TachoResult::repairs; users must be told what was changed.
#pragma once

#include <cmath>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

namespace detect {

struct TachoOptions {
  int pulses_per_rev = 1;  // pulses per shaft revolution, >= 1
  // Trigger level [signal units]; NaN: auto, the midpoint of the robust minimum and maximum.
  double threshold = std::numeric_limits<double>::quiet_NaN();
  double hysteresis_fraction = 0.1;  // hysteresis band as a fraction of (robust max - robust
                                     // min), [0, 0.9]
  double repair_tolerance = 0.3;     // tolerance on interval / local median, in units of the
                                     // median interval, (0, 0.45]
  int median_window = 9;             // intervals in the local median, odd, >= 5
  bool repair = true;                // false: detect anomalies and report them, change nothing

  void validate() const;  // throws diag::InputError naming the field
};

struct TachoRepair {
  enum class Kind {
    kMissedPulse,        // a pulse was inserted at time_s
    kExtraPulse,         // the pulse at time_s was dropped
    kIrregularInterval,  // the interval starting at time_s fits neither; left unchanged
  };
  Kind kind = Kind::kMissedPulse;
  double time_s = 0;
};
std::string_view to_string(TachoRepair::Kind k);

struct TachoResult {
  std::vector<double> pulse_times_s;  // after repair, strictly increasing [s]
  std::vector<TachoRepair> repairs;   // in time order
  double threshold = 0;               // level used [signal units]
  double hysteresis = 0;              // full width of the hysteresis band [signal units]
  int pulses_per_rev = 1;             // copied from the options
};

// Throws diag::InputError for fs_hz <= 0 or non-finite samples. A signal without a usable edge
// gives no pulses (an outcome, not an error).
TachoResult tacho_pulses(std::span<const double> tacho, double fs_hz,
                         const TachoOptions& options = {});

// Repair step alone, for pulse times from elsewhere (a file, a scaled train). Same rules.
TachoResult repair_pulses(std::span<const double> pulse_times_s, const TachoOptions& options = {});

// Speed vs time. Sample j is the mean speed over window_intervals pulse intervals,
//   rpm_j = 60 * W / (pulses_per_rev * (t_{j+W} - t_j)),  at time (t_j + t_{j+W}) / 2,
// which is exact for a speed that varies linearly in time (the mean of a linear function over an
// interval is its value at the midpoint). W = pulses_per_rev averages one revolution, which also
// cancels the spacing errors of a multi-pulse wheel. W >= 1; fewer than W + 1 pulses: empty.
struct SpeedProfile {
  std::vector<double> time_s;
  std::vector<double> rpm;
};
SpeedProfile speed_profile(std::span<const double> pulse_times_s, int pulses_per_rev,
                           int window_intervals = 1);
SpeedProfile speed_profile(const TachoResult& tacho, int pulses_per_rev, int window_intervals = 1);

}  // namespace detect
