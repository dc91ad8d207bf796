// The reports name a channel by what it is wherever they name it (channel_label, report.hpp):
// the channel sections, the findings' "best seen on" (a link to the channel's section when it has
// one), the indicator table and the terminal summary; every in-page link of the HTML report
// resolves to an id. A short synthetic recording of two accelerometers, one given a section
// (max_channel_sections = 1), and one finding on it (the report's rendering is under test, not
// the detectors: the finding is written in).
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "report/html_report.hpp"
#include "report/report.hpp"

namespace {

diag::Signal accelerometer(const std::string& name, const std::string& location, double hz) {
  diag::Signal s;
  s.name = name;
  s.fs_hz = 5000;
  s.unit = "m/s^2";
  s.location = location;
  s.samples.resize(10000);  // 2 s
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    s.samples[i] = std::sin(2 * std::numbers::pi * hz * static_cast<double>(i) / s.fs_hz) +
                   0.1 * std::sin(0.37 * static_cast<double>(i * i % 1013));
  }
  return s;
}

struct Reports {
  std::string html, text;
};

const Reports& reports() {
  static const Reports r = [] {
    diag::Recording rec;
    rec.signals.push_back(accelerometer("X105_DE_time", "drive_end", 161.7));
    rec.signals.push_back(accelerometer("X105_FE_time", "fan_end", 101.8));
    detect::AnalysisResult a = detect::analyze_recording(rec, nullptr);
    detect::Finding f;
    f.kind = "bearing";
    f.fault = diag::FaultKind::kInnerRace;
    f.bearing = "drive_end";
    f.channel = "X105_DE_time";
    f.frequency_hz = 161.7;
    f.confidence = 0.7;
    a.findings.push_back(f);
    f.channel = "X105_FE_time";  // a channel without a section: named, not linked
    a.findings.push_back(f);
    report::HtmlReportOptions opt;
    opt.max_channel_sections = 1;
    return Reports{report::render_html_report(a, opt), report::format_summary(a)};
  }();
  return r;
}

const std::string kDe = "drive end accelerometer (X105_DE_time)";
const std::string kFe = "fan end accelerometer (X105_FE_time)";

TEST(ReportLabels, HtmlNamesEveryChannelByItsLabel) {
  const std::string& h = reports().html;
  // The section's title, the findings' "best seen on" and the indicator table: one label.
  EXPECT_NE(h.find("<summary>" + kDe), std::string::npos);
  EXPECT_NE(h.find("best seen on <a href=\"#ch-X105_DE_time\">" + kDe + "</a>"), std::string::npos);
  EXPECT_NE(h.find("best seen on " + kFe), std::string::npos);
  EXPECT_NE(h.find("<tr><td class=l><a href=\"#ch-X105_DE_time\">" + kDe + "</a></td>"),
            std::string::npos);
  EXPECT_NE(h.find("<tr><td class=l>" + kFe + "</td>"), std::string::npos);
  // The bare name is never the text of a link nor a table cell of its own.
  for (const std::string name : {"X105_DE_time", "X105_FE_time"}) {
    EXPECT_EQ(h.find(">" + name + "</a>"), std::string::npos) << name;
    EXPECT_EQ(h.find(">" + name + "</td>"), std::string::npos) << name;
  }
}

bool word_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Every id="X" / id=X of the document (X of letters, digits, '_' and '-'; the attribute name
// not part of a longer word), and the targets of every href="#X". A scan, not std::regex: GCC 12
// under the sanitizers warns maybe-uninitialized inside <regex> (an error with -Werror).
std::set<std::string> ids_in(const std::string& h) {
  std::set<std::string> ids;
  for (std::size_t p = h.find("id="); p != std::string::npos; p = h.find("id=", p + 3)) {
    if (p > 0 && word_char(h[p - 1])) continue;
    std::size_t q = p + 3;
    if (q < h.size() && h[q] == '"') ++q;
    std::size_t e = q;
    while (e < h.size() && (word_char(h[e]) || h[e] == '-')) ++e;
    if (e > q) ids.insert(h.substr(q, e - q));
  }
  return ids;
}

std::vector<std::string> link_targets(const std::string& h) {
  std::vector<std::string> out;
  const std::string open = "href=\"#";
  for (std::size_t p = h.find(open); p != std::string::npos; p = h.find(open, p + 1)) {
    const std::size_t q = p + open.size(), e = h.find('"', q);
    if (e == std::string::npos) break;
    if (e > q) out.push_back(h.substr(q, e - q));
  }
  return out;
}

TEST(ReportLabels, EveryInPageLinkOfTheHtmlResolves) {
  const std::string& h = reports().html;
  const std::set<std::string> ids = ids_in(h);
  const std::vector<std::string> links = link_targets(h);
  for (const auto& target : links) EXPECT_TRUE(ids.count(target)) << "no id for #" << target;
  // The contents (verdict, machine, findings, indicators, the section), the finding, the row.
  EXPECT_GE(links.size(), 7u);
}

TEST(ReportLabels, TextSummaryNamesChannelsByTheSameLabel) {
  const std::string& t = reports().text;
  EXPECT_NE(t.find("\n  " + kDe + " [m/s^2] rms "), std::string::npos) << t;
  EXPECT_NE(t.find("\n  " + kFe + " [m/s^2] rms "), std::string::npos) << t;
  EXPECT_NE(t.find("inner_race, best seen on " + kDe + " - "), std::string::npos) << t;
}

}  // namespace
