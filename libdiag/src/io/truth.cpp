#include "diag/io/truth.hpp"

#include <cmath>
#include <set>

#include "diag/error.hpp"
#include "diag/io/json_fields.hpp"

namespace diag {
namespace {

using json = nlohmann::json;

// The number at `key` (NaN when absent or null); InputError when it is not a number.
double number_or_unset(const json& j, const char* key, const std::string& where,
                       const std::string& path) {
  if (!j.contains(key) || j[key].is_null()) return TruthDefect::kUnset;
  if (!j[key].is_number()) fail(where, path + key, "must be a number");
  return j[key].get<double>();
}

TruthDefect parse_defect(const json& j, const std::string& where, const std::string& path) {
  Fields f(j, where, path,
           {"type", "gear", "shaft", "bearing", "tooth", "size_m", "depth_m", "width_fraction",
            "size_gear_rad", "size_output_rad", "phase_rad", "period_input_rev",
            "first_event_input_rad", "shaft_frequency_hz", "gears_on_shaft", "on_power_path"});
  TruthDefect d;
  d.kind = parse_fault_kind(f.str("type"), where, f.sub("type"));
  for (auto [key, out] : {std::pair{"gear", &d.gear}, {"shaft", &d.shaft}, {"bearing", &d.bearing}})
    if (f.has(key)) *out = f.str(key);
  if (f.has("tooth")) d.tooth = f.integer("tooth");
  const std::string p = path + ".";
  d.size_m = number_or_unset(j, "size_m", where, p);
  d.depth_m = number_or_unset(j, "depth_m", where, p);
  d.width_fraction = number_or_unset(j, "width_fraction", where, p);
  d.size_gear_rad = number_or_unset(j, "size_gear_rad", where, p);
  d.size_output_rad = number_or_unset(j, "size_output_rad", where, p);
  d.phase_rad = number_or_unset(j, "phase_rad", where, p);
  d.period_input_rev = number_or_unset(j, "period_input_rev", where, p);
  d.first_event_input_rad = number_or_unset(j, "first_event_input_rad", where, p);
  d.shaft_frequency_hz = number_or_unset(j, "shaft_frequency_hz", where, p);
  if (f.has("gears_on_shaft")) {
    const json& g = f.raw("gears_on_shaft");
    if (!g.is_array()) f.fail("gears_on_shaft", "must be an array of strings");
    for (const json& n : g) {
      if (!n.is_string()) f.fail("gears_on_shaft", "must be an array of strings");
      d.gears_on_shaft.push_back(n.get<std::string>());
    }
  }
  if (f.has("on_power_path")) d.on_power_path = f.boolean("on_power_path", false);
  return d;
}

json defect_json(const TruthDefect& d) {
  json j{{"type", std::string(to_string(d.kind))}};
  for (auto [key, v] : {std::pair{"gear", &d.gear}, {"shaft", &d.shaft}, {"bearing", &d.bearing}})
    if (!v->empty()) j[key] = *v;
  if (d.tooth >= 0) j["tooth"] = d.tooth;
  const std::pair<const char*, double> numbers[] = {
      {"size_m", d.size_m},
      {"depth_m", d.depth_m},
      {"width_fraction", d.width_fraction},
      {"size_gear_rad", d.size_gear_rad},
      {"size_output_rad", d.size_output_rad},
      {"phase_rad", d.phase_rad},
      {"period_input_rev", d.period_input_rev},
      {"first_event_input_rad", d.first_event_input_rad},
      {"shaft_frequency_hz", d.shaft_frequency_hz}};
  for (const auto& [key, v] : numbers)
    if (!std::isnan(v)) j[key] = v;
  if (!d.gears_on_shaft.empty()) j["gears_on_shaft"] = d.gears_on_shaft;
  if (d.on_power_path) j["on_power_path"] = *d.on_power_path;
  return j;
}

}  // namespace

SimulationTruth SimulationTruth::from_json(const json& j, const std::string& where) {
  if (!j.is_object()) fail(where, "", "the truth must be a JSON object");
  SimulationTruth t;
  if (!j.contains("kind") || !j["kind"].is_string() || j["kind"].get<std::string>().empty())
    fail(where, "kind", "required string is missing");
  t.kind = j["kind"].get<std::string>();
  t.input_speed_rpm_min = number_or_unset(j, "input_speed_rpm_min", where, "");
  t.input_speed_rpm_max = number_or_unset(j, "input_speed_rpm_max", where, "");
  if (j.contains("input_speed_rpm")) {  // face-gear truth: one speed
    t.input_speed_rpm_min = t.input_speed_rpm_max =
        number_or_unset(j, "input_speed_rpm", where, "");
  }
  t.input_torque_nm = number_or_unset(j, "input_torque_nm", where, "");
  t.load_torque_nm = number_or_unset(j, "load_torque_nm", where, "");
  // "defects", or an older dynamic truth's "faults": the same entries.
  for (const char* key : {"defects", "faults"}) {
    if (!j.contains(key)) continue;
    if (!j[key].is_array()) fail(where, key, "must be an array");
    for (std::size_t i = 0; i < j[key].size(); ++i) {
      t.defects.push_back(
          parse_defect(j[key][i], where, std::string(key) + "[" + std::to_string(i) + "]"));
    }
  }
  // An older bearing truth's "fault": one defect of the bearing simulated.
  if (j.contains("fault")) {
    if (!j["fault"].is_string()) fail(where, "fault", "must be a string");
    const FaultKind k = parse_fault_kind(j["fault"].get<std::string>(), where, "fault");
    if (k != FaultKind::kNone) {
      TruthDefect d;
      d.kind = k;
      t.defects.push_back(std::move(d));
    }
  }
  static const std::set<std::string> typed = {"kind",
                                              "input_speed_rpm_min",
                                              "input_speed_rpm_max",
                                              "input_speed_rpm",
                                              "input_torque_nm",
                                              "load_torque_nm",
                                              "defects",
                                              "faults",
                                              "fault"};
  for (const auto& [key, value] : j.items()) {
    if (!typed.count(key)) t.extra[key] = value;
  }
  return t;
}

json SimulationTruth::to_json() const {
  json j = extra.is_object() ? extra : json::object();
  j["kind"] = kind;
  const std::pair<const char*, double> op[] = {{"input_speed_rpm_min", input_speed_rpm_min},
                                               {"input_speed_rpm_max", input_speed_rpm_max},
                                               {"input_torque_nm", input_torque_nm},
                                               {"load_torque_nm", load_torque_nm}};
  for (const auto& [key, v] : op)
    if (!std::isnan(v)) j[key] = v;
  j["defects"] = json::array();
  for (const TruthDefect& d : defects) j["defects"].push_back(defect_json(d));
  return j;
}

std::optional<SimulationTruth> parse_truth(const std::string& truth_json,
                                           const std::string& where) {
  if (truth_json.empty()) return std::nullopt;
  const std::string w = where + ": /truth";
  return SimulationTruth::from_json(parse_json_text(truth_json, w), w);
}

std::optional<SimulationTruth> parse_truth(const Recording& rec, const std::string& where) {
  return parse_truth(rec.truth_json, where);
}

}  // namespace diag
