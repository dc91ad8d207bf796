#include "detect/gear/sidebands.hpp"

#include <algorithm>
#include <cmath>

#include "diag/error.hpp"
#include "diag/range_check.hpp"

namespace detect {

namespace {}  // namespace

void SidebandOptions::validate() const {
  const std::string w = "SidebandOptions";
  if (mesh_harmonics < 1 || mesh_harmonics > 20)
    diag::fail_range(w, "mesh_harmonics", mesh_harmonics, "1..20");
  if (sidebands < 1 || sidebands > 20) diag::fail_range(w, "sidebands", sidebands, "1..20");
  if (search_bins < 0 || search_bins > 20) diag::fail_range(w, "search_bins", search_bins, "0..20");
  if (floor_bins < 3) diag::fail_range(w, "floor_bins", floor_bins, ">= 3");
  if (!(line_threshold_db > 0)) diag::fail_range(w, "line_threshold_db", line_threshold_db, "> 0");
  if (min_lines < 1) diag::fail_range(w, "min_lines", min_lines, ">= 1");
  if (!(margin_db >= 0)) diag::fail_range(w, "margin_db", margin_db, ">= 0");
  if (!(min_sideband_to_mesh_db >= -200 && min_sideband_to_mesh_db <= 0))
    diag::fail_range(w, "min_sideband_to_mesh_db", min_sideband_to_mesh_db, "[-200, 0]");
  if (!(dynamic_range_db > line_threshold_db && dynamic_range_db <= kMaxProminenceDb))
    diag::fail_range(w, "dynamic_range_db", dynamic_range_db, "(line_threshold_db, 300]");
}

SidebandAnalysis analyse_sidebands(const SpectrumView& spectrum, double mesh_hz,
                                   std::span<const ShaftCandidate> shafts,
                                   const SidebandOptions& opt, const SidebandContext& context) {
  opt.validate();
  spectrum.validate("analyse_sidebands");
  if (!(mesh_hz > 0) || !std::isfinite(mesh_hz))
    diag::fail_range("analyse_sidebands", "mesh_hz", mesh_hz, "> 0");
  for (std::size_t i = 0; i < shafts.size(); ++i)
    if (!(shafts[i].frequency_hz > 0) || !std::isfinite(shafts[i].frequency_hz))
      diag::fail_range("analyse_sidebands", "shafts[" + std::to_string(i) + "].frequency_hz",
                       shafts[i].frequency_hz, "> 0");
  for (std::size_t i = 0; i < context.other_mesh_hz.size(); ++i)
    if (!(context.other_mesh_hz[i] > 0) || !std::isfinite(context.other_mesh_hz[i]))
      diag::fail_range("analyse_sidebands", "context.other_mesh_hz[" + std::to_string(i) + "]",
                       context.other_mesh_hz[i], "> 0");

  const auto& f = spectrum.frequency_hz;
  const double df = (f.back() - f.front()) / static_cast<double>(f.size() - 1);
  const double search = opt.search_bins * df;
  const double floor = search + opt.floor_bins * df;
  const double min_floor = precision_floor(spectrum, opt.dynamic_range_db);

  SidebandAnalysis out;
  for (int h = 1; h <= opt.mesh_harmonics; ++h) {
    out.mesh.push_back(measure_line(spectrum, h * mesh_hz, search, floor, min_floor));
    if (out.mesh.back().valid)
      out.mesh_reference = std::max(out.mesh_reference, out.mesh.back().amplitude);
  }
  const double min_amplitude =
      out.mesh_reference * std::pow(10.0, opt.min_sideband_to_mesh_db / 20);

  // Criterion (c): the other meshes' harmonics and the combination tones, n1 f_mesh + n2 f_other.
  const int n_max = opt.mesh_harmonics + 1;
  const double shared_hz = 2 * search + df;
  auto is_shared = [&](double f_line) {
    for (double fo : context.other_mesh_hz)
      for (int n1 = 0; n1 <= n_max; ++n1)
        for (int n2 = -n_max; n2 <= n_max; ++n2)
          if (n2 != 0 && std::abs(n1 * mesh_hz + n2 * fo - f_line) <= shared_hz) return true;
    return false;
  };

  for (const ShaftCandidate& c : shafts) {
    ShaftSidebands s;
    bool first_order = false;
    s.name = c.name;
    s.frequency_hz = c.frequency_hz;
    for (int h = 1; h <= opt.mesh_harmonics; ++h) {
      for (int k = -opt.sidebands; k <= opt.sidebands; ++k) {
        if (k == 0) continue;
        SidebandLine l;
        l.harmonic = h;
        l.order = k;
        const double expected = h * mesh_hz + k * c.frequency_hz;
        if (expected > 0) {
          l.line = measure_line(spectrum, expected, search, floor, min_floor);
        } else {
          l.line.expected_hz = expected;  // below DC: reported, never detected
        }
        l.shared = is_shared(expected);
        l.detected = l.line.valid && !l.shared && l.line.prominence_db >= opt.line_threshold_db &&
                     l.line.amplitude >= min_amplitude;
        if (l.detected) {
          ++s.detected;
          s.score_db += l.line.prominence_db;
          first_order |= std::abs(k) == 1;
        }
        s.lines.push_back(l);
      }
    }
    s.passes = s.detected >= opt.min_lines && (first_order || !opt.require_first_order);
    out.shafts.push_back(std::move(s));
  }

  int best = -1;
  for (int i = 0; i < static_cast<int>(out.shafts.size()); ++i)
    if (out.shafts[i].passes && (best < 0 || out.shafts[i].score_db > out.shafts[best].score_db))
      best = i;
  if (best < 0) return out;
  for (int i = 0; i < static_cast<int>(out.shafts.size()); ++i) {
    if (i != best && out.shafts[i].passes &&
        out.shafts[best].score_db - out.shafts[i].score_db < opt.margin_db) {
      out.status = SidebandStatus::kAmbiguous;
      return out;
    }
  }
  out.status = SidebandStatus::kPointed;
  out.pointed = best;
  return out;
}

}  // namespace detect
