// One self-contained HTML report of an analysis (analyze.hpp): inline CSS and inline SVG plots
// (svg_plot.hpp), no scripts, no external assets; opens in any browser and prints.
//
// Layout (an engineer reads the top and opens what he needs):
//  - the verdict: the number of findings (a baseline ALARM is one) and each finding's evidence
//    (what, where, confidence, frequency, the channel that shows it best, linked); green when
//    nothing was found, red when something was. One colour scheme throughout: red a finding, an
//    ALARM or a damaged shaft; amber uncertain or ambiguous; green nothing found (healthy is never
//    red);
//  - a table of contents (links to ids), the machine (shafts, meshes, notes folded, speed over
//    time), findings, the damaged-shaft table, the two-direction table (only when a location has
//    both directions), the indicator table, the baseline comparison;
//  - one folded section (<details>, no scripts) per vibration channel, titled by what the channel
//    is ("drive end vibration sensor (X105_DE_time)": location, kind from role and unit,
//    direction; never parsed from the name), with folded subsections:
//    time waveform, the spectrogram (analyze.hpp SpectrogramTrace: at most 240 x 129 cells drawn
//    as an 8-bit palette PNG inside the SVG, viridis over the top 80 dB, with its colour bar:
//    the same few kB for a short or a long record) and the kurtogram map (levels x frequency,
//    the envelope's band outlined);
//    amplitude spectrum with the mesh harmonics and Welch PSD in (unit)^2/Hz; each mesh's zoom
//    with its candidate shafts' sideband positions (detected lines solid); for a channel whose
//    bearings were diagnosed, the envelope spectrum the decision read (the squared envelope of
//    the prewhitened signal in the band diagnose_bearings_from_signal chose, which is not the raw
//    kurtogram's) on an axis to 1.1 x the highest harmonic scored, every scored line of FTF, BPFO,
//    BPFI, 2BSF labelled, solid where the decision counted it and dashed where it expected one and
//    saw none, and the lines' table; otherwise the envelope spectrum of the kurtogram's band with
//    the families labelled and the fault bands shaded; order spectrum up to 1.15 x the third
//    harmonic of the highest mesh order; per shaft the TSA and, on its own scale, the difference
//    signal, with the gear indicator table.
// Units are shown with superscripts (m/s^2 -> m/s², PSD (m/s²)²/Hz); SVG plots shrink to the page
// width. Measured in headless Chromium by python/tests/test_html_report.py.
#pragma once

#include <string>

#include "detect/analysis/analyze.hpp"

namespace report {

struct HtmlReportOptions {
  std::string title = "geardiag analysis";
  std::string source;             // the recording's file name, shown in the header
  int max_channel_sections = 24;  // vibration channels given plots, in order, >= 0 (the tables
                                  // always list every channel)
  int plot_width_px = 820;        // [200, 4000]
  void validate() const;          // throws diag::InputError naming the field
};

std::string render_html_report(const detect::AnalysisResult& r, const HtmlReportOptions& opt = {});

}  // namespace report
