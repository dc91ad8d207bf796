// The folded section of one channel in the HTML report (html_page.hpp): its verdict line, then
// folded groups of figures: time waveform, spectrogram and kurtogram; spectra; mesh zooms;
// envelope spectrum and bearings; order spectrum; TSA per shaft; notes.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "html_page.hpp"
#include "report/curves.hpp"
#include "report/report.hpp"

namespace report::html {

using namespace detect;

namespace {

// What the figures of one channel share.
struct ChannelView {
  explicit ChannelView(const ChannelAnalysis& channel) : c(channel) {}
  const ChannelAnalysis& c;
  bool orders = false;   // spectra in the order domain, read at the mean speed
  double input_hz = 0;   // the input shaft's mean speed (0: no gearbox)
  std::string unit;      // for display
  std::string amp_unit;  // the amplitude axes' unit
  int shown = 0;         // findings best seen on this channel
  PlotOptions base;      // the page's plot width
  PlotOptions spectrum;  // the amplitude spectrum's axes; the later spectra start from them
};

ChannelView channel_view(const Page& page, const ChannelAnalysis& c) {
  const AnalysisResult& r = page.r;
  ChannelView v(c);
  v.orders = r.speed.spectra_domain == "order";
  for (const auto& sh : r.shafts) {
    if (sh.shaft == r.input_shaft) v.input_hz = sh.speed_hz;
  }
  v.unit = pretty_unit(c.unit);
  v.amp_unit = c.unit.empty() ? "signal units" : v.unit;
  for (const auto& f : r.findings) v.shown += f.channel == c.name ? 1 : 0;
  v.base.width_px = page.opt.plot_width_px;
  v.spectrum = v.base;
  v.spectrum.title = v.orders ? "Amplitude order spectrum" : "Amplitude spectrum";
  if (c.spectrum_parts > 1) {
    v.spectrum.title += " (power average of " + std::to_string(c.spectrum_parts) + " parts)";
  }
  v.spectrum.x_label =
      v.orders ? "frequency at the mean speed [Hz] (input order x " + f3(v.input_hz) + " Hz)"
               : "frequency [Hz]";
  v.spectrum.y_label = "amplitude [" + v.amp_unit + "]";
  v.spectrum.y_db = true;
  return v;
}

// The section's title line and what the channel is.
void channel_summary(const ChannelView& v, std::ostringstream& o) {
  const ChannelAnalysis& c = v.c;
  o << "<details class=channel id=\"" << anchor("ch-", c.name) << "\"><summary>"
    << html_escape(channel_label(c)) << " "
    << (c.shaft.empty() ? "" : "<span class=note>(shaft " + html_escape(c.shaft) + ")</span> ")
    << (v.shown > 0 ? "<span class=bad>" + std::to_string(v.shown) +
                          (v.shown == 1 ? " finding" : " findings") + "</span>"
                    : std::string(c.sensor ? "<span class=good>no finding</span>"
                                           : "<span class=note>not a sensor: shown only</span>"))
    << "</summary>\n<p class=note>" << html_escape(v.unit) << ", fs " << f3(c.fs_hz) << " Hz, "
    << c.samples << " samples; RMS " << f3(c.time.rms) << ", kurtosis " << f3(c.time.kurtosis)
    << ", crest factor " << f3(c.time.crest_factor) << "</p>\n";
}

// Time waveform, spectrogram and kurtogram.
void time_group(const ChannelView& v, int width_px, std::ostringstream& o) {
  const ChannelAnalysis& c = v.c;
  if (c.waveform.x.size() <= 1 && c.kurtogram.empty()) return;
  o << "<details><summary>Time waveform" << (c.spectrogram.time_s.size() > 1 ? ", spectrogram" : "")
    << (c.kurtogram.empty() ? "" : " and kurtogram") << "</summary>\n";
  if (c.waveform.x.size() > 1) {
    PlotOptions pw = v.base;
    pw.title = "Time waveform";
    pw.x_label = "time [s]";
    pw.y_label = v.amp_unit;
    pw.height_px = 200;
    const PlotSeries ws{c.waveform.x, c.waveform.y, "", "#1f77b4"};
    o << svg_line_plot(std::span(&ws, 1), pw);
  }
  if (c.spectrogram.time_s.size() > 1) {
    o << spectrogram_svg(
        c.spectrogram, (c.unit.empty() ? "unit\u00b2" : pretty_unit(squared_unit(c.unit))) + "/Hz",
        anchor("sg-", c.name), width_px);
  }
  if (!c.kurtogram.empty() && !c.kurtogram.front().kurtosis.empty()) {
    o << kurtogram_svg(c.kurtogram, c.envelope_low_hz, c.envelope_high_hz, c.kurtogram_level,
                       width_px);
  }
  o << "</details>\n";
}

// The amplitude spectrum with the mesh harmonics, and the Welch PSD.
void spectra_group(const ChannelView& v, std::ostringstream& o) {
  const ChannelAnalysis& c = v.c;
  std::vector<PlotMarker> mk;
  for (std::size_t j = 0; j < c.meshes.size(); ++j) {
    for (const auto& l : c.meshes[j].sidebands.mesh) {
      mk.push_back({l.expected_hz,
                    (&l == &c.meshes[j].sidebands.mesh.front() ? c.meshes[j].name : ""),
                    kColors[j % 6], true});
    }
  }
  o << "<details open><summary>Spectra</summary>\n";
  const PlotSeries sp{c.spectrum.x, c.spectrum.y, "", "#1f77b4"};
  o << svg_line_plot(std::span(&sp, 1), v.spectrum, mk);
  if (c.psd.x.size() > 1) {
    PlotOptions pp = v.spectrum;
    pp.title = "Welch PSD (" + f3(c.psd_resolution_hz) + " Hz resolution, " +
               std::to_string(c.psd_segments) + " segments)";
    pp.y_label =
        "PSD [" + (c.unit.empty() ? "units\u00b2" : pretty_unit(squared_unit(c.unit))) + "/Hz]";
    pp.db_power = true;
    pp.height_px = 220;
    const PlotSeries ps{c.psd.x, c.psd.y, "", "#2ca02c"};
    o << svg_line_plot(std::span(&ps, 1), pp);
  }
  o << "</details>\n";
}

// A zoom on each mesh with its candidate shafts' sideband positions (detected lines solid).
void mesh_group(const ChannelView& v, std::ostringstream& o) {
  const ChannelAnalysis& c = v.c;
  bool any_zoom = false;
  for (const auto& m : c.meshes) any_zoom = any_zoom || m.zoom.x.size() >= 2;
  if (!any_zoom) return;
  o << "<details><summary>Meshes: sidebands</summary>\n";
  for (const MeshAnalysis& m : c.meshes) {
    if (m.zoom.x.size() < 2) continue;
    std::vector<PlotMarker> sm{{m.mesh_hz, "mesh", "#000", false}};
    for (std::size_t s = 0; s < m.sidebands.shafts.size(); ++s) {
      for (const auto& l : m.sidebands.shafts[s].lines) {
        if (l.harmonic != 1) continue;
        sm.push_back({l.line.expected_hz, l.order == 1 ? m.sidebands.shafts[s].name : "",
                      kColors[s % 6], !l.detected});
      }
    }
    PlotOptions pz = v.spectrum;
    pz.title = "Mesh " + m.name + " (" + f3(m.mesh_hz) + " Hz): sidebands, status " +
               (m.sidebands.status == SidebandStatus::kPointed
                    ? "pointed at " +
                          m.sidebands.shafts[static_cast<std::size_t>(m.sidebands.pointed)].name
                : m.sidebands.status == SidebandStatus::kAmbiguous ? "ambiguous"
                                                                   : "none");
    pz.height_px = 220;
    const PlotSeries zs{m.zoom.x, m.zoom.y, "", "#1f77b4"};
    o << svg_line_plot(std::span(&zs, 1), pz, sm);
  }
  o << "</details>\n";
}

// The kurtogram band's envelope spectrum with each bearing's fault families labelled (dashed,
// the one decided solid) and the fault bands shaded.
std::string envelope_plot(const ChannelView& v) {
  const ChannelAnalysis& c = v.c;
  std::vector<PlotMarker> fm;
  std::vector<PlotBand> bands;
  static const char* kFamily[] = {"FTF", "BPFO", "BPFI", "2BSF"};
  for (const BearingAnalysis& ba : c.bearings) {
    const double fund[] = {ba.frequencies.ftf_hz, ba.frequencies.bpfo_hz, ba.frequencies.bpfi_hz,
                           ba.frequencies.ball_fault_hz};
    const char* named = ba.diagnosed && ba.diagnosis.status == BearingDecisionStatus::kFault
                            ? finding_name(ba.diagnosis.fault)
                            : "";
    const char* fault_of[] = {"", to_string(BearingFault::kOuterRace),
                              to_string(BearingFault::kInnerRace),
                              to_string(BearingFault::kRollingElement)};
    for (int f = 0; f < 4; ++f) {
      const bool seen = std::string(named) == fault_of[f] && f > 0;
      for (int h = 1; h <= (f == 0 ? 1 : 3); ++h) {  // FTF: the fundamental only
        const std::string label = (h == 1 ? "" : std::to_string(h) + "x") + kFamily[f];
        fm.push_back({h * fund[f], c.bearings.size() > 1 ? ba.bearing + " " + label : label,
                      kColors[(f + 2) % 6], !seen});
      }
    }
    for (const auto& fb : ba.bands) {
      bands.push_back({fb.low_hz, fb.high_hz, "", kColors[(fb.family + 2) % 6]});
    }
  }
  PlotOptions pe = v.spectrum;
  pe.title = std::string(v.orders ? "Envelope order spectrum" : "Envelope spectrum") + ", band " +
             f3(c.envelope_low_hz) + "-" + f3(c.envelope_high_hz) + " Hz (kurtogram" +
             (c.envelope_parts > 1 ? "; the power average of " + std::to_string(c.envelope_parts) +
                                         " parts, each in its own band"
                                   : std::string()) +
             "); fault families dashed, the one decided solid";
  pe.y_label = "amplitude [" + v.amp_unit + "]";
  pe.y_db = false;
  const PlotSeries es{c.envelope.x, c.envelope.y, "", "#8c564b"};
  return svg_line_plot(std::span(&es, 1), pe, fm, bands);
}

// The envelope spectrum: the bearing decision's own when a bearing was diagnosed, else the
// kurtogram band's; then each bearing's fault frequencies and decision.
void envelope_group(const ChannelView& v, std::ostringstream& o) {
  const ChannelAnalysis& c = v.c;
  if (c.envelope.x.size() <= 1) return;
  o << "<details" << (v.shown > 0 ? " open" : "") << "><summary>Envelope spectrum"
    << (c.bearings.empty() ? "" : " and bearings") << "</summary>\n";
  const std::string decided = decision_envelope_html(c, v.spectrum, v.orders);
  o << (decided.empty() ? envelope_plot(v) : decided);
  for (const auto& b : c.bearings) {
    o << "<p class=note>Bearing " << html_escape(b.bearing) << ": FTF " << f3(b.frequencies.ftf_hz)
      << ", BPFO " << f3(b.frequencies.bpfo_hz) << ", BPFI " << f3(b.frequencies.bpfi_hz)
      << ", 2BSF " << f3(b.frequencies.ball_fault_hz)
      << " Hz; decision (prewhitened squared envelope, kurtogram band "
      << f3(b.band_centre_hz - b.band_width_hz / 2) << "-"
      << f3(b.band_centre_hz + b.band_width_hz / 2) << " Hz and whole band): "
      << (!b.diagnosed ? "not run"
          : b.diagnosis.status == BearingDecisionStatus::kFault
              ? "<span class=bad>" + std::string(finding_name(b.diagnosis.fault)) + "</span>"
          : b.diagnosis.status == BearingDecisionStatus::kAmbiguous
              ? "<span class=warn>ambiguous (nothing reported)</span>"
              : "<span class=good>no fault</span>")
      << "</p>\n";
  }
  o << "</details>\n";
}

// The order spectrum, up to a little above the third harmonic of the highest mesh order.
void order_group(const ChannelView& v, const AnalysisResult& r, std::ostringstream& o) {
  const ChannelAnalysis& c = v.c;
  if (c.order_spectrum.x.size() <= 1) return;
  std::vector<PlotMarker> om;
  double top = 0;
  if (v.input_hz > 0) {
    for (std::size_t j = 0; j < r.meshes.size(); ++j) {
      for (int h = 1; h <= 3; ++h) {
        om.push_back({h * r.meshes[j].frequency_hz / v.input_hz, h == 1 ? r.meshes[j].name : "",
                      kColors[j % 6], true});
        top = std::max(top, h * r.meshes[j].frequency_hz / v.input_hz);
      }
    }
  }
  PlotOptions pr = v.spectrum;
  pr.title = "Order spectrum (input-shaft orders)";
  pr.x_label = "order [cycles/rev]";
  pr.y_label = "amplitude [" + v.amp_unit + "]";
  pr.height_px = 220;
  if (top > 0 && top * 1.15 < c.order_spectrum.x.back()) {
    pr.x_min = 0;
    pr.x_max = top * 1.15;
  }
  const PlotSeries os{c.order_spectrum.x, c.order_spectrum.y, "", "#9467bd"};
  o << "<details><summary>Order spectrum</summary>\n"
    << svg_line_plot(std::span(&os, 1), pr, om) << "</details>\n";
}

// The gear indicators of the gears on one shaft.
void gear_table(const ShaftTsaAnalysis& t, std::ostringstream& o) {
  if (t.gears.empty()) return;
  o << "<table><tr><th class=l>gear</th><th>z</th><th>FM0</th><th>FM4</th><th>M6A</th>"
       "<th>M8A</th><th>NA4</th><th>ER</th><th>SER</th><th>SLF</th><th>SI</th></tr>";
  for (const auto& g : t.gears) {
    const auto& i = g.indicators;
    o << "<tr><td class=l>" << html_escape(g.gear) << "</td><td>" << g.teeth << "</td><td>"
      << f3(i.fm0) << "</td><td>" << f3(i.fm4) << "</td><td>" << f3(i.m6a) << "</td><td>"
      << f3(i.m8a) << "</td><td>" << f3(i.na4) << "</td><td>" << f3(i.er) << "</td><td>"
      << f3(i.ser) << "</td><td>" << f3(i.slf) << "</td><td>" << f3(i.si) << "</td></tr>";
  }
  o << "</table>\n";
}

// Per shaft: the TSA and, on its own scale, the difference signal, with the gear indicators.
void tsa_group(const ChannelView& v, std::ostringstream& o) {
  for (const auto& t : v.c.tsa) {
    o << "<details><summary>TSA of shaft " << html_escape(t.shaft) << "</summary>\n";
    if (!t.computed) {
      o << "<p class=note>" << html_escape(t.note) << "</p>\n</details>\n";
      continue;
    }
    std::vector<double> angle(t.tsa.size());
    for (std::size_t i = 0; i < angle.size(); ++i) {
      angle[i] = 360.0 * static_cast<double>(i) / static_cast<double>(angle.size());
    }
    PlotOptions pt = v.spectrum;
    pt.title = "TSA of shaft " + t.shaft + " (" + std::to_string(t.revolutions) + " revolutions)";
    pt.x_label = "shaft angle [deg]";
    pt.y_label = v.amp_unit;
    pt.y_db = false;
    pt.height_px = 200;
    const PlotSeries ts{angle, t.tsa, "", "#1f77b4"};
    o << svg_line_plot(std::span(&ts, 1), pt);
    pt.title = "Difference signal of shaft " + t.shaft +
               " (TSA less shaft orders, mesh harmonics and first sidebands)";
    const PlotSeries td{angle, t.difference, "", "#d62728"};
    o << svg_line_plot(std::span(&td, 1), pt);
    if (!t.note.empty()) o << "<p class=note>" << html_escape(t.note) << "</p>\n";
    gear_table(t, o);
    o << "</details>\n";
  }
}

}  // namespace

void channel_section(const Page& page, const ChannelAnalysis& c, std::ostringstream& o) {
  const ChannelView v = channel_view(page, c);
  channel_summary(v, o);
  time_group(v, page.opt.plot_width_px, o);
  spectra_group(v, o);
  mesh_group(v, o);
  envelope_group(v, o);
  order_group(v, page.r, o);
  tsa_group(v, o);
  if (!c.notes.empty()) {
    o << "<details><summary>Notes (" << c.notes.size() << ")</summary>\n";
    for (const auto& n : c.notes) o << "<p class=note>" << html_escape(n) << "</p>\n";
    o << "</details>\n";
  }
  o << "</details>\n";
}

}  // namespace report::html
