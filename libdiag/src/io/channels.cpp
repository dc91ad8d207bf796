#include "diag/io/channels.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "diag/error.hpp"
#include "diag/io/input_file.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/util/number_format.hpp"

namespace diag {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

// The shaft of the description's bearing named `location`; -1 when none.
int bearing_shaft(const Gearbox& gb, const std::string& location) {
  if (location.empty()) return -1;
  for (const BearingSpec& b : gb.bearings()) {
    if (b.name == location) return gb.shaft_index(b.shaft);
  }
  return -1;
}

// Tokens of a channel name split at anything but letters and digits, lower case.
std::vector<std::string> name_tokens(const std::string& name) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : name) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      cur += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!cur.empty()) {
      out.push_back(cur);
      cur.clear();
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

}  // namespace

std::string mesh_name(const Gearbox& gb, int mesh) {
  const Mesh& m = gb.meshes().at(static_cast<std::size_t>(mesh));
  return gb.gears()[static_cast<std::size_t>(m.driver)].name + "_" +
         gb.gears()[static_cast<std::size_t>(m.driven)].name;
}

int mesh_index(const Gearbox& gb, const std::string& name) {
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    if (mesh_name(gb, static_cast<int>(j)) == name) return static_cast<int>(j);
  }
  return -1;
}

std::vector<std::size_t> sensor_channels(const Recording& rec) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < rec.signals.size(); ++i) {
    if (rec.signals[i].role == Role::kVibration) out.push_back(i);
  }
  return out;
}

int sensor_shaft(const Signal& s, const Gearbox& gb) {
  if (!s.shaft.empty()) return gb.shaft_index(s.shaft);
  return bearing_shaft(gb, s.location);
}

std::vector<std::size_t> shaft_sensors(const Recording& rec, const Gearbox& gb,
                                       const std::string& shaft) {
  const int want = gb.shaft_index(shaft);
  std::vector<std::size_t> out;
  if (want < 0) return out;
  for (std::size_t i : sensor_channels(rec)) {
    if (sensor_shaft(rec.signals[i], gb) == want) out.push_back(i);
  }
  return out;
}

std::vector<int> sensor_meshes(const Signal& s, const Gearbox& gb) {
  if (!s.mesh.empty()) {
    const int j = mesh_index(gb, s.mesh);
    if (j >= 0) return {j};
  }
  std::vector<int> out;
  const int shaft = sensor_shaft(s, gb);
  if (shaft < 0) return out;
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    const Mesh& m = gb.meshes()[j];
    if (gb.shaft_of_gear(m.driver) == shaft || gb.shaft_of_gear(m.driven) == shaft) {
      out.push_back(static_cast<int>(j));
    }
  }
  return out;
}

const Signal* shaft_tacho(const Recording& rec, const std::string& shaft) {
  // A tacho built in memory by older code may name its shaft only in `location`.
  for (const Signal& t : rec.tachos) {
    if (!shaft.empty() && (t.shaft.empty() ? t.location : t.shaft) == shaft) return &t;
  }
  return nullptr;
}

int pulses_per_rev(const Signal& tacho) { return std::max(1, tacho.ppr); }

