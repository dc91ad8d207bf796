// geardiag batch: `analyze` (detect::analyze_file, as a library call) over many recordings
// into one table, one row per recording, and an HTML trend of chosen indicators and of the anomaly
// score against a healthy baseline. Files are analysed in parallel (one per worker thread, each
// analysis single-threaded) and, under mpirun, split across the ranks (tools/parallel.hpp); rank
// 0 gathers the rows and writes the table in the order the files were given. A file that cannot
// be read or analysed is a row with its error, never the end of the batch.
#include <gsl/gsl_cdf.h>

#include <algorithm>
#include <boost/program_options.hpp>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "allocator.hpp"
#include "batch.hpp"
#include "channel_options.hpp"
#include "cli_options.hpp"
#include "commands.hpp"
#include "detect/analysis/analyze.hpp"
#include "detect/analysis/analyze_file.hpp"
#include "detect/baseline/mesh_harmonic_growth.hpp"
#include "detect/gear/gear_damage.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/open_recording.hpp"
#include "diag/io/recording_frames.hpp"
#include "diag/util/number_format.hpp"
#include "output.hpp"
#include "parallel.hpp"
#include "report/html_report.hpp"
#include "report/report.hpp"
#include "report/svg_plot.hpp"
#include "time_stamp.hpp"

namespace po = boost::program_options;
namespace fs = std::filesystem;

namespace geardiag {

namespace {

using nlohmann::json;

// The date-time in a file name: at some position, digits and optional separators in the order
// YYYY [-] MM [-] DD [T_ -] hh [:-] mm [:-] ss (2024-03-01_12-30-00, 20240301T123000, ...).
// Written out rather than as a std::regex: GCC 12's <regex> trips -Wmaybe-uninitialized under
// the sanitizers. Returns the six fields, or an empty vector.
struct DateTimePart {
  int digits;
  const char* separators;  // an optional separator before the part ("" for none)
};
constexpr DateTimePart kDateTimeParts[] = {{4, ""},     {2, "-"},  {2, "-"},
                                           {2, "T_ -"}, {2, ":-"}, {2, ":-"}};

std::vector<std::string> date_time_in(const std::string& name) {
  // Parts k.. from position i; the optional separators tried taken first, then skipped (as a
  // greedy regex would).
  std::vector<std::string> fields;
  auto match = [&](auto&& self, std::size_t k, std::size_t i) -> bool {
    if (k == std::size(kDateTimeParts)) return true;
    const DateTimePart& part = kDateTimeParts[k];
    auto digits_at = [&](std::size_t j) {
      if (j + part.digits > name.size()) return false;
      for (int d = 0; d < part.digits; ++d) {
        if (!std::isdigit(static_cast<unsigned char>(name[j + d]))) return false;
      }
      fields.push_back(name.substr(j, part.digits));
      if (self(self, k + 1, j + part.digits)) return true;
      fields.pop_back();
      return false;
    };
    if (i < name.size() && *part.separators && std::strchr(part.separators, name[i]) &&
        digits_at(i + 1)) {
      return true;
    }
    return digits_at(i);
  };
  for (std::size_t i = 0; i < name.size(); ++i) {
    fields.clear();
    if (match(match, 0, i)) return fields;
  }
  return {};
}

// "YYYY-MM-DDTHH:MM:SS" from the file's metadata (timestamp, time, start_time, recorded_at,
// date), else from its name (date_time_in); empty when neither says.
std::string time_stamp(const std::map<std::string, std::string>& metadata,
                       const std::string& file) {
  for (const char* key : {"timestamp", "time", "start_time", "recorded_at", "date"}) {
    const auto it = metadata.find(key);
    if (it != metadata.end() && !it->second.empty()) return it->second;
  }
  const std::vector<std::string> m = date_time_in(fs::path(file).filename().string());
  if (m.size() != 6) return "";
  return m[0] + "-" + m[1] + "-" + m[2] + "T" + m[3] + ":" + m[4] + ":" + m[5];
}

// The findings in short form, from their JSON (report::to_json's): "gear_damage counter z2 z3
// (100 %); ...".
std::string short_findings(const json& findings) {
  std::string out;
  for (const json& f : findings) {
    std::ostringstream s;
    s << f.value("kind", "");
    if (!f.value("shaft", "").empty()) s << " " << f["shaft"].get<std::string>();
    for (const json& g : f.value("gears", json::array())) s << " " << g.get<std::string>();
    if (!f.value("bearing", "").empty()) {
      s << " " << f["bearing"].get<std::string>() << " " << f.value("fault", "");
    }
    s << " (" << std::lround(100 * f.value("confidence", 0.0)) << " %)";
    out += (out.empty() ? "" : "; ") + s.str();
  }
  return out;
}

// An event in words: its kind, its fault where that says more ("wear", not "wear wear"), the
// shaft, the gears and the bearing: "gear_damage tooth_damage counter z2 z3", "wear input p1 w1",
// "bearing inner_race input input_bearing1", "baseline anomaly".
std::string event_name(const json& e) {
  std::string out = e.value("kind", "");
  if (e.value("fault", "") != out) out += " " + e.value("fault", "");
  if (e.contains("shaft")) out += " " + e["shaft"].get<std::string>();
  for (const json& g : e.value("gears", json::array())) out += " " + g.get<std::string>();
  if (e.contains("bearing")) out += " " + e["bearing"].get<std::string>();
  return out;
}

// The indicators a history trends beside analyze's features: each mesh's harmonic growth against
// the baseline ("wear/<mesh>/growth_db", mesh_harmonic_growth.hpp), and per bearing and fault
// family the most prominent envelope line the bearing decision scored over the sensor channels
// ("bearing/<bearing>/<FTF|BPFO|BPFI|BSF>_db", dB over the local floor) and the decision's score
// of the family ("bearing/<bearing>/<outer_race|inner_race|rolling_element>_score_db", the
// largest over the sensor channels).
std::map<std::string, double> history_indicators(const detect::AnalysisResult& r) {
  std::map<std::string, double> out;
  if (r.baseline) {
    for (const detect::AnalysisMeshWear& w : r.baseline->wear) {
      if (std::isfinite(w.growth_db)) out["wear/" + w.mesh + "/growth_db"] = w.growth_db;
    }
  }
  if (r.gear_damage) {  // the locator's score of the recording alone, beside its comparison's
    for (const detect::ShaftDamage& sd : r.gear_damage->shafts) {
      if (std::isfinite(sd.score_alone)) {
        out["gear_damage/" + sd.shaft + "/score_alone"] = sd.score_alone;
      }
    }
  }
  static const char* const kFamily[] = {"FTF", "BPFO", "BPFI", "BSF"};
  for (const detect::ChannelAnalysis& c : r.channels) {
    if (!c.sensor) continue;
    for (const detect::BearingAnalysis& b : c.bearings) {
      if (!b.diagnosed) continue;
      for (const detect::BearingLine& line : b.lines) {
        if (line.family < 0 || line.family > 3 || !std::isfinite(line.prominence_db)) continue;
        const std::string key = "bearing/" + b.bearing + "/" + kFamily[line.family] + "_db";
        const auto it = out.find(key);
        if (it == out.end() || line.prominence_db > it->second) out[key] = line.prominence_db;
      }
      // The decision's own score of each fault family (its band view), whether or not it named
      // the fault: what a finding's score_db is, so that a history can read a later finding
      // against what the healthy reference scored there.
      for (const detect::FamilyScore& fam : b.diagnosis.band_decision.families) {
        if (fam.fault == detect::BearingFault::kCage || !std::isfinite(fam.score_db)) continue;
        const std::string key =
            "bearing/" + b.bearing + "/" + detect::to_string(fam.fault) + "_score_db";
        const auto it = out.find(key);
        if (it == out.end() || fam.score_db > it->second) out[key] = fam.score_db;
      }
    }
  }
  return out;
}

// A history's gear baselines: each reference recording's revolution averages, taken once per
// description (detect::gear_damage_baseline_of) and shared by every recording compared with it,
// instead of each recording's analysis taking every reference recording's again. The same
// averages, so the same bytes; on each MPI rank its own.
class GearBaselineCache {
 public:
  struct Entry {
    std::shared_ptr<const detect::GearDamageBaseline> baseline;
    std::string error;  // why it cannot be taken (then no baseline)
  };
  // `healthy`'s averages for `gearbox`, whose text (or "" for --gearbox) is `key`, as `request`
  // would take them.
  const Entry& get(const detect::AnalyzeRequest& request, const detect::RecordingInput& healthy,
                   const diag::Gearbox& gearbox, const std::string& key) {
    std::shared_ptr<Slot> slot;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      auto& s = slots_[{healthy.name(), key}];
      if (!s) s = std::make_shared<Slot>();
      slot = s;
    }
    std::call_once(slot->once, [&] {
      try {
        slot->entry.baseline = detect::gear_damage_baseline_of(request, healthy, gearbox);
      } catch (const diag::InputError& e) {
        slot->entry.error = e.what();
      }
    });
    return slot->entry;
  }

