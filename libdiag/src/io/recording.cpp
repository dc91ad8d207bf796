#include "diag/io/recording.hpp"

#include <cmath>
#include <map>
#include <string>
#include <string_view>

#include "diag/error.hpp"
#include "diag/io/printable.hpp"

namespace diag {

namespace {

struct DirectionName {
  Direction direction;
  std::string_view name;
};

constexpr DirectionName kDirectionNames[] = {
    {Direction::kUnspecified, ""},         {Direction::kAlongLoa, "along_loa"},
    {Direction::kNormalLoa, "normal_loa"}, {Direction::kHorizontal, "horizontal"},
    {Direction::kVertical, "vertical"},    {Direction::kAngle, "angle"},
    {Direction::kTacho, "tacho"},
};

struct RoleName {
  Role role;
  std::string_view name;
};

constexpr RoleName kRoleNames[] = {
    {Role::kVibration, "vibration"}, {Role::kTacho, "tacho"}, {Role::kAngle, "angle"},
    {Role::kSpeed, "speed"},         {Role::kForce, "force"}, {Role::kDisplacement, "displacement"},
    {Role::kOther, "other"},
};

std::string channel_list(const Recording& rec) {
  std::string out;
  for (const auto* group : {&rec.signals, &rec.tachos}) {
    for (const Signal& s : *group) {
      if (!out.empty()) out += ", ";
      out += s.name;
    }
  }
  return out.empty() ? std::string("none") : out;
}

}  // namespace

std::string_view to_string(Direction d) {
  for (const auto& entry : kDirectionNames) {
    if (entry.direction == d) return entry.name;
  }
  return "";
}

Direction direction_from_string(std::string_view name) {
  for (const auto& entry : kDirectionNames) {
    if (entry.name == name) return entry.direction;
  }
  throw InputError(format_error("direction", std::string(name),
                                "unknown direction; expected one of \"\", along_loa, normal_loa, "
                                "horizontal, vertical, angle, tacho"));
}

std::string_view to_string(Role r) {
  for (const auto& entry : kRoleNames) {
    if (entry.role == r) return entry.name;
  }
  return "";
}

Role role_from_string(std::string_view name) {
  for (const auto& entry : kRoleNames) {
    if (entry.name == name) return entry.role;
  }
  throw InputError(format_error("role", std::string(name),
                                "unknown role; expected one of vibration, tacho, angle, speed, "
                                "force, displacement, other"));
}

const Signal* Recording::find(std::string_view name) const {
  for (const auto* group : {&signals, &tachos}) {
    for (const Signal& s : *group) {
      if (s.name == name) return &s;
    }
  }
  return nullptr;
}

const Signal& Recording::require(std::string_view name, const std::string& where) const {
  if (const Signal* s = find(name)) return *s;
  throw InputError(format_error(where, "channel '" + std::string(name) + "'",
                                "no such channel; the recording has: " + channel_list(*this)));
}

void validate(const Signal& s, const std::string& where) {
  if (s.name.empty()) {
    throw InputError(format_error(where, "channel name", "must not be empty"));
  }
  const std::string field = "channel '" + s.name + "'";
  if (s.name.find('/') != std::string::npos || s.name == "." || s.name == "..") {
    throw InputError(format_error(where, field, "name must not contain '/' nor be '.' or '..'"));
  }
  if (!(s.fs_hz > 0.0) || !std::isfinite(s.fs_hz)) {
    throw InputError(format_error(
        where, field + ": fs_hz",
        "sampling rate " + std::to_string(s.fs_hz) + " Hz is not valid; must be finite and > 0"));
  }
  if (s.samples.empty()) {
    throw InputError(format_error(where, field, "has no samples"));
  }
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    if (!std::isfinite(s.samples[i])) {
      throw InputError(format_error(where, field,
                                    "sample " + std::to_string(i) + " is " +
                                        (std::isnan(s.samples[i]) ? "NaN" : "infinite") +
                                        "; samples must be finite"));
    }
  }
}

namespace {

// The length of the control character at text[i] (0: none): a C0 byte, DEL, or a C1 character
// in UTF-8 (0xC2 0x80 ... 0xC2 0x9F).
std::size_t control_at(std::string_view text, std::size_t i) {
  const auto c = static_cast<unsigned char>(text[i]);
  if (c < 0x20 || c == 0x7f) return 1;
  if (c == 0xC2 && i + 1 < text.size()) {
    const auto next = static_cast<unsigned char>(text[i + 1]);
    if (next >= 0x80 && next <= 0x9F) return 2;
  }
  return 0;
}

}  // namespace

bool has_control_characters(std::string_view text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (control_at(text, i) > 0) return true;
  }
  return false;
}

std::string printable_text(std::string_view text) {
  if (!has_control_characters(text)) return std::string(text);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = control_at(text, i);
    if (n == 0) {
      out += text[i++];
      continue;
    }
    for (std::size_t k = 0; k < n; ++k, ++i) {
      const auto c = static_cast<unsigned char>(text[i]);
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

void make_printable(Recording& rec) {
  for (auto* group : {&rec.signals, &rec.tachos}) {
    for (Signal& s : *group) {
      for (std::string* text : {&s.name, &s.unit, &s.location, &s.shaft, &s.mesh}) {
        *text = printable_text(*text);
      }
    }
  }
  std::map<std::string, std::string> metadata;
  for (const auto& [key, value] : rec.metadata) {
    metadata[printable_text(key)] = printable_text(value);
  }
  rec.metadata = std::move(metadata);
}

}  // namespace diag
