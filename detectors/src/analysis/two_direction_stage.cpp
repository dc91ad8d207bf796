// analyze's two-direction stage: for each along-LOA sensor, its normal-LOA partner at the same
// location, and the mesh-harmonic energies in both directions (two_direction.hpp, stages.hpp).
#include "detect/gear/two_direction.hpp"
#include "diag/io/channels.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

void two_direction_stage(const AnalysisContext& ctx, const std::vector<Spectrum>& spectra,
                         AnalysisResult& r) {
  for (std::size_t ai = 0; ai < r.channels.size(); ++ai) {
    const ChannelAnalysis& a = r.channels[ai];
    if (a.direction != diag::Direction::kAlongLoa || spectra[ai].amplitude.empty()) continue;
    // The partner: the normal-LOA sensor at the same location following the same mesh (the
    // channel contract's location and mesh; no name is parsed); without a mesh on either, the
    // only normal-LOA sensor at that location.
    int ni = -1, same_location = -1, count = 0;
    for (std::size_t k = 0; k < r.channels.size(); ++k) {
      const ChannelAnalysis& n = r.channels[k];
      if (n.direction != diag::Direction::kNormalLoa || n.location != a.location ||
          spectra[k].amplitude.empty() || n.fs_hz != a.fs_hz || n.samples != a.samples) {
        continue;
      }
      if (!a.mesh.empty() && n.mesh == a.mesh) ni = static_cast<int>(k);
      same_location = static_cast<int>(k);
      ++count;
    }
    if (ni < 0 && count == 1 && (a.mesh.empty() || r.channels[same_location].mesh.empty())) {
      ni = same_location;
    }
    if (ni < 0) {
      r.notes.push_back("two directions: no normal_loa partner for '" + a.name + "'");
      continue;
    }
    std::vector<std::size_t> meshes;
    for (int j : diag::sensor_meshes(ctx.rec.signals[ai], *ctx.gb)) {
      meshes.push_back(static_cast<std::size_t>(j));
    }
    if (meshes.empty()) {
      for (std::size_t j = 0; j < r.meshes.size(); ++j) meshes.push_back(j);
    }
    const Spectrum& sa = spectra[ai];
    const Spectrum& sn = spectra[static_cast<std::size_t>(ni)];
    for (std::size_t j : meshes) {
      TwoDirectionRow row;
      row.location = a.location;
      row.along_channel = a.name;
      row.normal_channel = r.channels[static_cast<std::size_t>(ni)].name;
      row.mesh = r.meshes[j].name;
      row.comparison = compare_two_directions(
          {sa.frequency_hz, sa.amplitude}, {sn.frequency_hz, sn.amplitude},
          sa.enbw_hz / sa.resolution_hz, r.meshes[j].frequency_hz, ctx.opt.two_direction);
      r.two_direction.push_back(std::move(row));
    }
  }
}

}  // namespace detect::analysis_stages