void infer_format1_roles(Recording& rec) {
  // The simulator's format-1 names: "<shaft>_bearing<k>" locations, "_<mesh>" suffixes after
  // "along_loa"/"normal_loa" when a shaft has two meshes, mesh quantities located at the mesh.
  const bool simulated = rec.metadata.count("simulator") > 0;
  std::vector<std::string> meshes;
  for (const Signal& s : rec.signals) {
    if (s.direction == Direction::kUnspecified && simulated && !s.location.empty() &&
        std::find(meshes.begin(), meshes.end(), s.location) == meshes.end()) {
      meshes.push_back(s.location);
    }
  }
  bool undirected = false;
  for (Signal& s : rec.signals) {
    switch (s.direction) {
      case Direction::kAngle:
        s.role = Role::kAngle;
        s.shaft = s.location;
        break;
      case Direction::kTacho:
        s.role = Role::kTacho;
        s.shaft = s.location;
        s.ppr = 1;
        break;
      case Direction::kUnspecified:
        if (simulated) {
          s.role = s.unit == "N"   ? Role::kForce
                   : s.unit == "m" ? Role::kDisplacement
                                   : Role::kOther;
          s.mesh = s.location;
        } else {
          s.role = Role::kVibration;
          undirected = true;
        }
        break;
      default:
        s.role = Role::kVibration;
        if (simulated) {
          if (const auto p = s.location.rfind("_bearing"); p != std::string::npos && p > 0) {
            s.shaft = s.location.substr(0, p);
          }
          for (const std::string& m : meshes) {
            const std::string suffix = "_" + m;
            if (s.name.size() > suffix.size() &&
                s.name.compare(s.name.size() - suffix.size(), suffix.size(), suffix) == 0) {
              s.mesh = m;
            }
          }
        }
    }
  }
  for (Signal& t : rec.tachos) {
    t.role = Role::kTacho;
    if (t.shaft.empty()) t.shaft = t.location;
    t.ppr = std::max(1, t.ppr);
  }
  rec.roles_stated = !undirected;
  rec.notes.push_back(std::string("format-1 recording: channel roles inferred from directions") +
                      (simulated ? ", units and the simulator's channel names" : "") +
                      (undirected ? "; channels without direction taken as vibration" : ""));
}

ChannelMap parse_channel_map(const nlohmann::json& j, const std::string& where) {
  Fields top(j, where, "", {"channels"});
  if (!top.has("channels") || !j["channels"].is_array()) {
    top.fail("channels", "required array of channel entries is missing");
  }
  ChannelMap map;
  std::vector<std::string> seen;
  const auto& list = j["channels"];
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string path = "channels[" + std::to_string(i) + "]";
    Fields f(list[i], where, path,
             {"name", "role", "unit", "direction", "location", "shaft", "mesh", "ppr"});
    ChannelMapEntry e;
    e.name = f.str("name");
    if (std::find(seen.begin(), seen.end(), e.name) != seen.end()) {
      f.fail("name", "channel '" + e.name + "' is described twice");
    }
    seen.push_back(e.name);
    if (f.has("role")) {
      try {
        e.role = role_from_string(f.str("role"));
      } catch (const InputError&) {
        f.fail("role",
               "unknown role '" + f.str("role") +
                   "'; expected vibration, tacho, angle, speed, force, displacement, other");
      }
    }
    if (f.has("direction")) {
      try {
        e.direction = direction_from_string(f.str("direction"));
      } catch (const InputError&) {
        f.fail("direction", "unknown direction '" + f.str("direction") +
                                "'; expected along_loa, normal_loa, horizontal, vertical");
      }
    }
    auto text = [&](const char* key, std::optional<std::string>& out) {
      if (!f.has(key)) return;
      if (!f.raw(key).is_string()) f.fail(key, "must be a string");
      out = f.raw(key).get<std::string>();
    };
    text("unit", e.unit);
    text("location", e.location);
    text("shaft", e.shaft);
    text("mesh", e.mesh);
    if (f.has("ppr")) {
      const int ppr = f.integer("ppr");
      if (ppr < 1 || ppr > 100000) f.fail("ppr", std::to_string(ppr) + " is not in [1, 100000]");
      e.ppr = ppr;
    }
    map.channels.push_back(std::move(e));
  }
  return map;
}

ChannelMap load_channel_map(const std::filesystem::path& path) {
  return parse_channel_map(load_json_file(path), path.string());
}

ChannelMapEntry parse_tacho_option(const std::string& text, const std::string& option) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw InputError(format_error(option, text, "expected CHANNEL=SHAFT or CHANNEL=SHAFT:PPR"));
  }
  ChannelMapEntry e;
  e.name = text.substr(0, eq);
  e.role = Role::kTacho;
  std::string shaft = text.substr(eq + 1);
  int ppr = 1;
  if (const auto colon = shaft.rfind(':'); colon != std::string::npos) {
    const std::string count = shaft.substr(colon + 1);
    shaft = shaft.substr(0, colon);
    std::size_t used = 0;
    try {
      ppr = std::stoi(count, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != count.size() || count.empty() || ppr < 1 || ppr > 100000) {
      throw InputError(
          format_error(option, text, "PPR '" + count + "' is not a whole number in [1, 100000]"));
    }
  }
  if (shaft.empty()) throw InputError(format_error(option, text, "the shaft name is empty"));
  e.shaft = shaft;
  e.ppr = ppr;
  return e;
}

