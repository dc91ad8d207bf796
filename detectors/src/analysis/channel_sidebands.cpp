// analyze's per-channel stage: mesh harmonics and sideband families of every mesh
// (sidebands.hpp, stages.hpp).
#include <algorithm>

#include "detect/gear/sidebands.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

void sideband_stage(ChannelWork& w) {
  const AnalysisContext& ctx = w.ctx;
  const Spectrum& sp = w.spectrum;
  ChannelAnalysis& c = w.out;
  const diag::Gearbox& gb = *ctx.gb;
  const auto& speeds = ctx.kin.speeds;
  const SpectrumView view{sp.frequency_hz, sp.amplitude};
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    const diag::Mesh& m = gb.meshes()[j];
    const auto sa = static_cast<std::size_t>(gb.shaft_of_gear(m.driver));
    const auto sb = static_cast<std::size_t>(gb.shaft_of_gear(m.driven));
    std::vector<ShaftCandidate> cand{{gb.shafts()[sa].name, speeds[sa].speed_hz},
                                     {gb.shafts()[sb].name, speeds[sb].speed_hz}};
    MeshAnalysis ma;
    ma.mesh = static_cast<int>(j);
    ma.name = ctx.meshes[j].name;
    ma.mesh_hz = ctx.meshes[j].frequency_hz;
    // The rest of the gearbox: another mesh's harmonics and the combination tones of two
    // meshes are not sidebands of a shaft (sidebands.hpp).
    SidebandContext context;
    for (std::size_t i = 0; i < ctx.meshes.size(); ++i) {
      if (i != j) context.other_mesh_hz.push_back(ctx.meshes[i].frequency_hz);
    }
    ma.sidebands = analyse_sidebands(view, ma.mesh_hz, cand, ctx.opt.sidebands, context);
    if (ctx.opt.traces) {
      const double span =
          (ctx.opt.sidebands.sidebands + 2) * std::max(cand[0].frequency_hz, cand[1].frequency_hz);
      ma.zoom = slice_for_plot(sp.frequency_hz, sp.amplitude, ma.mesh_hz - span, ma.mesh_hz + span,
                               ctx.plot_points);
    }
    c.meshes.push_back(std::move(ma));
  }
}

}  // namespace detect::analysis_stages