 private:
  struct Slot {
    std::once_flag once;
    Entry entry;
  };
  std::mutex mutex_;
  std::map<std::pair<std::string, std::string>, std::shared_ptr<Slot>> slots_;
};

struct Inputs {
  std::optional<diag::Gearbox> gearbox;          // --gearbox
  std::vector<detect::RecordingInput> baseline;  // read once, prepared for each file's gearbox
  // A history's first reference recording: the damaged-shaft locator's revolution averages.
  std::optional<detect::RecordingInput> gear_baseline;
  // And the reference's other recordings (AnalyzeRequest::more_gear_baselines).
  std::vector<detect::RecordingInput> more_gear_baselines;
  // Their averages, taken once (null: each analysis takes its own).
  std::shared_ptr<GearBaselineCache> gear_cache;
  ChannelOptions channels;
  std::optional<double> fs;
  std::string reports;       // --reports: the folder of every recording's own HTML report
  std::string load_channel;  // --load: a channel whose RMS is the machine's load
  // A history's wear thresholds per mesh, from its band's reference (wear_gates, below).
  std::map<std::string, double> wear_threshold_db;
};

// The name of recording `index`'s report in --reports: its position (so that two files of one
// name stay apart) and its name.
std::string report_name(std::size_t index, const std::string& file) {
  char number[24];
  std::snprintf(number, sizeof number, "%04zu", index);
  return std::string(number) + "_" + fs::path(file).filename().string() + ".html";
}

// One file as opened (ahead, on the main thread: run_in_rounds, since opening an HDF5 file forks
// its crash guard's child), frame by frame: its frames, or why not.
struct Opened {
  diag::OpenedFrames frames;
  std::string error;
};

Opened open_file(const std::string& file, const Inputs& in) {
  Opened r;
  try {
    diag::OpenOptions o;
    o.fs_hz = in.fs;
    r.frames = diag::open_recording_frames(file, o);
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  return r;
}

// A history's gear baselines for `request` from the cache (Inputs::gear_cache), for the
// description the analysis will use (--gearbox, else the recording's own): set as the locator's
// options, the request's own cleared; where one cannot be taken, none, and `error` says why (as
// analyse says when the analysis itself could not take them). A recording without a description
// keeps the request's (the analysis says why it cannot use them).
void share_gear_baselines(detect::AnalyzeRequest& request, const Inputs& in, std::string& error) {
  std::optional<diag::Gearbox> gb = in.gearbox;
  std::string key;
  if (!gb) {
    try {
      key = request.recording.opened.frames->frame(0, 0).gearbox_json;
      if (key.empty()) return;
      gb = diag::parse_gearbox_text(key, request.recording.name() + ": /gearbox");
    } catch (const diag::InputError&) {
      return;  // the analysis reports it
    }
  }
  std::vector<const detect::RecordingInput*> healthy = {&*request.gear_baseline};
  for (const detect::RecordingInput& m : request.more_gear_baselines) healthy.push_back(&m);
  std::vector<std::shared_ptr<const detect::GearDamageBaseline>> taken;
  for (const detect::RecordingInput* h : healthy) {
    const GearBaselineCache::Entry& e = in.gear_cache->get(request, *h, *gb, key);
    if (!e.error.empty()) {
      error = "gear baseline not used: " + e.error;
      taken.clear();
      break;
    }
    taken.push_back(e.baseline);
  }
  request.gear_baseline.reset();
  request.more_gear_baselines.clear();
  if (taken.empty()) return;
  request.options.gear_damage.baseline = taken.front();
  request.options.gear_damage.more_baselines.assign(taken.begin() + 1, taken.end());
}

// One recording's row: file, time, speed, findings, baseline score, and every feature. The file
// is read by its worker, frame by frame (analyze_file): memory holds a frame per worker, whatever
// the files' lengths.
json analyse(std::size_t index, const std::string& file, Opened opened, const Inputs& in) {
  json row = {{"file", file}, {"status", "ok"}};
  try {
    if (!opened.frames.frames) throw diag::InputError(opened.error);
    detect::AnalyzeRequest request;
    request.recording = detect::RecordingInput(std::move(opened.frames), file);
    request.gearbox = in.gearbox;
    request.channels = in.channels;
    request.baseline = in.baseline;
    request.baseline_options.wear_threshold_db = in.wear_threshold_db;
    request.baseline_required = false;  // the row keeps its analysis; the error column says why
    request.options.threads = 1;        // the files are the parallel work
    request.options.traces = !in.reports.empty();   // the report's plots
    request.average_spectra = !in.reports.empty();  // only the reports show spectra
    request.gear_baseline = in.gear_baseline;
    request.more_gear_baselines = in.more_gear_baselines;
    std::string gear_baseline_error;
    if (in.gear_baseline && in.gear_cache) share_gear_baselines(request, in, gear_baseline_error);
    request.load_channel = in.load_channel;
    const detect::FileAnalysis a = [&] {
      if (!request.gear_baseline) return detect::analyze_file(request);
      // A history's gear baseline where the recordings allow one (a description, revolutions
      // to average); else the analysis without it, the reason kept.
      try {
        return detect::analyze_file(request);
      } catch (const diag::InputError& e) {
        const std::string what = e.what();
        if (!what.starts_with("--gear-baseline")) throw;
        gear_baseline_error = "gear baseline not used: " + what;
        request.gear_baseline.reset();
        request.more_gear_baselines.clear();
        return detect::analyze_file(request);
      }
    }();
    const detect::AnalysisResult& r = a.result;
    row["time"] = time_stamp(a.metadata, file);
    if (r.speed.mean_rpm > 0) row["speed_rpm"] = r.speed.mean_rpm;
    const json findings = report::to_json(r)["findings"];
    row["findings"] = short_findings(findings);
    row["finding_list"] = findings;
    for (const detect::ChannelAnalysis& c : r.channels) {
      if (!c.sensor) continue;
      row["first_channel"] = c.name;
      break;
    }
    if (r.baseline) {
      row["anomaly_score"] = r.baseline->anomaly_score;
      row["alarm"] = r.baseline->alarm ? 1 : 0;
      row["alarm_threshold"] = r.baseline->threshold;
    }
    if (!a.baseline_error.empty()) row["error"] = a.baseline_error;
    if (!gear_baseline_error.empty()) {
      row["error"] =
          row.value("error", "") + (row.contains("error") ? "; " : "") + gear_baseline_error;
    }
    for (const detect::ChannelAnalysis& c : r.channels) {  // for a history's bearing growth
      for (const detect::BearingAnalysis& b : c.bearings)
        row["bearing_shafts"][b.bearing] = b.shaft;
    }
    if (r.gear_damage) {  // for a history's own locator findings (locator_growth)
      for (const detect::ShaftDamage& sd : r.gear_damage->shafts) {
        if (!sd.compared) continue;
        row["gear_damage_shafts"][sd.shaft] = {{"frequency_hz", sd.frequency_hz},
                                               {"gears", sd.gears},
                                               {"channel", sd.channel},
                                               {"angle_deg", sd.angle_deg},
                                               {"snr", sd.snr},
                                               {"exclusive_share", sd.exclusive_share},
                                               {"uncertain", sd.uncertain}};
      }
    }
    json features = json::object();
    for (const auto& [name, value] : detect::features(r)) features[name] = value;
    for (const auto& [name, value] : history_indicators(r)) features[name] = value;
    row["features"] = features;
    if (!in.load_channel.empty() && features.contains(in.load_channel + "/rms")) {
      row["load"] = features[in.load_channel + "/rms"];  // its operating state's load
    }
    if (!in.reports.empty()) {  // the page `geardiag analyze --html` writes, at once (memory flat)
      report::HtmlReportOptions ho;
      ho.source = fs::path(file).filename().string();
      ho.title = "geardiag analysis: " + ho.source;
      const std::string page = (fs::path(in.reports) / report_name(index, file)).string();
      write_output(page, report::render_html_report(r, ho), "--reports");
      row["report"] = page;
    }
  } catch (const std::exception& e) {
    const std::string what = e.what();
    row["status"] = "error";
    row["error"] = what.find(file) == std::string::npos ? file + ": " + what : what;
  }
  return row;
}

std::string csv_cell(const json& v) {
  if (v.is_null()) return "";
  std::string s = v.is_string() ? v.get<std::string>() : v.dump();
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

const std::vector<std::string> kFixedColumns = {
    "file",          "time",  "status",          "error",   "speed_rpm",
    "anomaly_score", "alarm", "alarm_threshold", "findings"};

std::string table_csv(const std::vector<json>& rows, const std::set<std::string>& features) {
  std::ostringstream out;
  for (std::size_t i = 0; i < kFixedColumns.size(); ++i) out << (i ? "," : "") << kFixedColumns[i];
  for (const std::string& f : features) out << "," << csv_cell(f);
  out << "\n";
  for (const json& row : rows) {
    for (std::size_t i = 0; i < kFixedColumns.size(); ++i) {
      out << (i ? "," : "") << csv_cell(row.value(kFixedColumns[i], json()));
    }
    const json& fv = row.contains("features") ? row["features"] : json::object();
    for (const std::string& f : features) out << "," << csv_cell(fv.value(f, json()));
    out << "\n";
  }
  return out.str();
}

// A history's gate on the reference's own scores: a later recording's locator score or anomaly
// score must exceed this times the largest over the reference (withhold_within_reference,
// withhold_alarm_within_reference, below).
constexpr double kReferenceScoreMargin = 1.5;

// A history's bearing margins (judge_bearings, below): a finding the reference also gave must
// score this much more; a fault family's line that grows this much over the reference's is a
// finding.
constexpr double kBearingMarginDb = 3.0;
constexpr double kBearingGrowthDb = 6.0;

// The trend page: one plot per chosen indicator, then (from what the rows hold) the damaged-shaft
// locator's scores per shaft, the wear growth per mesh, the bearing lines per bearing and the
// anomaly score, each with its thresholds and the events marked; against the dates of a dated
// history, else the recording's position in the table. Then the events and the recordings.
// `page_dir`: the page's folder, from which the links to the recordings' reports are made.
// `gate`: a history's locator gates (locator_gates);
// `bearing_gate`: its bearing lines' growth gates (BatchResult::bearing_gate); `wear_gate`: its
// wear thresholds per mesh (BatchResult::wear_gate; a batch that is no history draws the fixed
// one of a single recording).
std::string trend_html(const std::vector<json>& rows, const std::vector<std::string>& chosen,
                       const std::string& order, const json& events, const fs::path& page_dir,
                       const std::map<std::string, double>& gate,
                       const std::map<std::string, double>& bearing_gate,
                       const std::map<std::string, double>& wear_gate) {
  // A history in time order whose every recording has a time is drawn against it (days since the
  // first); otherwise against the position in the table.
  std::vector<double> at(rows.size());
  bool dated = order == "time";
  for (std::size_t i = 0; i < rows.size() && dated; ++i) {
    at[i] = epoch_s(rows[i].value("time", ""));
    dated = std::isfinite(at[i]);
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    at[i] = dated ? (at[i] - epoch_s(rows.front()["time"].get<std::string>())) / 86400
                  : static_cast<double>(i);
  }
  std::ostringstream html;
  html << "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>geardiag batch trend"
          "</title><style>body{font-family:sans-serif;margin:2em}td,th{padding:2px 8px;"
          "text-align:left}.bad{color:#d62728}.ref{color:#555}</style></head><body>"
          "<h1>geardiag batch: trend over "
       << rows.size() << " recordings</h1><p>x: ";
  if (dated) {
    html << "days since the first recording ("
         << report::html_escape(rows.front()["time"].get<std::string>())
         << "); failed files leave a gap.</p>";
  } else {
    html << "the recording's position in the table"
         << (order == "time" ? " (in time order" : " (files in the order given")
         << "; failed files leave a gap).</p>";
  }
  // The events, marked on every plot at their first recording.
  std::vector<report::PlotMarker> markers;
  for (const json& e : events) {
    const std::size_t first = e["first_recording"].get<std::size_t>();
    if (first >= rows.size() || e.value("status", "confirmed") == "unconfirmed") continue;
    std::string label = e["kind"].get<std::string>();
    for (const char* k : {"shaft", "bearing"}) {
      if (e.contains(k)) label += " " + e[k].get<std::string>();
    }
    markers.push_back({at[first], label, "#d62728", true, static_cast<int>(markers.size() % 3)});
  }
  // One plot: a series per indicator (row feature, or a top-level key of the row) and a
  // horizontal line per threshold.
  struct Line {
    std::string label, key;
    bool feature = true;
  };
  static const char* const kColors[] = {"#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#17becf"};
  // The thresholds': the first red, then each of the others its own colour.
  static const char* const kThresholdColors[] = {"#d62728", "#ff7f0e", "#7f7f7f", "#bcbd22",
                                                 "#e377c2"};
  auto plot = [&](const std::string& title, const std::string& y_label,
                  const std::vector<Line>& lines,
                  const std::vector<std::pair<std::string, double>>& thresholds) {
    std::vector<std::vector<double>> xs(lines.size()), ys(lines.size());
    double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo;
    for (std::size_t l = 0; l < lines.size(); ++l) {
      for (std::size_t i = 0; i < rows.size(); ++i) {
        const json& r = rows[i];
        const json* v = nullptr;
        if (!lines[l].feature && r.contains(lines[l].key)) v = &r[lines[l].key];
        if (lines[l].feature && r.contains("features") && r["features"].contains(lines[l].key)) {
          v = &r["features"][lines[l].key];
        }
        if (!v || !v->is_number()) continue;
        xs[l].push_back(at[i]);
        ys[l].push_back(v->get<double>());
        x_lo = std::min(x_lo, at[i]);
        x_hi = std::max(x_hi, at[i]);
      }
    }
    if (!(x_lo <= x_hi)) {
      html << "<h2>" << report::html_escape(title) << "</h2><p>no value in any recording</p>";
      return;
    }
    std::vector<report::PlotSeries> series;
    for (std::size_t l = 0; l < lines.size(); ++l) {
      if (!xs[l].empty()) series.push_back({xs[l], ys[l], lines[l].label, kColors[l % 5]});
    }
    const std::vector<double> tx = {x_lo, x_hi == x_lo ? x_lo + 1 : x_hi};
    std::vector<std::vector<double>> tys;
    tys.reserve(thresholds.size());
    for (const auto& [label, value] : thresholds) {
      if (!std::isfinite(value)) continue;
      tys.push_back({value, value});
      series.push_back({tx, tys.back(), label, kThresholdColors[(tys.size() - 1) % 5]});
    }
    report::PlotOptions po;
    po.title = title;
    po.x_label = dated ? "days" : "recording";
    po.y_label = y_label;
    html << "<h2>" << report::html_escape(title) << "</h2>"
         << report::svg_line_plot(series, po, markers);
  };
  for (const std::string& name : chosen) plot(name, name, {{name, name}}, {});
  // The indicators a machine's history is judged on, from what the rows hold: per shaft the
  // damaged-shaft locator's scores, per mesh the harmonic growth, per bearing its fault families'
  // envelope lines; then the anomaly score.
  std::set<std::string> shafts, meshes, bearings;
  for (const json& r : rows) {
    const json features = r.value("features", json::object());
    for (const auto& [name, v] : features.items()) {
      const std::size_t slash = name.find('/', name.find('/') + 1);
      if (slash == std::string::npos) continue;
      const std::string group = name.substr(0, name.find('/'));
      const std::string what = name.substr(group.size() + 1, slash - group.size() - 1);
      if (group == "gear_damage") shafts.insert(what);
      if (group == "wear") meshes.insert(what);
      if (group == "bearing") bearings.insert(what);
    }
  }
  const detect::GearDamageOptions locator;
  for (const std::string& shaft : shafts) {
    std::vector<std::pair<std::string, double>> t = {{"damaged above", locator.damaged_fm4}};
    const auto it = gate.find(shaft + "/score");
    if (it != gate.end()) {  // a history: its gates, and the floor of its own findings
      t.push_back({"reference gate (against the reference)", it->second});
      t.push_back({"uncertain above", locator.healthy_fm4});
    }
    const auto alone = gate.find(shaft + "/score_alone");
    if (alone != gate.end()) t.push_back({"reference gate (alone)", alone->second});
    plot("damaged-shaft locator, shaft " + shaft, "tooth score",
         {{"against the reference", "gear_damage/" + shaft + "/score"},
          {"alone", "gear_damage/" + shaft + "/score_alone"}},
         t);
  }
  if (!meshes.empty()) {
    std::vector<Line> lines;
    for (const std::string& m : meshes) lines.push_back({m, "wear/" + m + "/growth_db"});
    std::vector<std::pair<std::string, double>> t;
    for (const auto& [mesh, v] : wear_gate) t.push_back({mesh + ": flagged above", v});
    if (!rows.front().value("reference", false)) {  // not a history
      t.push_back({"flagged above", detect::MeshHarmonicGrowthOptions{}.threshold_db});
    }
    plot("mesh harmonic growth against the reference (wear)", "dB", lines, t);
  }
  for (const std::string& b : bearings) {
    std::vector<Line> lines;
    for (const char* f : {"BPFO", "BPFI", "BSF", "FTF"}) {
      lines.push_back({f, "bearing/" + b + "/" + f + "_db"});
    }
    std::vector<std::pair<std::string, double>> t;
    for (const char* f : {"BPFO", "BPFI", "BSF", "FTF"}) {
      const auto it = bearing_gate.find("bearing/" + b + "/" + f + "_db");
      if (it != bearing_gate.end())
        t.push_back({std::string(f) + ": the reference's + " +
                         diag::format_significant(kBearingGrowthDb, 2) + " dB",
                     it->second});
    }
    plot("bearing " + b + ": most prominent envelope line per fault family", "dB over the floor",
         lines, t);
  }
  double threshold = std::nan("");
  for (const json& r : rows) {
    if (r.contains("alarm_threshold")) threshold = r["alarm_threshold"].get<double>();
  }
  if (std::isfinite(threshold)) {
    // A history whose reference scores over the threshold against itself: its gate too
    // (withhold_alarm_within_reference; with several bands, the largest band's).
    double reference = 0;
    for (const json& r : rows) {
      if (r.value("reference", false) && r.contains("anomaly_score")) {
        reference = std::max(reference, r["anomaly_score"].get<double>());
      }
    }
    std::vector<std::pair<std::string, double>> t = {{"alarm threshold", threshold}};
    if (kReferenceScoreMargin * reference > threshold) {
      t.push_back({"reference gate", kReferenceScoreMargin * reference});
    }
    plot("anomaly score", "anomaly score", {{"anomaly score", "anomaly_score", false}}, t);
  }
  // The history: its events, then every recording with its verdict.
  if (!events.empty()) {
    html << "<h2>Events</h2><ul>";
    for (const json& e : events) {
      html << "<li class=bad>" << report::html_escape(event_name(e)) << ": "
           << report::html_escape(e.value("status", "confirmed")) << ", from recording "
           << e["first_recording"].get<std::size_t>() << " ("
           << report::html_escape(e["first_time"].get<std::string>()) << "), seen in "
           << e["recordings"].size() << "</li>";
    }
    html << "</ul>";
  }
  if (rows.front().contains("index") || rows.front().contains("report")) {
    html << "<h2>Recordings</h2><table><tr><th>#</th><th>file</th><th>time</th><th>status</th>"
            "<th>anomaly score</th><th>findings</th></tr>";
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const json& r = rows[i];
      // The file, linked to its own report (--reports) relative to this page.
      std::string file = report::html_escape(r.value("file", ""));
      if (r.contains("report")) {
        const fs::path to = fs::proximate(r["report"].get<std::string>(), page_dir);
        file = "<a href=\"" + report::html_escape(to.generic_string()) + "\">" + file + "</a>";
      }
      const std::string status = r.value("status", "");
      const bool alarm = r.value("alarm", 0) != 0;
      html << "<tr class="
           << (status == "reference" ? "ref"
               : alarm               ? "bad"
                                     : "ok")
           << "><td>" << r.value("index", i) << "</td><td>" << file << "</td><td>"
           << report::html_escape(r.value("time", "")) << "</td><td>" << report::html_escape(status)
           << "</td><td>"
           << (r.contains("anomaly_score")
                   ? diag::format_significant(r["anomaly_score"].get<double>(), 4)
                   : std::string())
           << "</td><td>" << report::html_escape(r.value("error", r.value("findings", "")))
           << "</td></tr>";
    }
    html << "</table>";
  }
  html << "</body></html>\n";
  return html.str();
}

// The time a file says it was recorded, before it is analysed: an HDF5 recording's metadata
// (its header only), else a date-time in its name; empty when neither says (or the file cannot
// be opened: its row then says why).
std::string file_time(const std::string& file) {
  std::map<std::string, std::string> metadata;
  try {
    if (diag::is_hdf5_file(file)) metadata = diag::RecordingReader(file).metadata();
  } catch (const std::exception&) {
    metadata.clear();
  }
  return time_stamp(metadata, file);
}

// What makes two recordings' findings one fault in one place (an event of the history).
std::string event_key(const json& f) {
  std::string key = f.value("kind", "") + "|" + f.value("fault", "") + "|" + f.value("shaft", "") +
                    "|" + f.value("bearing", "") + "|";
  for (const json& g : f.value("gears", json::array())) key += g.get<std::string>() + ",";
  return key;
}

// The damaged-shaft locator in a history scores every recording twice: against the reference's
// recordings of its operating state (`score`: per shaft against the one that explains it best,
// the pitch errors' pattern cancelled; a reference recording against the others) and alone
// (`score_alone`). The reference's recordings, scored the same way, show how high a healthy
// recording of this machine scores: speed and load jitter, noise, the gears' own pattern (which
// alone may flag a shaft on every recording, healthy ones too). Each shaft's gate is the
// prediction bound of its reference scores' logarithm,
//     exp(m + t_df(1 - kLocatorFalseAlarmRate) max(s, kLocatorSpreadFloor) sqrt(1 + 1/n)),
// m the mean of the shaft's n reference log scores, s their standard deviation pooled over the
// band's shafts (the same score; df = the sum of n - 1 over them): for log-normal scores of one
// scale, a healthy recording exceeds it with probability kLocatorFalseAlarmRate. The scale is
// pooled because two or three values per shaft say little of it; the tooth score is a largest
// over teeth, its logarithm's spread much the same on every shaft of a machine. With fewer than
// kLocatorMinDof degrees of freedom (one reference recording) the gate is kReferenceScoreMargin
// x the largest reference score, distribution-free: a healthy recording exceeds the largest of
// n healthy scores with probability at most 1 / (n + 1). Then:
//  - a later recording's gear_damage finding on a shaft stands only when one of its two scores
//    exceeds its gate; else it is withheld, and its row says why (withhold_within_reference);
//  - where no gear_damage finding stands, the slowest shaft whose comparison score lies in the
//    locator's uncertain band (over GearDamageOptions::healthy_fm4, significant) and over its
//    gate is a finding of the history's own (locator_growth): a small crack raises a shaft's
//    score against its own reference well before the single recording's threshold, set for
//    gears other than the reference's.
// Measured on life histories (docs/validation.md): the bound alone is exceeded by 2.6 % of the
// healthy recordings' comparison scores and 1.5 % of the alone scores (the tails are heavier than
// the model's), none of them over the uncertain band's floor.
// The prediction bound of a new value from n values of mean `mean` and standard deviation `sd`
// on `df` degrees of freedom: mean + t_df(1 - rate) max(sd, floor) sqrt(1 + 1/n) (the wear
// indicator's and the locator's gates; for Gaussian values of that spread a new one exceeds it
// with probability `rate`).
double prediction_bound(double mean, double sd, double df, double n, double rate, double floor) {
  const double t = gsl_cdf_tdist_Pinv(1 - rate, df);
  return mean + t * std::max(sd, floor) * std::sqrt(1 + 1 / n);
}

constexpr double kLocatorFalseAlarmRate = 0.01;
constexpr double kLocatorSpreadFloor = 0.05;  // of the log score: a scale under 5 % is not
                                              // believed from a few recordings
constexpr std::size_t kLocatorMinDof = 2;

// A shaft's locator gate for one of its two scores over a band's reference (locator_gates).
struct LocatorGate {
  std::size_t n = 0;     // the reference recordings that scored it
  double largest = 0;    // their largest score
  double mean_log = 0;   // the mean of their scores' logarithms
  double sd_log = 0;     // the pooled standard deviation of the logarithms (below)
  std::size_t df = 0;    // its degrees of freedom
  double threshold = 0;  // the gate: the prediction bound (from_spread), else the margin rule
};

bool from_spread(const LocatorGate& g) { return g.df >= kLocatorMinDof && g.n >= 2; }

// The gates per "<shaft>/score" and "<shaft>/score_alone" over a band's reference recordings
// (`members`); empty when the gear baseline was used in none of them.
std::map<std::string, LocatorGate> locator_gates(const std::vector<json>& rows,
                                                 const std::vector<std::size_t>& members) {
  std::map<std::string, std::vector<double>> logs;
  for (std::size_t m : members) {
    const json& row = rows[m];
    if (row.value("status", "") == "error" ||
        row.value("error", "").find("gear baseline not used") != std::string::npos) {
      continue;
    }
    const json features = row.value("features", json::object());
    for (const auto& [name, v] : features.items()) {
      if (!name.starts_with("gear_damage/") || !v.is_number()) continue;
      const std::string key = name.substr(12);  // "<shaft>/score" or "<shaft>/score_alone"
      if (std::count(key.begin(), key.end(), '/') != 1) continue;  // a gear's own score
      if (!key.ends_with("/score_alone") && !key.ends_with("/score")) continue;
      const double x = v.get<double>();
      if (std::isfinite(x) && x > 0) logs[key].push_back(std::log(x));
    }
  }
  std::map<std::string, LocatorGate> out;
  for (const char* which : {"/score", "/score_alone"}) {
    double ss = 0;
    std::size_t df = 0;
    for (const auto& [key, l] : logs) {
      if (!key.ends_with(which)) continue;  // "/score_alone" does not end with "/score"
      LocatorGate g;
      g.n = l.size();
      g.mean_log = std::accumulate(l.begin(), l.end(), 0.0) / static_cast<double>(l.size());
      g.largest = std::exp(*std::max_element(l.begin(), l.end()));
      for (double x : l) ss += (x - g.mean_log) * (x - g.mean_log);
      df += l.size() - 1;
      out[key] = g;
    }
    const double sd = df > 0 ? std::sqrt(ss / static_cast<double>(df)) : 0.0;
    for (auto& [key, g] : out) {
      if (!key.ends_with(which)) continue;
      g.sd_log = sd;
      g.df = df;
      g.threshold = from_spread(g)
                        ? std::exp(prediction_bound(g.mean_log, sd, static_cast<double>(df),
                                                    static_cast<double>(g.n),
                                                    kLocatorFalseAlarmRate, kLocatorSpreadFloor))
                        : kReferenceScoreMargin * g.largest;
    }
  }
  return out;
}

// Withholds the row's gear_damage findings whose shaft scores under its gates on both scores
// (locator_gates).
void withhold_within_reference(json& row, const std::map<std::string, LocatorGate>& gates) {
  if (gates.empty() || row.value("error", "").find("gear baseline not used") != std::string::npos) {
    return;
  }
  json kept = json::array();
  for (const json& f : row.value("finding_list", json::array())) {
    const std::string shaft = f.value("shaft", "");
    bool stands = f.value("kind", "") != "gear_damage";
    std::string why;
    for (const char* which : {"/score", "/score_alone"}) {
      const auto it = gates.find(shaft + which);
      const json v = row["features"].value("gear_damage/" + shaft + which, json());
      if (it == gates.end() || !v.is_number()) {
        stands = true;  // nothing to compare with
        continue;
      }
      stands = stands || v.get<double>() > it->second.threshold;
      why += std::string(why.empty() ? "" : ", ") +
             (std::string(which) == "/score" ? "against the gear baseline " : "alone ") +
             diag::format_significant(v.get<double>(), 3) + " (gate " +
             diag::format_significant(it->second.threshold, 3) + ", reference up to " +
             diag::format_significant(it->second.largest, 3) + ")";
    }
    if (stands) {
      kept.push_back(f);
      continue;
    }
    row["withheld"].push_back(
        {{"finding", short_findings(json::array({f}))},
         {"reason", "the shaft scores within the healthy reference's own scores: " + why}});
  }
  row["finding_list"] = kept;
  row["findings"] = short_findings(kept);
}

// Where no gear_damage finding stands: the slowest shaft whose comparison with the reference
// lies in the locator's uncertain band and over its gate, as a finding (the locator's reasons
// for the slowest: gear_damage.hpp, step 6).
void locator_growth(json& row, const std::map<std::string, LocatorGate>& gates) {
  if (row.value("error", "").find("gear baseline not used") != std::string::npos) return;
  for (const json& f : row.value("finding_list", json::array())) {
    if (f.value("kind", "") == "gear_damage") return;
  }
  const json shafts = row.value("gear_damage_shafts", json::object());
  const json features = row.value("features", json::object());
  auto hz = [](const json& sh) {  // the shaft's speed (a NaN comes back as null: last)
    const json f = sh.value("frequency_hz", json());
    return f.is_number() ? f.get<double>() : std::numeric_limits<double>::infinity();
  };
  std::string pick;
  for (const auto& [shaft, s] : shafts.items()) {
    const auto it = gates.find(shaft + "/score");
    const json v = features.value("gear_damage/" + shaft + "/score", json());
    if (it == gates.end() || !from_spread(it->second) || !s.value("uncertain", false) ||
        !v.is_number() || v.get<double>() <= it->second.threshold) {
      continue;
    }
    if (pick.empty() || hz(s) < hz(shafts[pick])) pick = shaft;
  }
  if (pick.empty()) return;
  const json& s = shafts[pick];
  const LocatorGate& g = gates.at(pick + "/score");
  const double score = features["gear_damage/" + pick + "/score"].get<double>();
  const detect::GearDamageOptions locator;
  detect::Finding f;
  f.kind = "gear_damage";
  f.fault = diag::FaultKind::kToothDamage;
  f.shaft = pick;
  f.gears = s.value("gears", std::vector<std::string>{});
  f.channel = s.value("channel", "");
  f.confidence = std::clamp(
      (score - locator.healthy_fm4) / (2.0 * (locator.damaged_fm4 - locator.healthy_fm4)), 0.0,
      1.0);
  // (A number that was not finite comes back as null from the rows' JSON: NaN here.)
  auto number = [&](const char* key) {
    const json v = s.value(key, json());
    return v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN();
  };
  f.evidence = {{"score", score},
                {"snr", number("snr")},
                {"exclusive_share", number("exclusive_share")},
                {"angle_deg", number("angle_deg")},
                {"gate", g.threshold}};
  std::string which;
  for (std::size_t k = 0; k < f.gears.size(); ++k) {
    which += (k == 0 ? "" : k + 1 == f.gears.size() ? " or " : ", ") + f.gears[k];
  }
  f.note = "a tooth of " + which + " stands out at " +
           diag::format_significant(std::round(number("angle_deg")), 3) +
           " deg of the shaft's revolution against the healthy reference: score " +
           diag::format_significant(score, 3) + ", in the locator's uncertain band (" +
           diag::format_significant(locator.healthy_fm4, 3) + ", " +
           diag::format_significant(locator.damaged_fm4, 3) +
           "] and over the gate the reference's own scores give (" +
           diag::format_significant(g.threshold, 3) + ": a healthy recording exceeds it with " +
           "probability " + diag::format_significant(100 * kLocatorFalseAlarmRate, 2) + " %)";
  json kept = row.value("finding_list", json::array());
  kept.push_back(detect::to_json(f));
  row["finding_list"] = kept;
  row["findings"] = short_findings(kept);
}

// A history's bearings against the reference's own recordings. The bearing decision of one
// recording can fire on a healthy machine: a bearing's fault frequency may sit on a shaft
// harmonic of the gearbox (the counter bearing's BPFO within 1 % of twice the input speed in a
// two-stage box), or a line may stand out by chance. Such a finding shows in the reference too.
// So, per band:
//  - a later recording's bearing finding (bearing, fault) stands only when its score exceeds by
//    kBearingMarginDb the largest score the bearing decision gave that fault over the band's
//    reference recordings, whether or not it named the fault there
//    ("bearing/<bearing>/<fault>_score_db", history_indicators); else it is withheld, its row
//    says why. A line on a shaft harmonic scores high in the healthy reference too, even in the
//    recordings where the decision happened not to fire.
//  - a fault family's envelope line ("bearing/<bearing>/<BPFO|BPFI|BSF>_db", history_indicators)
//    that stands kBearingGrowthDb over the reference's largest of the same line is a finding of
//    its own (growth; per bearing the family that grew most), where the recording's decision
//    gave none that stands for that bearing. The cage line (FTF) is left out: it also rises with
//    a ball fault, whose load zone it modulates.
// Distribution-free, a healthy recording exceeds the largest of n healthy values with probability
// at most 1/(n + 1); the margins (chosen beforehand: 3 dB, twice the power; 6 dB, four times)
// take the rate further down, and an event needs two successive recordings (confirm_events). On
// the development life histories no healthy line rose more than 5.8 dB over its reference
// (docs/validation.md).
// (kBearingMarginDb and kBearingGrowthDb: above trend_html, which draws the growth gates.)

struct ReferenceBearings {
  std::map<std::string, double> score_db;     // "<bearing>|<fault>": the decision's largest score
  std::map<std::string, double> line_db;      // "bearing/<bearing>/<FAM>_db": largest
  std::map<std::string, double> line_low_db;  // and smallest
};

ReferenceBearings reference_bearings(const std::vector<json>& rows,
                                     const std::vector<std::size_t>& members) {
  ReferenceBearings out;
  for (std::size_t m : members) {
    const json& row = rows[m];
    if (row.value("status", "") == "error") continue;
    const json features = row.value("features", json::object());
    for (const auto& [name, v] : features.items()) {
      if (!name.starts_with("bearing/") || !v.is_number()) continue;
      const double db = v.get<double>();
      if (name.ends_with("_score_db")) {  // "bearing/<bearing>/<fault>_score_db"
        const std::string rest = name.substr(8, name.size() - 8 - 9);
        const std::string key =
            rest.substr(0, rest.rfind('/')) + "|" + rest.substr(rest.rfind('/') + 1);
        out.score_db[key] = std::max(out.score_db.count(key) ? out.score_db[key] : db, db);
        continue;
      }
      out.line_db[name] = std::max(out.line_db.count(name) ? out.line_db[name] : db, db);
      out.line_low_db[name] =
          std::min(out.line_low_db.count(name) ? out.line_low_db[name] : db, db);
    }
  }
  return out;
}

// A line the reference itself holds within the growth margin (its largest and smallest values
// less than kBearingGrowthDb apart): only against such a line is a rise of that margin growth. A
// line that swings more in the healthy reference (one near 0 Hz, where the envelope's slow
// fluctuations are, or on a strong gear line) is trended, not judged.
bool steady(const ReferenceBearings& ref, const std::string& line) {
  const auto hi = ref.line_db.find(line);
  const auto lo = ref.line_low_db.find(line);
  return hi != ref.line_db.end() && lo != ref.line_low_db.end() &&
         hi->second - lo->second < kBearingGrowthDb;
}

void judge_bearings(json& row, const ReferenceBearings& ref) {
  json kept = json::array();
  std::set<std::string> standing;  // "<bearing>|<fault>" of the findings that stand
  for (const json& f : row.value("finding_list", json::array())) {
    if (f.value("kind", "") != "bearing") {
      kept.push_back(f);
      continue;
    }
    const std::string key = f.value("bearing", "") + "|" + f.value("fault", "");
    const auto it = ref.score_db.find(key);
    const double db = f.value("score_db", 0.0);
    if (it == ref.score_db.end() || db > it->second + kBearingMarginDb) {
      kept.push_back(f);
      standing.insert(key);
      continue;
    }
    row["withheld"].push_back(
        {{"finding", short_findings(json::array({f}))},
         {"reason", "the healthy reference scored the same fault up to " +
                        diag::format_significant(it->second, 3) + " dB; this recording " +
                        diag::format_significant(db, 3) + " dB, not " +
                        diag::format_significant(kBearingMarginDb, 2) + " dB more"}});
  }
  // Per bearing without a standing finding, the family whose line grew most, when it grew more
  // than kBearingGrowthDb: one defect is one family, though the others' lines may rise with it
  // (a slow shaft's BPFO, BPFI and BSF harmonics lie close together). The cage line (FTF) only
  // where no race or ball line grew: a defective ball's impacts come and go as the cage carries
  // it through the load zone, so the envelope gains a line at the cage's rate, often more than
  // at the ball's own (whose line may sit among the gears' shaft harmonics); a race defect has
  // lines of its own. It is read as the rolling elements' (or the cage's) defect.
  static const std::map<std::string, std::string> kFault = {{"BPFO", "outer_race"},
                                                            {"BPFI", "inner_race"},
                                                            {"BSF", "rolling_element"},
                                                            {"FTF", "rolling_element"}};
  struct Growth {
    std::string family;
    double growth = 0, line = 0, reference = 0;
  };
  std::map<std::string, Growth> grown;  // by bearing
  const json features = row.value("features", json::object());
  for (const auto& [name, v] : features.items()) {
    if (!name.starts_with("bearing/") || !v.is_number()) continue;
    const auto it = ref.line_db.find(name);
    if (it == ref.line_db.end() || !steady(ref, name)) continue;
    const std::string rest = name.substr(8);  // "<bearing>/<FAM>_db"
    const std::string bearing = rest.substr(0, rest.rfind('/'));
    const std::string family = rest.substr(rest.rfind('/') + 1, rest.size() - rest.rfind('/') - 4);
    const double growth = v.get<double>() - it->second;
    if (!kFault.count(family) || growth <= kBearingGrowthDb) continue;
    const bool cage = family == "FTF";
    const auto have = grown.find(bearing);
    if (have == grown.end() || (have->second.family == "FTF" && !cage) ||
        (growth > have->second.growth && (cage == (have->second.family == "FTF")))) {
      grown[bearing] = {family, growth, v.get<double>(), it->second};
    }
  }
  const json shafts = row.value("bearing_shafts", json::object());
  for (const auto& [bearing, g] : grown) {
    if (std::any_of(standing.begin(), standing.end(),
                    [&](const std::string& k) { return k.starts_with(bearing + "|"); })) {
      continue;
    }
    json f = {
        {"kind", "bearing"},
        {"fault", kFault.at(g.family)},
        {"bearing", bearing},
        {"confidence", std::min(1.0, g.growth / (2 * kBearingGrowthDb))},
        {"score_db", g.line},
        {"evidence", {{"growth_db", g.growth}, {"line_db", g.line}, {"reference_db", g.reference}}},
        {"note", "the " + g.family + " lines of " + bearing + " stand " +
                     diag::format_significant(g.growth, 3) +
                     " dB over the healthy reference's largest (" +
                     diag::format_significant(g.reference, 3) + " dB over the local floor)" +
                     (g.family == "FTF" ? ", no race or ball line with them: the rolling "
                                          "elements' defect, modulated by the cage (or the cage)"
                                        : "")}};
    if (shafts.contains(bearing)) f["shaft"] = shafts[bearing];
    kept.push_back(f);
  }
  row["finding_list"] = kept;
  row["findings"] = short_findings(kept);
}

// The anomaly alarm against the reference's own scores. Each reference recording is scored
// against the reference it belongs to (in-sample, so lower than a new healthy recording would
// score); when even those exceed the alarm threshold, the reference is not one operating state
// (a first recording before a run-in, a sensor remounted), and a later recording alarming at the
// same level says nothing new. A later recording's alarm (the baseline finding) stands only when
// its score exceeds kReferenceScoreMargin x the largest of the band's reference scores, where
// that lies above the threshold; else it is withheld, the row's alarm cleared and its
// `withheld` saying why. Where the reference scores below the threshold (the usual case) the
// threshold stands as it is.
void withhold_alarm_within_reference(json& row, const std::vector<json>& rows,
                                     const std::vector<std::size_t>& members) {
  if (row.value("alarm", 0) == 0 || !row.contains("anomaly_score")) return;
  double largest = 0;
  for (std::size_t m : members) {
    if (rows[m].contains("anomaly_score") && rows[m]["anomaly_score"].is_number()) {
      largest = std::max(largest, rows[m]["anomaly_score"].get<double>());
    }
  }
  const double gate = kReferenceScoreMargin * largest;
  const double score = row["anomaly_score"].get<double>();
  if (gate <= row.value("alarm_threshold", 0.0) || score > gate) return;
  json kept = json::array();
  for (const json& f : row.value("finding_list", json::array())) {
    if (f.value("kind", "") != "baseline") {
      kept.push_back(f);
      continue;
    }
    row["withheld"].push_back(
        {{"finding", short_findings(json::array({f}))},
         {"reason", "the healthy reference's own recordings score up to " +
                        diag::format_significant(largest, 3) +
                        " against it, over the alarm "
                        "threshold " +
                        diag::format_significant(row.value("alarm_threshold", 0.0), 3) +
                        "; this recording " + diag::format_significant(score, 3) + ", not over " +
                        diag::format_significant(kReferenceScoreMargin, 3) + " x theirs"}});
  }
  row["alarm"] = 0;
  row["finding_list"] = kept;
  row["findings"] = short_findings(kept);
}

// An event is confirmed when two successive recordings judged against the reference (status ok:
// the not comparable and failed ones are passed over) show it: one recording alone can be an
// outlier of a healthy machine (the damaged-shaft locator's comparison scored 23-35 on healthy
// shafts of single recordings of life histories, its threshold 20, and the next recording fell
// back). `first_recording` is the first of the two, `confirmed_recording` the second; an event
// never confirmed is "unconfirmed", or "pending" when its last sighting is the history's last
// judged recording (the next one will tell).
void confirm_events(std::vector<json>& rows, const std::vector<bool>& reference, json& events) {
  std::vector<std::size_t> judged;  // the rows judged, in order
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!reference[i] && rows[i].value("status", "") == "ok") judged.push_back(i);
  }
  for (json& e : events) {
    const std::set<std::size_t> seen = e["recordings"].get<std::set<std::size_t>>();
    e["status"] = "unconfirmed";
    e["confirmed_recording"] = nullptr;
    for (std::size_t k = 0; k + 1 < judged.size(); ++k) {
      if (seen.count(judged[k]) && seen.count(judged[k + 1])) {
        e["status"] = "confirmed";
        e["first_recording"] = judged[k];
        e["first_time"] = rows[judged[k]].value("time", "");
        e["confirmed_recording"] = judged[k + 1];
        break;
      }
    }
    if (e["status"] == "unconfirmed" && !judged.empty() && seen.count(judged.back())) {
      e["status"] = "pending";
    }
  }
}

