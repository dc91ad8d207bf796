#include "detect/finding.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

namespace detect {

double Finding::evidence_value(std::string_view name) const {
  for (const auto& [key, value] : evidence) {
    if (key == name) return value;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

void Finding::set_evidence(std::string name, double value) {
  for (auto& [key, v] : evidence) {
    if (key == name) {
      v = value;
      return;
    }
  }
  evidence.emplace_back(std::move(name), value);
}

namespace {

// A count stays an integer in the JSON (events, harmonics seen), a measure a number.
nlohmann::json number(double v) {
  if (std::isfinite(v) && v == std::floor(v) && std::abs(v) < 1e15) {
    return static_cast<long long>(v);
  }
  return v;
}

}  // namespace

nlohmann::json to_json(const Finding& f) {
  nlohmann::json j{{"kind", f.kind}, {"fault", std::string(diag::to_string(f.fault))}};
  if (!f.shaft.empty()) j["shaft"] = f.shaft;
  if (!f.gears.empty()) j["gears"] = f.gears;
  if (!f.bearing.empty()) j["bearing"] = f.bearing;
  if (!f.channel.empty()) j["channel"] = f.channel;
  if (std::isfinite(f.frequency_hz)) j["frequency_hz"] = f.frequency_hz;
  j["confidence"] = f.confidence;
  if (std::isfinite(f.size)) {
    j["size"] = f.size;
    j["size_unit"] = f.size_unit;
  }
  j["note"] = f.note;
  nlohmann::json ev = nlohmann::json::object();
  for (const auto& [key, value] : f.evidence) {
    ev[key] = number(value);
    if (!j.contains(key)) j[key] = number(value);
  }
  j["evidence"] = std::move(ev);
  if (std::isfinite(f.first_s) && std::isfinite(f.last_s)) {
    j["time_s"] = {f.first_s, f.last_s};
    j["frames_seen"] = f.frames_seen;
    j["frames_examined"] = f.frames_examined;
  }
  return j;
}

}  // namespace detect
