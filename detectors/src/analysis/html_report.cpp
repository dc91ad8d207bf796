#include "detect/analysis/html_report.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <utility>

#include "detect/analysis/curves.hpp"
#include "detect/analysis/svg_plot.hpp"
#include "diag/error.hpp"
#include "diag/util/number_format.hpp"

namespace detect {

namespace {

std::string f3(double v) { return std::isfinite(v) ? diag::format_significant(v, 4) : "&ndash;"; }

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
.verdict li{margin:.3em 0}nav.toc ol{columns:2;font-size:.95em}details{margin:.4em 0}
details>summary{cursor:pointer;font-weight:bold;padding:.3em 0}details.channel>summary{
font-size:1.15em;border-bottom:1px solid #ccc}details details{margin-left:1em}
table{max-width:100%;overflow-x:auto;display:block}
)";

// A unit for display: powers as superscripts ("m/s^2" -> "m/s²"); empty -> "unit unknown".
std::string pretty_unit(std::string u) {
  if (u.empty()) return "unit unknown";
  for (const auto& [from, to] : {std::pair{"^2", "\u00b2"}, std::pair{"^3", "\u00b3"}}) {
    for (std::size_t i = u.find(from); i != std::string::npos; i = u.find(from, i)) {
      u.replace(i, 2, to);
    }
  }
  return u;
}

// "ch-<name>" with every character outside [A-Za-z0-9_-] as "_<hex>": a valid id and fragment.
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

// A bearing finding's fault name (the vocabulary of diag/faults/fault_kind.hpp); "" for gears.
std::string fault_name(const Finding& f) {
  return f.bearing.empty() ? "" : std::string(diag::to_string(f.fault));
}

// One line of evidence for a finding; `channel` is the link to (or the label of) the channel that
// shows it best.
std::string finding_line(const Finding& f, const std::string& channel) {
  std::string gears;
  for (const auto& g : f.gears) gears += (gears.empty() ? "" : ", ") + g;
  std::string what = f.kind == "bearing"       ? "bearing " + f.bearing + ": " + fault_name(f)
                     : f.kind == "gear_damage" ? "damaged gear on shaft " + f.shaft
                                               : f.kind + " on shaft " + f.shaft;
  if (!gears.empty() && f.kind != "bearing") what += " (" + gears + ")";
  std::string line = "<b>" + html_escape(what) + "</b>, confidence " + f3(f.confidence);
  if (std::isfinite(f.frequency_hz)) line += ", at " + f3(f.frequency_hz) + " Hz";
  if (!f.channel.empty()) line += ", best seen on " + channel;
  if (!f.note.empty()) line += ". " + html_escape(f.note);
  return line;
}

const char* kColors[] = {"#d62728", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2"};

// The fast kurtogram as a map (Antoni 2007, fig. 4): one row per level, one cell per band,
// shaded by kurtosis from white (0 or less) to dark blue (the largest); the band the envelope
// used outlined in black. Frequencies from 0 to fs/2 on x.
std::string kurtogram_svg(const std::vector<KurtogramLevel>& levels, double low_hz, double high_hz,
                          double selected_level, int width_px) {
  const int left = 60, right = 20, top = 28, row = 18;
  const int h = top + row * static_cast<int>(levels.size()) + 40;
  const double w = width_px - left - right;
  const double nyq =
      levels.front().bandwidth_hz * static_cast<double>(levels.front().kurtosis.size());
  double kmax = 0;
  for (const auto& l : levels) {
    for (double k : l.kurtosis) kmax = std::max(kmax, k);
  }
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width_px << "\" height=\"" << h
    << "\" viewBox=\"0 0 " << width_px << " " << h << "\" font-family=\"sans-serif\" "
    << "font-size=\"11\"><text x=\"" << width_px / 2 << "\" y=\"16\" text-anchor=\"middle\" "
    << "font-weight=\"bold\" font-size=\"12\">Kurtogram (largest kurtosis " << f3(kmax)
    << "; the envelope band " << f3(low_hz) << "-" << f3(high_hz) << " Hz outlined)</text>\n";
  for (std::size_t r = 0; r < levels.size(); ++r) {
    const KurtogramLevel& l = levels[r];
    const double y = top + row * static_cast<double>(r);
    for (std::size_t i = 0; i < l.kurtosis.size(); ++i) {
      const double v = kmax > 0 ? std::clamp(l.kurtosis[i] / kmax, 0.0, 1.0) : 0.0;
      const int shade = static_cast<int>(std::lround(255 * (1 - v)));
      char fill[16];
      std::snprintf(fill, sizeof fill, "#%02x%02x%02x", shade, shade,
                    255 - static_cast<int>(std::lround(115 * v)));
      const double x0 = left + w * (static_cast<double>(i) * l.bandwidth_hz) / nyq;
      o << "<rect x=\"" << f3(x0) << "\" y=\"" << y << "\" width=\"" << f3(w * l.bandwidth_hz / nyq)
        << "\" height=\"" << row << "\" fill=\"" << fill << "\"/>";
    }
    o << "<text x=\"" << left - 4 << "\" y=\"" << y + row - 5 << "\" text-anchor=\"end\">"
      << f3(l.level) << "</text>\n";
    if (std::abs(l.level - selected_level) < 1e-9) {
      o << "<rect x=\"" << f3(left + w * low_hz / nyq) << "\" y=\"" << y << "\" width=\""
        << f3(w * (high_hz - low_hz) / nyq) << "\" height=\"" << row
        << "\" fill=\"none\" stroke=\"#000\" stroke-width=\"2\"/>\n";
    }
  }
  const double yb = top + row * static_cast<double>(levels.size());
  for (double t : nice_ticks(0, nyq)) {
    const double x = left + w * t / nyq;
    o << "<line x1=\"" << f3(x) << "\" x2=\"" << f3(x) << "\" y1=\"" << yb << "\" y2=\"" << yb + 4
      << "\" stroke=\"#000\"/><text x=\"" << f3(x) << "\" y=\"" << yb + 15
      << "\" text-anchor=\"middle\">" << f3(t) << "</text>";
  }
  o << "<text x=\"" << left + w / 2 << "\" y=\"" << yb + 32
    << "\" text-anchor=\"middle\">frequency [Hz]</text><text x=\"12\" y=\"" << top + 10
    << "\" >level</text></svg>\n";
  return o.str();
}

// ---- spectrogram: an indexed-colour PNG inside an SVG with its axes and colour bar ----

// CRC-32 (ISO 3309, as PNG chunks use it) and Adler-32 (RFC 1950) of `d`.
std::uint32_t crc32(const std::string& d) {
  std::uint32_t c = 0xffffffffu;
  for (unsigned char ch : d) {
    c ^= ch;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

void put_be32(std::string& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out += static_cast<char>((v >> s) & 0xffu);
}

// A PNG (RFC 2083) of 8-bit palette indices, `width` x rows, row-major from the top; the zlib
// stream holds stored (uncompressed) deflate blocks: no compression library needed, and the
// image is small by construction (SpectrogramTrace's bounded grid).
std::string png_indexed(const std::vector<unsigned char>& idx, std::size_t width,
                        const std::vector<std::array<unsigned char, 3>>& palette) {
  const std::size_t rows = idx.size() / width;
  std::string raw;
  for (std::size_t r = 0; r < rows; ++r) {
    raw += '\0';  // filter type 0 (none)
    raw.append(reinterpret_cast<const char*>(idx.data() + r * width), width);
  }
  std::string z = "\x78\x01";
  for (std::size_t at = 0; at < raw.size() || at == 0; at += 65535) {
    const std::size_t len = std::min<std::size_t>(65535, raw.size() - at);
    z += static_cast<char>(at + len >= raw.size() ? 1 : 0);  // BFINAL on the last, BTYPE 00
    z += static_cast<char>(len & 0xff);
    z += static_cast<char>(len >> 8);
    z += static_cast<char>(~len & 0xff);
    z += static_cast<char>((~len >> 8) & 0xff);
    z.append(raw, at, len);
  }
  std::uint32_t a = 1, b = 0;
  for (unsigned char ch : raw) {
    a = (a + ch) % 65521;
    b = (b + a) % 65521;
  }
  put_be32(z, (b << 16) | a);
  std::string png = "\x89PNG\r\n\x1a\n";
  const auto chunk = [&png](const std::string& type, const std::string& data) {
    put_be32(png, static_cast<std::uint32_t>(data.size()));
    png += type + data;
    put_be32(png, crc32(type + data));
  };
  std::string ihdr;
  put_be32(ihdr, static_cast<std::uint32_t>(width));
  put_be32(ihdr, static_cast<std::uint32_t>(rows));
  ihdr += std::string("\x08\x03\x00\x00\x00", 5);  // 8 bits, palette, deflate, no filter/interlace
  chunk("IHDR", ihdr);
  std::string plte;
  for (const auto& c : palette) plte.append(reinterpret_cast<const char*>(c.data()), 3);
  chunk("PLTE", plte);
  chunk("IDAT", z);
  chunk("IEND", "");
  return png;
}

std::string base64(const std::string& d) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  for (std::size_t i = 0; i < d.size(); i += 3) {
    std::uint32_t v = static_cast<unsigned char>(d[i]) << 16;
    if (i + 1 < d.size()) v |= static_cast<unsigned char>(d[i + 1]) << 8;
    if (i + 2 < d.size()) v |= static_cast<unsigned char>(d[i + 2]);
    o += k[(v >> 18) & 63];
    o += k[(v >> 12) & 63];
    o += i + 1 < d.size() ? k[(v >> 6) & 63] : '=';
    o += i + 2 < d.size() ? k[v & 63] : '=';
  }
  return o;
}

// Viridis (matplotlib's default map) through five of its colours, linearly interpolated.
std::array<unsigned char, 3> viridis(double v) {
  static const double kStops[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  const double p = std::clamp(v, 0.0, 1.0) * 4;
  const int i = std::min(3, static_cast<int>(p));
  const double f = p - i;
  std::array<unsigned char, 3> c{};
  for (int k = 0; k < 3; ++k) {
    c[static_cast<std::size_t>(k)] = static_cast<unsigned char>(
        std::lround(kStops[i][k] + f * (kStops[i + 1][k] - kStops[i][k])));
  }
  return c;
}

// The spectrogram of a channel: time on x, frequency on y, the PSD in dB over the top 80 dB as
// colour (viridis, with its bar). `id` makes the colour bar's gradient id unique on the page.
std::string spectrogram_svg(const SpectrogramTrace& s, const std::string& psd_unit,
                            const std::string& id, int width_px) {
  constexpr double kRangeDb = 80;
  const std::size_t cols = s.time_s.size(), bins = s.frequency_hz.size();
  const double top = *std::max_element(s.psd_db.begin(), s.psd_db.end());
  std::vector<std::array<unsigned char, 3>> palette(256);
  for (std::size_t i = 0; i < palette.size(); ++i)
    palette[i] = viridis(static_cast<double>(i) / 255);
  std::vector<unsigned char> idx(cols * bins);
  for (std::size_t r = 0; r < bins; ++r) {
    for (std::size_t m = 0; m < cols; ++m) {
      const double v = (s.psd_db[m * bins + (bins - 1 - r)] - (top - kRangeDb)) / kRangeDb;
      idx[r * cols + m] = static_cast<unsigned char>(std::lround(255 * std::clamp(v, 0.0, 1.0)));
    }
  }
  const double dt = cols > 1 ? s.time_s[1] - s.time_s[0] : 1;
  const double t0 = s.time_s.front() - dt / 2, t1 = s.time_s.back() + dt / 2;
  const double f1 = s.frequency_hz.back();
  const int h = 280, L = 70, R = 80, T = 30, B = 45;
  const double pw = width_px - L - R, ph = h - T - B;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width_px << "\" height=\"" << h
    << "\" viewBox=\"0 0 " << width_px << " " << h
    << "\" font-family=\"sans-serif\" font-size=\"11\"><defs><linearGradient id=\"" << id
    << "\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">";
  for (int k = 0; k <= 4; ++k) {
    const auto c = viridis(k / 4.0);
    char col[8];
    std::snprintf(col, sizeof col, "#%02x%02x%02x", c[0], c[1], c[2]);
    o << "<stop offset=\"" << k / 4.0 << "\" stop-color=\"" << col << "\"/>";
  }
  o << "</linearGradient></defs><text x=\"" << width_px / 2
    << "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\" font-weight=\"bold\">Spectrogram "
       "(Hann, "
    << 2 * kSpectrogramRows << " samples per segment, "
    << f3(bins > 1 ? s.frequency_hz[1] - s.frequency_hz[0] : 0) << " Hz bins, " << f3(t1 - t0)
    << " s in " << cols << " columns)</text>";
  o << "<image x=\"" << L << "\" y=\"" << T << "\" width=\"" << f3(pw) << "\" height=\"" << ph
    << "\" preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" "
       "href=\"data:image/png;base64,"
    << base64(png_indexed(idx, cols, palette)) << "\"/>";
  o << "<rect x=\"" << L << "\" y=\"" << T << "\" width=\"" << f3(pw) << "\" height=\"" << ph
    << "\" fill=\"none\" stroke=\"#333\"/>";
  for (double t : nice_ticks(t0, t1, 8)) {
    const double x = L + pw * (t - t0) / (t1 - t0);
    o << "<line x1=\"" << f3(x) << "\" x2=\"" << f3(x) << "\" y1=\"" << T + ph << "\" y2=\""
      << T + ph + 4 << "\" stroke=\"#000\"/><text x=\"" << f3(x) << "\" y=\"" << T + ph + 15
      << "\" text-anchor=\"middle\">" << f3(t) << "</text>";
  }
  for (double f : nice_ticks(0, f1, 5)) {
    const double y = T + ph * (1 - f / f1);
    o << "<line x1=\"" << L - 4 << "\" x2=\"" << L << "\" y1=\"" << f3(y) << "\" y2=\"" << f3(y)
      << "\" stroke=\"#000\"/><text x=\"" << L - 6 << "\" y=\"" << f3(y + 4)
      << "\" text-anchor=\"end\">" << f3(f) << "</text>";
  }
  const double bx = L + pw + 14;
  o << "<rect x=\"" << f3(bx) << "\" y=\"" << T << "\" width=\"12\" height=\"" << ph
    << "\" fill=\"url(#" << id << ")\" stroke=\"#333\"/><text x=\"" << f3(bx + 15) << "\" y=\""
    << T + 9 << "\">" << f3(top) << "</text><text x=\"" << f3(bx + 15) << "\" y=\"" << T + ph
    << "\">" << f3(top - kRangeDb) << "</text><text transform=\"translate(" << f3(bx + 40) << ","
    << T + ph / 2 << ") rotate(-90)\" text-anchor=\"middle\">dB re 1 " << html_escape(psd_unit)
    << "</text><text x=\"" << f3(L + pw / 2) << "\" y=\"" << h - 8
    << "\" text-anchor=\"middle\">time [s]</text><text transform=\"translate(14," << T + ph / 2
    << ") rotate(-90)\" text-anchor=\"middle\">frequency [Hz]</text></svg>\n";
  return o.str();
}

// ---- the bearing decision's own envelope spectrum with the lines it scored ----

// One plot per demodulation band the decision used on this channel (bearings on one shaft share
// it), with every scored harmonic of every family: solid where the decision counted the line
// (prominence at or above its threshold), dashed where it expected one and saw none; then the
// lines' table. Empty when no bearing of the channel was diagnosed.
std::string decision_envelope_html(const ChannelAnalysis& c, const PlotOptions& po, bool orders) {
  static const char* kFamilyColor[] = {"#ff7f0e", "#17becf", "#8c564b", "#e377c2"};
  std::ostringstream o;
  for (std::size_t b = 0; b < c.bearings.size();) {
    const BearingAnalysis& first = c.bearings[b];
    std::size_t e = b + 1;
    while (e < c.bearings.size() && c.bearings[e].shaft == first.shaft &&
           c.bearings[e].band_centre_hz == first.band_centre_hz &&
           c.bearings[e].band_width_hz == first.band_width_hz) {
      ++e;
    }
    if (first.decision_envelope.x.size() < 2) {
      b = e;
      continue;
    }
    std::vector<PlotMarker> mk;
    double top = 0;
    for (std::size_t i = b; i < e; ++i) {
      for (const BearingLine& l : c.bearings[i].lines) {
        const std::string who = e - b > 1 ? c.bearings[i].bearing + " " : "";
        mk.push_back({l.seen ? l.found_hz : l.expected_hz,
                      who + l.label + (l.seen ? " (seen)" : ""), kFamilyColor[l.family % 4],
                      !l.seen});
        top = std::max(top, l.expected_hz);
      }
    }
    std::stable_sort(mk.begin(), mk.end(),
                     [](const PlotMarker& p, const PlotMarker& q) { return p.x < q.x; });
    for (std::size_t i = 0; i < mk.size(); ++i) mk[i].label_row = static_cast<int>(i % 4);
    const double low = first.band_centre_hz - first.band_width_hz / 2;
    PlotOptions pe = po;
    pe.title = "Envelope spectrum the bearing decision read: band " + f3(low) + "-" +
               f3(low + first.band_width_hz) + " Hz (kurtogram of the prewhitened signal)";
    pe.x_label = orders ? "frequency at the mean speed [Hz]" : "frequency [Hz]";
    pe.y_label = "squared envelope (prewhitened)";
    pe.y_db = false;
    pe.height_px = 300;
    pe.x_min = 0;
    pe.x_max = 1.1 * top;
    const PlotSeries es{first.decision_envelope.x, first.decision_envelope.y, "", "#1f77b4"};
    o << svg_line_plot(std::span(&es, 1), pe, mk)
      << "<p class=note>Solid: a line the decision counted (at least its line threshold over the "
         "local floor); dashed: where a line of the family was expected and none stood out. "
         "FTF cage rate, BPFO outer race, BPFI inner race, 2BSF twice the ball spin frequency; "
         "2x, 3x: harmonics.</p>\n<table><tr><th class=l>bearing</th><th class=l>line</th>"
         "<th>expected [Hz]</th><th>found [Hz]</th><th>prominence [dB]</th><th class=l>seen</th>"
         "</tr>";
    for (std::size_t i = b; i < e; ++i) {
      for (const BearingLine& l : c.bearings[i].lines) {
        o << "<tr><td class=l>" << html_escape(c.bearings[i].bearing) << "</td><td class=l>"
          << html_escape(l.label) << "</td><td>" << f3(l.expected_hz) << "</td><td>"
          << f3(l.found_hz) << "</td><td>" << f3(l.prominence_db) << "</td><td class=l>"
          << (l.seen ? "<b>seen</b>" : "no") << "</td></tr>";
      }
    }
    o << "</table>\n";
    b = e;
  }
  return o.str();
}

}  // namespace

std::string channel_label(const ChannelAnalysis& c) {
  std::string kind;
  if (c.role == diag::Role::kVibration) {
    static const char* kAccel[] = {"m/s^2", "m/s2", "mm/s^2", "g", "G"};
    static const char* kVel[] = {"m/s", "mm/s", "in/s", "ips"};
    kind = "vibration sensor";
    for (const char* u : kAccel) kind = c.unit == u ? "accelerometer" : kind;
    for (const char* u : kVel) kind = c.unit == u ? "velocity sensor" : kind;
    if (c.unit == "Pa") kind = "microphone";
  } else {
    kind = std::string(diag::to_string(c.role));
  }
  std::string where = c.location;
  std::replace(where.begin(), where.end(), '_', ' ');
  std::string label = (where.empty() ? "" : where + " ") + kind;
  if (c.direction != diag::Direction::kUnspecified) {
    label += ", " + std::string(diag::to_string(c.direction));
  }
  return label + " (" + c.name + ")";
}

std::string channel_label(const AnalysisResult& r, const std::string& name) {
  for (const ChannelAnalysis& c : r.channels) {
    if (c.name == name) return channel_label(c);
  }
  return name;
}

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
  // Channels given a section of plots: vibration channels with a spectrum, in order, at most
  // max_channel_sections; the others link to nothing.
  std::vector<const ChannelAnalysis*> plotted;
  for (const auto& c : r.channels) {
    if (c.vibration && !c.spectrum.x.empty() &&
        plotted.size() < static_cast<std::size_t>(opt.max_channel_sections)) {
      plotted.push_back(&c);
    }
  }
  // A channel as the reports name it (channel_label), linked to its section when it has one.
  const auto channel_link = [&](const std::string& name) {
    const std::string label = html_escape(channel_label(r, name));
    for (const ChannelAnalysis* c : plotted) {
      if (c->name == name) return "<a href=\"#" + anchor("ch-", name) + "\">" + label + "</a>";
    }
    return label;
  };
  const bool alarm = r.baseline && r.baseline->alarm;
  bool uncertain = false;
  if (r.gear_damage) {
    for (const auto& s : r.gear_damage->shafts) uncertain = uncertain || s.uncertain;
  }

  std::ostringstream o;
  o << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"viewport\" "
       "content=\"width=device-width\"><title>"
    << html_escape(opt.title) << "</title><style>" << kCss << "</style></head><body>\n";
  o << "<h1>" << html_escape(opt.title) << "</h1>\n<p>";
  if (!opt.source.empty()) o << "Recording <b>" << html_escape(opt.source) << "</b>, ";
  o << r.channels.size() << " channels, " << f3(r.duration_s) << " s";
  if (!r.gearbox_name.empty()) o << ", gearbox <b>" << html_escape(r.gearbox_name) << "</b>";
  o << ".</p>\n";

  // ---- summary: the verdict, every finding with its evidence, the alarm ----
  const std::size_t n_findings = r.findings.size() + (alarm ? 1 : 0);
  o << "<section id=summary class=\"verdict "
    << (n_findings > 0 ? "bad"
        : uncertain    ? ""
                       : "good")
    << "\"><h2>Verdict: "
    << (n_findings > 0 ? std::to_string(n_findings) + (n_findings == 1 ? " finding" : " findings")
        : uncertain    ? "no finding, one shaft uncertain"
                       : "no finding")
    << "</h2>\n";
  if (n_findings == 0) {
    o << "<p>Nothing points at a shaft, gear or bearing"
      << (r.baseline ? "; the recording is within its baseline" : "") << ".</p>\n";
  } else {
    o << "<ol>";
    if (alarm) {
      o << "<li><span class=bad>ALARM</span>: anomaly score " << f3(r.baseline->anomaly_score)
        << " against the baseline, above the threshold " << f3(r.baseline->threshold);
      if (!r.baseline->deviations.empty()) {
        const auto& d = r.baseline->deviations.front();
        o << "; largest deviation " << html_escape(d.feature) << " (z = " << f3(d.z) << ")";
      }
      o << " (<a href=\"#baseline\">baseline</a>)</li>";
    }
    for (const auto& f : r.findings) {
      o << "<li>" << finding_line(f, channel_link(f.channel)) << "</li>";
    }
    o << "</ol>\n";
  }
  if (r.baseline && !alarm) {
    o << "<p>Against the baseline: <span class=good>normal</span> (anomaly score "
      << f3(r.baseline->anomaly_score) << ", threshold " << f3(r.baseline->threshold) << ").</p>\n";
  }
  o << "</section>\n";

  // ---- table of contents ----
  o << "<nav class=toc><h2 id=contents>Contents</h2><ol>"
       "<li><a href=\"#summary\">Verdict</a></li><li><a href=\"#machine\">Machine and speed</a>"
       "</li><li><a href=\"#findings\">Findings</a></li>";
  if (r.gear_damage) o << "<li><a href=\"#gear-damage\">Damaged-shaft location</a></li>";
  if (!r.two_direction.empty()) o << "<li><a href=\"#two-direction\">Two directions</a></li>";
  o << "<li><a href=\"#indicators\">Indicators</a></li>";
  if (r.baseline) o << "<li><a href=\"#baseline\">Against the baseline</a></li>";
  for (const ChannelAnalysis* c : plotted) {
    o << "<li><a href=\"#" << anchor("ch-", c->name) << "\">" << html_escape(channel_label(*c))
      << "</a></li>";
  }
  o << "</ol></nav>\n";

  // ---- machine: shafts, meshes, notes, speed over time ----
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
  if (alarm) {  // the baseline ALARM is a finding (counted in the verdict)
    o << "<p><span class=bad>ALARM</span> against the baseline: anomaly score "
      << f3(r.baseline->anomaly_score) << " above " << f3(r.baseline->threshold)
      << " (<a href=\"#baseline\">baseline</a>).</p>\n";
  }
  if (r.findings.empty()) {
    if (!alarm) o << "<p class=good>No finding.</p>\n";
  } else {
    o << "<table><tr><th class=l>kind</th><th class=l>shaft / gears</th><th class=l>bearing / "
         "fault</th><th>frequency [Hz]</th><th class=l>channel</th><th>confidence</th>"
         "<th class=l>note</th></tr>";
    for (const auto& f : r.findings) {
      std::string gears;
      for (const auto& g : f.gears) gears += (gears.empty() ? "" : ", ") + g;
      o << "<tr><td class=l><span class=bad>" << html_escape(f.kind) << "</span></td><td class=l>"
        << html_escape(f.shaft) << (gears.empty() ? "" : " (" + html_escape(gears) + ")")
        << "</td><td class=l>" << html_escape(f.bearing) << " " << html_escape(fault_name(f))
        << "</td><td>" << f3(f.frequency_hz) << "</td><td class=l>" << channel_link(f.channel)
        << "</td><td>" << f3(f.confidence) << "</td><td class=l>" << html_escape(f.note)
        << "</td></tr>";
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
        << "</td><td>" << s.revolutions << "</td><td class=l>" << channel_link(s.channel)
        << "</td><td><b>" << f3(s.score) << "</b></td><td>" << f3(s.snr) << "</td><td>"
        << f3(s.level) << "</td><td>" << f3(s.exclusive_share) << "</td><td class=l>"
        << (s.revolutions == 0 ? "skipped"
            : s.damaged        ? "<span class=bad>damaged</span>"
            : s.uncertain      ? "<span class=warn>uncertain</span>"
                               : "<span class=good>no localised fault</span>")
        << "</td></tr>";
    }
    o << "</table>\n";
    if (!g.note.empty()) o << "<p class=note>" << html_escape(g.note) << "</p>\n";
  }

  // ---- two directions ----
  if (!r.two_direction.empty()) {
    o << "<h2 id=two-direction>Two directions: along and normal to the line of action</h2>\n"
         "<p class=note>Energy (mean square) at the mesh harmonics; normal/along ratio in dB: "
         "friction/surface-condition indicator (higher: more friction-driven vibration).</p>"
         "<table><tr><th class=l>location</th><th class=l>mesh</th><th>mesh [Hz]</th>"
         "<th>along energy</th><th>normal energy</th><th>normal/along [dB]</th>"
         "<th class=l>channels</th></tr>";
    for (const auto& t : r.two_direction) {
      o << "<tr><td class=l>" << html_escape(t.location) << "</td><td class=l>"
        << html_escape(t.mesh) << "</td><td>" << f3(t.comparison.mesh_hz) << "</td><td>"
        << f3(t.comparison.along_energy) << "</td><td>" << f3(t.comparison.normal_energy)
        << "</td><td><b>" << f3(t.comparison.normal_to_along_db) << "</b></td><td class=l>"
        << channel_link(t.along_channel) << " / " << channel_link(t.normal_channel) << "</td></tr>";
    }
    o << "</table>\n";
  }

  // ---- indicators ----
  o << "<h2 id=indicators>Indicators of every channel</h2>\n<table><tr><th class=l>channel</th><th "
       "class=l>unit"
       "</th><th class=l>direction</th><th>RMS</th><th>peak</th><th>crest</th><th>kurtosis</th>"
       "<th>skewness</th></tr>";
  for (const auto& c : r.channels) {
    o << "<tr><td class=l>" << channel_link(c.name) << "</td><td class=l>"
      << html_escape(pretty_unit(c.unit)) << "</td><td class=l>" << diag::to_string(c.direction)
      << "</td><td>" << f3(c.time.rms) << "</td><td>" << f3(c.time.peak) << "</td><td>"
      << f3(c.time.crest_factor) << "</td><td>" << f3(c.time.kurtosis) << "</td><td>"
      << f3(c.time.skewness) << "</td></tr>";
  }
  o << "</table>\n";
  if (r.baseline) {
    const AnalysisBaseline& b = *r.baseline;
    o << "<h3 id=baseline>Against the baseline</h3>\n<p>Anomaly score <b>" << f3(b.anomaly_score)
      << "</b> (mean z&sup2; over " << b.deviations.size() << " features; threshold "
      << f3(b.threshold)
      << "): " << (b.alarm ? "<span class=bad>ALARM</span>" : "<span class=good>normal</span>")
      << ". Baseline: " << b.recordings.size() << " recordings, " << b.samples
      << " samples; channels compared: ";
    for (std::size_t k = 0; k < b.channels.size(); ++k)
      o << (k ? ", " : "") << channel_link(b.channels[k]);
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
    if (!b.wear.empty()) {
      o << "<h4>Wear: mesh harmonics against the baseline</h4>\n<p class=note>Growth = 20 "
           "log<sub>10</sub> of the RMS of the amplitudes at 1-3 &times; the mesh frequency over "
           "the baseline's median, each read at its own speed, averaged over the channels; worn "
           "flanks above the threshold (mesh_harmonic_growth.hpp).</p>"
           "<table><tr><th class=l>mesh</th><th>mesh frequency [Hz]</th><th>growth [dB]</th>"
           "<th>threshold [dB]</th><th class=l>verdict</th></tr>";
      for (const auto& w : b.wear) {
        o << "<tr><td class=l>" << html_escape(w.mesh) << "</td><td>" << f3(w.mesh_hz)
          << "</td><td>" << f3(w.growth_db) << "</td><td>" << f3(w.threshold_db)
          << "</td><td class=l>"
          << (w.flagged ? "<span class=bad>worn</span>" : "<span class=good>normal</span>")
          << "</td></tr>";
      }
      o << "</table>\n";
    }
  }

  // ---- per channel: folded sections ----
  const bool orders = r.speed.spectra_domain == "order";
  double input_hz = 0;
  for (const auto& sh : r.shafts) {
    if (sh.shaft == r.input_shaft) input_hz = sh.speed_hz;
  }
  int skipped = 0;
  for (const auto& c : r.channels) skipped += c.vibration && !c.spectrum.x.empty() ? 1 : 0;
  skipped -= static_cast<int>(plotted.size());
  for (const ChannelAnalysis* cp : plotted) {
    const ChannelAnalysis& c = *cp;
    const std::string unit = pretty_unit(c.unit);
    const std::string amp_unit = c.unit.empty() ? "signal units" : unit;
    // A channel's own verdict: the findings it shows best.
    int shown = 0;
    for (const auto& f : r.findings) shown += f.channel == c.name ? 1 : 0;
    o << "<details class=channel id=\"" << anchor("ch-", c.name) << "\"><summary>"
      << html_escape(channel_label(c)) << " "
      << (c.shaft.empty() ? "" : "<span class=note>(shaft " + html_escape(c.shaft) + ")</span> ")
      << (shown > 0 ? "<span class=bad>" + std::to_string(shown) +
                          (shown == 1 ? " finding" : " findings") + "</span>"
                    : std::string(c.sensor ? "<span class=good>no finding</span>"
                                           : "<span class=note>not a sensor: shown only</span>"))
      << "</summary>\n<p class=note>" << html_escape(unit) << ", fs " << f3(c.fs_hz) << " Hz, "
      << c.samples << " samples; RMS " << f3(c.time.rms) << ", kurtosis " << f3(c.time.kurtosis)
      << ", crest factor " << f3(c.time.crest_factor) << "</p>\n";
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
    if (c.waveform.x.size() > 1 || !c.kurtogram.empty()) {
      o << "<details><summary>Time waveform"
        << (c.spectrogram.time_s.size() > 1 ? ", spectrogram" : "")
        << (c.kurtogram.empty() ? "" : " and kurtogram") << "</summary>\n";
      if (c.waveform.x.size() > 1) {
        PlotOptions pw = po;
        pw.title = "Time waveform";
        pw.x_label = "time [s]";
        pw.y_label = amp_unit;
        pw.height_px = 200;
        const PlotSeries ws{c.waveform.x, c.waveform.y, "", "#1f77b4"};
        o << svg_line_plot(std::span(&ws, 1), pw);
      }
      if (c.spectrogram.time_s.size() > 1) {
        o << spectrogram_svg(
            c.spectrogram,
            (c.unit.empty() ? "unit\u00b2" : pretty_unit(squared_unit(c.unit))) + "/Hz",
            anchor("sg-", c.name), opt.plot_width_px);
      }
      if (!c.kurtogram.empty() && !c.kurtogram.front().kurtosis.empty()) {
        o << kurtogram_svg(c.kurtogram, c.envelope_low_hz, c.envelope_high_hz, c.kurtogram_level,
                           opt.plot_width_px);
      }
      o << "</details>\n";
    }
    o << "<details open><summary>Spectra</summary>\n";
    po.title = orders ? "Amplitude order spectrum" : "Amplitude spectrum";
    po.x_label = orders ? "frequency at the mean speed [Hz] (input order x " + f3(input_hz) + " Hz)"
                        : "frequency [Hz]";
    po.y_label = "amplitude [" + amp_unit + "]";
    po.y_db = true;
    const PlotSeries sp{c.spectrum.x, c.spectrum.y, "", "#1f77b4"};
    o << svg_line_plot(std::span(&sp, 1), po, mk);
    if (c.psd.x.size() > 1) {
      PlotOptions pp = po;
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
    // Zoom on each mesh with sideband positions.
    bool any_zoom = false;
    for (const auto& m : c.meshes) any_zoom = any_zoom || m.zoom.x.size() >= 2;
    if (any_zoom) o << "<details><summary>Meshes: sidebands</summary>\n";
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
    if (any_zoom) o << "</details>\n";
    // Envelope spectrum with each bearing's fault families labelled.
    if (c.envelope.x.size() > 1) {
      o << "<details" << (shown > 0 ? " open" : "") << "><summary>Envelope spectrum"
        << (c.bearings.empty() ? "" : " and bearings") << "</summary>\n";
      std::vector<PlotMarker> fm;
      std::vector<PlotBand> bands;
      static const char* kFamily[] = {"FTF", "BPFO", "BPFI", "2BSF"};
      for (std::size_t b = 0; b < c.bearings.size(); ++b) {
        const BearingAnalysis& ba = c.bearings[b];
        const double fund[] = {ba.frequencies.ftf_hz, ba.frequencies.bpfo_hz,
                               ba.frequencies.bpfi_hz, ba.frequencies.ball_fault_hz};
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
      PlotOptions pe = po;
      pe.title = std::string(orders ? "Envelope order spectrum" : "Envelope spectrum") + ", band " +
                 f3(c.envelope_low_hz) + "-" + f3(c.envelope_high_hz) +
                 " Hz (kurtogram); fault families dashed, the one decided solid";
      pe.y_label = "amplitude [" + amp_unit + "]";
      pe.y_db = false;
      const PlotSeries es{c.envelope.x, c.envelope.y, "", "#8c564b"};
      // The decision's own spectrum when a bearing was diagnosed; else the kurtogram band's.
      const std::string decided = decision_envelope_html(c, po, orders);
      o << (decided.empty() ? svg_line_plot(std::span(&es, 1), pe, fm, bands) : decided);
      for (const auto& b : c.bearings) {
        o << "<p class=note>Bearing " << html_escape(b.bearing) << ": FTF "
          << f3(b.frequencies.ftf_hz) << ", BPFO " << f3(b.frequencies.bpfo_hz) << ", BPFI "
          << f3(b.frequencies.bpfi_hz) << ", 2BSF " << f3(b.frequencies.ball_fault_hz)
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
    // Order spectrum, up to a little above the third harmonic of the highest mesh order.
    if (c.order_spectrum.x.size() > 1) {
      std::vector<PlotMarker> om;
      double top = 0;
      if (input_hz > 0) {
        for (std::size_t j = 0; j < r.meshes.size(); ++j) {
          for (int h = 1; h <= 3; ++h) {
            om.push_back({h * r.meshes[j].frequency_hz / input_hz, h == 1 ? r.meshes[j].name : "",
                          kColors[j % 6], true});
            top = std::max(top, h * r.meshes[j].frequency_hz / input_hz);
          }
        }
      }
      PlotOptions pr = po;
      pr.title = "Order spectrum (input-shaft orders)";
      pr.x_label = "order [cycles/rev]";
      pr.y_label = "amplitude [" + amp_unit + "]";
      pr.height_px = 220;
      if (top > 0 && top * 1.15 < c.order_spectrum.x.back()) {
        pr.x_min = 0;
        pr.x_max = top * 1.15;
      }
      const PlotSeries os{c.order_spectrum.x, c.order_spectrum.y, "", "#9467bd"};
      o << "<details><summary>Order spectrum</summary>\n"
        << svg_line_plot(std::span(&os, 1), pr, om) << "</details>\n";
    }
    // TSA per shaft: the average and, on its own scale, the difference signal.
    for (const auto& t : c.tsa) {
      o << "<details><summary>TSA of shaft " << html_escape(t.shaft) << "</summary>\n";
      if (!t.computed) {
        o << "<p class=note>" << html_escape(t.note) << "</p>\n</details>\n";
        continue;
      }
      std::vector<double> angle(t.tsa.size());
      for (std::size_t i = 0; i < angle.size(); ++i) {
        angle[i] = 360.0 * static_cast<double>(i) / static_cast<double>(angle.size());
      }
      PlotOptions pt = po;
      pt.title = "TSA of shaft " + t.shaft + " (" + std::to_string(t.revolutions) + " revolutions)";
      pt.x_label = "shaft angle [deg]";
      pt.y_label = amp_unit;
      pt.y_db = false;
      pt.height_px = 200;
      const PlotSeries ts{angle, t.tsa, "", "#1f77b4"};
      o << svg_line_plot(std::span(&ts, 1), pt);
      pt.title = "Difference signal of shaft " + t.shaft +
                 " (TSA less shaft orders, mesh harmonics and first sidebands)";
      const PlotSeries td{angle, t.difference, "", "#d62728"};
      o << svg_line_plot(std::span(&td, 1), pt);
      if (!t.note.empty()) o << "<p class=note>" << html_escape(t.note) << "</p>\n";
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
      o << "</details>\n";
    }
    if (!c.notes.empty()) {
      o << "<details><summary>Notes (" << c.notes.size() << ")</summary>\n";
      for (const auto& n : c.notes) o << "<p class=note>" << html_escape(n) << "</p>\n";
      o << "</details>\n";
    }
    o << "</details>\n";
  }
  if (skipped > 0) {
    o << "<p class=note>" << skipped
      << " further channels are listed in the indicator table only (max_channel_sections = "
      << opt.max_channel_sections << ").</p>\n";
  }
  o << "<p class=note>Generated by geardiag analyze.</p>\n</body></html>\n";
  return o.str();
}

}  // namespace detect