// A history's operating states: the reference's speeds grouped into bands (sorted, a new band
// where the next speed lies more than 2 kComparableSpeed above the band's last), and within each,
// with a load channel (--load), its loads the same way (kComparableLoad, on the channel's RMS);
// each band the reference of the later recordings whose speed and load lie within it, widened by
// kComparableSpeed and kComparableLoad (a recording outside every band is not comparable).
// Without speeds (no description), one band of every reference recording.
constexpr double kComparableSpeed = 0.05;
constexpr double kComparableLoad = 0.10;

// A mesh's wear threshold from a band's reference (wear_gates, below).
struct WearGate {
  std::size_t n = 0;     // the reference recordings that read the mesh's growth
  double mean = 0;       // their growth's mean [dB]
  double sd = 0;         // its standard deviation [dB] (n - 1 in the denominator; 0 for n = 1)
  double threshold = 0;  // [dB]: from the spread (from_spread), else the single recording's
};

struct OperatingBand {
  double lo = 0, hi = 0;                 // speed [rpm]; 0, 0 without speeds
  double load_lo = 0, load_hi = 0;       // the load channel's RMS; 0, 0 without a load channel
  std::vector<std::size_t> members;      // reference rows, in time order
  std::map<std::string, WearGate> wear;  // per mesh read; empty until wear_gates
};

