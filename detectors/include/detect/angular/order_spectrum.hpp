// Order spectrum: amplitude vs shaft order of a signal resampled at uniform shaft angle
// (MATLAB orderspectrum's job, here as an amplitude spectrum).
//
// The resampled record is cut into segments of segment_revs whole revolutions (0: one segment,
// the whole record), each is windowed (Hann or rectangular), transformed, and the amplitudes are
// averaged as power (RMS over segments):
//   A_k = sqrt( mean_over_segments |2 X_k / sum(w)|^2 ),  halved at order 0 and at the Nyquist,
// so a sinusoid a cos(2 pi q theta + phi) at an order q that falls on a line (q = k / segment_revs)
// reads A = a. Order of line k: k / segment_revs [cycles per revolution]. Segments overlap by
// `overlap` (a fraction, whole revolutions are kept: the hop is rounded to revolutions).
#pragma once

#include <vector>

#include "detect/angular/resample.hpp"

namespace detect {

struct OrderSpectrumOptions {
  enum class Window {
    kHann,         // sidelobes -31 dB, falling 18 dB/octave; amplitude exact on a line
    kRectangular,  // narrowest line; exact for orders on a line, leaks for the others
  };
  int segment_revs = 0;  // revolutions per segment, >= 0 (0: whole record, one segment)
  double overlap = 0.5;  // segment overlap fraction, [0, 0.9]
  Window window = Window::kHann;
  double max_order = 0;  // the lines up to this order only (0: all, up to samples_per_rev / 2)

  void validate() const;  // throws diag::InputError naming the field
};

struct OrderSpectrum {
  std::vector<double> order;      // [cycles/rev], 0 .. samples_per_rev / 2
  std::vector<double> amplitude;  // [signal units], peak amplitude of a sinusoid on a line
  int segments = 0;               // segments averaged
  double resolution_order = 0;    // line spacing [orders] = 1 / segment_revs
};

// Throws diag::InputError when segment_revs exceeds the revolutions held, or there are none.
OrderSpectrum order_spectrum(const AngleResampled& resampled,
                             const OrderSpectrumOptions& options = {});

}  // namespace detect
