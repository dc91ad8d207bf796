// geardiag validate --dataset DIR: runs `analyze` on every recording of a dataset made by
// `geardiag dataset` and compares its verdict with the manifest's truth: the detectability map of
// that gearbox. The verdict is the damaged-gear locator's (detect/gear/gear_damage.hpp, finding
// kind "gear_damage"): a recording is "detected" when it names a shaft, "located" when that shaft
// carries the class's first fault. Printed: the confusion matrix (true class x the shaft named,
// "none" when no finding), the detection and location rates per class and the detection rate
// against fault size, speed and noise (four equal-width bins over the range present). --json and
// --html write the same.
#include "validate_dataset.hpp"

#include <algorithm>
#include <boost/program_options.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include "cli_options.hpp"
#include "detect/analysis/analyze_file.hpp"
#include "diag/error.hpp"
#include "diag/io/open_recording.hpp"
#include "output.hpp"
#include "parallel.hpp"
#include "report/svg_plot.hpp"
#include "validate_kinematic.hpp"

namespace po = boost::program_options;
namespace fs = std::filesystem;

namespace geardiag {

namespace {

using nlohmann::json;

}  // namespace

// Detection rate of the faulty recordings against one manifest column, in four equal-width bins.
json rate_by(const std::vector<json>& rows, const std::string& column) {
  double lo = INFINITY, hi = -INFINITY;
  for (const json& r : rows) {
    if (!r[column].is_number()) continue;
    lo = std::min(lo, r[column].get<double>());
    hi = std::max(hi, r[column].get<double>());
  }
  json out = json::array();
  if (!(lo <= hi)) return out;
  const int bins = hi > lo ? 4 : 1;
  std::vector<int> n(bins, 0), hit(bins, 0);
  for (const json& r : rows) {
    if (!r[column].is_number()) continue;
    const double x = r[column].get<double>();
    const int b = hi > lo ? std::min(bins - 1, static_cast<int>((x - lo) / (hi - lo) * bins)) : 0;
    ++n[b];
    hit[b] += r["detected"].get<bool>();
  }
  for (int b = 0; b < bins; ++b) {
    const double w = (hi - lo) / bins;
    out.push_back({{"from", lo + b * w},
                   {"to", lo + (b + 1) * w},
                   {"recordings", n[b]},
                   {"detected", hit[b]},
                   {"rate", n[b] ? json(static_cast<double>(hit[b]) / n[b]) : json(nullptr)}});
  }
  return out;
}

namespace {

std::string html_report(const json& rep) {
  std::ostringstream h;
  h << "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>geardiag validate --dataset"
       "</title><style>body{font-family:sans-serif;margin:2em}td,th{border:1px solid #ccc;"
       "padding:3px 8px}table{border-collapse:collapse}</style></head><body>"
       "<h1>Detectability map: "
    << report::html_escape(rep["dataset"].get<std::string>()) << "</h1>";
  h << "<h2>Confusion matrix (true class x shaft named by the gear-damage locator)</h2><table>"
       "<tr><th>class</th>";
  for (const auto& col : rep["columns"])
    h << "<th>" << report::html_escape(col.get<std::string>()) << "</th>";
  h << "<th>detected</th><th>located</th></tr>";
  for (const auto& [cls, row] : rep["classes"].items()) {
    h << "<tr><td>" << report::html_escape(cls) << "</td>";
    for (const auto& col : rep["columns"])
      h << "<td>" << row["predicted"].value(col.get<std::string>(), 0) << "</td>";
    h << "<td>" << row["detected"] << " / " << row["recordings"] << "</td><td>" << row["located"]
      << "</td></tr>";
  }
  h << "</table>";
  for (const char* by : {"size_mm", "speed_rpm", "noise_m_per_s2"}) {
    h << "<h2>Detection rate of the faulty recordings vs " << by << "</h2><table><tr><th>" << by
      << "</th><th>detected / recordings</th><th>rate</th></tr>";
    for (const json& b : rep["rate_by"][by]) {
      h << "<tr><td>" << b["from"].get<double>() << " - " << b["to"].get<double>() << "</td><td>"
        << b["detected"] << " / " << b["recordings"] << "</td><td>"
        << (b["rate"].is_null() ? ""
                                : std::to_string(std::lround(100 * b["rate"].get<double>())) + " %")
        << "</td></tr>";
    }
    h << "</table>";
  }
  h << "</body></html>\n";
  return h.str();
}

}  // namespace

void judge_dataset_recordings(const std::string& dir, const std::vector<json>& rows, int jobs,
                              const std::function<diag::Recording(const std::string&)>& read,
                              const DatasetJudge& judge) {
  Progress progress("validate", rows.size(), true);
  std::vector<std::optional<diag::Recording>> recs(rows.size());
  std::vector<std::string> read_error(rows.size());
  auto path_of = [&](std::size_t i) {
    return (fs::path(dir) / rows[i]["file"].get<std::string>()).string();
  };
  run_in_rounds(
      rows.size(), jobs,
      [&](std::size_t i) {
        try {
          recs[i] = read(path_of(i));
        } catch (const std::exception& e) {
          read_error[i] = e.what();
        }
      },
      [&](std::size_t i) {
        judge(i, recs[i], path_of(i), read_error[i]);
        recs[i].reset();
        progress.tick();
      });
  progress.finish();
}

std::vector<json> read_manifest(const std::string& dir, const std::string& option) {
  const fs::path manifest = fs::path(dir) / "manifest.jsonl";
  std::ifstream in(manifest);
  if (!in) throw diag::InputError(option + " " + dir + ": no manifest.jsonl (not a dataset?)");
  std::vector<json> rows;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    try {
      rows.push_back(json::parse(line));
      if (!rows.back().contains("file") || !rows.back().contains("class"))
        throw std::runtime_error("");
    } catch (const std::exception&) {
      throw diag::InputError(manifest.string() + ": line " + std::to_string(n) +
                             ": not a manifest row");
    }
  }
  if (rows.empty()) throw diag::InputError(manifest.string() + ": no recordings");
  return rows;
}

