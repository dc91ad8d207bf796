// Window design: the sample values of a data window, kept apart from applying it (spectrum.hpp,
// welch.hpp and the others multiply by the values this returns).
//
// Every window here is a cosine sum  w_j = sum_k (-1)^k a_k cos(2 pi k j / D),  j = 0..n-1, with
//   D = n     for a periodic window (the DFT-even form: one period of a periodic sequence; what
//             spectral analysis wants, scipy.signal.get_window's default), and
//   D = n - 1 for a symmetric window (w_j = w_{n-1-j}; what FIR design wants, MATLAB's default).
// Coefficients a_k:
//   rectangular      a = {1}
//   Hann             a = {0.5, 0.5}
//   Hamming          a = {0.54, 0.46}
//   Blackman-Harris  a = {0.35875, 0.48829, 0.14128, 0.01168}  (4-term, -92 dB; Harris 1978,
//                    Proc. IEEE 66(1), Table I; = scipy.signal.windows.blackmanharris)
//   flat-top HFT95   a = {1, 1.9383379, 1.3045202, 0.4028270, 0.0350665} / 4.6807516  (Heinzel,
//                    Ruediger & Schilling 2002, "Spectrum and spectral density estimation by the
//                    DFT", sec. D.1.6: PSLL -95.0 dB, ENBW 3.8112 bins, amplitude flatness
//                    0.0044 dB = 0.051 %; scaled here to a peak of 1)
//   flat-top MATLAB  a = {0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368}
//                    (MATLAB flattopwin = scipy.signal.windows.flattop; ENBW 3.7702 bins,
//                    flatness 0.0098 dB = 0.11 %: slightly worse than HFT95, kept for
//                    comparisons with those tools)
// n == 1 gives {1} for every type.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

namespace detect {

enum class WindowType {
  kRectangular,
  kHann,
  kHamming,
  kBlackmanHarris,  // 4-term, -92 dB side lobes
  kFlatTop,         // Heinzel HFT95: the amplitude-accurate window of this library
  kFlatTopMatlab,   // MATLAB flattopwin / scipy flattop coefficients
};

enum class WindowSymmetry {
  kPeriodic,   // D = n: for spectral analysis (DFT-even)
  kSymmetric,  // D = n - 1: for filter design
};

// The window's n values. n >= 1 (throws diag::InputError "window: n: ..." otherwise).
std::vector<double> make_window(WindowType type, std::size_t n,
                                WindowSymmetry symmetry = WindowSymmetry::kPeriodic);

// make_window's values, shared: the last few windows made are kept (a record's spectra are taken
// window after window of the same length; computing the cosines was 6 % of analyze's CPU).
// Thread-safe; the same values as make_window.
std::shared_ptr<const std::vector<double>> shared_window(
    WindowType type, std::size_t n, WindowSymmetry symmetry = WindowSymmetry::kPeriodic);

// shared_window's values with their sum and sum of squares (summed in index order once, when the
// window is made: the same bits as summing the values again), for the scalings and the ENBW.
struct SharedWindow {
  std::shared_ptr<const std::vector<double>> values;
  double sum = 0;
  double sum_sq = 0;
};
SharedWindow shared_window_sums(WindowType type, std::size_t n,
                                WindowSymmetry symmetry = WindowSymmetry::kPeriodic);

// Coherent gain: mean(w) (the factor a bin-centred sine's DFT peak is multiplied by, over n/2).
double coherent_gain(std::span<const double> w);
// Equivalent noise bandwidth in bins: n sum(w^2) / (sum w)^2.
double enbw_bins(std::span<const double> w);

// "rectangular", "hann", "hamming", "blackmanharris", "flattop", "flattop-matlab".
std::string_view to_string(WindowType type);
// Inverse of to_string; throws diag::InputError naming `field` and the allowed names.
WindowType parse_window(std::string_view name, std::string_view field = "window");

}  // namespace detect
