#include "diag/faults/fault_kind.hpp"

#include <array>
#include <utility>

#include "diag/error.hpp"
#include "diag/io/json_fields.hpp"

namespace diag {
namespace {

struct Entry {
  FaultKind kind;
  std::string_view name;
  FaultSite site;
};

// One row per kind, in the enum's order (to_string indexes it).
constexpr std::array<Entry, 18> kEntries{{
    {FaultKind::kNone, "none", FaultSite::kNone},
    {FaultKind::kCrack, "crack", FaultSite::kGear},
    {FaultKind::kChip, "chip", FaultSite::kGear},
    {FaultKind::kSpall, "spall", FaultSite::kGear},
    {FaultKind::kPit, "pit", FaultSite::kGear},
    {FaultKind::kMissing, "missing", FaultSite::kGear},
    {FaultKind::kBrokenTip, "broken_tip", FaultSite::kGear},
    {FaultKind::kProfile, "profile", FaultSite::kGear},
    {FaultKind::kWear, "wear", FaultSite::kGear},
    {FaultKind::kToothDamage, "tooth_damage", FaultSite::kGear},
    {FaultKind::kGearModulation, "gear_modulation", FaultSite::kGear},
    {FaultKind::kEccentricity, "eccentricity", FaultSite::kShaft},
    {FaultKind::kBentShaft, "bent_shaft", FaultSite::kShaft},
    {FaultKind::kOuterRace, "outer_race", FaultSite::kBearing},
    {FaultKind::kInnerRace, "inner_race", FaultSite::kBearing},
    {FaultKind::kRollingElement, "rolling_element", FaultSite::kBearing},
    {FaultKind::kCage, "cage", FaultSite::kBearing},
    {FaultKind::kAnomaly, "anomaly", FaultSite::kNone},
}};
constexpr std::size_t kKinds = kEntries.size();

constexpr std::array<std::pair<std::string_view, FaultKind>, 10> kAliases{{
    {"root_crack", FaultKind::kCrack},
    {"spalling", FaultKind::kSpall},
    {"pitting", FaultKind::kPit},
    {"missing_tooth", FaultKind::kMissing},
    {"broken_tooth", FaultKind::kMissing},
    {"breakage", FaultKind::kMissing},
    {"runout", FaultKind::kEccentricity},
    {"ball", FaultKind::kRollingElement},
    {"roller", FaultKind::kRollingElement},
    {"healthy", FaultKind::kNone},
}};

const std::array<FaultKind, kKinds> kAll = [] {
  std::array<FaultKind, kKinds> a{};
  for (std::size_t i = 0; i < kKinds; ++i) a[i] = kEntries[i].kind;
  return a;
}();

}  // namespace

std::string_view to_string(FaultKind k) {
  const auto i = static_cast<std::size_t>(k);
  return i < kKinds ? kEntries[i].name : "none";
}

std::string_view to_string(FaultSite s) {
  switch (s) {
    case FaultSite::kGear:
      return "gear";
    case FaultSite::kShaft:
      return "shaft";
    case FaultSite::kBearing:
      return "bearing";
    case FaultSite::kNone:
      break;
  }
  return "none";
}

FaultSite site_of(FaultKind k) {
  const auto i = static_cast<std::size_t>(k);
  return i < kKinds ? kEntries[i].site : FaultSite::kNone;
}

std::span<const FaultKind> all_fault_kinds() { return kAll; }

std::optional<FaultKind> fault_kind_from_string(std::string_view name) {
  for (std::size_t i = 0; i < kKinds; ++i) {
    if (kEntries[i].name == name) return kEntries[i].kind;
  }
  for (const auto& [alias, kind] : kAliases) {
    if (alias == name) return kind;
  }
  return std::nullopt;
}

FaultKind parse_fault_kind(std::string_view name, const std::string& where,
                           const std::string& field) {
  if (const auto k = fault_kind_from_string(name)) return *k;
  std::string list;
  for (std::size_t i = 0; i < kKinds; ++i) {
    list += (list.empty() ? "" : ", ") + std::string(kEntries[i].name);
  }
  fail(where, field, "'" + std::string(name) + "' is not a fault kind (one of " + list + ")");
}

FaultKind parse_gear_fault_kind(const Fields& fields, const std::string& key,
                                std::string_view dflt) {
  const std::string name = fields.has(key) ? fields.name(key) : std::string(dflt);
  const std::optional<FaultKind> kind = fault_kind_from_string(name);
  if (!kind || site_of(*kind) != FaultSite::kGear) {
    std::string kinds;
    for (const FaultKind k : all_fault_kinds()) {
      if (site_of(k) != FaultSite::kGear || k == FaultKind::kGearModulation) continue;
      kinds += (kinds.empty() ? "" : ", ") + std::string(to_string(k));
    }
    fields.fail(key, "'" + name + "' is not a gear fault kind (" + kinds + ")");
  }
  return *kind;
}

}  // namespace diag
