#include "kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "detect/angular/pulse_refine.hpp"
#include "detect/angular/resample.hpp"
#include "detect/angular/speed_estimate.hpp"
#include "detect/angular/tacho.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "stages.hpp"

namespace detect {

namespace {

// Speeds with 6 significant digits.
std::string fmt(double v, int prec = 6) { return analysis_stages::fmt(v, prec); }

// Relative speed range above which a record is reported as non-stationary.
constexpr double kStationaryTolerance = 0.01;

// How far the speed is sought from the nominal one, relative: a nominal speed 10 % off the true
// one (docs/cli/analyze.md) puts the true speed up to 1/0.9 - 1 = 11.1 % from it.
constexpr double kSpeedSearchFraction = 0.125;
// Cycles of the lowest candidate line in one frame of the speed estimate's STFT.
constexpr double kCyclesPerFrame = 40;

void summarise(AnalysisSpeed& sp) {
  if (sp.speed_rpm.empty()) return;
  const auto [lo, hi] = std::minmax_element(sp.speed_rpm.begin(), sp.speed_rpm.end());
  sp.min_rpm = *lo;
  sp.max_rpm = *hi;
  double sum = 0;
  for (double v : sp.speed_rpm) sum += v;
  sp.mean_rpm = sum / static_cast<double>(sp.speed_rpm.size());
  // A speed read from a line's phase is biased in the first and last frames by the demodulation
  // filter's edges (the CWRU outer-race record at a steady 1796 rpm: 1809.6 rpm in the first frame,
  // 1790-1800 in the others): whether the machine is steady is judged on the frames between.
  auto first = sp.speed_rpm.begin();
  auto last = sp.speed_rpm.end();
  if (sp.source == "vibration" && sp.speed_rpm.size() >= 5) ++first, --last;
  const auto [in_lo, in_hi] = std::minmax_element(first, last);
  sp.stationary = (*in_hi - *in_lo) <= kStationaryTolerance * sp.mean_rpm;
}

// Every shaft's once-per-revolution times from the reference shaft's, by the gearbox ratios.
void from_reference(ShaftKinematics& k, const diag::Gearbox& gb, int ref,
                    const std::vector<double>& ref_pulses, double ref_hz,
                    const std::string& source_ref, const std::string& source_other) {
  for (std::size_t b = 0; b < gb.shafts().size(); ++b) {
    const double ratio = gb.shaft_speed_hz(static_cast<int>(b)) / gb.shaft_speed_hz(ref);
    k.speeds[b].speed_hz = ref_hz * ratio;
    k.speeds[b].source = static_cast<int>(b) == ref ? source_ref : source_other;
    k.pulses_s[b] = static_cast<int>(b) == ref ? ref_pulses : scale_pulses(ref_pulses, ratio, 1);
  }
  k.reference_shaft = ref;
}

}  // namespace

std::vector<double> smooth_pulse_times_local_quadratic(const std::vector<double>& pulses_s,
                                                       int half_window) {
  const std::size_t n = pulses_s.size(), w = static_cast<std::size_t>(half_window);
  if (half_window < 1 || n < 2 * w + 1) return pulses_s;
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t lo = std::min(k >= w ? k - w : 0, n - (2 * w + 1));
    // Normal equations of t = a + b u + c u^2 in u = i - k (centred for conditioning).
    double s[5] = {0, 0, 0, 0, 0}, r[3] = {0, 0, 0};
    for (std::size_t i = lo; i < lo + 2 * w + 1; ++i) {
      const double u = static_cast<double>(i) - static_cast<double>(k);
      double p = 1;
      for (int e = 0; e < 5; ++e, p *= u) {
        s[e] += p;
        if (e < 3) r[e] += p * pulses_s[i];
      }
    }
    // a of the 3x3 system [[s0 s1 s2] [s1 s2 s3] [s2 s3 s4]] (a b c) = r, by Cramer's rule.
    auto det3 = [](double a0, double a1, double a2, double b0, double b1, double b2, double c0,
                   double c1, double c2) {
      return a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0);
    };
    const double d = det3(s[0], s[1], s[2], s[1], s[2], s[3], s[2], s[3], s[4]);
    out[k] = det3(r[0], s[1], s[2], r[1], s[2], s[3], r[2], s[3], s[4]) / d;
  }
  return out;
}

