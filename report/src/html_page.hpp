// The parts of the HTML report (internal to report/src): html_report.cpp writes the page and its
// recording-level sections, html_channel.cpp the folded section of each channel, html_figures.cpp
// the figures that are not line plots (kurtogram, spectrogram) and the bearing decision's view.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "report/html_report.hpp"
#include "report/svg_plot.hpp"

namespace report::html {

// A number for the page: 4 significant digits, "&ndash;" for NaN and infinities.
std::string f3(double v);
// A unit for display: powers as superscripts ("m/s^2" -> "m/s²"); empty -> "unit unknown".
std::string pretty_unit(std::string u);
// "ch-<name>" with every character outside [A-Za-z0-9_-] as "_<hex>": a valid id and fragment.
std::string anchor(const std::string& prefix, const std::string& name);
// A bearing finding's fault name (the vocabulary of diag/faults/fault_kind.hpp); "" for gears.
std::string fault_name(const detect::Finding& f);

// The series and marker colours, by mesh, shaft or bearing family.
inline constexpr const char* kColors[] = {"#d62728", "#9467bd", "#ff7f0e",
                                          "#17becf", "#8c564b", "#e377c2"};

// What every section reads: the result, the options and the channels given a section of plots.
struct Page {
  const detect::AnalysisResult& r;
  const HtmlReportOptions& opt;
  std::vector<const detect::ChannelAnalysis*> plotted;  // in order, at most max_channel_sections

  // A channel as the reports name it (channel_label), linked to its section when it has one.
  std::string channel_link(const std::string& name) const;
};

// The folded section of one plotted channel: its verdict, then its figures.
void channel_section(const Page& page, const detect::ChannelAnalysis& c, std::ostringstream& o);

// The fast kurtogram as a map (Antoni 2007, fig. 4): one row per level, one cell per band,
// shaded by kurtosis from white (0 or less) to dark blue (the largest); the band the envelope
// used outlined in black. Frequencies from 0 to fs/2 on x.
std::string kurtogram_svg(const std::vector<detect::KurtogramLevel>& levels, double low_hz,
                          double high_hz, double selected_level, int width_px);

// The spectrogram of a channel: time on x, frequency on y, the PSD in dB over the top 80 dB as
// colour (viridis, with its bar), an indexed-colour PNG inside the SVG. `id` makes the colour
// bar's gradient id unique on the page.
std::string spectrogram_svg(const detect::SpectrogramTrace& s, const std::string& psd_unit,
                            const std::string& id, int width_px);

// One plot per demodulation band the bearing decision used on this channel (bearings on one
// shaft share it), with every scored harmonic of every family: solid where the decision counted
// the line (prominence at or above its threshold), dashed where it expected one and saw none;
// then the lines' table. Empty when no bearing of the channel was diagnosed.
std::string decision_envelope_html(const detect::ChannelAnalysis& c, const PlotOptions& po,
                                   bool orders);

}  // namespace report::html
