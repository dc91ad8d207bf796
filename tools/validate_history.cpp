// geardiag validate --history DIR: every life history of a dataset (`geardiag dataset` with a
// `life` block, tools/dataset_life.hpp) through the command a user runs on a machine's history,
// `geardiag batch --healthy-first K` (run_batch, tools/batch.hpp), and its verdicts against the
// manifest's truth: per history the first event the history confirms (two successive recordings)
// after the fault's onset (the detection delay, in recordings, and the fault's size there), the
// shaft and gear it names (right / silent / wrong), and every event confirmed on a healthy
// recording (a false alarm); per class the rates. docs/cli/validate.md.
#include <algorithm>
#include <boost/program_options.hpp>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "batch.hpp"
#include "cli_options.hpp"
#include "diag/error.hpp"
#include "diag/util/number_format.hpp"
#include "output.hpp"
#include "parallel.hpp"
#include "validate_dataset.hpp"

namespace po = boost::program_options;
namespace fs = std::filesystem;

namespace geardiag {

namespace {

using nlohmann::json;

// A manifest row's string field, "" when absent or null.
std::string text(const json& row, const char* key) {
  return row.contains(key) && row[key].is_string() ? row[key].get<std::string>() : std::string();
}

// The fault's size in a manifest row: crack depth, chip size or spall length [mm], wear depth
// [um], a bearing defect's impact amplitude [m/s^2]; NaN for none (a missing tooth, or a healthy
// row).
double fault_size(const json& row) {
  const std::string type = text(row, "fault1_type");
  const char* key = type == "wear"      ? "fault1_depth_um"
                    : type == "bearing" ? "fault1_amplitude_m_per_s2"
                                        : "fault1_size_mm";
  if (type.empty() || type == "missing" || !row.contains(key) || !row[key].is_number()) {
    return std::nan("");
  }
  return row[key].get<double>();
}

std::string size_unit(const std::string& type) {
  return type == "wear" ? "um" : type == "bearing" ? "m/s^2" : "mm";
}

// A recording's claims: its findings (the one Finding form; the baseline alarm is one of them).
bool claims(const json& row) {
  return row.value("alarm", 0) != 0 || !row.value("finding_list", json::array()).empty();
}

// Which gear an event names: "right" (the true gear alone), "either" (the true gear among the
// gears of its shaft: "z2 or z3"), "wrong", or "none".
std::string gear_verdict(const json& gears, const std::string& gear) {
  if (gears.empty()) return "none";
  const bool has = std::find(gears.begin(), gears.end(), json(gear)) != gears.end();
  return !has ? "wrong" : gears.size() == 1 ? "right" : "either";
}

// An event in short form: "gear_damage counter z2 z3".
std::string short_findings_of(const json& e) {
  std::string out = e.value("kind", "");
  for (const char* k : {"shaft", "bearing"}) {
    if (e.contains(k)) out += " " + e[k].get<std::string>();
  }
  for (const json& g : e.value("gears", json::array())) out += " " + g.get<std::string>();
  return out;
}

std::string what_claimed(const json& row) {
  std::string out = row.value("findings", "");
  if (out.empty() && row.value("alarm", 0) != 0) out = "alarm";
  return out;
}

struct ClassTally {
  int histories = 0, detected = 0;
  std::vector<double> delays, sizes;
  std::map<std::string, int> shaft, gear;
  std::string type;
};

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string fmt(double v) { return std::isfinite(v) ? diag::format_significant(v, 3) : "-"; }

}  // namespace

int validate_history(int argc, char** argv) {
  std::string dir, json_out;
  int jobs = 0, healthy_first = 0;
  po::options_description desc(
      "geardiag validate --history DIR [--healthy-first K] [--json OUT.json] [--jobs N]\n\n"
      "Runs every life history of DIR (made by geardiag dataset with a `life` block) through\n"
      "`geardiag batch --healthy-first K` (K: the dataset's reference recordings) and compares\n"
      "its events (confirmed by two successive recordings) with the truth: per history the\n"
      "detection delay after the fault's onset (recordings), the fault's size when detected,\n"
      "the shaft and gear named (right / silent / wrong), and the events confirmed on healthy\n"
      "recordings (false alarms); per class the rates.\n\noptions");
  desc.add_options()("help,h", "this help")("history", po::value(&dir)->required(),
                                            "a life dataset's folder")(
      "healthy-first", po::value(&healthy_first)->default_value(0),
      "reference recordings per history (0: the dataset's)")("json", po::value(&json_out),
                                                             "the report as JSON")(
      "jobs,j", po::value(&jobs)->default_value(0), "worker threads; 0 = every core");
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm)) return 0;
  MpiWorld world(&argc, &argv);
  jobs = resolve_jobs(jobs);
  if (!json_out.empty()) check_output(json_out, "--json");
  if (healthy_first < 0) throw diag::InputError("--healthy-first: must be >= 0");
  const std::vector<json> rows = read_manifest(dir, "--history");
  std::map<int, std::vector<std::size_t>> histories;  // history -> manifest rows, by step
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!rows[i].contains("history") || !rows[i]["history"].is_number_integer()) {
      throw diag::InputError("--history " + dir +
                             ": not a life dataset (its manifest has no `history` column; "
                             "make one with a `life` block, docs/cli/dataset.md)");
    }
    histories[rows[i]["history"].get<int>()].push_back(i);
  }
  for (auto& [h, members] : histories) {
    std::sort(members.begin(), members.end(), [&](std::size_t a, std::size_t b) {
      return rows[a].value("step", 0) < rows[b].value("step", 0);
    });
  }
  std::map<std::string, ClassTally> classes;
  std::vector<std::string> class_order;
  // Healthy recordings judged after the reference, the confirmed events on them (false alarms),
  // and the findings of single healthy recordings (sightings: not events unless the next shows
  // them too).
  int healthy_after = 0, false_alarms = 0, sightings = 0, not_comparable = 0, errors = 0;
  json report = {{"dataset", dir}, {"histories", json::array()}};
  Progress progress("validate --history", histories.size(), world.root());
  for (const auto& [h, members] : histories) {
    const json& first = rows[members.front()];
    const int k = healthy_first > 0 ? healthy_first : first.value("reference_recordings", 3);
    BatchRequest request;
    request.jobs = jobs;
    request.healthy_first = k;
    request.progress = false;
    std::map<std::string, std::size_t> by_file;
    for (std::size_t m : members) {
      request.files.push_back((fs::path(dir) / rows[m]["file"].get<std::string>()).string());
      by_file[request.files.back()] = m;
    }
    BatchResult batch;
    std::string failure;
    try {
      batch = run_batch(request, world);
    } catch (const diag::InputError& e) {  // e.g. a reference recording that cannot be read
      failure = e.what();
    }
    progress.tick();
    if (!world.root()) continue;
    if (!failure.empty()) {
      errors += static_cast<int>(members.size());
      report["histories"].push_back({{"history", h}, {"error", failure}});
      std::cerr << "history " << h << ": " << failure << "\n";
      continue;
    }
    // The truth: the class, the fault's onset, type, gear and shaft.
    const std::string cls = first["class"].get<std::string>();
    int onset = -1;
    std::string type, gear, shaft, bearing, bearing_fault;
    for (std::size_t m : members) {
      const json& r = rows[m];
      if (r.value("faults", 0) > 0 && onset < 0) {
        onset = r.value("step", 0);
        type = text(r, "fault1_type");
        gear = text(r, "fault1_gear");
        shaft = text(r, "fault1_shaft");
        bearing = text(r, "fault1_bearing");
        bearing_fault = text(r, "fault1_bearing_fault");
      }
    }
    if (!classes.count(cls)) class_order.push_back(cls);
    ClassTally& tally = classes[cls];
    ++tally.histories;
    if (!type.empty()) tally.type = type;
    json hj = {{"history", h},
               {"class", cls},
               {"reference", k},
               {"recordings", members.size()},
               {"notes", batch.notes}};
    if (onset >= 0) {
      hj["fault"] = {{"type", type}, {"shaft", shaft}, {"onset_step", onset}};
      if (type == "bearing") {
        hj["fault"]["bearing"] = bearing;
        hj["fault"]["fault"] = bearing_fault;
      } else {
        hj["fault"]["gear"] = gear;
      }
    }
    json fa = json::array();
    bool detected = false;
    hj["steps"] = json::array();
    std::vector<int> step_of(batch.rows.size());
    std::vector<bool> faulty_at(batch.rows.size());
    for (std::size_t i = 0; i < batch.rows.size(); ++i) {
      const json& row = batch.rows[i];
      const json& truth = rows[by_file.at(batch.files[i])];
      step_of[i] = truth.value("step", 0);
      faulty_at[i] = truth.value("faults", 0) > 0;
      // Every recording as the history judged it, with the indicators it trends.
      json sj = {{"step", step_of[i]},
                 {"status", row.value("status", "")},
                 {"faulty", faulty_at[i]},
                 {"claimed", what_claimed(row)}};
      if (std::isfinite(fault_size(truth))) sj["size"] = fault_size(truth);
      for (const char* key : {"speed_rpm", "anomaly_score"}) {
        if (row.contains(key)) sj[key] = row[key];
      }
      json indicators = json::object();
      const json features = row.value("features", json::object());
      for (const auto& [name, v] : features.items()) {
        if (name.starts_with("gear_damage/") || name.starts_with("wear/") ||
            name.starts_with("bearing/")) {
          indicators[name] = v;
        }
      }
      sj["indicators"] = indicators;
      if (row.contains("withheld")) sj["withheld"] = row["withheld"];
      hj["steps"].push_back(sj);
      if (batch.reference[i]) continue;
      const std::string status = row.value("status", "");
      if (status == "error") {
        ++errors;
        continue;
      }
      not_comparable += status == "not comparable";
      if (!faulty_at[i] && status == "ok") {
        ++healthy_after;
        sightings += claims(row);
      }
    }
    // The verdicts are the history's confirmed events (two successive recordings).
    std::vector<const json*> at_detection;
    int detection_step = -1;
    for (const json& e : batch.events) {
      if (e.value("status", "") != "confirmed") continue;
      const auto c = e["confirmed_recording"].get<std::size_t>();
      const auto f = e["first_recording"].get<std::size_t>();
      std::string what = e.value("kind", "");
      for (const char* k : {"shaft", "bearing"}) {
        if (e.contains(k)) what += " " + e[k].get<std::string>();
      }
      if (!faulty_at[c]) {
        ++false_alarms;
        fa.push_back({{"step", step_of[f]}, {"confirmed_step", step_of[c]}, {"claimed", what}});
        continue;
      }
      if (detection_step < 0 || step_of[c] < detection_step) {
        detection_step = step_of[c];
        at_detection.clear();
      }
      if (step_of[c] == detection_step) at_detection.push_back(&e);
    }
    if (detection_step >= 0) {
      detected = true;
      // The place the events name: right when one names the true shaft or gear, wrong when
      // they name only other places, silent when they name none.
      std::string where = "silent", which = "none", claimed;
      int first_step = detection_step;
      for (const json* e : at_detection) {
        claimed += (claimed.empty() ? "" : "; ") + short_findings_of(*e);
        first_step = std::min(first_step, step_of[(*e)["first_recording"].get<std::size_t>()]);
        const std::string place = e->contains("shaft")     ? (*e)["shaft"].get<std::string>()
                                  : e->contains("bearing") ? "bearing"
                                                           : "";
        if (place.empty()) continue;
        if (type == "bearing") {  // right when it names the bearing; the family in the next column
          if (e->value("bearing", "") == bearing) {
            where = "right";
            if (which != "right")
              which = e->value("fault", "") == bearing_fault ? "right" : "wrong";
          } else if (where != "right") {
            where = "wrong";
          }
          continue;
        }
        // A mesh's finding (wear) names the pinion's shaft and both gears: right when the true
        // gear is among them.
        const json gears = e->value("gears", json::array());
        if (place == shaft || std::find(gears.begin(), gears.end(), json(gear)) != gears.end()) {
          where = "right";
        } else if (where != "right") {
          where = "wrong";
        }
        const std::string g = gear_verdict((*e).value("gears", json::array()), gear);
        if (g != "none" && (which == "none" || which == "wrong" || g == "right")) which = g;
      }
      double size = std::nan("");
      for (std::size_t m : members) {
        if (rows[m].value("step", -1) == detection_step) size = fault_size(rows[m]);
      }
      ++tally.detected;
      tally.delays.push_back(detection_step - onset);
      if (std::isfinite(size)) tally.sizes.push_back(size);
      ++tally.shaft[where];
      ++tally.gear[which];
      hj["detection"] = {{"first_seen_step", first_step},
                         {"confirmed_step", detection_step},
                         {"delay", detection_step - onset},
                         {"claimed", claimed},
                         {"shaft", where},
                         {"gear", which}};
      if (std::isfinite(size)) hj["detection"]["size"] = size;
    }
    if (onset >= 0 && !detected) ++tally.shaft["missed"];
    hj["false_alarms"] = fa;
    report["histories"].push_back(hj);
  }
  progress.finish();
  if (!world.root()) return 0;
  // The table.
  std::ostringstream out;
  out << histories.size() << " histories of " << rows.size() << " recordings in " << dir << "\n";
  out << std::left << std::setw(16) << "class" << std::setw(11) << "histories" << std::setw(10)
      << "detected" << std::setw(16) << "delay med/max" << std::setw(18) << "size at detection"
      << std::setw(28) << "place right/silent/wrong"
      << "gear (bearing: fault) right/either/wrong\n";
  json summary = json::object();
  for (const std::string& c : class_order) {
    ClassTally& t = classes[c];
    const bool faulty = !t.type.empty();
    const double max_delay =
        t.delays.empty() ? std::nan("") : *std::max_element(t.delays.begin(), t.delays.end());
    out << std::setw(16) << c << std::setw(11) << t.histories << std::setw(10)
        << (faulty ? std::to_string(t.detected) : "-") << std::setw(16)
        << (faulty ? fmt(median(t.delays)) + " / " + fmt(max_delay) : "-") << std::setw(18)
        << (faulty && !t.sizes.empty() ? fmt(median(t.sizes)) + " " + size_unit(t.type) : "-")
        << std::setw(28)
        << (faulty ? std::to_string(t.shaft["right"]) + " / " + std::to_string(t.shaft["silent"]) +
                         " / " + std::to_string(t.shaft["wrong"])
                   : "-")
        << (faulty ? std::to_string(t.gear["right"]) + " / " + std::to_string(t.gear["either"]) +
                         " / " + std::to_string(t.gear["wrong"])
                   : "-")
        << "\n";
    json cj = {{"histories", t.histories}};
    if (faulty) {
      cj["fault"] = t.type;
      cj["detected"] = t.detected;
      cj["missed"] = t.shaft["missed"];
      cj["delay_median"] = median(t.delays);
      cj["delay_max"] = max_delay;
      cj["delays"] = t.delays;
      cj["size_at_detection_median"] = median(t.sizes);
      cj["size_unit"] = size_unit(t.type);
      cj["shaft"] = {
          {"right", t.shaft["right"]}, {"silent", t.shaft["silent"]}, {"wrong", t.shaft["wrong"]}};
      cj["gear"] = {{"right", t.gear["right"]},
                    {"either", t.gear["either"]},
                    {"wrong", t.gear["wrong"]},
                    {"none", t.gear["none"]}};
    }
    summary[c] = cj;
  }
  out << "false alarms (events confirmed on a healthy recording): " << false_alarms << " over "
      << healthy_after << " healthy recordings judged after the reference";
  if (healthy_after > 0) out << " (" << fmt(100.0 * false_alarms / healthy_after) << " %)";
  out << "; single healthy recordings with a finding (not confirmed by the next): " << sightings
      << "; not comparable: " << not_comparable << "; failed: " << errors << "\n";
  std::cout << out.str();
  report["classes"] = summary;
  report["false_alarms"] = {
      {"healthy_recordings", healthy_after},
      {"alarms", false_alarms},
      {"rate", healthy_after ? json(1.0 * false_alarms / healthy_after) : json(nullptr)}};
  report["not_comparable"] = not_comparable;
  report["failed"] = errors;
  if (!json_out.empty()) write_output(json_out, report.dump(1) + "\n", "--json");
  return 0;
}

}  // namespace geardiag
