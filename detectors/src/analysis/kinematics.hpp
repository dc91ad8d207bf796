// analyze's first stage: the shaft angles and speeds every later stage uses. Internal to
// detectors/src/analysis.
//
// Sources, in order: the first tacho of a shaft of the description (diag::shaft_tacho, its own
// pulses per revolution); else the vibration (speed_estimate.hpp: the ridge of the strongest mesh
// harmonic, or shaft harmonic on a description without gears, within +-12.5 % of the nominal
// speed, refined by the line's phase), so that a nominal speed up to 10 % off gives the same
// averages as the right one; else the nominal input speed,
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
  // The revolutions every TSA uses (analyze's per-shaft TSA and the damaged-shaft locator), per
  // shaft: the reference's pulses corrected once (refine_tsa_pulses) and scaled to each shaft.
  // Empty until refine_tsa_pulses ran; then tsa_reference names the shaft tsa_reference_pulses
  // are once per revolution of.
  std::vector<std::vector<double>> tsa_pulses_s;
  std::string tsa_reference;
  std::vector<double> tsa_reference_pulses;
};

// Pulse times smoothed by a local quadratic least-squares fit of t(k) over 2 half_window + 1
// pulses (Savitzky & Golay 1964; the window shifted inward at the ends), evaluated at k: the
// timing jitter of each pulse (up to half a sampling period for a sharp tacho edge, tacho.hpp)
// averaged out, a smooth run-up kept (t(k) is locally quadratic for a constant acceleration).
// Fewer pulses than the window: returned as given.
std::vector<double> smooth_pulse_times_local_quadratic(const std::vector<double>& pulses_s,
                                                       int half_window);

// The pulse correction of the tacho/TSA layer (pulse_refine.hpp: smoothed, then corrected from a
// mesh line's phase on the fastest shaft), run once on the reference shaft's pulses with the
// locator's settings (options.gear_damage), so that analyze's per-shaft TSA and the locator
// average over the same revolutions. Fills k.tsa_pulses_s; when the correction cannot run (too
// few revolutions, no channel), the pulses as they are, and a note says why.
void refine_tsa_pulses(const diag::Recording& rec, const diag::Gearbox& gb,
                       const AnalyzeOptions& opt, ShaftKinematics& k,
                       std::vector<std::string>& notes);

ShaftKinematics shaft_kinematics(const diag::Recording& rec, const diag::Gearbox& gb,
                                 double duration_s, const AnalyzeOptions& opt,
                                 std::vector<std::string>& notes);

}  // namespace detect
