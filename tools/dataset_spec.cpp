#include "dataset_spec.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>

#include "dataset_life.hpp"
#include "dataset_simulator.hpp"
#include "detect/gear/gear_damage.hpp"
#include "detect/gear/sidebands.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/util/number_format.hpp"
#include "sim/bearing/bearing_signal.hpp"
#include "sim/dynamics/gearbox_model.hpp"
#include "sim/dynamics/scenario.hpp"
#include "sim/dynamics/simulate.hpp"

namespace geardiag {

using nlohmann::json;

std::string indexed(const std::string& key, std::size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

// A number or [lo, hi] (lo <= hi), each within [min, max] (and > min when `open_min`).
Range parse_range(const diag::Fields& f, const std::string& key, double min, double max,
                  bool open_min) {
  const json& v = f.raw(key);
  Range r;
  if (v.is_number()) {
    r.lo = r.hi = f.num(key);
  } else if (v.is_array() && v.size() == 2 && v[0].is_number() && v[1].is_number()) {
    r.lo = v[0].get<double>();
    r.hi = v[1].get<double>();
    if (!(r.lo <= r.hi)) f.fail(key, "a range [lo, hi] needs lo <= hi");
  } else {
    f.fail(key, "must be a number or a range [lo, hi] of two numbers");
  }
  for (double x : {r.lo, r.hi}) {
    if (!std::isfinite(x) || (open_min ? !(x > min) : !(x >= min)) || x > max) {
      f.fail(key, diag::format_significant(x, 6) + " is outside " + (open_min ? "(" : "[") +
                      diag::format_significant(min, 6) + ", " + diag::format_significant(max, 6) +
                      "]");
    }
  }
  return r;
}

IntRange parse_int_range(const diag::Fields& f, const std::string& key, int min, int max) {
  const json& v = f.raw(key);
  IntRange r;
  auto is_int = [](const json& x) {
    return x.is_number_integer() ||
           (x.is_number_float() && std::floor(x.get<double>()) == x.get<double>() &&
            std::abs(x.get<double>()) < 1e9);
  };
  if (is_int(v)) {
    r.lo = r.hi = f.integer(key);
  } else if (v.is_array() && v.size() == 2 && is_int(v[0]) && is_int(v[1])) {
    r.lo = static_cast<int>(v[0].get<double>());
    r.hi = static_cast<int>(v[1].get<double>());
    if (r.lo > r.hi) f.fail(key, "a range [lo, hi] needs lo <= hi");
  } else {
    f.fail(key, "must be an integer or a range [lo, hi] of two integers");
  }
  if (r.lo < min || r.hi > max) {
    f.fail(key, "must be within [" + std::to_string(min) + ", " + std::to_string(max) + "]");
  }
  return r;
}

// Class names become file names: letters, digits, '_' and '-'.
std::string class_name(const diag::Fields& f) {
  const std::string name = f.str("name");
  const bool ok = name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
                    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
                  });
  if (!ok) f.fail("name", "'" + name + "' may hold only letters, digits, '_' and '-' (<= 64)");
  return name;
}

void parse_classes(const diag::Fields& f, int per_class, const std::set<std::string>& fields,
                   DatasetSpec& s,
                   const std::function<void(const diag::Fields&, DatasetClass&)>& parse_fields) {
  if (!f.has("classes") || !f.raw("classes").is_array() || f.raw("classes").empty()) {
    f.fail("classes", "required: a non-empty array of classes");
  }
  std::set<std::string> allowed = fields, names;
  allowed.insert({"name", "recordings"});
  for (std::size_t c = 0; c < f.raw("classes").size(); ++c) {
    const diag::Fields cf(f.raw("classes")[c], f.where(), indexed("classes", c), allowed);
    DatasetClass cls;
    cls.name = class_name(cf);
    if (!names.insert(cls.name).second) cf.fail("name", "'" + cls.name + "' is used twice");
    cls.recordings = per_class;
    if (cf.has("recordings")) {
      cls.recordings = cf.integer("recordings");
      if (cls.recordings < 0) cf.fail("recordings", "must be >= 0");
    }
    parse_fields(cf, cls);
    s.max_faults = std::max({s.max_faults, cls.faults.size(), cls.defects.size()});
    s.total += static_cast<std::size_t>(cls.recordings);
    s.classes.push_back(std::move(cls));
  }
  if (s.total == 0) f.fail("classes", "no recordings to generate");
  if (s.total > 100000000) f.fail("classes", "more than 1e8 recordings");
}

std::vector<std::string> parse_gearbox_paths(const diag::Fields& f) {
  std::vector<std::string> paths;
  if (!f.has("gearbox")) f.fail("gearbox", "required: a path or an array of paths");
  const json& g = f.raw("gearbox");
  if (g.is_string()) {
    paths.push_back(f.str("gearbox"));
  } else if (g.is_array() && !g.empty()) {
    for (const json& p : g) {
      if (!p.is_string() || p.get<std::string>().empty()) {
        f.fail("gearbox", "an array of gearbox paths holds only non-empty strings");
      }
      paths.push_back(p.get<std::string>());
    }
  } else {
    f.fail("gearbox", "must be a path or a non-empty array of paths");
  }
  return paths;
}

