#include "detect/analysis/html_report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "detect/analysis/svg_plot.hpp"
#include "diag/error.hpp"

namespace detect {

namespace {

std::string f3(double v) {
  if (!std::isfinite(v)) return "&ndash;";
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

const char* kCss = R"(body{font-family:sans-serif;margin:1.5em;color:#222;max-width:1100px}
h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ccc;margin-top:1.6em}
h3{font-size:1.05em;margin-top:1.2em}table{border-collapse:collapse;margin:.5em 0;font-size:.9em}
td,th{border:1px solid #ccc;padding:3px 7px;text-align:right}th{background:#f2f2f2}
td.l,th.l{text-align:left}.alarm{color:#b00;font-weight:bold}.ok{color:#070}
.note{color:#666;font-size:.9em}svg{display:block;margin:.4em 0}
)";

const char* kColors[] = {"#d62728", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2"};

}  // namespace

void HtmlReportOptions::validate() const {
  if (max_channel_sections < 0) {
    throw diag::InputError("html_report: max_channel_sections: is not >= 0");
  }
  if (plot_width_px < 200 || plot_width_px > 4000) {
    throw diag::InputError("html_report: plot_width_px: " + std::to_string(plot_width_px) +
                           " is not in [200, 4000]");
  }
}

std::string render_html_report(const AnalysisResult& r, const HtmlReportOptions& opt) {
  opt.validate();
  std::ostringstream o;
  o << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
    << html_escape(opt.title) << "</title><style>" << kCss << "</style></head><body>\n";
  o << "<h1>" << html_escape(opt.title) << "</h1>\n<p>";
  if (!opt.source.empty()) o << "Recording <b>" << html_escape(opt.source) << "</b>, ";
  o << r.channels.size() << " channels, " << f3(r.duration_s) << " s";
  if (!r.gearbox_name.empty()) o << ", gearbox <b>" << html_escape(r.gearbox_name) << "</b>";
  o << ".</p>\n";
  if (!r.shafts.empty()) {
    o << "<table><tr><th class=l>shaft</th><th>speed [rpm]</th><th>speed [Hz]</th>"
         "<th class=l>source</th></tr>";
    for (const auto& s : r.shafts) {
      o << "<tr><td class=l>" << html_escape(s.shaft) << "</td><td>" << f3(s.speed_hz * 60)
        << "</td><td>" << f3(s.speed_hz) << "</td><td class=l>" << html_escape(s.source)
        << "</td></tr>";
    }
    o << "</table>\n<table><tr><th class=l>mesh</th><th>frequency [Hz]</th></tr>";
    for (const auto& m : r.meshes) {
      o << "<tr><td class=l>" << html_escape(m.name) << "</td><td>" << f3(m.frequency_hz)
        << "</td></tr>";
    }
    o << "</table>\n";
  }
  for (const auto& n : r.notes) o << "<p class=note>" << html_escape(n) << "</p>\n";
  // ---- speed over time (from the tacho or the vibration) ----
  if (r.speed.time_s.size() > 1) {
    PlotOptions ps;
    ps.title = "Speed of " + r.speed.reference_shaft + " from the " + r.speed.source +
               (r.speed.stationary ? " (stationary)" : " (varying)");
    ps.x_label = "time [s]";
    ps.y_label = "speed [rpm]";
    ps.height_px = 200;
    const PlotSeries series{r.speed.time_s, r.speed.speed_rpm, "", "#1f77b4"};
    o << svg_line_plot(std::span(&series, 1), ps);
  }

  // ---- findings ----
  o << "<h2 id=findings>Findings</h2>\n";
  if (r.baseline) {
    o << "<p>Anomaly score against the baseline: <b>" << f3(r.baseline->anomaly_score)
      << "</b> (threshold " << f3(r.baseline->threshold) << "): "
      << (r.baseline->alarm ? "<span class=alarm>ALARM</span>" : "<span class=ok>normal</span>")
      << "</p>\n";
  }
  if (r.findings.empty()) {
    o << "<p>No finding.</p>\n";
  } else {
    o << "<table><tr><th class=l>kind</th><th class=l>shaft / gears</th><th class=l>bearing / "
         "fault</th><th>frequency [Hz]</th><th class=l>channel</th><th>confidence</th>"
         "<th class=l>note</th></tr>";
    for (const auto& f : r.findings) {
      std::string gears;
      for (const auto& g : f.gears) gears += (gears.empty() ? "" : ", ") + g;
      o << "<tr><td class=l>" << html_escape(f.kind) << "</td><td class=l>" << html_escape(f.shaft)
        << (gears.empty() ? "" : " (" + html_escape(gears) + ")") << "</td><td class=l>"
        << html_escape(f.bearing) << " " << html_escape(f.fault) << "</td><td>"
        << f3(f.frequency_hz) << "</td><td class=l>" << html_escape(f.channel) << "</td><td>"
        << f3(f.confidence) << "</td><td class=l>" << html_escape(f.note) << "</td></tr>";
    }
    o << "</table>\n";
  }

  // ---- damaged-shaft location ----
  if (r.gear_damage) {
    const GearDamageResult& g = *r.gear_damage;
    o << "<h2 id=gear-damage>Damaged-shaft location (TSA per shaft)</h2>\n"
         "<p class=note>Per shaft: the time-synchronous average over its revolutions (angles "
         "from the "
      << html_escape(r.gear_damage_angles)
      << "), less the shaft order, the mesh harmonics and their first sidebands, and less the "
         "orders a faster shaft shares. Score: per gear on the shaft, the largest energy of one "
         "tooth pitch of what is left over the median of the other teeth (1: no tooth stands "
         "out; ordinary pitch errors stay below about 15; damaged above "
      << f3(GearDamageOptions{}.damaged_fm4)
      << " with the default options); SNR: its energy over the noise's (1: noise alone); level: "
         "its RMS over the regular signal's.</p>\n<p>Status: <b>"
      << html_escape(g.status) << "</b></p>\n"
      << "<table><tr><th class=l>shaft</th><th>speed [Hz]</th><th>revolutions</th>"
         "<th class=l>channel</th><th>score</th><th>SNR</th><th>level</th><th>exclusive share"
         "</th><th class=l>verdict</th></tr>";
    for (const auto& s : g.shafts) {
      o << "<tr><td class=l>" << html_escape(s.shaft) << "</td><td>" << f3(s.frequency_hz)
        << "</td><td>" << s.revolutions << "</td><td class=l>" << html_escape(s.channel)
        << "</td><td><b>" << f3(s.score) << "</b></td><td>" << f3(s.snr) << "</td><td>"
        << f3(s.level) << "</td><td>" << f3(s.exclusive_share) << "</td><td class=l>"
        << (s.revolutions == 0 ? "skipped"
            : s.damaged        ? "<span class=alarm>damaged</span>"
            : s.uncertain      ? "uncertain"
                               : "<span class=ok>no localised fault</span>")
        << "</td></tr>";
    }
    o << "</table>\n";
    if (!g.note.empty()) o << "<p class=note>" << html_escape(g.note) << "</p>\n";
  }

  // ---- two directions ----
  o << "<h2 id=two-direction>Two directions: along and normal to the line of action</h2>\n";
  if (r.two_direction.empty()) {
    o << "<p class=note>No location with both an along_loa and a normal_loa channel (or no "
         "gearbox).</p>\n";
  } else {
    o << "<p class=note>Energy (mean square) at the mesh harmonics; normal/along ratio in dB: "
         "friction/surface-condition indicator (higher: more friction-driven vibration).</p>"
         "<table><tr><th class=l>location</th><th class=l>mesh</th><th>mesh [Hz]</th>"
         "<th>along energy</th><th>normal energy</th><th>normal/along [dB]</th>"
         "<th class=l>channels</th></tr>";
    for (const auto& t : r.two_direction) {
      o << "<tr><td class=l>" << html_escape(t.location) << "</td><td class=l>"
        << html_escape(t.mesh) << "</td><td>" << f3(t.comparison.mesh_hz) << "</td><td>"
        << f3(t.comparison.along_energy) << "</td><td>" << f3(t.comparison.normal_energy)
        << "</td><td><b>" << f3(t.comparison.normal_to_along_db) << "</b></td><td class=l>"
        << html_escape(t.along_channel) << " / " << html_escape(t.normal_channel) << "</td></tr>";
    }
    o << "</table>\n";
  }

  // ---- indicators ----
  o << "<h2 id=indicators>Indicators</h2>\n<table><tr><th class=l>channel</th><th class=l>unit"
       "</th><th class=l>direction</th><th>RMS</th><th>peak</th><th>crest</th><th>kurtosis</th>"
       "<th>skewness</th></tr>";
  for (const auto& c : r.channels) {
    o << "<tr><td class=l>" << html_escape(c.name) << "</td><td class=l>" << html_escape(c.unit)
      << "</td><td class=l>" << diag::to_string(c.direction) << "</td><td>" << f3(c.time.rms)
      << "</td><td>" << f3(c.time.peak) << "</td><td>" << f3(c.time.crest_factor) << "</td><td>"
      << f3(c.time.kurtosis) << "</td><td>" << f3(c.time.skewness) << "</td></tr>";
  }
  o << "</table>\n";
  if (r.baseline) {
    const AnalysisBaseline& b = *r.baseline;
    o << "<h3 id=baseline>Against the baseline</h3>\n<p>Anomaly score <b>" << f3(b.anomaly_score)
      << "</b> (mean z&sup2; over " << b.deviations.size() << " features; threshold "
      << f3(b.threshold)
      << "): " << (b.alarm ? "<span class=alarm>ALARM</span>" : "<span class=ok>normal</span>")
      << ". Baseline: " << b.recordings.size() << " recordings, " << b.samples
      << " samples; channels compared: ";
    for (std::size_t k = 0; k < b.channels.size(); ++k)
      o << (k ? ", " : "") << html_escape(b.channels[k]);
    o << ".</p>\n";
    for (const auto& n : b.notes) o << "<p class=note>" << html_escape(n) << "</p>\n";
    o << "<p class=note>z = (value &minus; baseline median) / robust spread (1.4826 MAD, at "
         "least the spread floor); features are unit-free (baseline.hpp), largest |z| first.</p>"
         "<table><tr><th class=l>feature</th><th>value</th><th>baseline median</th>"
         "<th>robust spread</th><th>z</th></tr>";
    for (const auto& d : b.deviations) {
      const bool big = d.z * d.z > b.threshold;  // alone above the threshold: highlighted
      o << "<tr><td class=l>" << html_escape(d.feature) << "</td><td>" << f3(d.value) << "</td><td>"
        << f3(d.baseline_centre) << "</td><td>" << f3(d.baseline_spread) << "</td><td>"
        << (big ? "<span class=alarm>" : "") << f3(d.z) << (big ? "</span>" : "") << "</td></tr>";
    }
    o << "</table>\n";
  }

  // ---- per channel ----
  int sections = 0;
  for (const auto& c : r.channels) {
    if (!c.vibration || c.spectrum.x.empty()) continue;
    if (sections++ >= opt.max_channel_sections) {
      o << "<p class=note>Further channels are listed in the tables only (max_channel_sections = "
        << opt.max_channel_sections << ").</p>\n";
      break;
    }
    const std::string unit = c.unit.empty() ? "units" : c.unit;
    o << "<h2 id=\"ch-" << html_escape(c.name) << "\">Channel " << html_escape(c.name) << "</h2>\n"
      << "<p class=note>" << html_escape(unit) << ", " << diag::to_string(c.direction)
      << (c.location.empty() ? "" : ", at " + html_escape(c.location)) << ", fs " << f3(c.fs_hz)
      << " Hz, " << c.samples << " samples</p>\n";
    PlotOptions po;
    po.width_px = opt.plot_width_px;
    // Spectrum with the mesh harmonics.
    std::vector<PlotMarker> mk;
    for (std::size_t j = 0; j < c.meshes.size(); ++j) {
      for (const auto& l : c.meshes[j].sidebands.mesh) {
        mk.push_back({l.expected_hz,
                      (&l == &c.meshes[j].sidebands.mesh.front() ? c.meshes[j].name : ""),
                      kColors[j % 6], true});
      }
    }
    // At varying speed the spectra are order spectra read at the mean speed (analyze.hpp).
    const bool orders = r.speed.spectra_domain == "order";
    double input_hz = 0;
    for (const auto& sh : r.shafts) {
      if (sh.shaft == r.input_shaft) input_hz = sh.speed_hz;
    }
    po.title = orders ? "Amplitude order spectrum" : "Amplitude spectrum";
    po.x_label = orders ? "frequency at the mean speed [Hz] (input order x " + f3(input_hz) + " Hz)"
                        : "frequency [Hz]";
    po.y_label = "amplitude [" + unit + "]";
    po.y_db = true;
    const PlotSeries sp{c.spectrum.x, c.spectrum.y, "", "#1f77b4"};
    o << svg_line_plot(std::span(&sp, 1), po, mk);
    // Zoom on each mesh with sideband positions.
    for (std::size_t j = 0; j < c.meshes.size(); ++j) {
      const MeshAnalysis& m = c.meshes[j];
      if (m.zoom.x.size() < 2) continue;
      std::vector<PlotMarker> sm{{m.mesh_hz, "mesh", "#000", false}};
      for (std::size_t s = 0; s < m.sidebands.shafts.size(); ++s) {
        for (const auto& l : m.sidebands.shafts[s].lines) {
          if (l.harmonic != 1) continue;
          sm.push_back({l.line.expected_hz, l.order == 1 ? m.sidebands.shafts[s].name : "",
                        kColors[s % 6], !l.detected});
        }
      }
      PlotOptions pz = po;
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
    // Welch PSD.
    if (c.psd.x.size() > 1) {
      PlotOptions pp = po;
      pp.title = "Welch PSD (" + f3(c.psd_resolution_hz) + " Hz resolution, " +
                 std::to_string(c.psd_segments) + " segments)";
      pp.y_label = "PSD [" + unit + "^2/Hz]";
      pp.db_power = true;
      pp.height_px = 220;
      const PlotSeries ps{c.psd.x, c.psd.y, "", "#2ca02c"};
      o << svg_line_plot(std::span(&ps, 1), pp);
    }
    // Envelope with the bearing fault bands.
    if (c.envelope.x.size() > 1) {
      std::vector<PlotBand> bands;
      for (std::size_t b = 0; b < c.bearings.size(); ++b) {
        for (const auto& fb : c.bearings[b].bands) {
          bands.push_back({fb.low_hz, fb.high_hz, c.bearings[b].bearing + " " + fb.label,
                           kColors[(fb.family + 2) % 6]});
        }
      }
      PlotOptions pe = po;
      pe.title = std::string(orders ? "Envelope order spectrum" : "Envelope spectrum") + ", band " +
                 f3(c.envelope_low_hz) + "-" + f3(c.envelope_high_hz) + " Hz (kurtogram)";
      pe.y_db = false;
      const PlotSeries es{c.envelope.x, c.envelope.y, "", "#8c564b"};
      o << svg_line_plot(std::span(&es, 1), pe, {}, bands);
      for (const auto& b : c.bearings) {
        o << "<p class=note>Bearing " << html_escape(b.bearing) << ": FTF "
          << f3(b.frequencies.ftf_hz) << ", BPFO " << f3(b.frequencies.bpfo_hz) << ", BPFI "
          << f3(b.frequencies.bpfi_hz) << ", ball " << f3(b.frequencies.ball_fault_hz)
          << " Hz; decision (prewhitened squared envelope, kurtogram band "
          << f3(b.band_centre_hz - b.band_width_hz / 2) << "-"
          << f3(b.band_centre_hz + b.band_width_hz / 2) << " Hz and whole band): "
          << (!b.diagnosed ? "not run"
              : b.diagnosis.status == BearingDecisionStatus::kFault
                  ? std::string(finding_name(b.diagnosis.fault))
              : b.diagnosis.status == BearingDecisionStatus::kAmbiguous
                  ? "ambiguous (nothing reported)"
                  : "no fault")
          << "</p>\n";
      }
    }
    // Order spectrum.
    if (c.order_spectrum.x.size() > 1) {
      std::vector<PlotMarker> om;
      double fin = 0;
      for (const auto& sh : r.shafts) {
        if (sh.shaft == r.input_shaft) fin = sh.speed_hz;
      }
      if (fin > 0) {
        for (std::size_t j = 0; j < r.meshes.size(); ++j) {
          for (int h = 1; h <= 3; ++h) {
            om.push_back({h * r.meshes[j].frequency_hz / fin, h == 1 ? r.meshes[j].name : "",
                          kColors[j % 6], true});
          }
        }
      }
      PlotOptions pr = po;
      pr.title = "Order spectrum (input-shaft orders)";
      pr.x_label = "order [cycles/rev]";
      pr.height_px = 220;
      const PlotSeries os{c.order_spectrum.x, c.order_spectrum.y, "", "#9467bd"};
      o << svg_line_plot(std::span(&os, 1), pr, om);
    }
    // TSA per shaft.
    for (const auto& t : c.tsa) {
      if (!t.computed) {
        o << "<p class=note>TSA of shaft " << html_escape(t.shaft) << ": " << html_escape(t.note)
          << "</p>\n";
        continue;
      }
      std::vector<double> angle(t.tsa.size());
      for (std::size_t i = 0; i < angle.size(); ++i) {
        angle[i] = 360.0 * static_cast<double>(i) / static_cast<double>(angle.size());
      }
      PlotOptions pt = po;
      pt.title = "TSA of shaft " + t.shaft + " (" + std::to_string(t.revolutions) + " revolutions)";
      pt.x_label = "shaft angle [deg]";
      pt.y_label = unit;
      pt.y_db = false;
      pt.height_px = 220;
      const PlotSeries ts[] = {{angle, t.tsa, "TSA", "#1f77b4"},
                               {angle, t.difference, "difference", "#d62728"}};
      o << svg_line_plot(ts, pt);
      if (!t.gears.empty()) {
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
    }
    for (const auto& n : c.notes) o << "<p class=note>" << html_escape(n) << "</p>\n";
  }
  o << "<p class=note>Generated by geardiag analyze.</p>\n</body></html>\n";
  return o.str();
}

}  // namespace detect
