// The reports of an analysis (detect::analyze_recording, detect/analysis/analyze.hpp): what a
// person or another program reads. The detectors compute; this library only writes what they
// found, and depends on the detectors and libdiag, never the other way round.
//
//   report.hpp       to_json (the JSON of `geardiag analyze --json`), format_summary (the terminal
//                    summary), channel_label (how every report names a channel)
//   html_report.hpp  render_html_report: one self-contained HTML page (`--html`)
//   svg_plot.hpp     the inline SVG line plots of the HTML pages (analyze, batch, validate)
//   curves.hpp       analysis_curves: every drawn curve as named columns (`--curves`, Python)
//   png.hpp, base64.hpp, colour_map.hpp
//                    the spectrogram image: an 8-bit palette PNG, base64 for a data: URI, and
//                    the viridis colour map
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "detect/analysis/analyze.hpp"

namespace report {

// JSON with stable keys (README "geardiag analyze"). Amplitudes are in each channel's "unit"
// (energies in unit^2, PSD in unit^2/Hz); keys with a physical unit of their own carry it
// (frequency_hz, speed_hz, ..._db). Traces (plots) are not serialised.
nlohmann::json to_json(const detect::AnalysisResult& r);

// A readable multi-line summary for the terminal.
std::string format_summary(const detect::AnalysisResult& r);

// What a channel is, for people, wherever a report names a channel (the HTML report, the
// summary): "drive end accelerometer (X105_DE_time)", from its role, unit, location and
// direction (the channel contract, diag/io/channels.hpp), never parsed from its name. By name: the
// label of that channel of r, the name itself when r has no such channel.
std::string channel_label(const detect::ChannelAnalysis& c);
std::string channel_label(const detect::AnalysisResult& r, const std::string& name);

}  // namespace report