namespace {

// The given speed (the description's, --rpm's or the file's) is a starting point: a measured
// mean speed more than 1 % off it (beyond a drift with load) is a warning naming both. The
// measurement is used.
void warn_off_nominal(double measured_hz, double nominal_hz, const std::string& from,
                      std::vector<std::string>& notes) {
  constexpr double kTolerance = 0.01;
  const double off = measured_hz / nominal_hz - 1;
  if (std::abs(off) <= kTolerance) return;
  const std::string how =
      std::abs(off) < 1
          ? fmt(100 * std::abs(off), 2) + " % " + (off > 0 ? "above" : "below") + " the nominal"
          : fmt(measured_hz / nominal_hz, 3) + " times the nominal";
  notes.push_back("warning: the speed measured from " + from + ", " + fmt(measured_hz * 60) +
                  " rpm, is " + how + " " + fmt(nominal_hz * 60) +
                  " rpm: the measured speed is used");
}

}  // namespace

ShaftKinematics shaft_kinematics(const diag::Recording& rec, const diag::Gearbox& gb,
                                 double duration_s, const AnalyzeOptions& opt,
                                 std::vector<std::string>& notes) {
  const std::size_t ns = gb.shafts().size();
  ShaftKinematics k;
  k.speeds.resize(ns);
  k.pulses_s.resize(ns);
  for (std::size_t s = 0; s < ns; ++s) {
    k.speeds[s].shaft = gb.shafts()[s].name;
    k.speeds[s].speed_hz = gb.shaft_speed_hz(static_cast<int>(s));
    k.speeds[s].source = "nominal";
  }
  const int input = gb.input_shaft();
  k.speed.reference_shaft = gb.shafts()[static_cast<std::size_t>(input)].name;
  k.speed.nominal_rpm = gb.shaft_speed_rpm(input);

  // ---- a tacho ----
  for (const diag::Signal& t : rec.tachos) {
    const std::string& named = t.shaft.empty() ? t.location : t.shaft;
    const int s = gb.shaft_index(named);
    if (s < 0) {
      notes.push_back("tacho '" + t.name + "' names no shaft of the gearbox ('" + named +
                      "'): not used");
      continue;
    }
    const int ppr =
        opt.tacho_pulses_per_rev > 0 ? opt.tacho_pulses_per_rev : diag::pulses_per_rev(t);
    TachoOptions to;
    to.pulses_per_rev = ppr;
    const TachoResult tr = tacho_pulses(t.samples, t.fs_hz, to);
    const auto& p = tr.pulse_times_s;
    if (p.size() < static_cast<std::size_t>(2 * ppr) + 1) {
      notes.push_back("tacho '" + t.name + "': " + std::to_string(p.size()) +
                      " pulses, too few for a speed: not used");
      continue;
    }
    // Once per revolution: every ppr-th pulse.
    std::vector<double> once;
    for (std::size_t i = 0; i < p.size(); i += static_cast<std::size_t>(ppr)) once.push_back(p[i]);
    const double f_meas = static_cast<double>(once.size() - 1) / (once.back() - once.front());
    from_reference(k, gb, s, once, f_meas, "tacho", "tacho " + t.name + " x ratio");
    k.speeds[static_cast<std::size_t>(s)].tacho_repairs = static_cast<int>(tr.repairs.size());
    if (!tr.repairs.empty()) {
      notes.push_back("tacho '" + t.name + "': " + std::to_string(tr.repairs.size()) +
                      " pulse repairs");
    }
    k.speed.source = "tacho";
    k.speed.reference_shaft = gb.shafts()[static_cast<std::size_t>(s)].name;
    k.speed.nominal_rpm = gb.shaft_speed_rpm(s);
    k.speed.line = "tacho '" + t.name + "', " + std::to_string(ppr) + " pulse(s)/rev";
    const SpeedProfile prof = speed_profile(once, 1);
    k.speed.time_s = prof.time_s;
    k.speed.speed_rpm = prof.rpm;
    summarise(k.speed);
    notes.push_back("shaft speeds from tacho '" + t.name + "': " + fmt(f_meas * 60) +
                    " rpm mean (nominal " + fmt(gb.shaft_speed_rpm(s)) + " rpm)");
    warn_off_nominal(f_meas, gb.shaft_speed_hz(s), "tacho '" + t.name + "'", notes);
    return k;
  }

  // ---- the vibration ----
  const std::vector<SpeedLine> lines = gearbox_speed_lines(gb, input, 3);
  std::vector<std::span<const double>> channels;
  double fs = 0;
  std::size_t length = 0;
  for (std::size_t i : diag::sensor_channels(rec)) {
    const diag::Signal& s = rec.signals[i];
    if (channels.empty()) fs = s.fs_hz, length = s.samples.size();
    if (s.fs_hz == fs && s.samples.size() == length) channels.push_back(s.samples);
  }
  const double nominal_hz = gb.shaft_speed_hz(input);
  if (!channels.empty() && !lines.empty() && opt.speed_from_vibration) {
    try {
      // A steady machine first (the line chosen on the whole record's average); when no line
      // stands out there (a run-up smears every line over its speed range), the run-up mode: the
      // nominal speed holds at nominal_time_s (default: mid-record, where a linear run-up passes
      // its mean speed), the line chosen there and followed both ways.
      const double record_s = static_cast<double>(length) / fs;
      double lowest_order = lines.front().order;
      for (const SpeedLine& l : lines) lowest_order = std::min(lowest_order, l.order);
      auto attempt = [&](double nominal_time_s, double around_hz) {
        SpeedEstimateOptions so;
        so.search_fraction = kSpeedSearchFraction;
        // A frame bin no wider than 1/kCyclesPerFrame of the lowest candidate line (a shaft
        // harmonic at 30 Hz needs 1.3 s frames where a mesh line at 500 Hz is told in 0.2 s),
        // and at least 8 frames in the record.
        const double lowest_hz = nominal_hz * lowest_order;
        so.frame_s =
            std::clamp(kCyclesPerFrame / lowest_hz, so.frame_s, std::max(so.frame_s, record_s / 8));
        so.hop_s = so.frame_s / 4;
        so.nominal_time_s = nominal_time_s;
        so.require_confirmation = lines.size() > 1;  // `usable` takes no other line
        return estimate_speed(channels, fs, around_hz, lines, so);
      };
      auto usable = [&](const SpeedEstimate& e) {
        return e.status == SpeedStatus::kTracked && (e.confirmations > 0 || lines.size() == 1);
      };
      SpeedEstimate est = attempt(opt.nominal_time_s >= 0 ? opt.nominal_time_s : -1.0, nominal_hz);
      // The lines fit a speed outside the band around the nominal one better than anything in
      // it (the nominal speed far off): searched again around that speed, and used only if the
      // search there finds it too (a line confirmed by another, showing as many lines).
      if (est.status == SpeedStatus::kElsewhere) {
        const double other_hz = est.better_speed_hz;
        const std::string fit = fmt(60 * other_hz) + " rpm (" +
                                std::to_string(est.better_lines_found) + " of " +
                                std::to_string(est.better_lines_counted) + " candidate lines)";
        SpeedEstimate there = attempt(-1.0, other_hz);
        if (usable(there) && there.lines_found + 1 >= est.better_lines_found) {
          notes.push_back("warning: the lines of the vibration fit " + fit +
                          ", not the band around the nominal " + fmt(60 * nominal_hz) +
                          " rpm: the speed is sought around " + fmt(60 * other_hz) + " rpm");
          est = std::move(there);
        } else {
          notes.push_back("warning: the lines of the vibration fit " + fit +
                          " rather than the nominal " + fmt(60 * nominal_hz) +
                          " rpm, but no line is confirmed there: the speed is not measured");
        }
      }
      if (!usable(est) && opt.nominal_time_s < 0 && est.status != SpeedStatus::kElsewhere) {
        SpeedEstimate run_up = attempt(0.5 * record_s, nominal_hz);
        if (usable(run_up)) {
          est = std::move(run_up);
          notes.push_back("no steady mesh line: the speed followed as a run-up from mid-record (" +
                          fmt(0.5 * record_s, 4) + " s), where the nominal speed is assumed");
        }
      }
      if (opt.nominal_time_s >= 0) {
        notes.push_back("the nominal speed assumed at " + fmt(opt.nominal_time_s, 4) + " s");
      }
      const bool confirmed = est.confirmations > 0 || lines.size() == 1;
      if (est.status == SpeedStatus::kTracked && confirmed) {
        std::vector<double> pulses = revolution_times_s(est);
        if (pulses.size() >= 3) {
          from_reference(k, gb, input, pulses, est.mean_speed_hz, "vibration", "vibration x ratio");
          k.speed.source = "vibration";
          k.speed.line = est.line.label + " (order " + fmt(est.line.order, 5) + ", " +
                         fmt(est.prominence_db, 3) + " dB)";
          k.speed.time_s = est.time_s;
          for (double f : est.speed_hz) k.speed.speed_rpm.push_back(60 * f);
          k.speed.phase_jitter_deg = est.phase_jitter_deg;
          k.speed.angle_uncertainty_deg = est.phase_jitter_deg / est.line.order;
          summarise(k.speed);
          notes.push_back("shaft speeds from the vibration (" + k.speed.line +
                          "): " + fmt(est.mean_speed_hz * 60) + " rpm mean (nominal " +
                          fmt(nominal_hz * 60) + " rpm); the line's phase jitter " +
                          fmt(est.phase_jitter_deg, 2) + " deg, the shaft angle's " +
                          fmt(k.speed.angle_uncertainty_deg, 2) + " deg");
          warn_off_nominal(est.mean_speed_hz, nominal_hz, "the vibration", notes);
          return k;
        }
      }
      std::string why = est.status == SpeedStatus::kNoLine          ? "no line"
                        : est.status == SpeedStatus::kAmbiguous     ? "ambiguous lines"
                        : est.status == SpeedStatus::kLowConfidence ? "low confidence"
                        : est.status == SpeedStatus::kElsewhere     ? "the lines fit another speed"
                                                                    : "no other line agrees";
      notes.push_back("speed from the vibration not used (" + why + ")");
    } catch (const diag::InputError& e) {
      notes.push_back(std::string("speed from the vibration skipped: ") + e.what());
    }
  }

  // ---- the nominal speed ----
  notes.push_back("no usable tacho: shaft angles from the nominal input speed " +
                  fmt(gb.input().speed_rpm) + " rpm, assumed constant");
  for (std::size_t s = 0; s < ns; ++s) {
    const double f = k.speeds[s].speed_hz;
    for (double t = 0; t <= duration_s; t = static_cast<double>(k.pulses_s[s].size()) / f) {
      k.pulses_s[s].push_back(t);
    }
  }
  k.reference_shaft = input;
  k.speed.source = "nominal";
  k.speed.mean_rpm = k.speed.min_rpm = k.speed.max_rpm = gb.shaft_speed_rpm(input);
  k.speed.stationary = true;
  return k;
}

