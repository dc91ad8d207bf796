// channel_label (report.hpp): how every report names a channel.
#include <algorithm>

#include "report/report.hpp"

namespace report {

std::string channel_label(const detect::ChannelAnalysis& c) {
  std::string kind;
  if (c.role == diag::Role::kVibration) {
    static const char* kAccel[] = {"m/s^2", "m/s2", "mm/s^2", "g", "G"};
    static const char* kVel[] = {"m/s", "mm/s", "in/s", "ips"};
    kind = "vibration sensor";
    for (const char* u : kAccel) kind = c.unit == u ? "accelerometer" : kind;
    for (const char* u : kVel) kind = c.unit == u ? "velocity sensor" : kind;
    if (c.unit == "Pa") kind = "microphone";
  } else {
    kind = std::string(diag::to_string(c.role));
  }
  std::string where = c.location;
  std::replace(where.begin(), where.end(), '_', ' ');
  std::string label = (where.empty() ? "" : where + " ") + kind;
  if (c.direction != diag::Direction::kUnspecified) {
    label += ", " + std::string(diag::to_string(c.direction));
  }
  return label + " (" + c.name + ")";
}

std::string channel_label(const detect::AnalysisResult& r, const std::string& name) {
  for (const detect::ChannelAnalysis& c : r.channels) {
    if (c.name == name) return channel_label(c);
  }
  return name;
}

}  // namespace report
