// NA4 and NB4: kurtosis of the current record normalised by the variance averaged over the run
// ensemble, so that the indicator keeps growing as damage spreads instead of settling back to 3
// (Zakrajsek, Townsend & Decker 1993, NASA TM-106032; Decker 2002, NASA TM-2002-211491;
// MathWorks gearConditionMetrics).
//
//   NA4(M) = N sum_i (r_Mi - r_bar_M)^4 / [ (1/M) sum_{m=1..M} sum_i (r_mi - r_bar_m)^2 ]^2
//
// r_m: residual signal of record m (TSA minus shaft orders and mesh harmonics), M the current
// record's index in the run; records may have different lengths N_m. With the population
// variance v_m = (1/N_m) sum_i (r_mi - r_bar_m)^2 and the current record's fourth central moment
// mu4 = (1/N) sum_i (r_Mi - r_bar_M)^4 this is NA4 = mu4 / (mean_m v_m)^2, which is the form used
// here (it is the printed formula when every record has N samples, and stays meaningful when they
// do not).
//
// NB4 is the same statistic on the envelope of the signal band-passed around the mesh frequency
// (Zakrajsek 1993): feed envelopes to an ensemble of its own.
#pragma once

#include <cstddef>
#include <span>

namespace detect {

class Na4Ensemble {
 public:
  // Adds one record's residual (or envelope, for NB4) to the run: O(N), O(1) memory.
  // InputError for an empty record.
  void add(std::span<const double> record);
  // NA4 of `current` against the ensemble as it stands. The definition includes the current
  // record in the average, so call add(current) first (or use push()).
  // InputError for an empty record or an empty ensemble; NaN when the mean variance is 0.
  double value(std::span<const double> current) const;
  // add(record), then value(record).
  double push(std::span<const double> record);

  std::size_t records() const { return records_; }
  double mean_variance() const;  // (1/M) sum_m v_m; InputError when empty
  void reset() { records_ = 0, variance_sum_ = 0; }

 private:
  std::size_t records_ = 0;
  double variance_sum_ = 0;  // sum_m v_m (Kahan-free: M is at most thousands of records)
};

using Nb4Ensemble = Na4Ensemble;  // same arithmetic on band-passed envelopes

}  // namespace detect
