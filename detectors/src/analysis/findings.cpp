// analyze's findings: the damaged-shaft locator's stage, and the fusion of every source of
// evidence into one list of Finding (detect/finding.hpp; kind "gear_damage", "bearing"; faults in
// the one vocabulary of diag/faults/fault_kind.hpp), and the sideband vote, reported as a note
// (stages.hpp).
#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "detect/bearing/bearing_diagnosis.hpp"
#include "detect/gear/gear_damage.hpp"
#include "diag/error.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

namespace {

// P(X >= k) for X ~ Binomial(n, p).
double binomial_tail(int n, int k, double p) {
  double tail = 0;
  for (int i = k; i <= n; ++i) {
    tail += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) +
                     i * std::log(p) + (n - i) * std::log1p(-p));
  }
  return std::min(1.0, tail);
}

// The most voted key and its count; a count of 0 when there is no vote or a tie at the top.
template <class Key>
std::pair<Key, int> plurality(const std::map<Key, int>& votes) {
  Key winner{};
  int top = 0, second = 0;
  for (const auto& [key, v] : votes) {
    if (v > top) {
      second = top;
      top = v;
      winner = key;
    } else {
      second = std::max(second, v);
    }
  }
  return {winner, top == second ? 0 : top};
}

// The locator's findings, said with the source of the shaft angles.
void gear_damage_findings(AnalysisResult& r) {
  if (r.gear_damage) {
    for (const Finding& g : r.gear_damage->findings) {
      Finding f = g;  // kind "gear_damage", fault tooth_damage, the locator's evidence
      f.note =
          "a localised fault once per revolution of " + g.shaft + " (TSA per shaft, " +
          r.gear_damage->status + "): " + g.note +
          (r.gear_damage_angles == "nominal" ? " (shaft angles from the nominal speed: no tacho)"
           : r.gear_damage_angles == "vibration"
               ? " (shaft angles from the vibration's mesh line: no tacho)"
               : "");
      r.findings.push_back(std::move(f));
    }
  }
}

