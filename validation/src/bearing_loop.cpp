#include "validate/bearing_loop.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <random>
#include <sstream>

#include "diag/error.hpp"
#include "diag/gearbox/bearing_rates.hpp"
#include "diag/units.hpp"

namespace validate {

namespace {

constexpr const char* kWhere = "bearing loop";
constexpr double kInterference = 2.0;  // shaft-order and mesh amplitude, in units of A

diag::BearingSpec skf6205() { return diag::skf6205("drive_end", "input"); }

// What the detector said, in the loop's terms.
std::string answer_of(const detect::BearingDiagnosis& d) {
  if (!d.findings.empty()) return std::string(diag::to_string(d.findings.front().fault));
  for (const auto& s : d.bearings)
    if (s.note == "cage") return "cage_note";
  return "";
}

Outcome judge(sim::BearingFaultKind truth, const std::string& answer) {
  using K = sim::BearingFaultKind;
  const bool finding = !answer.empty() && answer != "cage_note";
  switch (truth) {
    case K::kNone:
      return finding ? Outcome::kWrong : Outcome::kRight;
    case K::kCage:
      return finding ? Outcome::kWrong : answer == "cage_note" ? Outcome::kRight : Outcome::kSilent;
    default:
      if (!finding) return Outcome::kSilent;
      return answer == sim::to_string(truth) ? Outcome::kRight : Outcome::kWrong;
  }
}

void add(OutcomeCount& c, Outcome o) {
  (o == Outcome::kRight ? c.right : o == Outcome::kSilent ? c.silent : c.wrong) += 1;
}

}  // namespace

const char* to_string(Outcome o) {
  switch (o) {
    case Outcome::kRight:
      return "right";
    case Outcome::kSilent:
      return "silent";
    case Outcome::kWrong:
      return "wrong";
  }
  return "?";
}

void BearingLoopOptions::validate() const {
  diag::require(!classes.empty(), kWhere, "classes", "none given");
  diag::require(!shaft_hz.empty(), kWhere, "shaft_hz", "none given");
  for (double f : shaft_hz) diag::require(f > 0 && std::isfinite(f), kWhere, "shaft_hz", "> 0");
  diag::require(!sizes.empty(), kWhere, "sizes", "none given");
  for (double a : sizes) diag::require(a > 0 && std::isfinite(a), kWhere, "sizes", "> 0");
  diag::require(!snr_db.empty(), kWhere, "snr_db", "none given");
  diag::require(seeds >= 1, kWhere, "seeds", "must be >= 1");
  diag::require(fs_hz > 0 && std::isfinite(fs_hz), kWhere, "fs_hz", "must be finite and > 0");
  diag::require(duration_s > 0, kWhere, "duration_s", "must be > 0");
  detector.validate();
}

BearingLoopReport run_bearing_loop(const BearingLoopOptions& opt) {
  opt.validate();
  const diag::BearingSpec bearing = skf6205();
  BearingLoopReport r;
  r.classes = opt.classes;
  r.snr_db = opt.snr_db;
  r.by_class.assign(opt.classes.size(), {});
  r.by_class_snr.assign(opt.classes.size(), std::vector<OutcomeCount>(opt.snr_db.size()));
  for (std::size_t ci = 0; ci < opt.classes.size(); ++ci) {
    for (double shaft : opt.shaft_hz) {
      for (double size : opt.sizes) {
        for (std::size_t si = 0; si < opt.snr_db.size(); ++si) {
          for (int k = 0; k < opt.seeds; ++k) {
            const std::uint64_t seed = opt.first_seed + static_cast<std::uint64_t>(k);
            // Nuisance parameters from a stream of their own, distinct per grid point.
            std::seed_seq seq{
                static_cast<std::uint64_t>(opt.classes[ci]),
                static_cast<std::uint64_t>(std::llround(opt.snr_db[si] * 1000) + 1000000),
                static_cast<std::uint64_t>(std::llround(shaft * 1000)),
                static_cast<std::uint64_t>(std::llround(size * 1000)), seed};
            std::mt19937_64 rng(seq);
            auto uni = [&](double lo, double hi) {
              return std::uniform_real_distribution<double>(lo, hi)(rng);
            };
            sim::BearingSignalOptions so;
            so.fs_hz = opt.fs_hz;
            so.duration_s = opt.duration_s;
            so.shaft_hz = shaft;
            so.fault = opt.classes[ci];
            so.impact_amplitude = size;
            so.snr_db = opt.snr_db[si];
            so.mean_slip = uni(0.0, 0.01);
            so.jitter = uni(0.002, 0.01);
            so.resonance_hz = std::min(uni(2000.0, 4500.0), 0.4 * opt.fs_hz);
            so.damping_ratio = uni(0.03, 0.08);
            so.inner_strike_gain = uni(0.3, 0.8);
            so.ball_track_probability = uni(0.6, 1.0);
            so.shaft_amplitude = kInterference;
            so.mesh_hz = 27.3 * shaft;
            so.mesh_amplitude = kInterference;
            so.seed = rng();
            const sim::BearingSignal sig = sim::simulate_bearing_signal(bearing, so);
            BearingCase c;
            c.truth = so.fault;
            c.shaft_hz = shaft;
            c.size = size;
            c.snr_db = so.snr_db;
            c.seed = seed;
            const detect::BearingDiagnosis d = detect::diagnose_bearings_from_signal(
                sig.signal, shaft, std::span(&bearing, 1), opt.detector);
            c.answer = answer_of(d);
            c.outcome = judge(c.truth, c.answer);
            add(r.by_class[ci], c.outcome);
            add(r.by_class_snr[ci][si], c.outcome);
            r.cases.push_back(std::move(c));
            if (opt.on_case_done) opt.on_case_done();
          }
        }
      }
    }
  }
  return r;
}

std::string format_report(const BearingLoopReport& r) {
  std::ostringstream o;
  for (const BearingCase& c : r.cases) {
    if (c.outcome != Outcome::kWrong) continue;
    o << "wrong: " << sim::to_string(c.truth) << " at " << c.shaft_hz << " Hz, size " << c.size
      << ", SNR " << c.snr_db << " dB, seed " << c.seed << " -> "
      << (c.answer.empty() ? "nothing" : c.answer) << "\n";
  }
  o << "\nright / silent / wrong by class and SNR (fault power over noise power)\n\n| class |";
  for (double s : r.snr_db) o << " " << s << " dB |";
  o << " all |\n|---|";
  for (std::size_t i = 0; i <= r.snr_db.size(); ++i) o << "---|";
  o << "\n";
  auto cell = [&](const OutcomeCount& c) {
    o << " " << c.right << " / " << c.silent << " / " << c.wrong << " |";
  };
  for (std::size_t ci = 0; ci < r.classes.size(); ++ci) {
    o << "| "
      << (r.classes[ci] == sim::BearingFaultKind::kNone ? "healthy" : sim::to_string(r.classes[ci]))
      << " |";
    for (const OutcomeCount& c : r.by_class_snr[ci]) cell(c);
    cell(r.by_class[ci]);
    o << "\n";
  }
  return o.str();
}

}  // namespace validate