std::vector<std::string> names_or_any(const diag::Fields& f, const char* key, const char* what) {
  std::vector<std::string> out;
  if (!f.has(key))
    f.fail(key, std::string("required: a ") + what + ", an array of them or \"any\"");
  const json& g = f.raw(key);
  if (g.is_string() && g.get<std::string>() == "any") return out;
  if (g.is_string()) return {g.get<std::string>()};
  if (!g.is_array() || g.empty()) {
    f.fail(key, std::string("must be a ") + what + ", a non-empty array of them or \"any\"");
  }
  for (const json& name : g) {
    if (!name.is_string()) f.fail(key, "an array holds only strings");
    out.push_back(name.get<std::string>());
  }
  return out;
}

namespace {

// {"type": "bearing", "bearing", "fault", "amplitude_m_per_s2", "resonance_hz"}.
DatasetFault parse_bearing_fault(const json& j, const std::string& where, const std::string& path) {
  const diag::Fields f(j, where, path,
                       {"type", "bearing", "fault", "amplitude_m_per_s2", "resonance_hz"});
  DatasetFault d;
  d.type = "bearing";
  d.bearings = names_or_any(f, "bearing", "bearing name");
  d.bearing_faults = names_or_any(f, "fault", "bearing fault");
  for (std::string& k : d.bearing_faults) {  // the vocabulary's name (an alias is read as it)
    const std::optional<sim::BearingFaultKind> kind = sim::bearing_fault_kind(k);
    if (!kind)
      f.fail("fault", "'" + k + "' is not outer_race, inner_race, rolling_element or cage");
    k = sim::to_string(*kind);
  }
  if (d.bearing_faults.empty()) d.bearing_faults = {"outer_race", "inner_race", "rolling_element"};
  if (!f.has("amplitude_m_per_s2")) {
    f.fail("amplitude_m_per_s2", "required number or range is missing");
  }
  d.amplitude = parse_range(f, "amplitude_m_per_s2", 0, 1e6, true);
  if (f.has("resonance_hz")) d.resonance_hz = parse_range(f, "resonance_hz", 0, 1e6, true);
  return d;
}

DatasetFault parse_fault(const json& j, const std::string& where, const std::string& path) {
  if (j.is_object() && j.value("type", json()) == "bearing") {
    return parse_bearing_fault(j, where, path);
  }
  const diag::Fields f(j, where, path,
                       {"type", "gear", "tooth", "depth_mm", "size_mm", "length_mm", "depth_um",
                        "position_mm", "width_fraction"});
  DatasetFault d;
  d.type = f.str("type");
  // The size field of each type; the others are refused, not ignored.
  const std::map<std::string, std::set<std::string>> fields = {
      {"crack", {"depth_mm"}},
      {"chip", {"size_mm"}},
      {"missing", {}},
      {"spall", {"length_mm", "depth_um", "position_mm"}},
      {"wear", {"depth_um"}}};  // worn flanks of the gear's mesh (scenario faults[] type wear)
  const auto it = fields.find(d.type);
  if (it == fields.end())
    f.fail("type", "'" + d.type + "' is not crack, chip, missing, spall, wear or bearing");
  for (const char* key : {"depth_mm", "size_mm", "length_mm", "depth_um", "position_mm"}) {
    if (f.has(key) && !it->second.count(key)) {
      f.fail(key, "is not a field of a " + d.type + " fault");
    }
  }
  const double kBig = 1e3;
  if (d.type == "crack") d.size_mm = parse_range(f, "depth_mm", 0, kBig, true);
  if (d.type == "chip") d.size_mm = parse_range(f, "size_mm", 0, kBig, true);
  if (d.type == "spall") {
    if (!f.has("length_mm")) f.fail("length_mm", "required number or range is missing");
    if (!f.has("depth_um")) f.fail("depth_um", "required number or range is missing");
    d.size_mm = parse_range(f, "length_mm", 0, kBig, true);
    d.depth_um = parse_range(f, "depth_um", 0, 1e6, true);
    if (f.has("position_mm")) {
      d.has_position = true;
      d.position_mm = parse_range(f, "position_mm", -kBig, kBig, false);
    }
  }
  if (d.type == "wear") {
    if (!f.has("depth_um")) f.fail("depth_um", "required number or range is missing");
    d.depth_um = parse_range(f, "depth_um", 0, 999, true);  // the scenario's limit (< 1000 um)
  }
  if ((d.type == "crack" && !f.has("depth_mm")) || (d.type == "chip" && !f.has("size_mm"))) {
    f.fail(d.type == "crack" ? "depth_mm" : "size_mm", "required number or range is missing");
  }
  if (f.has("width_fraction")) d.width_fraction = parse_range(f, "width_fraction", 0, 1, true);
  d.gears = names_or_any(f, "gear", "gear name");
  if (f.has("tooth") && !(f.raw("tooth").is_string() && f.raw("tooth") == "any")) {
    d.any_tooth = false;
    d.tooth = parse_int_range(f, "tooth", 0, 999);
  }
  return d;
}

// Scenario fields the dataset draws itself; a base `scenario` may not set them.
const std::set<std::string> kDrawnScenarioFields = {
    "speed", "torque_nm", "faults", "accuracy_grade", "runout_um", "duration_s", "fs_hz", "seed"};

json fault_json(const DrawnFault& f) {
  if (f.type == "bearing") {
    return {{"type", f.type},
            {"bearing", f.bearing},
            {"fault", f.bearing_fault},
            {"amplitude_m_per_s2", f.amplitude},
            {"resonance_hz", f.resonance_hz}};
  }
  if (f.type == "wear") return {{"type", f.type}, {"gear", f.gear}, {"depth_um", f.depth_um}};
  json j = {{"type", f.type}, {"gear", f.gear}, {"tooth", f.tooth}};
  if (f.type == "crack") j["depth_mm"] = f.size_mm;
  if (f.type == "chip") j["size_mm"] = f.size_mm;
  if (f.type == "spall") {
    j["length_mm"] = f.size_mm;
    j["depth_um"] = f.depth_um;
    if (f.has_position) j["position_mm"] = f.position_mm;
  }
  if (f.width_fraction != 1) j["width_fraction"] = f.width_fraction;
  return j;
}

// The scenario of one operating point and set of faults, on top of the spec's base scenario.
json scenario_json(const DatasetSpec& s, double rpm, double torque, double oil, double noise,
                   int grade, double runout, std::uint64_t seed,
                   const std::vector<DrawnFault>& faults) {
  json j = s.scenario;
  j["speed"] = {{"rpm", rpm}};
  j["torque_nm"] = torque;
  if (s.has_oil) j["oil"]["temperature_c"] = oil;
  j["sensors"]["noise_m_per_s2"] = noise;
  j["accuracy_grade"] = grade;
  j["runout_um"] = runout;
  j["duration_s"] = s.duration_s;
  j["fs_hz"] = s.fs_hz;
  j["seed"] = seed;
  j["faults"] = json::array();
  for (const DrawnFault& f : faults) j["faults"].push_back(fault_json(f));
  return j;
}

using Stream = DrawStream;

}  // namespace