std::optional<double> row_value(const json& row, const char* key) {
  if (!row.contains(key) || !row[key].is_number()) return std::nullopt;
  return row[key].get<double>();
}

// `items` (value, row) grouped where the sorted values step by more than 2 `tolerance`.
std::vector<std::vector<std::pair<double, std::size_t>>> group_by(
    std::vector<std::pair<double, std::size_t>> items, double tolerance) {
  std::sort(items.begin(), items.end());
  std::vector<std::vector<std::pair<double, std::size_t>>> groups;
  for (const auto& item : items) {
    if (groups.empty() || item.first > groups.back().back().first * (1 + 2 * tolerance)) {
      groups.emplace_back();
    }
    groups.back().push_back(item);
  }
  return groups;
}

std::vector<OperatingBand> operating_bands(const std::vector<json>& rows,
                                           const std::vector<bool>& reference) {
  std::vector<std::pair<double, std::size_t>> speeds;
  std::vector<std::size_t> all;
  for (std::size_t i = 0; i < rows.size() && i < reference.size(); ++i) {
    if (!reference[i]) continue;
    all.push_back(i);
    if (const auto v = row_value(rows[i], "speed_rpm")) speeds.emplace_back(*v, i);
  }
  std::vector<std::vector<std::pair<double, std::size_t>>> by_speed;
  if (speeds.empty()) {
    by_speed.emplace_back();
    for (std::size_t i : all) by_speed.back().emplace_back(0.0, i);
  } else {
    by_speed = group_by(speeds, kComparableSpeed);
  }
  std::vector<OperatingBand> bands;
  for (const auto& group : by_speed) {
    std::vector<std::pair<double, std::size_t>> loads;
    for (const auto& [v, i] : group) {
      if (const auto l = row_value(rows[i], "load")) loads.emplace_back(*l, i);
    }
    if (loads.size() != group.size()) {  // not every recording has the load: speed only
      loads.clear();
      for (const auto& [v, i] : group) loads.emplace_back(0.0, i);
    }
    for (const auto& by_load : group_by(loads, kComparableLoad)) {
      OperatingBand b;
      b.lo = std::numeric_limits<double>::infinity();
      b.load_lo = b.lo;
      for (const auto& [l, i] : by_load) {
        const double v = row_value(rows[i], "speed_rpm").value_or(0.0);
        b.lo = std::min(b.lo, v);
        b.hi = std::max(b.hi, v);
        b.load_lo = std::min(b.load_lo, l);
        b.load_hi = std::max(b.load_hi, l);
        b.members.push_back(i);
      }
      std::sort(b.members.begin(), b.members.end());
      bands.push_back(std::move(b));
    }
  }
  return bands;
}

