#include "kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "detect/angular/speed_estimate.hpp"
#include "detect/angular/tacho.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"

namespace detect {

namespace {

std::string fmt(double v, int prec = 6) {
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

// Relative speed range above which a record is reported as non-stationary.
constexpr double kStationaryTolerance = 0.01;

void summarise(AnalysisSpeed& sp) {
  if (sp.speed_rpm.empty()) return;
  const auto [lo, hi] = std::minmax_element(sp.speed_rpm.begin(), sp.speed_rpm.end());
  sp.min_rpm = *lo;
  sp.max_rpm = *hi;
  double sum = 0;
  for (double v : sp.speed_rpm) sum += v;
  sp.mean_rpm = sum / static_cast<double>(sp.speed_rpm.size());
  sp.stationary = (sp.max_rpm - sp.min_rpm) <= kStationaryTolerance * sp.mean_rpm;
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
      const SpeedEstimate est = estimate_speed(channels, fs, nominal_hz, lines);
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
          summarise(k.speed);
          notes.push_back("shaft speeds from the vibration (" + k.speed.line +
                          "): " + fmt(est.mean_speed_hz * 60) + " rpm mean (nominal " +
                          fmt(nominal_hz * 60) + " rpm)");
          return k;
        }
      }
      std::string why = est.status == SpeedStatus::kNoLine          ? "no line"
                        : est.status == SpeedStatus::kAmbiguous     ? "ambiguous lines"
                        : est.status == SpeedStatus::kLowConfidence ? "low confidence"
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

}  // namespace detect
