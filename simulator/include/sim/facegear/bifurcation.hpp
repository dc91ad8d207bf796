// Bifurcation diagram of the face-gear pair against input speed (seed 002, fig. 10): at each
// speed an independent steady-state run from static equilibrium (so speeds can run in parallel
// and the output does not depend on the thread count), the DTE sampled once per mesh period after
// the transients (the Poincare section), the period class and the impact class.
#pragma once

#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "sim/facegear/face_gear.hpp"

namespace sim::facegear {

struct BifurcationOptions {
  double from_rpm = 100.0, to_rpm = 20000.0;  // > 0, to > from
  int steps = 200;                            // speeds, [2, 10000]
  int transient_periods = 300;                // mesh periods discarded per speed
  int record_periods = 100;                   // Poincare points per speed, >= 18
  int threads = 0;                            // 0: all cores
  // The located-event rk8pd by default: its contact switches are found by bisection, so a
  // period-2 label is not an artefact of unlocated switches (face_gear.hpp, poincare_rel_tol).
  Integrator integrator = Integrator::kAdaptive;
  void validate() const;
};

struct BifurcationPoint {
  double rpm = 0.0;
  std::vector<double> points;  // DTE [rad] once per mesh period
  std::string period_class;    // period-1 | period-2 | period-n | chaos
  ImpactClass impact = ImpactClass::kNoImpact;
  double dlf = 0.0;               // max |T_mesh| / T_static over the recorded periods
  double mean_mesh_torque = 0.0;  // [N m, pinion side] (the input torque less c_p Omega)
  double free_share = 0.0;        // share of recorded steps out of contact
  // A(GMF / 2) / A(GMF) of the DTE over the recorded periods (half_gmf_ratio): the period
  // doubling's subharmonic line in the spectrum.
  double half_gmf_ratio = 0.0;
};

struct Bifurcation {
  std::vector<BifurcationPoint> speeds;
  double natural_frequency_hz = 0.0;  // mesh mode at the operating torque
  int threads = 0;                    // worker threads used (not in the JSON: no effect on it)
  nlohmann::json to_json() const;
  // Scatter plot (speed vs DTE in micro-rad), points coloured by period class.
  std::string to_svg(const std::string& title) const;
};

// `progress(done, total)` is called from the worker threads (serialised) when given.
Bifurcation bifurcation(const FaceGearPair& pair, const Operating& op,
                        const BifurcationOptions& opt,
                        const std::function<void(int, int)>& progress = {});

}  // namespace sim::facegear
