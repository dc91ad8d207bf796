// One self-contained HTML report of an analysis (analyze.hpp): inline CSS and inline SVG plots
// (svg_plot.hpp), no scripts, no external assets; opens in any browser and prints.
//
// Sections: summary (recording, shafts, meshes, notes); findings (and the anomaly score against a
// baseline when the result holds one); the two-direction table; the time-domain indicator table
// (with baseline deviations when present); then per vibration channel: amplitude spectrum with the
// mesh harmonics marked, a zoom on each mesh with its candidate shafts' sideband positions
// marked (detected lines solid), Welch PSD, envelope spectrum with the bearing fault bands shaded,
// order spectrum with the mesh orders marked, and per shaft the TSA and difference signal with
// the gear indicator table.
#pragma once

#include <string>

#include "detect/analysis/analyze.hpp"

namespace detect {

struct HtmlReportOptions {
  std::string title = "geardiag analysis";
  std::string source;             // the recording's file name, shown in the header
  int max_channel_sections = 24;  // vibration channels given plots, in order, >= 0 (the tables
                                  // always list every channel)
  int plot_width_px = 820;        // [200, 4000]
  void validate() const;          // throws diag::InputError naming the field
};

std::string render_html_report(const AnalysisResult& r, const HtmlReportOptions& opt = {});

}  // namespace detect
