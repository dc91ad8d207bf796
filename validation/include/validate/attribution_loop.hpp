// Closed-loop validation of defect attribution: random defects are simulated with the kinematic
// simulator (seed 003) and attributed by the period matcher; the findings are compared with the
// truth. This is the one place besides the tests where simulator and detectors meet: it backs
// both the CI test and `geardiag validate --attribution`, so users can run the same loop on their
// own gearbox.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "detect/attribution/period_matcher.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "sim/kinematic/sporadic_defects.hpp"

namespace validate {

struct AttributionLoopOptions {
  int cases = 200;         // random cases, >= 1
  std::uint64_t seed = 1;  // the whole loop is reproducible from this seed
  double min_size_output_rad = 0.1 * 0.017453292519943295;  // smallest defect at the output
  double max_size_output_rad = 1.0 * 0.017453292519943295;  // largest (log-uniform between)
  // Share of cases with 0, 1, 2, 3 defects (weights, normalised).
  double weight[4] = {0.15, 0.45, 0.30, 0.10};
  double same_shaft_share = 0.3;  // of multi-defect cases: put two defects on one shaft
  // Of the other two-defect cases: one defect on the input shaft and one on the next shaft of the
  // power path, placed so that one of their events overlaps the other's (within a pulse width).
  double overlap_share = 0.3;
  double size_tolerance = 0.15;  // relative size error that counts as right
  bool random_gearbox = false;   // draw tooth counts per case (a three-shaft box)
  // With random_gearbox: share of boxes whose input pinion has 14..17 teeth and no profile shift
  // (undercut; accepted with a warning).
  double undercut_share = 0.0;
  // Measurement effects of the simulated rig (see sim::KinematicOptions).
  double runout_output_rad = 0.05 * 0.017453292519943295;
  double mesh_te_output_rad = 0.005 * 0.017453292519943295;
  double noise_output_rad = 0.002 * 0.017453292519943295;
  std::int64_t encoder_counts_per_rev = 1 << 16;
  detect::AttributionOptions attribution;
  // Called after each case, e.g. to show progress; empty: nothing. The results do not depend
  // on it.
  std::function<void()> on_case_done;
};

// One class of cases: what was simulated (healthy, one defect, two, two overlapping, three; on a
// gearbox with an undercut pinion or not).
struct ClassReport {
  int cases = 0;
  int defects = 0, attributed = 0;  // defects simulated, and matched by a finding (shaft, phase)
  // Defects with fewer than three recurrences clear of another defect's pulse: not separately
  // observable (their events lie inside another's), so not expected to be attributed.
  int hidden = 0;
  int sizes_checked = 0, sizes_within_tolerance = 0;
  int multiplicity_flagged = 0;  // cases
  int wrong_findings = 0;        // findings on a shaft that carries no defect
  double worst_size_error = 0;   // relative
};

struct LoopReport {
  int cases = 0;
  // confusion[truth shaft][attributed shaft or "none"/"multiplicity"]: single-defect cases.
  std::map<std::string, std::map<std::string, int>> confusion;
  int single_total = 0, single_correct = 0;
  int two_defects_total = 0, two_defects_attributed = 0;  // counted per defect
  int two_defects_hidden = 0;  // of two_defects_total: not separately observable (ClassReport)
  int three_defects_total = 0, three_defects_attributed = 0;  // counted per defect
  int three_multiplicity_flagged = 0;                         // cases
  int healthy_total = 0, healthy_clean = 0;                   // no finding, no multiplicity
  int sizes_checked = 0, sizes_within_tolerance = 0;
  int wrong_findings = 0;  // findings on a shaft that carries no defect
  double worst_size_error = 0;
  std::map<std::string, ClassReport> classes;  // by class name (see ClassReport)
};

LoopReport run_attribution_loop(const diag::Gearbox& gb, const AttributionLoopOptions& options);

// A random three-shaft gearbox (z1 -> z2 on input/counter, z3 -> z4 on counter/output) with
// tooth counts 18..60, for tests over many topologies; with undercut_pinion, z1 is 14..17 at no
// profile shift.
diag::Gearbox random_three_shaft(std::mt19937_64& rng, bool undercut_pinion = false);

// The table printed by tests and by `geardiag validate --attribution`.
std::string format_report(const LoopReport& r);

// The rungs of smallest_reliable_size's ladder: defect sizes at the output [deg], largest first.
inline constexpr double kSizeLadderDeg[] = {1.0,  0.5,  0.2,   0.1,   0.05,
                                            0.02, 0.01, 0.005, 0.002, 0.001};

// Smallest defect size at the output, from a geometric ladder (kSizeLadderDeg), at which at least
// `required_share` of single-defect cases are attributed to the right shaft with the size within
// tolerance; the ladder stops at the first rung that fails. Returns 0 when no rung qualifies.
double smallest_reliable_size(const diag::Gearbox& gb, AttributionLoopOptions options,
                              int cases_per_size, double required_share,
                              std::vector<std::pair<double, double>>* ladder = nullptr);

}  // namespace validate