// Sideband families: a vote over channels, reported as a note, never as a finding. Shaft-rate
// sidebands around a mesh are what a local defect or an eccentricity gives, but also what every
// healthy gear with ordinary manufacturing errors gives: measured (docs/validation.md, "The
// sideband vote is not a finding"), healthy gears of ISO 1328 grades 5-7 with and without 8 um
// runout drew a vote that passed the quorum below on 57 of 57 recordings (three gearboxes, four
// seeds; the pitch errors' sidebands stand 20-30 dB above the -50 dB line gate), and a 1.2 mm chip
// or a 1.5 mm root crack changed the vote's outcome in 7 of 54 recordings, in no consistent
// direction. A claim that fires on every healthy gearbox is no evidence of damage; the
// damaged-shaft locator (gear_damage) and the baseline comparisons are the detectors.
void sideband_vote_notes(const AnalysisContext& ctx, AnalysisResult& r) {
  for (std::size_t j = 0; j < r.meshes.size(); ++j) {
    std::map<std::string, int> votes;
    std::map<std::string, std::pair<double, std::string>> best;  // score, channel
    std::map<std::string, double> best_mean_db;  // the best channel's mean line prominence
    int analysed = 0;
    for (const auto& c : r.channels) {
      if (!c.sensor || j >= c.meshes.size()) continue;
      const SidebandAnalysis& sb = c.meshes[j].sidebands;
      if (sb.mesh.empty() || !sb.mesh.front().valid) continue;
      ++analysed;
      if (sb.status != SidebandStatus::kPointed) continue;
      const ShaftSidebands& w = sb.shafts[static_cast<std::size_t>(sb.pointed)];
      ++votes[w.name];
      if (w.score_db > best[w.name].first) {
        best[w.name] = {w.score_db, c.name};
        best_mean_db[w.name] = w.score_db / std::max(1, w.detected);
      }
    }
    const auto [winner, top] = plurality(votes);
    if (top == 0) continue;
    // A quorum: `top` channels of `analysed` pointing at one shaft must be unlikely for
    // channels that point at random with probability kFalsePointing each (binomial tail <=
    // kQuorumP): 1 of 2 passes, 2 of 28 does not, 4 of 28 does.
    constexpr double kFalsePointing = 0.05, kQuorumP = 0.1;
    if (binomial_tail(analysed, top, kFalsePointing) > kQuorumP) {
      r.notes.push_back("sidebands of mesh " + r.meshes[j].name + " point at " + winner +
                        " in only " + std::to_string(top) + " of " + std::to_string(analysed) +
                        " channels");
      continue;
    }
    std::string gear = winner;
    const diag::Mesh& m = ctx.gb->meshes()[j];
    for (int g : {m.driver, m.driven}) {
      if (ctx.gb->shafts()[static_cast<std::size_t>(ctx.gb->shaft_of_gear(g))].name == winner)
        gear = ctx.gb->gears()[static_cast<std::size_t>(g)].name;
    }
    // The mean prominence of the best channel's detected lines; at the detector's cap the
    // spectrum has no noise floor (a noise-free simulation): said so, not a number.
    const double mean_db = best_mean_db[winner];
    const std::string prominence = mean_db >= ctx.opt.sidebands.dynamic_range_db
                                       ? "at the " + fmt(ctx.opt.sidebands.dynamic_range_db) +
                                             " dB dynamic-range cap: no noise floor"
                                       : fmt(mean_db, 3) + " dB over the local floor on average";
    const double hz = r.meshes[j].frequency_hz;
    const std::string where =
        ctx.order_domain
            ? " Hz at the mean speed, order " + fmt(hz / ctx.input_hz, 5) + " of the input shaft"
            : " Hz";
    r.notes.push_back("sidebands of mesh " + r.meshes[j].name + " (" + fmt(hz, 5) + where +
                      ") point at " + winner + " in " + std::to_string(top) + " of " +
                      std::to_string(analysed) + " channels (best " + best[winner].second + ", " +
                      prominence + "): " + gear +
                      "'s mesh is modulated at its shaft's rate, as pitch errors and runout of "
                      "healthy gears do too; not a finding (the damaged-shaft locator and the "
                      "baseline comparisons are)");
  }
}

// The shaft harmonic a bearing fault frequency coincides with: k x f_s of a shaft s of the
// gearbox (k = 1 .. kMaxShaftOrder) within kCoincidence of f; "" when none. Why: in a gearbox the
// envelope carries every shaft's harmonics (its gears' pitch errors and runout modulate the
// meshes at the shaft rate), so a bearing line that falls on one of them cannot be told from it
// in one recording (the two-stage 23/41 x 19/53 box with bearings: the counter bearing's BPFO is
// 2.003 x the input speed). The tolerance is the decision's own: the contact rates slip up to
// 1 % below the kinematic ones.
constexpr int kMaxShaftOrder = 20;
constexpr double kCoincidence = 0.01;

struct ShaftHarmonic {
  std::string text;  // "2 x the input shaft's speed (66.667 Hz)"; empty: none
  int order = 0;
  double offset = 0;  // |f - k f_s| / f
};

ShaftHarmonic shaft_harmonic_at(const AnalysisContext& ctx, double f_hz) {
  ShaftHarmonic out;
  double best = kCoincidence;
  for (std::size_t s = 0; s < ctx.kin.speeds.size() && f_hz > 0; ++s) {
    const double fs = ctx.kin.speeds[s].speed_hz;
    if (!(fs > 0)) continue;
    const auto k = static_cast<int>(std::lround(f_hz / fs));
    if (k < 1 || k > kMaxShaftOrder) continue;
    const double rel = std::abs(f_hz - k * fs) / f_hz;
    if (rel <= best) {
      best = rel;
      out = {std::to_string(k) + " x the " + ctx.kin.speeds[s].shaft + " shaft's speed (" +
                 fmt(k * fs, 5) + " Hz)",
             k, rel};
    }
  }
  return out;
}