void apply_channel_map(Recording& rec, const ChannelMap& map, const Gearbox* gb,
                       const std::string& where) {
  for (std::size_t i = 0; i < map.channels.size(); ++i) {
    const ChannelMapEntry& e = map.channels[i];
    const std::string field = "channel '" + e.name + "'";
    // Find it in either group.
    std::vector<Signal>* group = nullptr;
    std::size_t index = 0;
    for (auto* g : {&rec.signals, &rec.tachos}) {
      for (std::size_t k = 0; k < g->size(); ++k) {
        if ((*g)[k].name == e.name) group = g, index = k;
      }
    }
    if (!group) {
      std::string list;
      for (const auto* g : {&rec.signals, &rec.tachos})
        for (const Signal& s : *g) list += (list.empty() ? "" : ", ") + s.name;
      throw InputError(format_error(where, field,
                                    "no such channel in the recording; it has: " +
                                        (list.empty() ? std::string("none") : list)));
    }
    Signal s = (*group)[index];
    if (e.role) s.role = *e.role;
    if (e.unit) s.unit = *e.unit;
    if (e.direction) s.direction = *e.direction;
    if (e.location) s.location = *e.location;
    if (e.shaft) s.shaft = *e.shaft;
    if (e.mesh) s.mesh = *e.mesh;
    if (e.ppr) s.ppr = *e.ppr;
    if (gb) {
      if (!s.shaft.empty() && gb->shaft_index(s.shaft) < 0) {
        std::string names;
        for (const Shaft& sh : gb->shafts()) names += (names.empty() ? "" : ", ") + sh.name;
        throw InputError(
            format_error(where, field + ": shaft",
                         "'" + s.shaft + "' is not a shaft of the gearbox (" + names + ")"));
      }
      if (!s.mesh.empty() && mesh_index(*gb, s.mesh) < 0) {
        throw InputError(
            format_error(where, field + ": mesh", "'" + s.mesh + "' is not a mesh of the gearbox"));
      }
    }
    if (s.role == Role::kTacho) {
      if (s.shaft.empty()) {
        throw InputError(format_error(where, field, "a tacho needs the shaft it turns with"));
      }
      s.ppr = std::max(1, s.ppr);
      s.direction = Direction::kTacho;
    } else {
      s.ppr = 0;
      if (s.direction == Direction::kTacho) s.direction = Direction::kUnspecified;
    }
    auto& target = s.role == Role::kTacho ? rec.tachos : rec.signals;
    if (&target == group) {
      (*group)[index] = std::move(s);
    } else {
      group->erase(group->begin() + static_cast<std::ptrdiff_t>(index));
      target.push_back(std::move(s));
    }
  }
}

std::array<double, 2> order_statistics(std::span<const double> x, std::array<std::size_t, 2> k) {
  if (x.empty() || k[0] >= x.size() || k[1] >= x.size()) {
    throw std::invalid_argument("order_statistics: rank past the end");
  }
  const auto [min_it, max_it] = std::minmax_element(x.begin(), x.end());
  const double min = *min_it, width = *max_it - min;
  std::array<double, 2> out{};
  const double scale = 4096.0 / width;
  // One value, or a span whose bin width a double cannot hold: plain selection.
  if (!(width > 0) || !std::isfinite(width) || !std::isfinite(scale)) {
    std::vector<double> sorted(x.begin(), x.end());
    for (int j = 0; j < 2; ++j) {
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k[j]),
                       sorted.end());
      out[j] = sorted[k[j]];
    }
    return out;
  }
  // bin(v) is non-decreasing in v (IEEE rounding is monotone): every sample of a lower bin is
  // smaller than every sample of a higher one, so the k-th smallest is in the bin where the
  // cumulative count passes k, at rank k minus the samples of the bins below.
  constexpr std::size_t kBins = 4096;
  const auto bin = [&](double v) {
    return std::min(kBins - 1, static_cast<std::size_t>((v - min) * scale));
  };
  std::vector<std::size_t> count(kBins, 0);
  for (const double v : x) ++count[bin(v)];
  std::array<std::size_t, 2> target{}, below{};
  for (int j = 0; j < 2; ++j) {
    std::size_t cumulative = 0, b = 0;
    while (cumulative + count[b] <= k[j]) cumulative += count[b++];
    target[j] = b;
    below[j] = cumulative;
  }
  for (int j = 0; j < 2; ++j) {
    std::vector<double> candidates;
    candidates.reserve(count[target[j]]);
    for (const double v : x) {
      if (bin(v) == target[j]) candidates.push_back(v);
    }
    const std::size_t r = k[j] - below[j];
    std::nth_element(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(r),
                     candidates.end());
    out[j] = candidates[r];
  }
  return out;
}

