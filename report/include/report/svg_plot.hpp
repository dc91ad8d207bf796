// A small inline-SVG line plot for self-contained HTML reports: axes with "nice" ticks (1, 2, 5
// x 10^k steps), labels, several series, vertical markers and shaded bands; long series are
// peak-hold decimated (detect/analysis/analyze.hpp, decimate_for_plot) so that narrow spectral
// lines survive.
// No scripts, no external assets: the string is valid SVG 1.1 to embed in HTML.
#pragma once

#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace report {

struct PlotSeries {
  std::span<const double> x, y;  // same length
  std::string label;             // legend text; empty: no legend entry
  std::string color = "#1f77b4";
};

struct PlotMarker {
  double x = 0;
  std::string label;  // drawn at the top of the line; may be empty
  std::string color = "#d62728";
  bool dashed = true;
  int label_row = 0;  // the label drawn this many text rows (10 px) below the top: staggers
                      // the labels of close lines, >= 0
};

struct PlotBand {
  double x0 = 0, x1 = 0;
  std::string label;
  std::string color = "#2ca02c";  // filled at 15 % opacity
};

struct PlotOptions {
  int width_px = 820;   // [200, 4000]
  int height_px = 260;  // [100, 4000]
  std::string title, x_label, y_label;
  double x_min = std::numeric_limits<double>::quiet_NaN();  // NaN: from the data
  double x_max = std::numeric_limits<double>::quiet_NaN();
  // dB axis: y shown as 20 log10(y) (amplitudes) or 10 log10(y) (powers, db_power), the range
  // limited to db_range below the largest value (zeros and tiny values are clipped there).
  bool y_db = false;
  bool db_power = false;
  double db_range = 100;
  std::size_t max_points = 2000;  // per series after decimation, >= 4
};

// Returns "<svg ...>...</svg>". Throws diag::InputError for bad options or series.
std::string svg_line_plot(std::span<const PlotSeries> series, const PlotOptions& opt,
                          std::span<const PlotMarker> markers = {},
                          std::span<const PlotBand> bands = {});

// About `target` tick positions covering [lo, hi] at a 1/2/5 x 10^k step; lo < hi.
std::vector<double> nice_ticks(double lo, double hi, int target = 6);

// Escapes & < > " ' for HTML text and attributes.
std::string html_escape(std::string_view s);

}  // namespace report