// The band of a recording at `rpm` and `load`, or -1 when it lies outside every band (widened by
// kComparableSpeed and kComparableLoad). An unknown speed or load, or bands without one, match.
int band_of(const std::vector<OperatingBand>& bands, std::optional<double> rpm,
            std::optional<double> load) {
  for (std::size_t b = 0; b < bands.size(); ++b) {
    const OperatingBand& o = bands[b];
    const bool speed_ok =
        o.hi == 0 || !rpm ||
        (*rpm >= o.lo * (1 - kComparableSpeed) && *rpm <= o.hi * (1 + kComparableSpeed));
    const bool load_ok =
        o.load_hi == 0 || !load ||
        (*load >= o.load_lo * (1 - kComparableLoad) && *load <= o.load_hi * (1 + kComparableLoad));
    if (speed_ok && load_ok) return static_cast<int>(b);
  }
  return -1;
}

int band_of(const std::vector<OperatingBand>& bands, const json& row) {
  return band_of(bands, row_value(row, "speed_rpm"), row_value(row, "load"));
}

// "1500-1510 rpm", with " at load 120-131" when the band has one.
std::string describe(const OperatingBand& b) {
  std::string out = b.hi > 0 ? diag::format_significant(b.lo, 5) + "-" +
                                   diag::format_significant(b.hi, 5) + " rpm"
                             : std::string("any speed");
  if (b.load_hi > 0) {
    out += " at load " + diag::format_significant(b.load_lo, 4) + "-" +
           diag::format_significant(b.load_hi, 4);
  }
  return out;
}

