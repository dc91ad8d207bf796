// geardiag validate --dataset DIR on a kinematic dataset (seed 003): every recording's input and
// output angles through the period matcher (detect/attribution/period_matcher.hpp, default
// options, as `geardiag attribute`), its findings compared with the manifest's defects.
//
// Verdict per recording:
//   healthy class:  right = no finding and no unexplained event; wrong = anything claimed.
//   with defects:   wrong   = a finding on a shaft that carries no defect (a false claim);
//                   right   = every shaft carrying a defect named, nothing else;
//                   partial = some of them named, nothing wrong;
//                   silent  = no finding (unexplained events flagged as multiplicity count here:
//                             the matcher says "several defects, not separable", not where).
// Sizes: a finding on a shaft with exactly one defect, its size at the output within 15 % of the
// truth (the closed loop's tolerance, validation/attribution_loop.hpp).
#include "validate_kinematic.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "detect/attribution/period_matcher.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/units.hpp"
#include "output.hpp"
#include "parallel.hpp"
#include "report/svg_plot.hpp"
#include "validate_dataset.hpp"

namespace fs = std::filesystem;

namespace geardiag {

namespace {

using nlohmann::json;

constexpr double kSizeTolerance = 0.15;

// The verdict of one recording from its findings (see the file comment).
void judge(json& r, const detect::AttributionResult& a) {
  std::multiset<std::string> truth;
  std::map<std::string, double> size_of;  // shaft -> size at the output [deg], one defect only
  for (int i = 1; i <= r.value("defects", 0); ++i) {
    const std::string p = "defect" + std::to_string(i) + "_";
    const std::string shaft = r[p + "shaft"];
    truth.insert(shaft);
    size_of[shaft] = r[p + "size_output_deg"].get<double>();
  }
  std::set<std::string> named;
  int wrong = 0, sizes = 0, sizes_ok = 0;
  for (const detect::Finding& f : a.findings) {
    named.insert(f.shaft);
    if (!truth.count(f.shaft)) {
      ++wrong;
    } else if (truth.count(f.shaft) == 1) {
      ++sizes;
      const double found = diag::units::rad_to_deg(f.evidence_value("size_output_rad"));
      sizes_ok += std::abs(found - size_of[f.shaft]) <= kSizeTolerance * size_of[f.shaft];
    }
  }
  std::size_t found = 0;
  for (const auto& [shaft, size] : size_of) found += named.count(shaft);
  std::string verdict;
  if (truth.empty()) {
    verdict = a.findings.empty() && !a.multiplicity ? "right" : "wrong";
  } else if (wrong > 0) {
    verdict = "wrong";
  } else if (found == size_of.size()) {
    verdict = "right";
  } else {
    verdict = found > 0 ? "partial" : "silent";
  }
  std::string names;
  for (const std::string& n : named) names += (names.empty() ? "" : " ") + n;
  r["named"] = names;
  r["verdict"] = verdict;
  r["multiplicity"] = a.multiplicity;
  r["sizes_checked"] = sizes;
  r["sizes_within_15pct"] = sizes_ok;
}

const std::vector<std::string> kVerdicts = {"right", "partial", "silent", "wrong", "error"};

}  // namespace

int validate_kinematic_dataset(const std::string& dir, std::vector<json>& rows,
                               const std::string& json_out, const std::string& html_out, int jobs) {
  judge_dataset_recordings(
      dir, rows, jobs, [](const std::string& path) { return diag::read_recording(path); },
      [&](std::size_t i, std::optional<diag::Recording>& rec, const std::string& path,
          const std::string& read_error) {
        json& r = rows[i];
        try {
          if (!rec) throw diag::InputError(read_error);
          const diag::Gearbox gb = diag::parse_gearbox_text(rec->gearbox_json, path);
          const detect::AttributionResult a = detect::attribute_defects(
              rec->require("input_angle_rad", path).samples,
              rec->require("output_angle_rad", path).samples, gb, detect::AttributionOptions{});
          judge(r, a);
        } catch (const std::exception& e) {
          r["verdict"] = "error";
          r["error"] = e.what();
        }
      });
  json classes = json::object();
  for (const json& r : rows) {
    json& c = classes[r["class"].get<std::string>()];
    if (c.is_null()) c = json::object();
    for (const std::string& v : kVerdicts) c[v] = c.value(v, 0);
    c["recordings"] = c.value("recordings", 0) + 1;
    c[r["verdict"].get<std::string>()] = c[r["verdict"].get<std::string>()].get<int>() + 1;
    c["multiplicity"] = c.value("multiplicity", 0) + (r.value("multiplicity", false) ? 1 : 0);
    c["sizes_checked"] = c.value("sizes_checked", 0) + r.value("sizes_checked", 0);
    c["sizes_within_15pct"] = c.value("sizes_within_15pct", 0) + r.value("sizes_within_15pct", 0);
  }
  // The detectability map: recordings with defects, "detected" when a defective shaft is named
  // (right or partial), against the first defect's size at the output and the angle noise.
  std::vector<json> faulty;
  for (json r : rows) {
    if (r.value("defects", 0) == 0) continue;
    r["detected"] = r["verdict"] == "right" || r["verdict"] == "partial";
    faulty.push_back(r);
  }
  const json by = {{"defect1_size_output_deg", rate_by(faulty, "defect1_size_output_deg")},
                   {"noise_deg", rate_by(faulty, "noise_deg")}};
  json rep = {{"dataset", dir},
              {"simulator", "kinematic"},
              {"rate_by", by},
              {"decision",
               "period matcher (geardiag attribute, default options): right = every defective "
               "shaft named and nothing else; partial = some named, none wrong; silent = none "
               "named; wrong = a shaft without a defect named (healthy: anything claimed)"},
              {"classes", classes},
              {"recordings", rows}};
  std::ostringstream table;
  table << "attribution (period matcher) per class:\n  class\trecordings";
  for (const std::string& v : kVerdicts) table << "\t" << v;
  table << "\tmultiplicity\tsizes within 15 %\n";
  for (const auto& [cls, c] : classes.items()) {
    table << "  " << cls << "\t" << c["recordings"];
    for (const std::string& v : kVerdicts) table << "\t" << c[v];
    table << "\t" << c["multiplicity"] << "\t" << c["sizes_within_15pct"] << "/"
          << c["sizes_checked"] << "\n";
  }
  for (const auto& [column, bins] : by.items()) {
    table << "defective shafts named (right or partial) vs " << column << ":\n";
    for (const json& b : bins) {
      table << "  " << b["from"].get<double>() << " - " << b["to"].get<double>() << ": "
            << b["detected"] << " / " << b["recordings"] << "\n";
    }
  }
  std::cout << table.str();
  if (!json_out.empty()) write_output(json_out, rep.dump(1) + "\n", "--json");
  if (!html_out.empty()) {
    write_output(html_out,
                 "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>geardiag validate "
                 "--dataset</title></head><body><h1>Attribution of a kinematic dataset: " +
                     report::html_escape(dir) + "</h1><p>" +
                     report::html_escape(rep["decision"].get<std::string>()) + "</p><pre>" +
                     report::html_escape(table.str()) + "</pre></body></html>\n",
                 "--html");
  }
  return 0;
}

}  // namespace geardiag
