// analyze's first stage: the shaft angles and speeds every later stage uses. Internal to
// detectors/src/analysis.
//
// Sources, in order: the first tacho of a shaft of the description (diag::shaft_tacho, its own
// pulses per revolution); else the vibration (speed_estimate.hpp: the ridge of the strongest mesh
// harmonic within +-10 % of the nominal speed, refined by the line's phase), so that a nominal
// speed a few percent off gives the same averages as the right one; else the nominal input speed,
// assumed constant. The speed over time is reported (min/mean/max, stationary or not).
#pragma once

#include <string>
#include <vector>

#include "detect/analysis/analyze.hpp"

namespace detect {

struct ShaftKinematics {
  std::vector<AnalysisShaftSpeed> speeds;     // per shaft of the description
  std::vector<std::vector<double>> pulses_s;  // per shaft, once per revolution
  int reference_shaft = -1;                   // the shaft measured (tacho) or estimated
  AnalysisSpeed speed;                        // the report: source, range, trace
};

ShaftKinematics shaft_kinematics(const diag::Recording& rec, const diag::Gearbox& gb,
                                 double duration_s, const AnalyzeOptions& opt,
                                 std::vector<std::string>& notes);

}  // namespace detect
