#include "validate/attribution_loop.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "diag/error.hpp"
#include "diag/units.hpp"

namespace validate {

using diag::units::deg_to_rad;
using diag::units::kTwoPi;
using nlohmann::json;

namespace {

double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

struct TruthDefect {
  std::string gear, shaft;
  double size_output_rad = 0, first_event_input_rad = 0, period_input_rev = 0;
};

struct Case {
  diag::Gearbox gb;
  std::vector<TruthDefect> truth;
  double step_rad = 0;
};

// Path gears on `shaft`.
std::vector<int> path_gears_on(const diag::Gearbox& gb, int shaft) {
  std::vector<int> out;
  for (int g : gb.shafts()[shaft].gears) {
    if (gb.on_power_path(g)) out.push_back(g);
  }
  return out;
}

// Builds one random case on gb: n defects on power-path gears, optionally two on one shaft, or
// (overlap, two defects) one on the input shaft and one on the next path shaft with one event of
// the second inside the pulse of one of the first's.
Case make_case(const diag::Gearbox& base, int n_defects, bool same_shaft, bool overlap,
               const AttributionLoopOptions& opt, std::mt19937_64& rng) {
  std::vector<int> path_gears;
  for (std::size_t g = 0; g < base.gears().size(); ++g) {
    if (base.on_power_path(static_cast<int>(g))) path_gears.push_back(static_cast<int>(g));
  }
  const double u_total = base.total_ratio();
  json desc = json::parse(base.description_json());
  desc["defects"] = json::array();
  Case c{base, {}, 0};
  std::vector<std::pair<int, double>> placed;  // (shaft, first event in input angle)
  const double log_lo = std::log(opt.min_size_output_rad),
               log_hi = std::log(opt.max_size_output_rad);
  for (int k = 0; k < n_defects; ++k) {
    for (int attempt = 0; attempt < 100; ++attempt) {
      int g = path_gears[rng() % path_gears.size()];
      if (same_shaft && k == 1) {
        const auto on_shaft =
            path_gears_on(base, base.shaft_of_gear(base.gear_index(c.truth[0].gear)));
        g = on_shaft[rng() % on_shaft.size()];
      }
      if (overlap) {
        const int shaft =
            k == 0 ? base.input_shaft() : base.shaft_of_gear(base.power_path().front().down_gear);
        const auto on_shaft = path_gears_on(base, shaft);
        g = on_shaft[rng() % on_shaft.size()];
      }
      const int shaft = base.shaft_of_gear(g);
      const diag::Gear gear(base.gears()[g].spec);
      const double u_i = base.ratio_to_output(g);
      double size_out = std::exp(log_lo + (log_hi - log_lo) * uniform(rng));
      // The model needs the loss within half a pitch of the gear.
      size_out = std::min(size_out, 0.45 * gear.angular_pitch_rad() / u_i);
      double phase = kTwoPi * uniform(rng);
      const double period = base.recurrence_period_input_rev(g);
      if (overlap && k == 1) {
        // A pulse spans 2 size_out u_total of input angle (hold and recovery). Put this defect's
        // event at the first defect's recurrence 1..4 plus an offset within the shorter pulse.
        const TruthDefect& a = c.truth[0];
        const double width = 2.0 * u_total * std::min(size_out, a.size_output_rad);
        const double target = a.first_event_input_rad +
                              static_cast<double>(1 + rng() % 4) * kTwoPi * a.period_input_rev +
                              (2.0 * uniform(rng) - 1.0) * width;
        const double p = kTwoPi * period;
        phase = (target - std::floor(target / p) * p) / period;
      }
      const double first = phase * period;
      // Two defects on one shaft must be apart by more than their pulses and the matcher's
      // position tolerance, else they are one event by construction.
      bool clash = false;
      for (const auto& [s, f] : placed) {
        if (s != shaft) continue;
        const double p = kTwoPi * period;
        double d = std::fmod(std::abs(f - first), p);
        d = std::min(d, p - d);
        clash |= d < std::max(deg_to_rad(10.0), 8.0 * opt.max_size_output_rad * u_total);
      }
      if (clash) continue;
      placed.emplace_back(shaft, first);
      desc["defects"].push_back({{"gear", base.gears()[g].name},
                                 {"size_deg", diag::units::rad_to_deg(size_out * u_i)},
                                 {"phase_deg", diag::units::rad_to_deg(phase)}});
      c.truth.push_back({base.gears()[g].name, base.shafts()[shaft].name, size_out, first, period});
      break;
    }
  }
  c.gb = diag::parse_gearbox(desc, "validation case");
  double min_size = opt.max_size_output_rad;
  for (const auto& t : c.truth) min_size = std::min(min_size, t.size_output_rad);
  // 20+ steps across the smallest pulse, which spans 2 size_out u_total of input angle.
  c.step_rad = std::min(1e-3, min_size * u_total / 12.0);
  return c;
}

// Defects of which fewer than three recurrences within the record are clear of every other
// defect's pulse (2 size_out u_total of input angle, plus `margin`): in the seed's model an event
// inside another's pulse leaves no trace of its own (the output stays stopped while either gap
// is taken up), so such a defect cannot be seen, e.g. a counter-shaft period that is a whole
// multiple of the input's with the events placed together.
int hidden_defects(const Case& c, double record_rad, double margin) {
  const double u_total = c.gb.total_ratio();
  auto pulses = [&](const TruthDefect& t) {
    std::vector<std::pair<double, double>> out;
    const double p = kTwoPi * t.period_input_rev, w = 2.0 * t.size_output_rad * u_total;
    for (double q = t.first_event_input_rad; q <= record_rad; q += p) out.emplace_back(q, q + w);
    return out;
  };
  int hidden = 0;
  for (std::size_t i = 0; i < c.truth.size(); ++i) {
    int clear = 0;
    for (const auto& [a, b] : pulses(c.truth[i])) {
      bool overlaps = false;
      for (std::size_t j = 0; j < c.truth.size(); ++j) {
        if (j == i) continue;
        for (const auto& [qa, qb] : pulses(c.truth[j]))
          overlaps |= qa <= b + margin && qb >= a - margin;
      }
      clear += !overlaps;
    }
    hidden += clear < 3;
  }
  return hidden;
}

}  // namespace

diag::Gearbox random_three_shaft(std::mt19937_64& rng, bool undercut_pinion) {
  auto teeth = [&](int lo, int hi) { return lo + static_cast<int>(rng() % (hi - lo + 1)); };
  // A 1:1 mesh would give two shafts the same period, which no recurrence analysis can tell
  // apart (the finding then names both shafts); such boxes are left out of the random set.
  for (int attempt = 0;; ++attempt) {
    const int z1 = undercut_pinion ? teeth(14, 17) : teeth(18, 40), z3 = teeth(18, 40);
    int z2 = z1, z4 = z3;
    while (z2 == z1) z2 = teeth(18, 60);
    while (z4 == z3) z4 = teeth(18, 60);
    json d = {
        {"name", "random-three-shaft"},
        {"shafts", {{{"name", "input"}}, {{"name", "counter"}}, {{"name", "output"}}}},
        {"gears",
         {{{"name", "z1"}, {"shaft", "input"}, {"teeth", z1}, {"module_mm", 3.0}},
          {{"name", "z2"}, {"shaft", "counter"}, {"teeth", z2}, {"module_mm", 3.0}},
          {{"name", "z3"}, {"shaft", "counter"}, {"teeth", z3}, {"module_mm", 3.0}},
          {{"name", "z4"}, {"shaft", "output"}, {"teeth", z4}, {"module_mm", 3.0}}}},
        {"meshes", {{{"driver", "z1"}, {"driven", "z2"}}, {{"driver", "z3"}, {"driven", "z4"}}}},
        {"input", {{"shaft", "input"}, {"speed_rpm", 30.0}, {"torque_nm", 50.0}}}};
    try {
      return diag::parse_gearbox(d, "random three-shaft gearbox");
    } catch (const diag::InputError&) {
      // An undercut pinion whose contact ratio falls below 1 with this wheel: draw again.
      if (attempt > 100) throw;
    }
  }
}

LoopReport run_attribution_loop(const diag::Gearbox& gb_in, const AttributionLoopOptions& opt) {
  std::mt19937_64 rng(opt.seed);
  LoopReport rep;
  const double wsum = opt.weight[0] + opt.weight[1] + opt.weight[2] + opt.weight[3];
  for (int i = 0; i < opt.cases; ++i) {
    const bool undercut = opt.random_gearbox && uniform(rng) < opt.undercut_share;
    const diag::Gearbox base = opt.random_gearbox ? random_three_shaft(rng, undercut) : gb_in;
    double w = uniform(rng) * wsum;
    int n_def = 0;
    while (n_def < 3 && w >= opt.weight[n_def]) w -= opt.weight[n_def++];
    const bool same_shaft = n_def >= 2 && uniform(rng) < opt.same_shaft_share;
    const bool overlap =
        n_def == 2 && !same_shaft && !base.power_path().empty() && uniform(rng) < opt.overlap_share;
    const Case c = make_case(base, n_def, same_shaft, overlap, opt, rng);
    bool has_undercut = false;
    for (const auto& g : base.gears()) has_undercut |= diag::Gear(g.spec).undercut();
    static const char* const kDefectClass[] = {"healthy", "one defect", "two defects",
                                               "three defects"};
    std::string cls = overlap ? "two overlapping" : kDefectClass[n_def];
    if (has_undercut) cls += ", undercut pinion";
    ClassReport& cr = rep.classes[cls];
    ++cr.cases;
    cr.defects += n_def;

    sim::KinematicOptions so;
    so.step_rad = c.step_rad;
    so.runout_output_rad = opt.runout_output_rad;
    so.mesh_te_output_rad = opt.mesh_te_output_rad;
    so.noise_output_rad = opt.noise_output_rad;
    so.encoder_counts_per_rev = opt.encoder_counts_per_rev;
    so.seed = rng();
    const sim::KinematicResult r = sim::simulate_kinematic(c.gb, so);
    const detect::AttributionResult a =
        detect::attribute_defects(r.input_angle_rad, r.output_angle_rad, c.gb, opt.attribution);
    ++rep.cases;

    // Match findings to truth: same shaft, first event at the same phase of the period.
    const double pos_tol = std::max(deg_to_rad(2.0), 10.0 * c.step_rad);
    std::vector<char> used(a.findings.size(), 0);
    int matched = 0;
    for (const auto& t : c.truth) {
      for (std::size_t f = 0; f < a.findings.size(); ++f) {
        const auto& fd = a.findings[f];
        if (used[f] || fd.shaft.find(t.shaft) == std::string::npos) continue;
        const double p = kTwoPi * t.period_input_rev;
        double d = std::fmod(
            std::abs(fd.evidence_value("first_event_input_rad") - t.first_event_input_rad), p);
        d = std::min(d, p - d);
        if (d > pos_tol) continue;
        used[f] = 1;
        ++matched;
        const double err =
            std::abs(fd.evidence_value("size_output_rad") - t.size_output_rad) / t.size_output_rad;
        ++rep.sizes_checked;
        ++cr.sizes_checked;
        if (err <= opt.size_tolerance) {
          ++rep.sizes_within_tolerance;
          ++cr.sizes_within_tolerance;
        }
        rep.worst_size_error = std::max(rep.worst_size_error, err);
        cr.worst_size_error = std::max(cr.worst_size_error, err);
        break;
      }
    }
    std::set<std::string> truth_shafts;
    for (const auto& t : c.truth) truth_shafts.insert(t.shaft);
    for (const auto& fd : a.findings) {
      bool ok = false;
      for (const auto& s : truth_shafts) ok |= fd.shaft.find(s) != std::string::npos;
      if (!ok) {
        ++rep.wrong_findings;
        ++cr.wrong_findings;
      }
    }
    cr.attributed += matched;
    const int hidden =
        hidden_defects(c, r.input_angle_rad.back() - r.input_angle_rad.front(), pos_tol);
    cr.hidden += hidden;
    if (n_def == 2) rep.two_defects_hidden += hidden;
    if (a.multiplicity) ++cr.multiplicity_flagged;

    switch (n_def) {
      case 0:
        ++rep.healthy_total;
        if (a.findings.empty() && !a.multiplicity) ++rep.healthy_clean;
        break;
      case 1: {
        ++rep.single_total;
        std::string got;
        if (a.multiplicity)
          got = "multiplicity";
        else if (a.findings.empty())
          got = "none";
        else if (a.findings.size() > 1)
          got = "several";
        else
          got = a.findings[0].shaft;
        ++rep.confusion[c.truth[0].shaft][got];
        if (got == c.truth[0].shaft && matched == 1) ++rep.single_correct;
        break;
      }
      case 2:
        rep.two_defects_total += 2;
        rep.two_defects_attributed += matched;
        break;
      default:
        rep.three_defects_total += 3;
        rep.three_defects_attributed += matched;
        if (a.multiplicity) ++rep.three_multiplicity_flagged;
        break;
    }
    if (opt.on_case_done) opt.on_case_done();
  }
  return rep;
}

std::string format_report(const LoopReport& r) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(1);
  auto pct = [](int a, int b) { return b > 0 ? 100.0 * a / b : 100.0; };
  o << "closed loop: " << r.cases << " cases\n";
  o << "single defect, attributed shaft (rows: truth):\n";
  std::set<std::string> cols;
  for (const auto& [t, row] : r.confusion) {
    for (const auto& [c, n] : row) cols.insert(c);
  }
  o << "  " << std::setw(14) << std::left << "truth \\ found";
  for (const auto& c : cols) o << std::setw(14) << c;
  o << "\n";
  for (const auto& [t, row] : r.confusion) {
    o << "  " << std::setw(14) << t;
    for (const auto& c : cols) {
      const auto it = row.find(c);
      o << std::setw(14) << (it == row.end() ? 0 : it->second);
    }
    o << "\n";
  }
  o << std::right;
  o << "  single defects on the right shaft:    " << r.single_correct << "/" << r.single_total
    << " (" << pct(r.single_correct, r.single_total) << " %)\n";
  o << "  defects attributed, two-defect cases: " << r.two_defects_attributed << "/"
    << r.two_defects_total << " (" << pct(r.two_defects_attributed, r.two_defects_total) << " %; "
    << r.two_defects_hidden << " hidden inside the other's pulses)\n";
  o << "  defects attributed, three-defect cases: " << r.three_defects_attributed << "/"
    << r.three_defects_total << " (" << pct(r.three_defects_attributed, r.three_defects_total)
    << " %), multiplicity flagged in " << r.three_multiplicity_flagged << " case(s)\n";
  o << "  healthy cases with no finding:        " << r.healthy_clean << "/" << r.healthy_total
    << "\n";
  o << "  sizes within tolerance:               " << r.sizes_within_tolerance << "/"
    << r.sizes_checked << " (worst error " << 100.0 * r.worst_size_error << " %)\n";
  o << "  findings on a shaft without a defect: " << r.wrong_findings << "\n";
  o << "by class:\n";
  o << "  class                              cases  attributed  hidden    sizes ok   worst size  "
       "multiplicity  wrong\n";
  for (const auto& [name, c] : r.classes) {
    o << "  " << std::left << std::setw(33) << name << std::right << std::setw(7) << c.cases
      << std::setw(8) << c.attributed << "/" << std::left << std::setw(4) << c.defects << std::right
      << std::setw(6) << c.hidden << std::setw(10) << c.sizes_within_tolerance << "/" << std::left
      << std::setw(4) << c.sizes_checked << std::right << std::setw(10)
      << 100.0 * c.worst_size_error << " %" << std::setw(14) << c.multiplicity_flagged
      << std::setw(7) << c.wrong_findings << "\n";
  }
  return o.str();
}

double smallest_reliable_size(const diag::Gearbox& gb, AttributionLoopOptions opt,
                              int cases_per_size, double required_share,
                              std::vector<std::pair<double, double>>* ladder) {
  opt.cases = cases_per_size;
  opt.weight[0] = 0;
  opt.weight[1] = 1;
  opt.weight[2] = opt.weight[3] = 0;
  double best = 0;
  for (double deg : kSizeLadderDeg) {
    opt.min_size_output_rad = opt.max_size_output_rad = deg_to_rad(deg);
    const LoopReport r = run_attribution_loop(gb, opt);
    const double share = r.single_total > 0 ? std::min(r.single_correct, r.sizes_within_tolerance) /
                                                  double(r.single_total)
                                            : 0.0;
    if (ladder) ladder->emplace_back(deg_to_rad(deg), share);
    if (share < required_share) break;
    best = deg_to_rad(deg);
  }
  return best;
}

}  // namespace validate