void refine_tsa_pulses(const diag::Recording& rec, const diag::Gearbox& gb,
                       const AnalyzeOptions& opt, ShaftKinematics& k,
                       std::vector<std::string>& notes) {
  k.tsa_pulses_s = k.pulses_s;
  const int ref = k.reference_shaft >= 0 ? k.reference_shaft : gb.input_shaft();
  k.tsa_reference = gb.shafts()[static_cast<std::size_t>(ref)].name;
  k.tsa_reference_pulses = k.pulses_s[static_cast<std::size_t>(ref)];
  try {
    const RefinedPulses rp = refine_pulses(rec, gb, k.tsa_reference, k.tsa_reference_pulses,
                                           pulse_refine_options(opt.gear_damage));
    const double base =
        std::abs(gb.shafts()[static_cast<std::size_t>(gb.shaft_index(rp.shaft))].speed_ratio);
    std::vector<std::vector<double>> scaled(gb.shafts().size());  // all or nothing
    for (std::size_t s = 0; s < scaled.size(); ++s) {
      scaled[s] = scale_pulses(rp.pulses, std::abs(gb.shafts()[s].speed_ratio) / base);
    }
    k.tsa_pulses_s = std::move(scaled);
    k.tsa_reference = rp.shaft;
    k.tsa_reference_pulses = rp.pulses;
    if (!rp.note.empty()) notes.push_back("TSA revolutions: " + rp.note);
  } catch (const diag::InputError& e) {
    notes.push_back(std::string("TSA revolutions not corrected (pulses as measured): ") + e.what());
  }
}

}  // namespace detect