// Bearings: diagnose_bearings_from_signal' decisions, voted over the channels that see each
// bearing. A decision whose fault frequency lies on a shaft harmonic (shaft_harmonic_at) is
// reported at half its confidence, its note saying so.
void bearing_findings(const AnalysisContext& ctx, AnalysisResult& r) {
  for (const diag::BearingSpec& b : ctx.gb->bearings()) {
    std::map<BearingFault, int> votes;
    std::map<BearingFault, std::pair<double, std::string>> best;
    std::map<BearingFault, double> freq;
    int analysed = 0;
    for (const auto& c : r.channels) {
      for (const auto& ba : c.bearings) {
        if (ba.bearing != b.name || !ba.diagnosed) continue;
        ++analysed;
        const BearingStatus& st = ba.diagnosis;
        if (st.status != BearingDecisionStatus::kFault) continue;
        ++votes[st.fault];
        for (const auto& fam : st.band_decision.families) {
          if (fam.fault != st.fault) continue;
          freq[fam.fault] = fam.fundamental_hz;
          auto& [score, channel] = best.try_emplace(fam.fault, -kInf, "").first->second;
          if (fam.score_db > score) score = fam.score_db, channel = c.name;
        }
      }
    }
    const auto [winner, top] = plurality(votes);
    if (top == 0) continue;
    Finding f;
    f.kind = "bearing";
    f.bearing = b.name;
    f.shaft = b.shaft;
    f.fault = fault_kind(winner);
    f.frequency_hz = freq[winner];
    f.channel = best[winner].second;
    f.confidence = 0.3 + 0.4 * top / analysed;
    f.evidence = {{"channels_pointing", top},
                  {"channels_analysed", analysed},
                  {"score_db", best[winner].first}};
    f.note = std::string(to_string(winner)) + " fault lines at " + fmt(f.frequency_hz, 5) +
             " Hz and harmonics in the prewhitened squared envelope spectrum (kurtogram band "
             "and whole band agree) of " +
             std::to_string(top) + " of " + std::to_string(analysed) + " channels (best " +
             f.channel + ", score " + fmt(best[winner].first, 3) + " dB)";
    const ShaftHarmonic harmonic = shaft_harmonic_at(ctx, f.frequency_hz);
    if (!harmonic.text.empty()) {
      f.confidence *= 0.5;
      f.set_evidence("shaft_harmonic_order", harmonic.order);
      f.note += "; that frequency lies within " + fmt(100 * harmonic.offset, 2) + " % of " +
                harmonic.text +
                ", where the gears' shaft-rate modulation puts a line too: one recording cannot "
                "tell the bearing from the shaft (a history against the machine's healthy "
                "recordings can)";
    }
    r.findings.push_back(std::move(f));
  }
}

}  // namespace

void gear_damage_stage(const AnalysisContext& ctx, AnalysisResult& r) {
  bool has_gear_shaft = false;
  for (const diag::Shaft& sh : ctx.gb->shafts()) has_gear_shaft |= !sh.gears.empty();
  if (has_gear_shaft) {
    // The revolutions are the ones analyze's TSA used, corrected once (refine_tsa_pulses): the
    // locator does not smooth or correct them again.
    GearDamageOptions o = ctx.opt.gear_damage;
    o.pulse_fit_degree = 0;
    o.refine_speed = false;
    try {
      r.gear_damage = locate_gear_damage(ctx.rec, *ctx.gb, ctx.kin.tsa_reference,
                                         ctx.kin.tsa_reference_pulses, o);
      r.gear_damage_angles = ctx.kin.speed.source;
    } catch (const diag::InputError& e) {
      r.notes.push_back(std::string("damaged-shaft location skipped: ") + e.what());
    }
  }
}

void fuse_findings(const AnalysisContext& ctx, AnalysisResult& r) {
  gear_damage_findings(r);
  sideband_vote_notes(ctx, r);
  bearing_findings(ctx, r);
  std::stable_sort(r.findings.begin(), r.findings.end(),
                   [](const Finding& a, const Finding& b) { return a.confidence > b.confidence; });
}

}  // namespace detect::analysis_stages