std::optional<double> pulse_train_rate_hz(const std::vector<double>& x, double fs_hz) {
  if (x.size() < 16 || !(fs_hz > 0)) return std::nullopt;
  // The two levels are robust extremes (0.2 and 99.8 percentiles: a pulse train with a duty
  // cycle down to 0.5 % keeps its high level there, and a spike does not move them).
  const double top = static_cast<double>(x.size() - 1);
  const auto [lo, hi] = order_statistics(
      x, {static_cast<std::size_t>(0.002 * top), static_cast<std::size_t>(0.998 * top)});
  const double range = hi - lo;
  if (!(range > 0)) return std::nullopt;
  std::size_t near_lo = 0, near_hi = 0;
  for (double v : x) {
    if (std::abs(v - lo) <= 0.2 * range) ++near_lo;
    if (std::abs(v - hi) <= 0.2 * range) ++near_hi;
  }
  const double n = static_cast<double>(x.size());
  if ((near_lo + near_hi) < 0.95 * n || near_lo < 0.002 * n || near_hi < 0.002 * n) {
    return std::nullopt;
  }
  // Rising edges with hysteresis: up through 55 %, re-armed below 45 % of the range.
  const double up = lo + 0.55 * range, down = lo + 0.45 * range;
  bool high = x.front() > up;
  std::size_t edges = 0, first = 0, last = 0;
  for (std::size_t i = 1; i < x.size(); ++i) {
    if (!high && x[i] > up) {
      high = true;
      if (edges == 0) first = i;
      last = i;
      ++edges;
    } else if (high && x[i] < down) {
      high = false;
    }
  }
  if (edges < 3) return std::nullopt;
  return static_cast<double>(edges - 1) * fs_hz / static_cast<double>(last - first);
}

