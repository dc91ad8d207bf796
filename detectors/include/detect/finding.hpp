// One conclusion of a detector: the single finding type that every module returns (the gear-damage
// locator, gear_damage.hpp; the bearing diagnosis, bearing_diagnosis.hpp; the recurrence-period
// matcher, period_matcher.hpp; analyze's fusion, analyze.hpp), and its JSON.
//
// What a finding says: which detector concluded (`kind`), what fault (`fault`, the one fault
// vocabulary of diag/faults/fault_kind.hpp), where (shaft, gears, bearing, the channel that shows
// it best), how sure ([0, 1]) and, where the detector can tell, how large (a size with its unit).
// The numbers behind it are named evidence ("score", "score_db", "period_input_rev", ...): each
// module documents its own; detail that is not a number stays in the module's result struct.
//
// JSON (to_json): {"kind", "fault", "shaft", "gears", "bearing", "channel", "frequency_hz",
// "confidence", "size", "size_unit", "note", "evidence": {name: number}, "time_s": [first, last],
// "frames_seen", "frames_examined"}; every evidence entry is
// also written at the top level under its own name (the keys `geardiag attribute` and `analyze`
// wrote before the finding types were one). Fields that do not apply are left out: empty strings
// and gear lists, NaN frequency and size.
#pragma once

#include <limits>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "diag/faults/fault_kind.hpp"

namespace detect {

struct Finding {
  // The detector that concluded: "gear_damage" (TSA damaged-shaft locator), "bearing" (bearing
  // diagnosis), "wear" (the wear indicator against a baseline), "attribution" (recurrence-period
  // matcher of the output shaft's lag). analyze's sideband vote is a note, never a finding
  // (findings.cpp: healthy gears with ordinary pitch errors pass it on every recording).
  std::string kind;
  diag::FaultKind fault = diag::FaultKind::kNone;  // what is wrong (kToothDamage: a local tooth
                                                   // defect whose type is not told)
  std::string shaft;                               // the shaft concerned ("" for bearings)
  std::vector<std::string> gears;                  // the gears it may be on (all on the shaft
                                                   // when the detector cannot tell which)
  std::string bearing;                             // BearingSpec::name ("" for gears)
  std::string channel;                             // the channel that shows it best
  double frequency_hz = std::numeric_limits<double>::quiet_NaN();  // the fault's rate [Hz]
  double confidence = 0;                                           // [0, 1]
  double size = std::numeric_limits<double>::quiet_NaN();          // size estimate (NaN: not told)
  std::string size_unit;                                           // its unit ("rad", "m", ...)
  std::vector<std::pair<std::string, double>> evidence;  // named numbers, in a fixed order
  std::string note;                                      // readable reason, alternatives
  // Where in a long recording it is seen (detect::analyze_file, which analyses a recording frame
  // by frame): from the start of the first frame that shows it to the end of the last [s], and
  // in how many of the frames examined. NaN and 0 when not placed in time.
  double first_s = std::numeric_limits<double>::quiet_NaN();
  double last_s = std::numeric_limits<double>::quiet_NaN();
  int frames_seen = 0, frames_examined = 0;

  // The evidence named `name`; NaN when there is none.
  double evidence_value(std::string_view name) const;
  // Adds (or replaces) an evidence entry.
  void set_evidence(std::string name, double value);
};

nlohmann::json to_json(const Finding& f);

}  // namespace detect