// A history's wear threshold per mesh, from its band's reference. The growth g of a mesh's
// harmonics (mesh_harmonic_growth.hpp) is the mean over the channels of each channel's level
// [dB] less a level per channel fixed by the reference, so a later recording's g and the
// reference recordings' own g_1..g_n (each against the whole reference, as every recording is)
// differ only by the recordings' levels. Where those scatter as independent Gaussians, a healthy
// recording's (g - mean) / (s sqrt(1 + 1/n)), with the mean and standard deviation s of the n
// reference values, is Student's t with n - 1 degrees of freedom (a prediction interval), so
//   threshold = mean + t_{n-1}(1 - kWearFalseAlarmRate) s sqrt(1 + 1/n)
// flags a healthy recording's mesh with probability kWearFalseAlarmRate, whatever the scatter
// of this machine's levels (its gears, sensors, and the reference's speed and load jitter). The
// fixed 4 dB of a single recording covers other gears of the same grade; one machine against its
// own reference scatters far less (docs/validation.md, "A machine's history"). An event needs
// two successive recordings besides (confirm_events). s is taken at least kWearSpreadFloorDb (a
// reference of copies of one recording), the threshold too. A mesh that fewer than
// kWearMinReference reference recordings read keeps the fixed threshold.
constexpr double kWearFalseAlarmRate = 0.01;
constexpr double kWearSpreadFloorDb = 0.1;
constexpr std::size_t kWearMinReference = 3;

bool from_spread(const WearGate& w) { return w.n >= kWearMinReference; }

std::map<std::string, WearGate> wear_gates(const std::vector<json>& rows,
                                           const std::vector<std::size_t>& members) {
  std::map<std::string, std::vector<double>> growth;  // per mesh, the reference's own
  for (std::size_t m : members) {
    if (rows[m].value("status", "") == "error") continue;
    const json features = rows[m].value("features", json::object());
    for (const auto& [name, v] : features.items()) {
      constexpr std::string_view kPrefix = "wear/", kSuffix = "/growth_db";
      if (!name.starts_with(kPrefix) || !name.ends_with(kSuffix) || !v.is_number()) continue;
      growth[name.substr(kPrefix.size(), name.size() - kPrefix.size() - kSuffix.size())].push_back(
          v.get<double>());
    }
  }
  std::map<std::string, WearGate> out;
  for (const auto& [mesh, g] : growth) {
    WearGate w;
    w.n = g.size();
    const double n = static_cast<double>(w.n);
    w.mean = std::accumulate(g.begin(), g.end(), 0.0) / n;
    double ss = 0;
    for (double x : g) ss += (x - w.mean) * (x - w.mean);
    w.sd = w.n > 1 ? std::sqrt(ss / (n - 1)) : 0.0;
    if (!from_spread(w)) {
      w.threshold = detect::MeshHarmonicGrowthOptions{}.threshold_db;
      out[mesh] = w;
      continue;
    }
    w.threshold =
        std::max(kWearSpreadFloorDb,
                 prediction_bound(w.mean, w.sd, n - 1, n, kWearFalseAlarmRate, kWearSpreadFloorDb));
    out[mesh] = w;
  }
  return out;
}

// The history's verdicts on the rows (in time order; `reference`: the healthy reference's rows;
// `bands`: operating_bands of them): a later recording whose state lies outside every band is "not
// comparable": what compares it with the reference (the anomaly score, its alarm and the wear
// of each mesh) is taken out of its row, never read against the wrong state. A damaged-shaft
// finding within its band's own scores is withheld (withhold_within_reference). Then the events:
// each distinct finding of the later comparable recordings, with the recordings that show it,
// confirmed or not (confirm_events). Returns the notes.
std::vector<std::string> judge_history(std::vector<json>& rows, const std::vector<bool>& reference,
                                       const std::vector<OperatingBand>& bands, json& events) {
  std::vector<std::string> notes;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i]["index"] = i;
    if (!reference[i]) continue;
    rows[i]["reference"] = true;
    if (rows[i]["status"] == "ok") rows[i]["status"] = "reference";
  }
  const bool states = !(bands.size() == 1 && bands[0].hi == 0 && bands[0].load_hi == 0);
  std::string ranges;
  for (const OperatingBand& b : bands) ranges += (ranges.empty() ? "" : "; ") + describe(b);
  if (!states) {
    notes.push_back(
        "no speed known for the reference (no description): every recording is "
        "compared with it");
  } else if (bands.size() == 1 && bands[0].load_hi == 0) {
    notes.push_back("the reference runs at " + ranges + ": a recording outside " +
                    diag::format_significant(bands[0].lo * (1 - kComparableSpeed), 5) + "-" +
                    diag::format_significant(bands[0].hi * (1 + kComparableSpeed), 5) +
                    " rpm is not comparable");
  } else {
    bool loads = false;
    for (const OperatingBand& b : bands) loads = loads || b.load_hi > 0;
    notes.push_back("the reference runs " +
                    (loads ? "in " + std::to_string(bands.size()) + " operating states ("
                           : "at " + std::to_string(bands.size()) + " speeds (") +
                    ranges +
                    "): each later recording is compared with the reference recordings of its " +
                    (loads ? "state (speed within 5 %, load within 10 %)" : "speed (within 5 %)") +
                    ", one outside every one is not comparable");
  }
  std::vector<std::map<std::string, LocatorGate>> locator;
  for (std::size_t b = 0; b < bands.size(); ++b) {
    locator.push_back(locator_gates(rows, bands[b].members));
    if (locator.back().empty()) continue;
    std::string list;
    bool spread = true;
    for (const auto& [key, g] : locator.back()) {
      list += (list.empty() ? "" : ", ") + key + " " + diag::format_significant(g.threshold, 3) +
              " (reference up to " + diag::format_significant(g.largest, 3) + ")";
      spread = spread && from_spread(g);
    }
    notes.push_back(
        "the damaged-shaft locator's gates" +
        (bands.size() > 1 ? " at " + describe(bands[b]) : std::string()) +
        " (score: against the reference, each reference recording against the others; "
        "score_alone: each recording alone), " +
        (spread ? "from the reference's own spread (a healthy recording exceeds one with "
                  "probability " +
                      diag::format_significant(100 * kLocatorFalseAlarmRate, 2) + " %)"
                : "too few reference scores to read a spread from (two degrees of freedom "
                  "needed), so " +
                      diag::format_significant(kReferenceScoreMargin, 3) +
                      " x the reference's largest") +
        ": " + list +
        "; a later recording's gear damage on a shaft stands when one of its scores exceeds its "
        "gate, and a shaft whose score against the reference is in the locator's uncertain band "
        "and over its gate is a finding");
  }
  for (const OperatingBand& b : bands) {
    std::string fixed, list;  // the meshes read by too few reference recordings; the others
    for (const auto& [mesh, w] : b.wear) {
      if (!from_spread(w)) {
        fixed += (fixed.empty() ? "" : ", ") + mesh;
        continue;
      }
      list += (list.empty() ? "" : ", ") + mesh + " " + diag::format_significant(w.threshold, 3) +
              " dB (reference " + diag::format_significant(w.mean, 2) + " +- " +
              diag::format_significant(w.sd, 2) + " dB over " + std::to_string(w.n) + ")";
    }
    if (!fixed.empty()) {
      notes.push_back(
          "the wear indicator" + (bands.size() > 1 ? " at " + describe(b) : std::string()) + " (" +
          fixed + ") keeps the single recording's threshold of " +
          diag::format_significant(detect::MeshHarmonicGrowthOptions{}.threshold_db, 3) +
          " dB: a spread needs at least " + std::to_string(kWearMinReference) +
          " reference recordings that read it");
    }
    if (list.empty()) continue;
    notes.push_back("the wear indicator's thresholds" +
                    (bands.size() > 1 ? " at " + describe(b) : std::string()) +
                    ", from the reference's own spread (mean + t s sqrt(1 + 1/n): a healthy "
                    "recording flags a mesh with probability " +
                    diag::format_significant(100 * kWearFalseAlarmRate, 2) + " %): " + list);
  }
  std::vector<ReferenceBearings> ref_bearings;
  for (const OperatingBand& b : bands) ref_bearings.push_back(reference_bearings(rows, b.members));
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    json& row = rows[i];
    if (reference[i] || row["status"] != "ok") continue;
    const int b = band_of(bands, row);
    if (b >= 0) {
      row["band"] = b;
      withhold_within_reference(row, locator[static_cast<std::size_t>(b)]);
      locator_growth(row, locator[static_cast<std::size_t>(b)]);
      withhold_alarm_within_reference(row, rows, bands[static_cast<std::size_t>(b)].members);
      judge_bearings(row, ref_bearings[static_cast<std::size_t>(b)]);
    } else {
      row["status"] = "not comparable";
      const auto v = row_value(row, "speed_rpm");
      const auto l = row_value(row, "load");
      std::string state =
          "its operating state (" +
          (v ? diag::format_significant(*v, 5) + " rpm" : std::string("speed unknown")) +
          (l ? " at load " + diag::format_significant(*l, 4) : std::string()) + ")";
      row["error"] = state + " is outside the reference's (" + ranges + "): not compared with it";
      for (const char* k : {"anomaly_score", "alarm", "alarm_threshold"}) row.erase(k);
      json kept = json::array();
      for (const json& f : row["finding_list"]) {
        if (f.value("kind", "") != "baseline" && f.value("kind", "") != "wear") kept.push_back(f);
      }
      row["finding_list"] = kept;
      row["findings"] = short_findings(kept);
    }
    for (const json& f : row.value("finding_list", json::array())) {
      const auto [it, fresh] = index.emplace(event_key(f), events.size());
      if (fresh) {
        json e = {{"kind", f.value("kind", "")}, {"fault", f.value("fault", "")}};
        for (const char* k : {"shaft", "bearing", "gears"}) {
          if (f.contains(k)) e[k] = f[k];
        }
        e["first_recording"] = i;
        e["first_time"] = row.value("time", "");
        e["recordings"] = json::array();
        e["trend"] = json::array();
        events.push_back(e);
      }
      json& e = events[it->second];
      if (e["recordings"].empty() || e["recordings"].back() != i) {
        e["recordings"].push_back(i);
        json point = {{"recording", i}, {"confidence", f.value("confidence", 0.0)}};
        if (row.contains("anomaly_score") && f.value("kind", "") == "baseline") {
          point["anomaly_score"] = row["anomaly_score"];
        }
        // The indicator behind it: the locator's scores of the shaft, a mesh's growth [dB].
        if (f.value("kind", "") == "gear_damage") {
          const json features = row.value("features", json::object());
          for (const char* which : {"score", "score_alone"}) {
            const std::string key = "gear_damage/" + f.value("shaft", "") + "/" + which;
            if (features.contains(key)) point[which] = features[key];
          }
        }
        if (f.contains("evidence") && f["evidence"].contains("growth_db")) {
          point["growth_db"] = f["evidence"]["growth_db"];
        }
        if (f.value("kind", "") == "bearing" && f.contains("score_db")) {
          point["score_db"] = f["score_db"];
        }
        e["trend"].push_back(point);
      }
      e["last_recording"] = i;
    }
  }
  confirm_events(rows, reference, events);
  for (json& row : rows) {
    if (!row.is_object()) continue;
    row.erase("bearing_shafts");
    row.erase("gear_damage_shafts");
  }
  return notes;
}

