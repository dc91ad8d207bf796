// analyze's per-channel stage: the TSA of every shaft with gears, its regular, residual and
// difference signals and each gear's metrics (tsa.hpp, indicators.hpp, stages.hpp).
#include <algorithm>

#include "detect/angular/tsa.hpp"
#include "detect/indicators/indicators.hpp"
#include "diag/error.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

void tsa_stage(ChannelWork& w) {
  const AnalysisContext& ctx = w.ctx;
  const AngularRecords& ang = w.ang;
  const std::size_t ci = w.index;
  const diag::Signal& sig = w.signal;
  ChannelAnalysis& c = w.out;
  const diag::Gearbox& gb = *ctx.gb;
  const AnalyzeOptions& opt = ctx.opt;
  for (std::size_t s = 0; s < gb.shafts().size(); ++s) {
    const diag::Shaft& shaft = gb.shafts()[s];
    if (shaft.gears.empty()) continue;
    ShaftTsaAnalysis ta;
    ta.shaft = shaft.name;
    std::vector<int> orders;
    for (int g : shaft.gears) orders.push_back(gb.gears()[static_cast<std::size_t>(g)].spec.teeth);
    const int spr = tsa_samples_per_rev(gb, s, opt);
    const auto& pulses = ctx.kin.tsa_pulses_s[s];  // corrected once (kinematics.hpp)
    const int revs = pulses.size() > 1 ? static_cast<int>(pulses.size()) - 1 : 0;
    if (revs < opt.tsa_min_revolutions) {
      ta.note = std::to_string(revs) + " revolutions in the record, fewer than " +
                std::to_string(opt.tsa_min_revolutions) + ": no TSA";
      c.tsa.push_back(std::move(ta));
      continue;
    }
    try {
      TsaOptions to;
      to.samples_per_rev = spr;
      to.min_revolutions = opt.tsa_min_revolutions;
      const auto& shared = ang.tsa_resampled[s];  // empty: no plan for this shaft
      const Tsa t = !shared.empty() && shared[ci] ? tsa(*shared[ci], opt.tsa_min_revolutions)
                                                  : tsa(sig.samples, sig.fs_hz, pulses, to);
      ta.revolutions = t.revolutions;
      ta.samples_per_rev = t.samples_per_rev;
      ta.tsa = t.samples;
      ta.regular = tsa_regular(t, orders);
      ta.residual = tsa_residual(t, orders);
      ta.difference = tsa_difference(t, orders);
      ta.computed = true;
      for (int g : shaft.gears) {
        const auto& ge = gb.gears()[static_cast<std::size_t>(g)];
        GearMetricOptions gm = opt.gear_metrics;
        gm.mesh_order = ge.spec.teeth;
        gm.ser_sidebands = std::min(gm.ser_sidebands, ge.spec.teeth - 1);
        gm.mesh_harmonics = std::min(gm.mesh_harmonics,
                                     (spr / 2 - 1 - gm.ser_sidebands) / std::max(1, gm.mesh_order));
        GearMetricsRow row;
        row.gear = ge.name;
        row.teeth = ge.spec.teeth;
        if (gm.ser_sidebands < 1 || gm.mesh_harmonics < 1) {
          ta.note = "gear " + ge.name + ": too few teeth or samples for the gear metrics";
          continue;
        }
        row.indicators = gear_indicators({ta.tsa, ta.difference, ta.regular, ta.residual}, gm);
        ta.gears.push_back(row);
      }
    } catch (const diag::InputError& e) {
      ta.note = std::string("TSA skipped: ") + e.what();
    }
    c.tsa.push_back(std::move(ta));
  }
}

}  // namespace detect::analysis_stages