int validate_dataset(int argc, char** argv) {
  std::string dir, json_out, html_out;
  int jobs = 0;
  po::options_description desc(
      "geardiag validate --dataset DIR [--json OUT.json] [--html OUT.html] [--jobs N]\n\n"
      "Analyses every recording of DIR/manifest.jsonl (made by geardiag dataset) and compares\n"
      "the damaged-gear locator's verdict with the truth: confusion matrix (class x shaft named),\n"
      "detection and location rate per class, detection rate vs fault size, speed and noise.\n"
      "A kinematic dataset goes through the period matcher (geardiag attribute): right /\n"
      "partial / silent / wrong per class.\n\n"
      "options");
  desc.add_options()("help,h", "this help")("dataset", po::value(&dir)->required(),
                                            "dataset folder")(
      "json", po::value(&json_out), "the report as JSON")("html", po::value(&html_out),
                                                          "the report as HTML")(
      "jobs,j", po::value(&jobs)->default_value(0), "worker threads; 0 = every core");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  jobs = resolve_jobs(jobs);
  if (!json_out.empty()) check_output(json_out, "--json");
  if (!html_out.empty()) check_output(html_out, "--html");
  std::vector<json> rows = read_manifest(dir, "--dataset");
  // Kinematic datasets go through the attribution (validate_kinematic.cpp); face-gear ones have
  // no detector.
  const std::string simulator = rows.front().value("simulator", "dynamic");
  if (simulator == "kinematic")
    return validate_kinematic_dataset(dir, rows, json_out, html_out, jobs);
  if (simulator != "dynamic") {
    throw diag::InputError("--dataset " + dir + ": a " + simulator +
                           " dataset: no detector reads these recordings yet (the manifest holds "
                           "each recording's simulated outcome)");
  }
  judge_dataset_recordings(
      dir, rows, jobs, [](const std::string& path) { return diag::open_recording(path); },
      [&](std::size_t i, std::optional<diag::Recording>& rec, const std::string& path,
          const std::string& read_error) {
        json& r = rows[i];
        std::string named = "none";
        try {
          if (!rec) throw diag::InputError(read_error);
          detect::AnalyzeRequest request;
          request.recording = detect::RecordingInput(
              std::make_shared<const diag::Recording>(std::move(*rec)), path);
          request.options.threads = 1;  // the recordings are the parallel work
          const detect::FileAnalysis a = detect::analyze_file(request);
          for (const auto& f : a.result.findings) {
            if (f.kind == "gear_damage") {
              named = f.shaft;
              break;
            }
          }
        } catch (const std::exception& e) {
          named = "error";
          r["error"] = e.what();
        }
        r["named"] = named;
        r["detected"] = named != "none" && named != "error";
        // A bearing fault's shaft is its bearing's: the gear locator naming it is no location.
        r["located"] = r.value("faults", 0) > 0 && r["fault1_shaft"].is_string() &&
                       r.value("fault1_type", json()) != "bearing" &&
                       named == r["fault1_shaft"].get<std::string>();
        r["size_mm"] = r.contains("fault1_size_mm") ? r["fault1_size_mm"] : json(nullptr);
      });
  std::set<std::string> columns = {"none"};
  json classes = json::object();
  std::vector<json> faulty;
  for (const json& r : rows) {
    const std::string cls = r["class"];
    columns.insert(r["named"].get<std::string>());
    json& c = classes[cls];
    if (!c.contains("predicted")) c["predicted"] = json::object();
    c["recordings"] = c.value("recordings", 0) + 1;
    c["detected"] = c.value("detected", 0) + (r["detected"].get<bool>() ? 1 : 0);
    c["located"] = c.value("located", 0) + (r["located"].get<bool>() ? 1 : 0);
    c["predicted"][r["named"].get<std::string>()] =
        c["predicted"].value(r["named"].get<std::string>(), 0) + 1;
    if (r.value("faults", 0) > 0) faulty.push_back(r);
  }
  json rep = {{"dataset", dir},
              {"decision", "gear_damage finding (the damaged-gear locator) names a shaft"},
              {"columns", columns},
              {"classes", classes},
              {"rate_by",
               {{"size_mm", rate_by(faulty, "size_mm")},
                {"speed_rpm", rate_by(faulty, "speed_rpm")},
                {"noise_m_per_s2", rate_by(faulty, "noise_m_per_s2")}}},
              {"recordings", rows}};
  std::cout << "confusion matrix (true class x shaft named by the gear-damage locator):\n  class";
  for (const std::string& c : columns) std::cout << "\t" << c;
  std::cout << "\tdetected\tlocated\n";
  for (const auto& [cls, c] : classes.items()) {
    std::cout << "  " << cls;
    for (const std::string& col : columns) std::cout << "\t" << c["predicted"].value(col, 0);
    std::cout << "\t" << c["detected"] << "/" << c["recordings"] << "\t" << c["located"] << "\n";
  }
  for (const char* by : {"size_mm", "speed_rpm", "noise_m_per_s2"}) {
    std::cout << "detection rate of the faulty recordings vs " << by << ":\n";
    for (const json& b : rep["rate_by"][by]) {
      std::cout << "  " << b["from"].get<double>() << " - " << b["to"].get<double>() << ": "
                << b["detected"] << " / " << b["recordings"] << "\n";
    }
  }
  const auto bearing_rows = std::count_if(rows.begin(), rows.end(), [](const json& r) {
    return r.value("fault1_type", json()) == "bearing";
  });
  if (bearing_rows > 0) {
    rep["note"] = std::to_string(bearing_rows) +
                  " recordings carry a bearing fault: this map judges the damaged-gear locator "
                  "only (their bearing findings are in `geardiag analyze`; `validate --history` "
                  "scores bearing faults over a life)";
    std::cout << "note: " << rep["note"].get<std::string>() << "\n";
  }
  if (!json_out.empty()) write_output(json_out, rep.dump(1) + "\n", "--json");
  if (!html_out.empty()) write_output(html_out, html_report(rep), "--html");
  return 0;
}

}  // namespace geardiag
