// The HTML report's figures that are not line plots (the kurtogram map, the spectrogram) and
// the bearing decision's own envelope spectrum with the lines it scored (html_page.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "html_page.hpp"
#include "report/base64.hpp"
#include "report/colour_map.hpp"
#include "report/png.hpp"

namespace report::html {

using namespace detect;

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

}  // namespace report::html
