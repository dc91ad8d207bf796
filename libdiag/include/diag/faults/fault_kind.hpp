// The fault vocabulary of geardiag: one enum and one name per kind, used by the simulator's
// scenarios and ground truth, by every detector's findings and by every writer (JSON, CSV, HTML,
// text) and reader. A name is written exactly as to_string gives it; parse_fault_kind also takes
// the aliases below on input (older files, users' scenario JSON, other tools' words) and maps
// them to the one kind.
//
//   site     name             what                                         aliases on input
//   gear     crack            tooth root crack                             root_crack
//   gear     chip             chipped tooth tip / corner
//   gear     spall            surface spall (fatigue pitting grown)        spalling
//   gear     pit              flank pitting                                pitting
//   gear     missing          broken-off (missing) tooth                   missing_tooth,
//                                                                          broken_tooth, breakage
//   gear     broken_tip       part of the tip broken off
//   gear     profile          a flank form deviation (profile defect)
//   gear     wear             distributed flank wear
//   gear     tooth_damage     a local tooth defect of unknown type (what a
//                             TSA locator or the recurrence matcher sees)
//   gear     gear_modulation  mesh modulation at a shaft's rate: a local
//                             defect, eccentricity or pitch errors (the
//                             sideband family; analyze makes no finding of it)
//   shaft    eccentricity     runout / eccentric gear or shaft             runout
//   shaft    bent_shaft       bent shaft
//   bearing  outer_race       outer-race defect (BPFO)
//   bearing  inner_race       inner-race defect (BPFI)
//   bearing  rolling_element  rolling-element (ball, roller) defect (2 BSF)  ball, roller
//   bearing  cage             cage defect (FTF)
//   -        none             healthy / no fault                           healthy
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace diag {

enum class FaultKind {
  kNone,
  // gear
  kCrack,
  kChip,
  kSpall,
  kPit,
  kMissing,
  kBrokenTip,
  kProfile,
  kWear,
  kToothDamage,
  kGearModulation,
  // shaft
  kEccentricity,
  kBentShaft,
  // bearing
  kOuterRace,
  kInnerRace,
  kRollingElement,
  kCage,
  // no site: the recording departs from its healthy baseline (the anomaly score's alarm)
  kAnomaly,
};

// Where a fault of this kind sits.
enum class FaultSite { kNone, kGear, kShaft, kBearing };

// The one name of a kind ("crack", "rolling_element", "none", ...).
std::string_view to_string(FaultKind k);
std::string_view to_string(FaultSite s);  // "none", "gear", "shaft", "bearing"
FaultSite site_of(FaultKind k);

// Every kind, in the order of the enum (kNone first).
std::span<const FaultKind> all_fault_kinds();

// The kind of a name or alias (exact, lower case); nullopt when it is neither.
std::optional<FaultKind> fault_kind_from_string(std::string_view name);

// The same, throwing InputError("where: field: 'name' is not a fault kind (one of ...)") when the
// name is unknown.
FaultKind parse_fault_kind(std::string_view name, const std::string& where,
                           const std::string& field);

class Fields;
// The gear fault kind in `fields[key]` (default `dflt` when absent), a name or an alias; refuses
// with fields.fail(key, ...) a word that is not a kind or a kind that does not sit on a gear.
// What a gearbox description's defects[].type and a kinematic dataset class's defect type take.
FaultKind parse_gear_fault_kind(const Fields& fields, const std::string& key,
                                std::string_view dflt);

}  // namespace diag