std::vector<std::string> infer_tachos(Recording& rec, const Gearbox* gb,
                                      const std::vector<std::string>& described) {
  std::vector<std::string> notes;
  if (rec.roles_stated) return notes;
  constexpr double kRateTolerance = 0.20;  // nominal speeds are often a few % off; 20 % still
                                           // separates shafts 1.5x apart
  std::vector<Signal> keep;
  for (Signal& s : rec.signals) {
    const bool skip = s.role != Role::kVibration ||
                      std::find(described.begin(), described.end(), s.name) != described.end();
    if (skip) {
      keep.push_back(std::move(s));
      continue;
    }
    const std::string name = lower(s.name);
    const bool named = contains(name, "tach") || contains(name, "key") || contains(name, "rpm");
    const std::optional<double> rate = pulse_train_rate_hz(s.samples, s.fs_hz);
    // Shafts named in the channel name, as whole tokens ("input", "tacho_input", "input-key").
    std::vector<int> named_shafts;
    if (gb) {
      const std::vector<std::string> tokens = name_tokens(s.name);
      for (std::size_t k = 0; k < gb->shafts().size(); ++k) {
        const std::string shaft = lower(gb->shafts()[k].name);
        if (std::find(tokens.begin(), tokens.end(), shaft) != tokens.end() || name == shaft) {
          named_shafts.push_back(static_cast<int>(k));
        }
      }
    }
    if (!rate) {
      if (named && contains(name, "rpm")) {
        s.role = Role::kSpeed;
        notes.push_back("channel '" + s.name +
                        "': named like a speed signal and not a pulse train: taken as a speed "
                        "signal, not analysed as vibration");
      } else if (named) {
        notes.push_back("channel '" + s.name +
                        "': named like a tacho but not a two-level pulse train: analysed as "
                        "vibration (say --tacho or --channels if it is a tacho)");
      }
      keep.push_back(std::move(s));
      continue;
    }
    s.role = Role::kTacho;
    s.direction = Direction::kTacho;
    std::string how = named ? "named like a tacho" : "a two-level pulse train";
    if (!gb) {
      s.role = Role::kOther;
      s.direction = Direction::kUnspecified;
      notes.push_back("channel '" + s.name + "': " + how + " at " +
                      diag::format_significant(*rate, 4) +
                      " pulses/s; without a gearbox its shaft is unknown: not analysed as "
                      "vibration");
      keep.push_back(std::move(s));
      continue;
    }
    // The shaft and pulses per revolution consistent with the rate: the named shaft first, else
    // a shaft turning at the pulse rate (one pulse per revolution).
    auto ppr_for = [&](int shaft) -> int {
      const double f = gb->shaft_speed_hz(shaft);
      const double p = std::round(*rate / f);
      if (p < 1 || std::abs(*rate / (p * f) - 1) > kRateTolerance) return 0;
      return static_cast<int>(p);
    };
    int shaft = -1, ppr = 0;
    for (int k : named_shafts) {
      if (const int p = ppr_for(k); p > 0) {
        shaft = k;
        ppr = p;
        break;
      }
    }
    if (shaft < 0 && named_shafts.empty()) {
      std::vector<int> once;
      for (std::size_t k = 0; k < gb->shafts().size(); ++k) {
        const double f = gb->shaft_speed_hz(static_cast<int>(k));
        if (std::abs(*rate / f - 1) <= kRateTolerance) once.push_back(static_cast<int>(k));
      }
      if (once.size() == 1) shaft = once.front(), ppr = 1;
    }
    if (shaft < 0 && named) {
      // Named like a tacho and a pulse train, but at a rate no shaft of the description turns
      // at: the tacho is the measurement, the description's speed is stale. Taken as the tacho
      // of the shaft it names (else the input shaft), one pulse per revolution, with a warning.
      shaft = named_shafts.size() == 1 ? named_shafts.front() : gb->input_shaft();
      ppr = 1;
      notes.push_back("warning: channel '" + s.name + "': a tacho at " +
                      diag::format_significant(*rate * 60, 4) +
                      " pulses/min contradicts the description's nominal " +
                      diag::format_significant(gb->shaft_speed_hz(shaft) * 60, 4) +
                      " rpm of shaft " + gb->shafts()[static_cast<std::size_t>(shaft)].name +
                      ": the tacho is used (1 pulse per revolution; say --tacho "
                      "CHANNEL=SHAFT:PPR otherwise) and the description's speed is not");
    }
    if (shaft < 0) {
      s.role = Role::kOther;
      s.direction = Direction::kUnspecified;
      notes.push_back("channel '" + s.name + "': " + how + " at " +
                      diag::format_significant(*rate, 4) +
                      " pulses/s, consistent with no single shaft of the description (nominal "
                      "input " +
                      diag::format_significant(gb->input().speed_rpm, 4) +
                      " rpm): not used as a tacho, not analysed as vibration (say --tacho "
                      "CHANNEL=SHAFT[:PPR])");
      keep.push_back(std::move(s));
      continue;
    }
    s.shaft = gb->shafts()[static_cast<std::size_t>(shaft)].name;
    s.ppr = ppr;
    notes.push_back("channel '" + s.name + "': " + how + " at " +
                    diag::format_significant(*rate, 4) + " pulses/s: taken as the tacho of shaft " +
                    s.shaft + " (" + std::to_string(ppr) + " pulse" + (ppr > 1 ? "s" : "") +
                    " per revolution; nominal " +
                    diag::format_significant(gb->shaft_speed_hz(shaft) * 60, 4) + " rpm)");
    rec.tachos.push_back(std::move(s));
  }
  rec.signals = std::move(keep);
  return notes;
}

}  // namespace diag