std::vector<std::string> read_list(const std::string& list) {
  std::ifstream in(list);
  if (!in) throw diag::InputError("--list " + list + ": cannot be read");
  std::vector<std::string> files;
  std::string line;
  const fs::path base = fs::path(list).parent_path();
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    fs::path p(line);
    files.push_back((p.is_relative() ? base / p : p).string());
  }
  return files;
}

}  // namespace

BatchResult run_batch(BatchRequest request, const MpiWorld& world) {
  BatchResult out;
  std::vector<std::string>& files = request.files;
  std::vector<std::string>& baselines = request.baselines;
  const std::vector<std::string>& healthy = request.healthy;
  const int healthy_first = request.healthy_first;
  if (files.empty()) throw diag::InputError("no recordings: give FILE... or --list LIST.txt");
  Inputs in;
  in.channels = request.channels;
  in.fs = request.fs;
  in.reports = request.reports;
  in.load_channel = request.load_channel;
  // A history: the recordings in time order, the reference first.
  const bool history = healthy_first != 0 || !healthy.empty();
  out.history = history;
  std::vector<std::string>& history_notes = out.notes;
  std::vector<bool>& reference = out.reference;
  std::string& order = out.order;
  if (history) {
    if (!baselines.empty()) {
      throw diag::InputError(
          "--baseline: a history's baseline is its reference "
          "(--healthy-first or --healthy), not given apart");
    }
    if (healthy_first != 0 && !healthy.empty()) {
      throw diag::InputError("--healthy-first and --healthy: give one reference, not both");
    }
    if (healthy.empty() &&
        (healthy_first < 0 || static_cast<std::size_t>(healthy_first) >= files.size())) {
      throw diag::InputError("--healthy-first: " + std::to_string(healthy_first) +
                             " is not in [1, " + std::to_string(files.size() - 1) +
                             "] (the reference, and at least one recording after it)");
    }
    std::vector<std::pair<std::string, std::string>> timed;  // (time, file)
    bool every_time = true;
    for (const std::string& f : files) {
      timed.emplace_back(file_time(f), f);
      every_time = every_time && !timed.back().first.empty();
    }
    if (every_time) {
      std::stable_sort(timed.begin(), timed.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      order = "time";
      for (std::size_t i = 0; i < files.size(); ++i) files[i] = timed[i].second;
    } else {
      history_notes.push_back("not every recording says when it was made: the order given");
    }
    if (!healthy.empty()) {
      files.insert(files.begin(), healthy.begin(), healthy.end());
      baselines = healthy;
    } else {
      baselines.assign(files.begin(), files.begin() + healthy_first);
    }
    reference.assign(files.size(), false);
    std::fill(reference.begin(), reference.begin() + static_cast<std::ptrdiff_t>(baselines.size()),
              true);
  }
  if (!request.gearbox.empty()) in.gearbox = diag::load_gearbox(request.gearbox);
  if (!in.reports.empty()) {
    std::error_code ec;
    fs::create_directories(in.reports, ec);
    if (ec || !fs::is_directory(in.reports)) {
      throw diag::InputError("--reports " + in.reports + ": not a folder that can be made (" +
                             (ec ? ec.message() : std::string("a file of that name exists")) + ")");
    }
  }
  // The baseline is read before any analysis: a bad baseline file stops the batch with its name.
  for (const std::string& b : baselines) {
    try {
      diag::OpenOptions o;
      o.fs_hz = in.fs;
      in.baseline.emplace_back(std::make_shared<const diag::Recording>(diag::open_recording(b, o)),
                               b);
    } catch (const diag::InputError& e) {
      throw diag::InputError(std::string(history ? "the reference " : "--baseline ") + e.what());
    }
  }
  // A history compares each recording's revolution averages with the reference's (below).
  // (Only with a description: without one there is no shaft to average over.)
  const bool described =
      in.gearbox || (!in.baseline.empty() && !in.baseline.front().recording->gearbox_json.empty());
  if (history && described) {
    in.gear_baseline = in.baseline.front();
    in.gear_cache = std::make_shared<GearBaselineCache>();
  }
  out.files = files;
  // One round of analyses: the rows `which` (split across the ranks), each with the inputs
  // `inputs_of` gives it; on rank 0 their rows land in out.rows.
  out.rows.assign(files.size(), json());
  auto analyse_rows = [&](const std::vector<std::size_t>& which,
                          const std::function<const Inputs&(std::size_t)>& inputs_of) {
    std::vector<std::size_t> mine;
    for (std::size_t k = static_cast<std::size_t>(world.rank()); k < which.size();
         k += static_cast<std::size_t>(world.size())) {
      mine.push_back(which[k]);
    }
    std::vector<json> rows(mine.size());
    Progress progress("batch", mine.size(), world.root() && request.progress);
    std::vector<Opened> opened(mine.size());
    run_in_rounds(
        mine.size(), request.jobs,
        [&](std::size_t i) { opened[i] = open_file(files[mine[i]], inputs_of(mine[i])); },
        [&](std::size_t i) {
          rows[i] = analyse(mine[i], files[mine[i]], std::move(opened[i]), inputs_of(mine[i]));
          opened[i] = {};
          progress.tick();
        });
    progress.finish();
    json part = json::array();
    for (std::size_t i = 0; i < mine.size(); ++i) part.push_back({mine[i], rows[i]});
    for (const std::string& p : world.gather(part.dump())) {
      for (const json& item : json::parse(p)) out.rows[item[0].get<std::size_t>()] = item[1];
    }
  };
  auto every = [&](std::size_t) -> const Inputs& { return in; };
  std::vector<std::size_t> all(files.size());
  std::iota(all.begin(), all.end(), std::size_t{0});
  if (!history) {
    analyse_rows(all, every);
    for (json& row : out.rows) {  // only a history's judgement reads it
      if (!row.is_object()) continue;
      row.erase("bearing_shafts");
      row.erase("gear_damage_shafts");
    }
    return out;
  }
  // A history: the reference first, each of its recordings against the whole reference; its
  // speeds (and loads) give the operating states (operating_bands), known to every rank.
  const std::vector<std::size_t> ref_rows(all.begin(), all.begin() + baselines.size());
  const std::vector<std::size_t> later(all.begin() + baselines.size(), all.end());
  // The damaged-shaft locator compares a recording with every reference recording of its state
  // and keeps, per shaft, the one that explains it best (GearDamageOptions::more_baselines); a
  // reference recording with the others (left out itself, so that the reference's own scores say
  // how a healthy recording scores).
  auto gear_reference = [&](Inputs inputs, const std::vector<detect::RecordingInput>& members,
                            std::optional<std::size_t> leave_out) {
    inputs.gear_baseline.reset();
    inputs.more_gear_baselines.clear();
    if (!described) return inputs;
    for (std::size_t m = 0; m < members.size(); ++m) {
      if (leave_out && m == *leave_out) continue;
      if (!inputs.gear_baseline) {
        inputs.gear_baseline = members[m];
      } else {
        inputs.more_gear_baselines.push_back(members[m]);
      }
    }
    return inputs;
  };
  std::vector<Inputs> ref_in;
  for (std::size_t m = 0; m < ref_rows.size(); ++m) {
    ref_in.push_back(gear_reference(in, in.baseline, m));
  }
  analyse_rows(ref_rows, [&](std::size_t i) -> const Inputs& { return ref_in[i]; });
  std::string speeds = json(out.rows).dump();
  world.broadcast(speeds);
  std::vector<OperatingBand> bands =
      operating_bands(json::parse(speeds).get<std::vector<json>>(), reference);
  // Each band is the reference of the recordings at its speed: its recordings the baseline, its
  // first the gear baseline.
  std::vector<Inputs> band_in(bands.size(), in);
  for (std::size_t b = 0; b < bands.size(); ++b) {
    band_in[b].baseline.clear();
    for (std::size_t m : bands[b].members) band_in[b].baseline.push_back(in.baseline[m]);
    band_in[b] = gear_reference(band_in[b], band_in[b].baseline, std::nullopt);
  }
  std::vector<int> band_at(files.size(), 0);
  for (std::size_t b = 0; b < bands.size(); ++b) {
    for (std::size_t m : bands[b].members) band_at[m] = static_cast<int>(b);
  }
  auto by_band = [&](std::size_t i) -> const Inputs& {
    return band_in[static_cast<std::size_t>(std::max(0, band_at[i]))];
  };
  if (bands.size() > 1) {  // each against its own band, itself left out
    for (std::size_t b = 0; b < bands.size(); ++b) {
      for (std::size_t k = 0; k < bands[b].members.size(); ++k) {
        ref_in[bands[b].members[k]] = gear_reference(band_in[b], band_in[b].baseline, k);
      }
    }
    analyse_rows(ref_rows, [&](std::size_t i) -> const Inputs& { return ref_in[i]; });
  }
  // Each band's wear thresholds from its reference's own growth (wear_gates), on every rank.
  std::string gates;
  if (world.root()) {
    json all_gates = json::array();
    for (const OperatingBand& b : bands) {
      json g = json::object();
      for (const auto& [mesh, w] : wear_gates(out.rows, b.members)) {
        g[mesh] = {w.n, w.mean, w.sd, w.threshold};
      }
      all_gates.push_back(g);
    }
    gates = all_gates.dump();
  }
  world.broadcast(gates);
  const json all_gates = json::parse(gates);
  for (std::size_t b = 0; b < bands.size(); ++b) {
    for (const auto& [mesh, g] : all_gates.at(b).items()) {
      const WearGate w = {g[0].get<std::size_t>(), g[1].get<double>(), g[2].get<double>(),
                          g[3].get<double>()};
      bands[b].wear[mesh] = w;
      if (from_spread(w)) band_in[b].wear_threshold_db[mesh] = w.threshold;
    }
  }
  // The later recordings: against the first band, then, for those whose speed lies in another
  // band, again against that one (their speed is known only from their analysis).
  analyse_rows(later, by_band);
  if (bands.size() > 1) {
    std::string again;
    if (world.root()) {
      json redo = json::array();
      for (std::size_t i : later) {
        const int b = band_of(bands, out.rows[i]);
        if (b > 0) redo.push_back({i, b});
      }
      again = redo.dump();
    }
    world.broadcast(again);
    std::vector<std::size_t> redo;
    for (const json& item : json::parse(again)) {
      redo.push_back(item[0].get<std::size_t>());
      band_at[redo.back()] = item[1].get<int>();
    }
    if (!redo.empty()) analyse_rows(redo, by_band);
  }
  if (!world.root()) return out;
  for (const OperatingBand& b : bands) {
    json state = {{"reference", b.members}, {"wear", json::object()}};
    if (b.hi > 0) state["speed_rpm"] = {b.lo, b.hi};
    if (b.load_hi > 0) state["load"] = {b.load_lo, b.load_hi};
    for (const auto& [mesh, w] : b.wear) {
      if (!from_spread(w)) continue;
      state["wear"][mesh] = {{"reference_recordings", w.n},
                             {"mean_db", w.mean},
                             {"sd_db", w.sd},
                             {"threshold_db", w.threshold}};
    }
    for (const auto& [key, g] : locator_gates(out.rows, b.members)) {
      state["locator"][key] = {{"reference_recordings", g.n},
                               {"largest", g.largest},
                               {"threshold", g.threshold},
                               {"from_spread", from_spread(g)}};
      if (!from_spread(g)) continue;
      state["locator"][key]["mean_log"] = g.mean_log;
      state["locator"][key]["sd_log"] = g.sd_log;
      state["locator"][key]["dof"] = g.df;
    }
    out.states.push_back(std::move(state));
  }
  for (std::string& n : judge_history(out.rows, reference, bands, out.events)) {
    history_notes.push_back(std::move(n));
  }
  if (bands.size() == 1) {
    for (const auto& [key, g] : locator_gates(out.rows, bands[0].members)) {
      out.locator_gate[key] = g.threshold;
    }
    const ReferenceBearings bearings = reference_bearings(out.rows, bands[0].members);
    for (const auto& [key, v] : bearings.line_db) {
      if (steady(bearings, key)) out.bearing_gate[key] = v + kBearingGrowthDb;
    }
    for (const auto& [mesh, w] : bands[0].wear) {
      if (from_spread(w)) out.wear_gate[mesh] = w.threshold;
    }
  }
  return out;
}

int cmd_batch(int argc, char** argv) {
  tune_allocator_for_recordings();
  BatchRequest request;
  std::vector<std::string>& files = request.files;
  std::vector<std::string> trend;
  std::string list, table, html, json_out;
  double fs_hz = 0;
  int jobs = 0;
  po::options_description desc(
      "geardiag batch FILE... | --list LIST.txt [--gearbox GB.json] [--baseline FILE...] "
      "-o TABLE.csv [--html OUT.html] [--json OUT.json] [--trend FEATURE...] [--jobs N]\n"
      "geardiag batch FILE... --healthy-first K | --healthy FILE... [...]: a machine's history\n"
      "mpirun -np N geardiag batch ...\n\n"
      "Analyses every recording as `geardiag analyze` does and writes one row per recording:\n"
      "file, time stamp (the file's metadata, else its name), speed, status and error, the\n"
      "anomaly score and alarm against --baseline (healthy recordings of the same channels),\n"
      "the findings in short form and every condition indicator per channel\n"
      "(\"<channel>/<indicator>\"). A file that fails is a row with its error. --html: the\n"
      "trend of the --trend indicators and of the anomaly score with its alarm threshold.\n"
      "--list: one file per line (relative to the list's folder; '#' comments).\n"
      "A history (--healthy-first K or --healthy): the recordings in time order (the file's\n"
      "time, else a date in its name, else the order given), the first K (or the --healthy\n"
      "files) the machine's healthy reference, learned per speed (and per load with --load);\n"
      "every later recording compared with the reference of its own speed (not comparable\n"
      "outside every one); an event is a finding two successive recordings show; --json: the\n"
      "recordings and the events (confirmed, pending or unconfirmed).\n\noptions");
  desc.add_options()("help,h", "this help")("files", po::value(&files)->multitoken(), "recordings")(
      "list", po::value(&list), "a file listing the recordings, one per line")(
      "gearbox", po::value(&request.gearbox),
      "gearbox description (default: each file's /gearbox)")(
      "baseline", po::value(&request.baselines)->multitoken(),
      "healthy recordings to compare with")("output,o", po::value(&table)->required(),
                                            "the table (CSV; '-': stdout)")(
      "html", po::value(&html), "trend page (HTML)")(
      "json", po::value(&json_out), "the recordings and the history's events (JSON)")(
      "healthy-first", po::value(&request.healthy_first)->default_value(0),
      "a history: the first K recordings in time order are the healthy reference")(
      "healthy", po::value(&request.healthy)->multitoken(),
      "a history: these recordings are the healthy reference")(
      "trend", po::value(&trend)->multitoken(),
      "indicators to trend (default: rms and kurtosis of the first sensor channel)")(
      "load", po::value(&request.load_channel),
      "a channel whose RMS level is the machine's load (a torque, a motor current): a history's "
      "reference is learned per speed and load, a long log's frames cut where it steps")(
      "reports", po::value(&request.reports),
      "a folder for each recording's own HTML report (as analyze --html), linked from --html")(
      "fs", po::value(&fs_hz), "sampling rate [Hz] for CSV without time column / MAT")(
      "jobs,j", po::value(&jobs)->default_value(0), "worker threads per process; 0 = every core");
  request.channels.add_to(desc, true);
  po::positional_options_description pos;
  pos.add("files", -1);
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm, &pos)) return 0;
  MpiWorld world(&argc, &argv);
  request.jobs = resolve_jobs(jobs);
  if (!list.empty()) {
    for (std::string& f : read_list(list)) files.push_back(std::move(f));
  }
  if (vm.count("fs")) {
    if (!(fs_hz > 0 && std::isfinite(fs_hz))) throw diag::InputError("--fs: must be > 0");
    request.fs = fs_hz;
  }
  const bool table_stdout = check_output(table, "--output");
  const bool html_stdout = !html.empty() && check_output(html, "--html");
  const bool json_stdout = !json_out.empty() && check_output(json_out, "--json");
  if (table_stdout + html_stdout + json_stdout > 1) {
    throw diag::InputError("-o, --html and --json: only one output can go to stdout");
  }
  const BatchResult batch = run_batch(std::move(request), world);
  if (!world.root()) return 0;
  const std::vector<json>& all = batch.rows;
  const json& events = batch.events;
  const std::vector<std::string>& history_notes = batch.notes;
  files = batch.files;
  std::set<std::string> features;
  std::size_t failed = 0, alarms = 0;
  for (const json& r : all) {
    failed += r["status"] == "error";
    alarms += r.value("alarm", 0);
    if (r.contains("features")) {
      for (const auto& [name, v] : r["features"].items()) features.insert(name);
    }
  }
  write_output(table, table_csv(all, features), "--output");
  if (!json_out.empty()) {
    json recordings = json::array();
    for (const json& r : all) {
      json out = r;
      out.erase("finding_list");
      out.erase("features");
      out.erase("first_channel");
      out["findings"] = r.value("finding_list", json::array());
      out["indicators"] = r.value("features", json::object());
      recordings.push_back(std::move(out));
    }
    json doc = {{"order", batch.order},
                {"notes", history_notes},
                {"recordings", recordings},
                {"events", events}};
    if (batch.history) {
      doc["states"] = batch.states;
      doc["reference"] = json::array();
      for (std::size_t i = 0; i < files.size(); ++i) {
        if (batch.reference[i]) doc["reference"].push_back(files[i]);
      }
    }
    write_output(json_out, doc.dump(1) + "\n", "--json");
  }
  if (!html.empty()) {
    if (trend.empty()) {  // the first sensor channel's, as the analysis lists them
      for (const json& r : all) {
        if (r.value("first_channel", "").empty()) continue;
        const std::string channel = r["first_channel"].get<std::string>();
        trend = {channel + "/rms", channel + "/kurtosis"};
        break;
      }
    }
    const fs::path page_dir = html_stdout ? fs::current_path() : fs::absolute(html).parent_path();
    write_output(html,
                 trend_html(all, trend, batch.order, events, page_dir, batch.locator_gate,
                            batch.bearing_gate, batch.wear_gate),
                 "--html");
  }
  std::ostream& say = table_stdout || html_stdout || json_stdout ? std::cerr : std::cout;
  say << files.size() << " recordings, " << failed << " failed, " << alarms << " alarm(s) -> "
      << table << (html.empty() ? "" : " and " + html)
      << (json_out.empty() ? "" : " and " + json_out) << "\n";
  for (const std::string& n : history_notes) say << "note: " << n << "\n";
  for (const json& e : events) {
    const std::size_t first = e["first_recording"].get<std::size_t>();
    const std::string status = e.value("status", "confirmed");
    const std::string what = event_name(e);
    const std::string at =
        fs::path(files[first]).filename().string() +
        (e["first_time"].get<std::string>().empty() ? ""
                                                    : ", " + e["first_time"].get<std::string>());
    std::size_t from_there = 0;
    for (const json& r : e["recordings"]) from_there += r.get<std::size_t>() >= first;
    if (status == "confirmed") {
      say << "event: " << what << ": from recording " << first << " (" << at
          << "), confirmed by recording " << e["confirmed_recording"].get<std::size_t>() << "; in "
          << from_there << " of the " << files.size() - first << " recordings from there\n";
    } else if (status == "pending") {
      say << "pending: " << what << ": in the last recording judged, " << e["last_recording"]
          << (e["recordings"].size() > 1
                  ? " (and " + std::to_string(e["recordings"].size() - 1) + " earlier, alone)"
                  : std::string())
          << "; the next recording confirms it or not\n";
    } else {
      say << "unconfirmed: " << what << ": in " << e["recordings"].size()
          << " recording(s), never in two successive ones (from recording " << first << ", " << at
          << "): not an event\n";
    }
  }
  return 0;
}

}  // namespace geardiag