std::string fnv1a64_hex(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

namespace {

// The gears a fault may land on in gearbox `gb`.
std::vector<int> candidate_gears(const DatasetFault& f, const diag::Gearbox& gb) {
  std::vector<int> out;
  if (f.gears.empty()) {
    for (std::size_t g = 0; g < gb.gears().size(); ++g) out.push_back(static_cast<int>(g));
  } else {
    for (const std::string& name : f.gears) out.push_back(gb.gear_index(name));
  }
  return out;
}

// The bearings a bearing fault may land on in gearbox `gb`: those named, else every bearing of
// the description at a simulator bearing location (<shaft>_bearing1 or _bearing2 of its shaft).
std::vector<int> candidate_bearings(const DatasetFault& f, const diag::Gearbox& gb) {
  std::vector<int> out;
  for (std::size_t b = 0; b < gb.bearings().size(); ++b) {
    const diag::BearingSpec& spec = gb.bearings()[b];
    const bool listed = f.bearings.empty() ? sim::at_bearing_location(spec)
                                           : std::find(f.bearings.begin(), f.bearings.end(),
                                                       spec.name) != f.bearings.end();
    if (listed) out.push_back(static_cast<int>(b));
  }
  return out;
}

// A bearing fault's bearings exist in every gearbox, and sit where the simulator has
// accelerometers; its ring lies below 0.45 fs.
void check_bearing_fault(const DatasetSpec& s, const DatasetFault& f, const std::string& field) {
  const std::string where = s.file.string();
  if (!(f.resonance_hz.hi < 0.45 * s.fs_hz)) {
    diag::fail(where, field + ".resonance_hz",
               diag::format_significant(f.resonance_hz.hi, 6) + " Hz is not below 0.45 fs = " +
                   diag::format_significant(0.45 * s.fs_hz, 6) + " Hz");
  }
  for (std::size_t b = 0; b < s.gearboxes.size(); ++b) {
    const diag::Gearbox& gb = s.gearboxes[b];
    std::string list;
    for (const auto& spec : gb.bearings()) list += (list.empty() ? "" : ", ") + spec.name;
    for (const std::string& name : f.bearings) {
      const auto it = std::find_if(gb.bearings().begin(), gb.bearings().end(),
                                   [&](const diag::BearingSpec& x) { return x.name == name; });
      if (it == gb.bearings().end()) {
        diag::fail(where, field + ".bearing",
                   "'" + name + "' is not a bearing of " + s.gearbox_paths[b] + " (" +
                       (list.empty() ? "it lists none" : list) + ")");
      }
      if (!sim::at_bearing_location(*it)) {
        diag::fail(where, field + ".bearing",
                   "'" + name + "' of " + s.gearbox_paths[b] +
                       " is not at a simulator bearing location (the simulator's accelerometers "
                       "are at <shaft>_bearing1 and <shaft>_bearing2: name it " +
                       sim::bearing_location(it->shaft, 1) + " or " +
                       sim::bearing_location(it->shaft, 2) + ")");
      }
    }
    if (candidate_bearings(f, gb).empty()) {
      diag::fail(where, field + ".bearing",
                 "\"any\": " + s.gearbox_paths[b] +
                     " has no bearing at a simulator bearing location (<shaft>_bearing1 or "
                     "<shaft>_bearing2)");
    }
  }
}

// Everything the simulator would refuse about a class, found before anything is written: each
// fault at its largest size, on every gear it may land on, at the highest speed and torque.
void check_classes(const DatasetSpec& s) {
  const std::string where = s.file.string();
  for (std::size_t c = 0; c < s.classes.size(); ++c) {
    for (std::size_t i = 0; i < s.classes[c].faults.size(); ++i) {
      const DatasetFault& f = s.classes[c].faults[i];
      const std::string field = indexed("classes", c) + "." + indexed("faults", i);
      if (f.type == "bearing") {
        check_bearing_fault(s, f, field);
        continue;
      }
      for (std::size_t b = 0; b < s.gearboxes.size(); ++b) {
        const diag::Gearbox& gb = s.gearboxes[b];
        for (const std::string& name : f.gears) {
          if (gb.gear_index(name) < 0) {
            std::string list;
            for (const auto& g : gb.gears()) list += (list.empty() ? "" : ", ") + g.name;
            diag::fail(where, field + ".gear",
                       "'" + name + "' is not a gear of " + s.gearbox_paths[b] + " (" + list + ")");
          }
        }
        for (int g : candidate_gears(f, gb)) {
          const int teeth = gb.gears()[g].spec.teeth;
          if (!f.any_tooth && f.tooth.hi >= teeth) {
            diag::fail(where, field + ".tooth",
                       std::to_string(f.tooth.hi) + " is not a tooth of gear '" +
                           gb.gears()[g].name + "' (0.." + std::to_string(teeth - 1) + ")");
          }
          DrawnFault d;
          d.type = f.type;
          d.gear = gb.gears()[g].name;
          d.tooth = f.any_tooth ? 0 : f.tooth.lo;
          d.size_mm = f.size_mm.hi;
          d.depth_um = f.depth_um.hi;
          d.position_mm = f.position_mm.hi;
          d.width_fraction = f.width_fraction.hi;
          d.has_depth = true;
          d.has_position = f.has_position;
          const json sc =
              scenario_json(s, s.speed_rpm.hi, s.torque_nm.hi, s.oil_c.hi, 0, 0, 0, 1, {d});
          try {
            const sim::Scenario parsed = sim::parse_scenario(sc, where);
            const sim::GearboxModel model(gb, parsed.dynamics);
          } catch (const diag::InputError& e) {
            diag::fail(where, field,
                       "on gear '" + gb.gears()[g].name + "' of " + s.gearbox_paths[b] +
                           " at its largest size: " + e.what());
          }
        }
      }
    }
  }
}

// fs must hold the mesh harmonics the detectors examine with the simulator's anti-alias margin
// (flat to 0.8 of the output Nyquist frequency): fs >= 2.5 H f_mesh at the highest speed.
void check_sampling_rate(const DatasetSpec& s) {
  const int harmonics = detect::SidebandOptions{}.mesh_harmonics;
  for (std::size_t b = 0; b < s.gearboxes.size(); ++b) {
    const diag::Gearbox gb = s.gearboxes[b].with_input_speed_rpm(s.speed_rpm.hi);
    for (std::size_t m = 0; m < gb.meshes().size(); ++m) {
      const double f = harmonics * gb.mesh_frequency_hz(static_cast<int>(m));
      if (s.fs_hz < 2.5 * f) {
        diag::fail(
            s.file.string(), "fs_hz",
            diag::format_significant(s.fs_hz, 6) + " Hz is below 2.5 x " +
                diag::format_significant(f, 6) + " Hz, mesh harmonic " + std::to_string(harmonics) +
                " of mesh " + diag::mesh_name(gb, static_cast<int>(m)) + " of " +
                s.gearbox_paths[b] + " at " + diag::format_significant(s.speed_rpm.hi, 6) +
                " rpm (the detectors examine mesh harmonics 1.." + std::to_string(harmonics) +
                "); use fs_hz >= " + diag::format_significant(std::ceil(2.5 * f), 6));
      }
    }
  }
}

bool matches_any(const std::vector<std::string>& patterns, const std::string& name) {
  return std::any_of(patterns.begin(), patterns.end(), [&](const std::string& p) {
    return ::fnmatch(p.c_str(), name.c_str(), 0) == 0;
  });
}

// sensor_sets[]: {name, channels[], tachos[]}; every pattern must match a channel (a tacho) of
// every gearbox, found by simulating each gearbox for 10 ms at the lowest speed.
void parse_sensor_sets(const diag::Fields& f, DatasetSpec& s) {
  const json& arr = f.raw("sensor_sets");
  if (!arr.is_array() || arr.empty()) f.fail("sensor_sets", "must be a non-empty array");
  std::vector<diag::Recording> probes;
  for (const diag::Gearbox& gb : s.gearboxes) {
    json sc = scenario_json(s, s.speed_rpm.lo, s.torque_nm.lo, s.oil_c.lo, 0, 0, 0, 1, {});
    sc["duration_s"] = 0.01;
    const sim::Scenario parsed = sim::parse_scenario(sc, s.file.string());
    probes.push_back(sim::to_recording(gb, sim::simulate_dynamic(gb, parsed.dynamics, parsed.run)));
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const diag::Fields sf(arr[i], s.file.string(), indexed("sensor_sets", i),
                          {"name", "channels", "tachos"});
    SensorSet set;
    set.name = class_name(sf);
    if (!names.insert(set.name).second) sf.fail("name", "'" + set.name + "' is used twice");
    for (const char* key : {"channels", "tachos"}) {
      if (!sf.has(key)) continue;
      const json& list = sf.raw(key);
      if (!list.is_array() || (list.empty() && std::string(key) == "channels")) {
        sf.fail(key, "must be an array of channel names or glob patterns");
      }
      for (const json& p : list) {
        if (!p.is_string() || p.get<std::string>().empty()) {
          sf.fail(key, "holds only non-empty strings");
        }
        (std::string(key) == "channels" ? set.channels : set.tachos).push_back(p);
      }
    }
    if (!sf.has("channels")) sf.fail("channels", "required: the channels this set keeps");
    set.all_tachos = !sf.has("tachos");
    for (std::size_t b = 0; b < probes.size(); ++b) {
      for (const bool tacho : {false, true}) {
        for (const std::string& p : tacho ? set.tachos : set.channels) {
          const auto& list = tacho ? probes[b].tachos : probes[b].signals;
          const bool hit = std::any_of(list.begin(), list.end(), [&](const diag::Signal& sig) {
            return matches_any({p}, sig.name);
          });
          if (!hit) {
            sf.fail(tacho ? "tachos" : "channels",
                    "'" + p + "' matches no " + (tacho ? "tachometer" : "channel") + " of " +
                        s.gearbox_paths[b] + " (geardiag info on a recording lists them)");
          }
        }
      }
    }
    s.sensor_sets.push_back(std::move(set));
  }
}

// The damaged-gear locator (detect/gear/gear_damage.hpp) averages whole revolutions of each shaft
// and skips a shaft with fewer than GearDamageOptions::min_revolutions in the record: a warning
// (not a refusal: the recordings are still valid) when the slowest shaft at the lowest speed
// turns fewer times than that within duration_s.
void warn_revolutions(DatasetSpec& s) {
  const int needed = detect::GearDamageOptions{}.min_revolutions;
  for (std::size_t b = 0; b < s.gearboxes.size(); ++b) {
    const diag::Gearbox gb = s.gearboxes[b].with_input_speed_rpm(s.speed_rpm.lo);
    for (std::size_t sh = 0; sh < gb.shafts().size(); ++sh) {
      const double revs = s.duration_s * gb.shaft_speed_hz(static_cast<int>(sh));
      if (revs >= needed) continue;
      s.warnings.push_back(
          s.file.string() + ": duration_s: " + diag::format_significant(s.duration_s, 6) +
          " s holds " + diag::format_significant(std::floor(revs * 10) / 10, 6) +
          " revolutions of shaft '" + gb.shafts()[sh].name + "' of " + s.gearbox_paths[b] + " at " +
          diag::format_significant(s.speed_rpm.lo, 6) +
          " rpm: the damaged-gear locator (validate "
          "--dataset) skips a shaft with fewer than " +
          std::to_string(needed) + " whole revolutions; use duration_s >= " +
          diag::format_significant(
              std::ceil(needed / gb.shaft_speed_hz(static_cast<int>(sh)) * 10) / 10, 6));
    }
  }
}

}  // namespace

DatasetSpec load_dataset_spec(const std::filesystem::path& file) {
  DatasetSpec s;
  s.file = file;
  s.json = diag::load_json_file(file);
  s.simulator = dataset_simulator(s.json, file);
  simulator_of(s).load(s);
  return s;
}

DrawnRecording draw_recording(const DatasetSpec& s, std::size_t k) {
  DrawnRecording r;
  r.index = k;
  std::size_t first = 0, c = 0;
  const std::size_t unit = s.life ? life_step(*s.life, k).history : k;  // classes count histories
  while (unit >= first + static_cast<std::size_t>(s.classes[c].recordings)) {
    first += static_cast<std::size_t>(s.classes[c].recordings);
    ++c;
  }
  const DatasetClass& cls = s.classes[c];
  r.cls = cls.name;
  const int digits = std::max(6, static_cast<int>(std::to_string(s.total - 1).size()));
  std::string index = std::to_string(k);
  r.id = std::string(static_cast<std::size_t>(digits) - index.size(), '0') + index + "-" + r.cls;
  if (s.life) {  // a life history's step: the history's draws (dataset_life.hpp)
    const LifeStep at = life_step(*s.life, k);
    r.history = static_cast<int>(at.history);
    r.step = at.step;
    r.id += "-life" + std::to_string(at.history);
    Stream history = history_stream(s.seed, at.history);
    simulator_of(s).draw(s, cls, history, r);
    return r;
  }
  Stream rng(s.seed, k);
  simulator_of(s).draw(s, cls, rng, r);
  return r;
}

void apply_sensor_set(const DatasetSpec& s, const DrawnRecording& r, diag::Recording& rec) {
  if (r.sensor_set < 0) return;
  const SensorSet& set = s.sensor_sets[static_cast<std::size_t>(r.sensor_set)];
  std::erase_if(rec.signals,
                [&](const diag::Signal& sig) { return !matches_any(set.channels, sig.name); });
  if (!set.all_tachos) {
    std::erase_if(rec.tachos,
                  [&](const diag::Signal& sig) { return !matches_any(set.tachos, sig.name); });
  }
}

std::vector<std::string> manifest_columns(const DatasetSpec& s) {
  return simulator_of(s).manifest_columns(s);
}

nlohmann::json manifest_row(const DatasetSpec& s, const DrawnRecording& r) {
  return simulator_of(s).manifest_row(s, r);
}

namespace {

// The dynamic model (sim/dynamics/simulate.hpp): the spec fields of this file's header.
class DynamicDataset final : public DatasetSimulator {
 public:
  const char* name() const override { return "dynamic"; }

  void load(DatasetSpec& s) const override {
    const std::filesystem::path& file = s.file;
    const std::string where = file.string();
    const diag::Fields f(s.json, where, "",
                         {"gearbox", "seed", "recordings_per_class", "duration_s", "fs_hz",
                          "operating_points", "noise_m_per_s2", "accuracy_grade", "runout_um",
                          "scenario", "classes", "simulator", "sensor_sets", "life"});
    // Gearboxes, relative to the spec's folder.
    s.gearbox_paths = parse_gearbox_paths(f);
    std::string hashed = s.json.dump();
    for (std::size_t i = 0; i < s.gearbox_paths.size(); ++i) {
      std::filesystem::path p = s.gearbox_paths[i];
      if (p.is_relative()) p = file.parent_path() / p;
      s.gearboxes.push_back(diag::load_gearbox(p));
      hashed += '\0' + s.gearboxes.back().description_json();
    }
    s.hash = fnv1a64_hex(hashed);
    const int seed = f.integer("seed");
    if (seed < 0) f.fail("seed", "must be >= 0");
    s.seed = static_cast<std::uint64_t>(seed);
    const int per_class = f.integer("recordings_per_class");
    if (per_class < 1)
      f.fail("recordings_per_class", "must be >= 1 (got " + std::to_string(per_class) + ")");
    s.duration_s = f.positive("duration_s");
    if (s.duration_s > sim::kMaxDurationS) f.fail("duration_s", "must be <= 3600 s");
    s.fs_hz = f.positive("fs_hz");
    if (s.fs_hz > sim::kMaxFsHz) f.fail("fs_hz", "must be <= 1e6 Hz");
    if (!f.has("operating_points")) f.fail("operating_points", "required: {speed_rpm, torque_nm}");
    {
      const diag::Fields op(f.raw("operating_points"), where, "operating_points",
                            {"speed_rpm", "torque_nm", "oil_temperature_c"});
      if (!op.has("speed_rpm")) op.fail("speed_rpm", "required number or range is missing");
      if (!op.has("torque_nm")) op.fail("torque_nm", "required number or range is missing");
      s.speed_rpm = parse_range(op, "speed_rpm", 0, diag::kMaxSpeedRpm, true);
      s.torque_nm = parse_range(op, "torque_nm", 0, diag::kMaxTorqueNm, false);
      if (op.has("oil_temperature_c")) {
        s.has_oil = true;
        s.oil_c = parse_range(op, "oil_temperature_c", -50, 200, false);
      }
    }
    if (f.has("noise_m_per_s2")) s.noise = parse_range(f, "noise_m_per_s2", 0, 1e6, false);
    if (f.has("accuracy_grade")) s.grade = parse_int_range(f, "accuracy_grade", 0, 12);
    if (f.has("runout_um")) s.runout_um = parse_range(f, "runout_um", 0, 1e4, false);
    if (f.has("scenario")) {
      if (!f.raw("scenario").is_object()) f.fail("scenario", "must be a JSON object");
      s.scenario = f.raw("scenario");
      for (const auto& [key, value] : s.scenario.items()) {
        if (kDrawnScenarioFields.count(key)) {
          f.fail("scenario." + key,
                 "is set by the dataset spec (operating_points, classes, "
                 "duration_s, fs_hz, seed ...), not by the base scenario");
        }
      }
      if (s.scenario.contains("sensors") && s.scenario["sensors"].is_object() &&
          s.scenario["sensors"].contains("noise_m_per_s2")) {
        f.fail("scenario.sensors.noise_m_per_s2", "is set by the spec's noise_m_per_s2");
      }
      if (s.has_oil && s.scenario.contains("oil") && s.scenario["oil"].is_object() &&
          s.scenario["oil"].contains("temperature_c")) {
        f.fail("scenario.oil.temperature_c", "is set by operating_points.oil_temperature_c");
      }
      sim::parse_scenario(s.scenario, where + ": scenario");
    }
    parse_classes(f, per_class, {"faults"}, s, [&](const diag::Fields& cf, DatasetClass& cls) {
      if (!cf.has("faults")) return;
      if (!cf.raw("faults").is_array()) cf.fail("faults", "must be an array");
      for (std::size_t i = 0; i < cf.raw("faults").size(); ++i) {
        cls.faults.push_back(parse_fault(cf.raw("faults")[i], where, cf.sub(indexed("faults", i))));
        if (cls.faults.back().type == "bearing") s.bearing_faults = true;
      }
    });
    parse_life(f, s);
    check_sampling_rate(s);
    check_classes(s);
    warn_revolutions(s);
    if (f.has("sensor_sets")) parse_sensor_sets(f, s);
  }

  void draw(const DatasetSpec& s, const DatasetClass& cls, DrawStream& rng,
            DrawnRecording& r) const override {
    r.gearbox = static_cast<int>(rng.pick(s.gearboxes.size()));
    const diag::Gearbox& gb = s.gearboxes[static_cast<std::size_t>(r.gearbox)];
    r.speed_rpm = rng.draw(s.speed_rpm);
    r.torque_nm = rng.draw(s.torque_nm);
    r.oil_c = rng.draw(s.oil_c);
    r.noise = rng.draw(s.noise);
    r.grade = rng.draw(s.grade);
    r.runout_um = rng.draw(s.runout_um);
    for (const DatasetFault& f : cls.faults) {
      if (f.type == "bearing") {  // four draws: the bearing, its fault, amplitude, resonance
        const std::vector<int> bearings = candidate_bearings(f, gb);
        const diag::BearingSpec& spec =
            gb.bearings()[static_cast<std::size_t>(bearings[rng.pick(bearings.size())])];
        DrawnFault d;
        d.type = f.type;
        d.bearing = spec.name;
        d.shaft = spec.shaft;
        d.bearing_fault = f.bearing_faults[rng.pick(f.bearing_faults.size())];
        d.amplitude = rng.draw(f.amplitude);
        d.resonance_hz = rng.draw(f.resonance_hz);
        r.faults.push_back(d);
        continue;
      }
      const std::vector<int> gears = candidate_gears(f, gb);
      const int g = gears[rng.pick(gears.size())];
      DrawnFault d;
      d.type = f.type;
      d.gear = gb.gears()[g].name;
      d.shaft = gb.gears()[g].shaft;
      const int teeth = gb.gears()[g].spec.teeth;
      d.tooth = rng.draw(f.any_tooth ? IntRange{0, teeth - 1} : f.tooth);
      // Two faults drawn onto the same tooth of the same gear: the later one moves on (a fixed
      // tooth stays where the spec put it).
      for (int tries = 0; f.any_tooth && tries < teeth; ++tries) {
        const bool taken = std::any_of(r.faults.begin(), r.faults.end(), [&](const DrawnFault& o) {
          return o.gear == d.gear && o.tooth == d.tooth;
        });
        if (!taken) break;
        d.tooth = (d.tooth + 1) % teeth;
      }
      d.size_mm = f.type == "missing" || f.type == "wear" ? 0.0 : rng.draw(f.size_mm);
      d.has_depth = f.type == "spall" || f.type == "wear";
      d.depth_um = rng.draw(f.depth_um);
      d.has_position = f.has_position;
      d.position_mm = rng.draw(f.position_mm);
      d.width_fraction = rng.draw(f.width_fraction);
      r.faults.push_back(d);
    }
    r.seed = rng.next() % 1000000000ULL;
    // Drawn last, and only when there are sets: the other draws stay those of a spec without them.
    if (!s.sensor_sets.empty()) r.sensor_set = static_cast<int>(rng.pick(s.sensor_sets.size()));
    if (s.life) live(s, cls, r);  // the step of a life: jitter, noise, the fault's growth
    r.scenario = scenario_json(s, r.speed_rpm, r.torque_nm, r.oil_c, r.noise, r.grade, r.runout_um,
                               r.seed, r.faults);
    if (s.life) r.scenario["sensors"]["noise_seed"] = r.noise_seed;
  }

  std::vector<std::string> manifest_columns(const DatasetSpec& s) const override {
    std::vector<std::string> cols = {"file",
                                     "id",
                                     "index",
                                     "class",
                                     "gearbox",
                                     "seed",
                                     "speed_rpm",
                                     "torque_nm",
                                     "oil_temperature_c",
                                     "noise_m_per_s2",
                                     "accuracy_grade",
                                     "runout_um",
                                     "duration_s",
                                     "fs_hz",
                                     "faults"};
    for (std::size_t i = 1; i <= s.max_faults; ++i) {
      for (const char* field : {"type", "gear", "shaft", "tooth", "size_mm", "depth_um",
                                "position_mm", "width_fraction"}) {
        cols.push_back("fault" + std::to_string(i) + "_" + field);
      }
    }
    if (s.bearing_faults) {  // only then, so that other datasets' manifests stay as they were
      for (std::size_t i = 1; i <= s.max_faults; ++i) {
        for (const char* field : {"bearing", "bearing_fault", "amplitude_m_per_s2"}) {
          cols.push_back("fault" + std::to_string(i) + "_" + field);
        }
      }
    }
    if (!s.sensor_sets.empty()) cols.push_back("sensor_set");
    if (s.life) {
      for (const char* c :
           {"history", "step", "time", "onset_step", "reference_recordings", "noise_seed"}) {
        cols.push_back(c);
      }
    }
    return cols;
  }

  json manifest_row(const DatasetSpec& s, const DrawnRecording& r) const override {
    json row = json::object();
    row["file"] = "recordings/" + r.id + ".h5";
    row["id"] = r.id;
    row["index"] = r.index;
    row["class"] = r.cls;
    row["gearbox"] = s.gearbox_paths[static_cast<std::size_t>(r.gearbox)];
    row["seed"] = r.seed;
    row["speed_rpm"] = r.speed_rpm;
    row["torque_nm"] = r.torque_nm;
    row["oil_temperature_c"] = s.has_oil ? json(r.oil_c) : json(nullptr);
    row["noise_m_per_s2"] = r.noise;
    row["accuracy_grade"] = r.grade;
    row["runout_um"] = r.runout_um;
    row["duration_s"] = s.duration_s;
    row["fs_hz"] = s.fs_hz;
    row["faults"] = r.faults.size();
    for (std::size_t i = 0; i < s.max_faults; ++i) {
      const std::string p = "fault" + std::to_string(i + 1) + "_";
      const DrawnFault* f = i < r.faults.size() ? &r.faults[i] : nullptr;
      row[p + "type"] = f ? json(f->type) : json(nullptr);
      row[p + "shaft"] = f ? json(f->shaft) : json(nullptr);
      const bool tooth = f && f->type != "bearing";
      row[p + "gear"] = tooth ? json(f->gear) : json(nullptr);
      row[p + "tooth"] = tooth && f->type != "wear" ? json(f->tooth) : json(nullptr);
      row[p + "size_mm"] =
          tooth && f->type != "missing" && f->type != "wear" ? json(f->size_mm) : json(nullptr);
      row[p + "depth_um"] = f && f->has_depth ? json(f->depth_um) : json(nullptr);
      row[p + "position_mm"] = f && f->has_position ? json(f->position_mm) : json(nullptr);
      row[p + "width_fraction"] = tooth ? json(f->width_fraction) : json(nullptr);
      if (s.bearing_faults) {
        const bool bearing = f && f->type == "bearing";
        row[p + "bearing"] = bearing ? json(f->bearing) : json(nullptr);
        row[p + "bearing_fault"] = bearing ? json(f->bearing_fault) : json(nullptr);
        row[p + "amplitude_m_per_s2"] = bearing ? json(f->amplitude) : json(nullptr);
      }
    }
    if (r.sensor_set >= 0)
      row["sensor_set"] = s.sensor_sets[static_cast<std::size_t>(r.sensor_set)].name;
    if (s.life) {
      row["history"] = r.history;
      row["step"] = r.step;
      row["time"] = r.time;
      row["onset_step"] = r.onset >= 0 ? json(r.onset) : json(nullptr);
      row["reference_recordings"] = s.life->reference;
      row["noise_seed"] = r.noise_seed;
    }
    return row;
  }

  diag::Recording simulate(const DatasetSpec& s, const DrawnRecording& r,
                           std::vector<std::string>& warnings) const override {
    const sim::Scenario sc = sim::parse_scenario(r.scenario, r.id + ": scenario");
    const diag::Gearbox& gb = s.gearboxes[static_cast<std::size_t>(r.gearbox)];
    const sim::DynamicResult result = sim::simulate_dynamic(gb, sc.dynamics, sc.run);
    diag::Recording rec = sim::to_recording(gb, result);
    apply_sensor_set(s, r, rec);
    if (!r.time.empty()) rec.metadata["timestamp"] = r.time;  // a life's step: when it was taken
    warnings.insert(warnings.end(), result.warnings.begin(), result.warnings.end());
    return rec;
  }

  const json& model(const DrawnRecording& r) const override { return r.scenario; }
};

}  // namespace

const DatasetSimulator& dynamic_dataset_simulator() {
  static const DynamicDataset instance;
  return instance;
}

}  // namespace geardiag
