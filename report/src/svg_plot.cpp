#include "report/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "detect/analysis/analyze.hpp"
#include "diag/error.hpp"
#include "diag/util/number_format.hpp"

namespace report {

namespace {

std::string num(double v) { return diag::format_fixed(v, 1); }

std::string tick_label(double v, double step) {
  char b[32];
  const int dec = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  if (std::abs(v) >= 1e5 || (std::abs(v) < 1e-3 && v != 0 && step < 1e-3)) {
    std::snprintf(b, sizeof b, "%.2g", v);
  } else {
    std::snprintf(b, sizeof b, "%.*f", std::min(dec, 6), v);
  }
  return b;
}

}  // namespace

std::string html_escape(std::string_view s) {
  std::string o;
  o.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      case '\'':
        o += "&#39;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> t;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || target < 1) return t;
  const double raw = (hi - lo) / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw) break;
  }
  for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step) {
    t.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  }
  return t;
}

std::string svg_line_plot(std::span<const PlotSeries> series, const PlotOptions& opt,
                          std::span<const PlotMarker> markers, std::span<const PlotBand> bands) {
  if (opt.width_px < 200 || opt.width_px > 4000 || opt.height_px < 100 || opt.height_px > 4000) {
    throw diag::InputError("svg_line_plot: width_px/height_px: outside [200|100, 4000]");
  }
  if (opt.max_points < 4) throw diag::InputError("svg_line_plot: max_points: is not >= 4");
  if (!(opt.db_range > 0)) throw diag::InputError("svg_line_plot: db_range: is not > 0");
  std::vector<detect::PlotTrace> tr;
  for (const auto& s : series) {
    if (s.x.size() != s.y.size()) {
      throw diag::InputError("svg_line_plot: series '" + s.label + "': x and y differ in length");
    }
    tr.push_back(detect::decimate_for_plot(s.x, s.y, opt.max_points));
  }
  double x0 = opt.x_min, x1 = opt.x_max;
  double ymax = -INFINITY, ymin = INFINITY;
  bool auto_x0 = std::isnan(x0), auto_x1 = std::isnan(x1);
  if (auto_x0) x0 = INFINITY;
  if (auto_x1) x1 = -INFINITY;
  for (const auto& t : tr) {
    for (std::size_t i = 0; i < t.x.size(); ++i) {
      if (!std::isfinite(t.x[i])) continue;
      if (auto_x0) x0 = std::min(x0, t.x[i]);
      if (auto_x1) x1 = std::max(x1, t.x[i]);
    }
  }
  if (!std::isfinite(x0) || !std::isfinite(x1)) x0 = 0, x1 = 1;
  if (x1 <= x0) x1 = x0 + 1;
  const double k = opt.db_power ? 10.0 : 20.0;
  for (auto& t : tr) {
    for (double& y : t.y) {
      if (opt.y_db) y = y > 0 ? k * std::log10(y) : -INFINITY;
    }
    for (std::size_t i = 0; i < t.x.size(); ++i) {
      if (t.x[i] < x0 || t.x[i] > x1 || !std::isfinite(t.y[i])) continue;
      ymax = std::max(ymax, t.y[i]);
      ymin = std::min(ymin, t.y[i]);
    }
  }
  if (!std::isfinite(ymax)) ymax = 1, ymin = 0;
  if (opt.y_db) ymin = std::max(ymin, ymax - opt.db_range);
  if (!opt.y_db && ymin > 0) ymin = 0;
  if (ymax <= ymin) ymax = ymin + 1;
  const double pad = 0.05 * (ymax - ymin);
  ymax += pad;
  if (!opt.y_db && ymin < 0) ymin -= pad;

  const double W = opt.width_px, Hh = opt.height_px;
  const double L = 70, R = 15, T = opt.title.empty() ? 15 : 30, B = 45;
  const double pw = W - L - R, ph = Hh - T - B;
  auto X = [&](double v) { return L + (v - x0) / (x1 - x0) * pw; };
  auto Y = [&](double v) {
    return T + (1 - (std::clamp(v, ymin, ymax) - ymin) / (ymax - ymin)) * ph;
  };

  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << opt.width_px << "\" height=\""
    << opt.height_px << "\" viewBox=\"0 0 " << opt.width_px << " " << opt.height_px
    << "\" font-family=\"sans-serif\" font-size=\"11\">";
  o << "<rect x=\"0\" y=\"0\" width=\"" << W << "\" height=\"" << Hh << "\" fill=\"#fff\"/>";
  if (!opt.title.empty()) {
    o << "<text x=\"" << num(W / 2) << "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\" "
      << "font-weight=\"bold\">" << html_escape(opt.title) << "</text>";
  }
  for (const auto& b : bands) {
    const double a = std::max(x0, b.x0), c = std::min(x1, b.x1);
    if (c <= a) continue;
    o << "<rect x=\"" << num(X(a)) << "\" y=\"" << num(T) << "\" width=\""
      << num(std::max(0.5, X(c) - X(a))) << "\" height=\"" << num(ph) << "\" fill=\""
      << html_escape(b.color) << "\" fill-opacity=\"0.15\"><title>" << html_escape(b.label)
      << "</title></rect>";
  }
  const auto xt = nice_ticks(x0, x1, 8), yt = nice_ticks(ymin, ymax, 5);
  const double xs = xt.size() > 1 ? xt[1] - xt[0] : 1, ys = yt.size() > 1 ? yt[1] - yt[0] : 1;
  for (double v : xt) {
    o << "<line x1=\"" << num(X(v)) << "\" y1=\"" << num(T) << "\" x2=\"" << num(X(v)) << "\" y2=\""
      << num(T + ph) << "\" stroke=\"#ddd\"/>";
    o << "<text x=\"" << num(X(v)) << "\" y=\"" << num(T + ph + 14) << "\" text-anchor=\"middle\">"
      << tick_label(v, xs) << "</text>";
  }
  for (double v : yt) {
    o << "<line x1=\"" << num(L) << "\" y1=\"" << num(Y(v)) << "\" x2=\"" << num(L + pw)
      << "\" y2=\"" << num(Y(v)) << "\" stroke=\"#ddd\"/>";
    o << "<text x=\"" << num(L - 4) << "\" y=\"" << num(Y(v) + 4) << "\" text-anchor=\"end\">"
      << tick_label(v, ys) << "</text>";
  }
  o << "<rect x=\"" << num(L) << "\" y=\"" << num(T) << "\" width=\"" << num(pw) << "\" height=\""
    << num(ph) << "\" fill=\"none\" stroke=\"#333\"/>";
  o << "<text x=\"" << num(L + pw / 2) << "\" y=\"" << num(Hh - 8) << "\" text-anchor=\"middle\">"
    << html_escape(opt.x_label) << "</text>";
  o << "<text transform=\"translate(14," << num(T + ph / 2)
    << ") rotate(-90)\" text-anchor=\"middle\">"
    << html_escape(opt.y_db ? opt.y_label + " [dB]" : opt.y_label) << "</text>";
  for (std::size_t s = 0; s < tr.size(); ++s) {
    o << "<polyline fill=\"none\" stroke-width=\"1\" stroke=\"" << html_escape(series[s].color)
      << "\" points=\"";
    for (std::size_t i = 0; i < tr[s].x.size(); ++i) {
      if (tr[s].x[i] < x0 || tr[s].x[i] > x1) continue;
      const double y = std::isfinite(tr[s].y[i]) ? tr[s].y[i] : ymin;
      o << num(X(tr[s].x[i])) << "," << num(Y(y)) << " ";
    }
    o << "\"/>";
    if (!series[s].label.empty()) {
      o << "<text x=\"" << num(L + pw - 5) << "\" y=\"" << num(T + 14 + 13 * s)
        << "\" text-anchor=\"end\" fill=\"" << html_escape(series[s].color) << "\">"
        << html_escape(series[s].label) << "</text>";
    }
  }
  for (const auto& m : markers) {
    if (m.x < x0 || m.x > x1) continue;
    o << "<line x1=\"" << num(X(m.x)) << "\" y1=\"" << num(T) << "\" x2=\"" << num(X(m.x))
      << "\" y2=\"" << num(T + ph) << "\" stroke=\"" << html_escape(m.color) << "\""
      << (m.dashed ? " stroke-dasharray=\"4,3\"" : "") << "/>";
    if (!m.label.empty()) {
      o << "<text x=\"" << num(X(m.x) + 2) << "\" y=\""
        << num(T + 10 + 10 * std::max(0, m.label_row)) << "\" fill=\"" << html_escape(m.color)
        << "\" font-size=\"9\">" << html_escape(m.label) << "</text>";
    }
  }
  o << "</svg>";
  return o.str();
}

}  // namespace report
