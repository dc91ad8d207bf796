// render_html_report (html_report.hpp): the page, its recording-level sections in order, and
// the folded section of each plotted channel (html_channel.cpp).
#include "report/html_report.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include "diag/error.hpp"
#include "html_page.hpp"
#include "report/report.hpp"
#include "report/svg_plot.hpp"

namespace report {

namespace html {

using namespace detect;

std::string f3(double v) {
  if (!std::isfinite(v)) return "&ndash;";
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

std::string pretty_unit(std::string u) {
  if (u.empty()) return "unit unknown";
  for (const auto& [from, to] : {std::pair{"^2", "\u00b2"}, std::pair{"^3", "\u00b3"}}) {
    for (std::size_t i = u.find(from); i != std::string::npos; i = u.find(from, i)) {
      u.replace(i, 2, to);
    }
  }
  return u;
}

std::string anchor(const std::string& prefix, const std::string& name) {
  std::string a = prefix;
  for (unsigned char ch : name) {
    if (std::isalnum(ch) || ch == '-' || ch == '_') {
      a += static_cast<char>(ch);
    } else {
      char b[8];
      std::snprintf(b, sizeof b, "_%02x", ch);
      a += b;
    }
  }
  return a;
}

std::string fault_name(const Finding& f) {
  return f.bearing.empty() ? "" : std::string(diag::to_string(f.fault));
}

std::string Page::channel_link(const std::string& name) const {
  const std::string label = html_escape(channel_label(r, name));
  for (const ChannelAnalysis* c : plotted) {
    if (c->name == name) return "<a href=\"#" + anchor("ch-", name) + "\">" + label + "</a>";
  }
  return label;
}

namespace {

// One verdict colour scheme for the whole page: .bad (red: a finding, an ALARM, a damaged
// shaft), .warn (amber: uncertain, ambiguous), .good (green: nothing found). Healthy is never red.
const char* kCss = R"(body{font-family:sans-serif;margin:1.5em;color:#222;max-width:1100px}
h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ccc;margin-top:1.6em}
h3{font-size:1.05em;margin-top:1.2em}table{border-collapse:collapse;margin:.5em 0;font-size:.9em}
td,th{border:1px solid #ccc;padding:3px 7px;text-align:right}th{background:#f2f2f2}
td.l,th.l{text-align:left}.bad{color:#b00;font-weight:bold}.warn{color:#a60;font-weight:bold}
.good{color:#070}.note{color:#666;font-size:.9em}svg{display:block;margin:.4em 0;max-width:100%;
height:auto}.verdict{padding:.6em 1em;border-left:6px solid #888;background:#f4f4f4;margin:1em 0}
.verdict.bad{border-color:#b00;background:#fdecea;color:#222;font-weight:normal}
.verdict.good{border-color:#070;background:#eaf6ea;color:#222}.verdict h2{margin-top:0;border:0}
.verdict.warn{border-color:#a60;background:#fdf3e1;color:#222;font-weight:normal}
.verdict li{margin:.3em 0}nav.toc ol{columns:2;font-size:.95em}details{margin:.4em 0}
details>summary{cursor:pointer;font-weight:bold;padding:.3em 0}details.channel>summary{
font-size:1.15em;border-bottom:1px solid #ccc}details details{margin-left:1em}
table{max-width:100%;overflow-x:auto;display:block}
)";

bool baseline_alarm(const AnalysisResult& r) { return r.baseline && r.baseline->alarm; }

// One line of evidence for a finding; `channel` is the link to (or the label of) the channel that
// shows it best.
std::string finding_line(const Finding& f, const std::string& channel) {
  std::string gears;
  for (const auto& g : f.gears) gears += (gears.empty() ? "" : ", ") + g;
  std::string what = f.kind == "bearing"       ? "bearing " + f.bearing + ": " + fault_name(f)
                     : f.kind == "gear_damage" ? "damaged gear on shaft " + f.shaft
                     : f.kind == "baseline"    ? std::string("ALARM against the baseline")
                                               : f.kind + " on shaft " + f.shaft;
  if (!gears.empty() && f.kind != "bearing") what += " (" + gears + ")";
  std::string line = "<b>" + html_escape(what) + "</b>, confidence " + f3(f.confidence);
  if (std::isfinite(f.frequency_hz)) line += ", at " + f3(f.frequency_hz) + " Hz";
  if (!f.channel.empty()) line += ", best seen on " + channel;
  if (!f.note.empty()) line += ". " + html_escape(f.note);
  return line;
}

bool incomplete(const AnalysisResult& r) { return r.coverage && !r.coverage->complete(); }

// What was examined: the recording's length, the frames, what was not examined and why.
void coverage_lines(const AnalysisResult& r, std::ostringstream& o) {
  if (!r.coverage) return;
  const AnalysisCoverage& c = *r.coverage;
  o << "<p>Examined " << f3(c.analysed_s) << " s of " << f3(c.duration_s) << " s";
  if (c.frames > 1) {
    o << " in " << c.frames_examined << " of " << c.frames << " frames of " << f3(c.frame_s)
      << " s (<a href=\"#timeline\">timeline</a>)";
  }
  o << (c.complete() ? ": every sample." : ": <span class=warn>not every sample</span>.")
    << "</p>\n";
  if (!c.not_examined.empty()) {
    o << "<ul>";
    for (const std::string& n : c.not_examined)
      o << "<li>not examined: " << html_escape(n) << "</li>";
    o << "</ul>\n";
  }
}

// The document's head and the title line.
void page_head(const Page& p, std::ostringstream& o) {
  const AnalysisResult& r = p.r;
  o << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"viewport\" "
       "content=\"width=device-width\"><title>"
    << html_escape(p.opt.title) << "</title><style>" << kCss << "</style></head><body>\n";
  o << "<h1>" << html_escape(p.opt.title) << "</h1>\n<p>";
  if (!p.opt.source.empty()) o << "Recording <b>" << html_escape(p.opt.source) << "</b>, ";
  o << r.channels.size() << " channels, " << f3(r.duration_s) << " s";
  if (!r.gearbox_name.empty()) o << ", gearbox <b>" << html_escape(r.gearbox_name) << "</b>";
  o << ".</p>\n";
}

// The verdict: every finding with its evidence (a baseline alarm is one: set_baseline).
void verdict_section(const Page& p, std::ostringstream& o) {
  const AnalysisResult& r = p.r;
  bool uncertain = false;
  if (r.gear_damage) {
    for (const auto& s : r.gear_damage->shafts) uncertain = uncertain || s.uncertain;
  }
  const std::size_t n_findings = r.findings.size();
  // A recording not fully examined is never "no finding" in green.
  const bool partial = incomplete(r);
  o << "<section id=summary class=\"verdict "
    << (n_findings > 0 ? "bad"
        : partial      ? "warn"
        : uncertain    ? ""
                       : "good")
    << "\"><h2>Verdict: "
    << (n_findings > 0 ? std::to_string(n_findings) + (n_findings == 1 ? " finding" : " findings")
        : partial      ? "not fully examined"
        : uncertain    ? "no finding, one shaft uncertain"
                       : "no finding")
    << "</h2>\n";
  coverage_lines(r, o);
  if (n_findings == 0) {
    o << "<p>Nothing points at a shaft, gear or bearing"
      << (partial ? " in the part examined; the rest was not looked at" : "")
      << (r.baseline ? "; the recording is within its baseline" : "") << ".</p>\n";
  } else {
    o << "<ol>";
    for (const auto& f : r.findings) {
      o << "<li>" << finding_line(f, p.channel_link(f.channel)) << "</li>";
    }
    o << "</ol>\n";
  }
  if (r.baseline && !baseline_alarm(r)) {
    o << "<p>Against the baseline: <span class=good>normal</span> (anomaly score "
      << f3(r.baseline->anomaly_score) << ", threshold " << f3(r.baseline->threshold) << ").</p>\n";
  }
  o << "</section>\n";
}

// The table of contents: links to the sections' ids.
void contents_section(const Page& p, std::ostringstream& o) {
  const AnalysisResult& r = p.r;
  o << "<nav class=toc><h2 id=contents>Contents</h2><ol>"
       "<li><a href=\"#summary\">Verdict</a></li><li><a href=\"#machine\">Machine and speed</a>"
       "</li><li><a href=\"#findings\">Findings</a></li>";
  if (r.segments.size() > 1) o << "<li><a href=\"#timeline\">Timeline</a></li>";
  if (r.gear_damage) o << "<li><a href=\"#gear-damage\">Damaged-shaft location</a></li>";
  if (!r.two_direction.empty()) o << "<li><a href=\"#two-direction\">Two directions</a></li>";
  o << "<li><a href=\"#indicators\">Indicators</a></li>";
  if (r.baseline) o << "<li><a href=\"#baseline\">Against the baseline</a></li>";
  for (const ChannelAnalysis* c : p.plotted) {
    o << "<li><a href=\"#" << anchor("ch-", c->name) << "\">" << html_escape(channel_label(*c))
      << "</a></li>";
  }
  o << "</ol></nav>\n";
}

// The machine: shafts, meshes, notes (folded), the speed over time (from the tacho or the
// vibration).
void machine_section(const Page& p, std::ostringstream& o) {
  const AnalysisResult& r = p.r;
  o << "<h2 id=machine>Machine and speed</h2>\n";
  if (!r.shafts.empty()) {
    o << "<table><tr><th class=l>shaft</th><th>speed [rpm]</th><th>speed [Hz]</th>"
         "<th class=l>source</th></tr>";
    for (const auto& s : r.shafts) {
      o << "<tr><td class=l>" << html_escape(s.shaft) << "</td><td>" << f3(s.speed_hz * 60)
        << "</td><td>" << f3(s.speed_hz) << "</td><td class=l>" << html_escape(s.source)
        << "</td></tr>";
    }
    o << "</table>\n";
    if (!r.meshes.empty()) {
      o << "<table><tr><th class=l>mesh</th><th>frequency [Hz]</th></tr>";
      for (const auto& m : r.meshes) {
        o << "<tr><td class=l>" << html_escape(m.name) << "</td><td>" << f3(m.frequency_hz)
          << "</td></tr>";
      }
      o << "</table>\n";
    }
  } else {
    o << "<p class=note>No gearbox description: only the unit-free indicators and spectra.</p>\n";
  }
  if (!r.notes.empty()) {
    o << "<details><summary>Notes (" << r.notes.size() << ")</summary>\n";
    for (const auto& n : r.notes) o << "<p class=note>" << html_escape(n) << "</p>\n";
    o << "</details>\n";
  }
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
}

// The findings table (the baseline ALARM first: it is a finding, counted in the verdict).
void findings_section(const Page& p, std::ostringstream& o) {
  const AnalysisResult& r = p.r;
  o << "<h2 id=findings>Findings</h2>\n";
  if (r.findings.empty()) {
    o << (incomplete(r) ? "<p class=warn>No finding in the part examined (not every sample).</p>\n"
                        : "<p class=good>No finding.</p>\n");
    return;
  }
  o << "<table><tr><th class=l>kind</th><th class=l>shaft / gears</th><th class=l>bearing / "
       "fault</th><th>frequency [Hz]</th><th class=l>channel</th><th>confidence</th>"
       "<th>seen [s]</th><th class=l>note</th></tr>";
  for (const auto& f : r.findings) {
    std::string gears;
    for (const auto& g : f.gears) gears += (gears.empty() ? "" : ", ") + g;
    o << "<tr><td class=l><span class=bad>"
      << html_escape(f.kind == "baseline" ? "baseline ALARM" : f.kind) << "</span></td><td class=l>"
      << html_escape(f.shaft) << (gears.empty() ? "" : " (" + html_escape(gears) + ")")
      << "</td><td class=l>" << html_escape(f.bearing) << " " << html_escape(fault_name(f))
      << "</td><td>" << f3(f.frequency_hz) << "</td><td class=l>" << p.channel_link(f.channel)
      << "</td><td>" << f3(f.confidence) << "</td><td>"
      << (std::isfinite(f.first_s) ? f3(f.first_s) + "&ndash;" + f3(f.last_s)
                                   : std::string("&ndash;"))
      << "</td><td class=l>" << html_escape(f.note) << "</td></tr>";
  }
  o << "</table>\n";
}

// The frames of a long recording over time: the speed and the main indicators of each frame, the
// frames with a finding shaded red, those not examined grey; then the table of frames.
void timeline_section(const Page& p, std::ostringstream& o) {
  const AnalysisResult& r = p.r;
  if (r.segments.size() < 2) return;
  o << "<h2 id=timeline>Timeline</h2>\n";
  std::vector<double> t, speed;
  std::vector<PlotBand> bands;
  for (const AnalysisSegment& s : r.segments) {
    if (s.verdict == "finding") bands.push_back({s.start_s, s.end_s, "", "#d62728"});
    if (s.verdict == "not examined") bands.push_back({s.start_s, s.end_s, "", "#888888"});
    if (std::isfinite(s.speed_rpm)) {
      t.push_back(0.5 * (s.start_s + s.end_s));
      speed.push_back(s.speed_rpm);
    }
  }
  PlotOptions po;
  po.x_label = "time [s]";
  po.height_px = 200;
  po.x_min = 0;
  po.x_max = r.segments.back().end_s;
  if (t.size() > 1) {
    po.title = "Speed per frame (red: a finding, grey: not examined)";
    po.y_label = "speed [rpm]";
    const PlotSeries series{t, speed, "", "#1f77b4"};
    o << svg_line_plot(std::span(&series, 1), po, {}, bands);
  }
  // The main indicators of the sensor channels (the first six).
  static const char* kColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c",
                                   "#9467bd", "#8c564b", "#17becf"};
  for (const auto& [title, field] :
       {std::pair{"RMS", &TimeIndicators::rms}, std::pair{"kurtosis", &TimeIndicators::kurtosis}}) {
    std::vector<std::string> names;
    for (const AnalysisSegment& s : r.segments) {
      for (const std::string& n : s.channels) {
        if (names.size() < 6 && std::find(names.begin(), names.end(), n) == names.end()) {
          names.push_back(n);
        }
      }
    }
    std::vector<std::vector<double>> xs(names.size()), ys(names.size());
    for (const AnalysisSegment& s : r.segments) {
      for (std::size_t i = 0; i < s.channels.size(); ++i) {
        const auto at = std::find(names.begin(), names.end(), s.channels[i]);
        if (at == names.end()) continue;
        const auto k = static_cast<std::size_t>(at - names.begin());
        xs[k].push_back(0.5 * (s.start_s + s.end_s));
        ys[k].push_back(s.indicators[i].*field);
      }
    }
    std::vector<PlotSeries> series;
    for (std::size_t k = 0; k < names.size(); ++k) {
      if (xs[k].size() > 1) {
        series.push_back({xs[k], ys[k], channel_label(r, names[k]), kColours[k % 6]});
      }
    }
    if (series.empty()) continue;
    po.title = std::string(title) + " per frame";
    po.y_label = title;
    o << svg_line_plot(series, po, {}, bands);
  }
  o << "<details><summary>Frames (" << r.segments.size()
    << ")</summary>\n<table><tr><th>from "
       "[s]</th><th>to [s]</th><th>speed [rpm]</th><th class=l>verdict</th><th class=l>findings"
       "</th>"
    << (r.baseline ? "<th>anomaly score</th>" : "") << "</tr>";
  for (const AnalysisSegment& s : r.segments) {
    std::string seen;
    for (std::size_t i : s.findings) {
      const Finding& f = r.findings[i];
      seen += (seen.empty() ? "" : "; ") + f.kind + " " + (f.bearing.empty() ? f.shaft : f.bearing);
    }
    if (!s.reason.empty()) seen = s.reason;
    if (!s.cut.empty()) seen = "from " + s.cut + (seen.empty() ? "" : ": " + seen);
    o << "<tr><td>" << f3(s.start_s) << "</td><td>" << f3(s.end_s) << "</td><td>" << f3(s.speed_rpm)
      << "</td><td class=l><span class="
      << (s.verdict == "finding"        ? "bad"
          : s.verdict == "not examined" ? "warn"
                                        : "good")
      << ">" << html_escape(s.verdict) << "</span></td><td class=l>" << html_escape(seen)
      << "</td>";
    if (r.baseline) o << "<td>" << f3(s.anomaly_score) << "</td>";
    o << "</tr>";
  }
  o << "</table></details>\n";
}

// The damaged-shaft locator's table.
void gear_damage_section(const Page& p, std::ostringstream& o) {
  const AnalysisResult& r = p.r;
  if (!r.gear_damage) return;
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
      << "</td><td>" << s.revolutions << "</td><td class=l>" << p.channel_link(s.channel)
      << "</td><td><b>" << f3(s.score) << "</b></td><td>" << f3(s.snr) << "</td><td>" << f3(s.level)
      << "</td><td>" << f3(s.exclusive_share) << "</td><td class=l>"
      << (s.revolutions == 0 ? "skipped"
          : s.damaged        ? "<span class=bad>damaged</span>"
          : s.uncertain      ? "<span class=warn>uncertain</span>"
                             : "<span class=good>no localised fault</span>")
      << "</td></tr>";
  }
  o << "</table>\n";
  if (!g.note.empty()) o << "<p class=note>" << html_escape(g.note) << "</p>\n";
}

// The two-direction table (only when a location has both directions).
void two_direction_section(const Page& p, std::ostringstream& o) {
  const AnalysisResult& r = p.r;
  if (r.two_direction.empty()) return;
  o << "<h2 id=two-direction>Two directions: along and normal to the line of action</h2>\n"
       "<p class=note>Energy (mean square) at the mesh harmonics; normal/along ratio in dB: "
       "friction/surface-condition indicator (higher: more friction-driven vibration).</p>"
       "<table><tr><th class=l>location</th><th class=l>mesh</th><th>mesh [Hz]</th>"
       "<th>along energy</th><th>normal energy</th><th>normal/along [dB]</th>"
       "<th class=l>channels</th></tr>";
  for (const auto& t : r.two_direction) {
    o << "<tr><td class=l>" << html_escape(t.location) << "</td><td class=l>" << html_escape(t.mesh)
      << "</td><td>" << f3(t.comparison.mesh_hz) << "</td><td>" << f3(t.comparison.along_energy)
      << "</td><td>" << f3(t.comparison.normal_energy) << "</td><td><b>"
      << f3(t.comparison.normal_to_along_db) << "</b></td><td class=l>"
      << p.channel_link(t.along_channel) << " / " << p.channel_link(t.normal_channel)
      << "</td></tr>";
  }
  o << "</table>\n";
}

// The time-domain indicators of every channel.
void indicators_section(const Page& p, std::ostringstream& o) {
  o << "<h2 id=indicators>Indicators of every channel</h2>\n<table><tr><th class=l>channel</th><th "
       "class=l>unit"
       "</th><th class=l>direction</th><th>RMS</th><th>peak</th><th>crest</th><th>kurtosis</th>"
       "<th>skewness</th></tr>";
  for (const auto& c : p.r.channels) {
    o << "<tr><td class=l>" << p.channel_link(c.name) << "</td><td class=l>"
      << html_escape(pretty_unit(c.unit)) << "</td><td class=l>" << diag::to_string(c.direction)
      << "</td><td>" << f3(c.time.rms) << "</td><td>" << f3(c.time.peak) << "</td><td>"
      << f3(c.time.crest_factor) << "</td><td>" << f3(c.time.kurtosis) << "</td><td>"
      << f3(c.time.skewness) << "</td></tr>";
  }
  o << "</table>\n";
}

// The wear indicator per mesh against the baseline.
void wear_table(const AnalysisBaseline& b, std::ostringstream& o) {
  if (b.wear.empty()) return;
  o << "<h4>Wear: mesh harmonics against the baseline</h4>\n<p class=note>Growth = 20 "
       "log<sub>10</sub> of the RMS of the amplitudes at 1-3 &times; the mesh frequency over "
       "the baseline's median, each read at its own speed, averaged over the channels; worn "
       "flanks above the threshold (mesh_harmonic_growth.hpp).</p>"
       "<table><tr><th class=l>mesh</th><th>mesh frequency [Hz]</th><th>growth [dB]</th>"
       "<th>threshold [dB]</th><th class=l>verdict</th></tr>";
  for (const auto& w : b.wear) {
    o << "<tr><td class=l>" << html_escape(w.mesh) << "</td><td>" << f3(w.mesh_hz) << "</td><td>"
      << f3(w.growth_db) << "</td><td>" << f3(w.threshold_db) << "</td><td class=l>"
      << (w.flagged ? "<span class=bad>worn</span>" : "<span class=good>normal</span>")
      << "</td></tr>";
  }
  o << "</table>\n";
}

// The baseline comparison: the score, every feature's deviation, the wear.
void baseline_section(const Page& p, std::ostringstream& o) {
  if (!p.r.baseline) return;
  const AnalysisBaseline& b = *p.r.baseline;
  o << "<h3 id=baseline>Against the baseline</h3>\n<p>Anomaly score <b>" << f3(b.anomaly_score)
    << "</b> (mean z&sup2; over " << b.deviations.size() << " features; threshold "
    << f3(b.threshold)
    << "): " << (b.alarm ? "<span class=bad>ALARM</span>" : "<span class=good>normal</span>")
    << ". Baseline: " << b.recordings.size() << " recordings, " << b.samples
    << " samples; channels compared: ";
  for (std::size_t k = 0; k < b.channels.size(); ++k)
    o << (k ? ", " : "") << p.channel_link(b.channels[k]);
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
      << (big ? "<span class=bad>" : "") << f3(d.z) << (big ? "</span>" : "") << "</td></tr>";
  }
  o << "</table>\n";
  wear_table(b, o);
}

}  // namespace

}  // namespace html

void HtmlReportOptions::validate() const {
  if (max_channel_sections < 0) {
    throw diag::InputError("html_report: max_channel_sections: is not >= 0");
  }
  if (plot_width_px < 200 || plot_width_px > 4000) {
    throw diag::InputError("html_report: plot_width_px: " + std::to_string(plot_width_px) +
                           " is not in [200, 4000]");
  }
}

std::string render_html_report(const detect::AnalysisResult& r, const HtmlReportOptions& opt) {
  opt.validate();
  // Channels given a section of plots: vibration channels with a spectrum, in order, at most
  // max_channel_sections; the others link to nothing.
  html::Page page{r, opt, {}};
  int with_spectrum = 0;
  for (const auto& c : r.channels) {
    if (!c.vibration || c.spectrum.x.empty()) continue;
    ++with_spectrum;
    if (page.plotted.size() < static_cast<std::size_t>(opt.max_channel_sections)) {
      page.plotted.push_back(&c);
    }
  }
  std::ostringstream o;
  html::page_head(page, o);
  html::verdict_section(page, o);
  html::contents_section(page, o);
  html::machine_section(page, o);
  html::findings_section(page, o);
  html::timeline_section(page, o);
  html::gear_damage_section(page, o);
  html::two_direction_section(page, o);
  html::indicators_section(page, o);
  html::baseline_section(page, o);
  for (const detect::ChannelAnalysis* c : page.plotted) html::channel_section(page, *c, o);
  const int skipped = with_spectrum - static_cast<int>(page.plotted.size());
  if (skipped > 0) {
    o << "<p class=note>" << skipped
      << " further channels are listed in the indicator table only (max_channel_sections = "
      << opt.max_channel_sections << ").</p>\n";
  }
  o << "<p class=note>Generated by geardiag analyze.</p>\n</body></html>\n";
  return o.str();
}

}  // namespace report
