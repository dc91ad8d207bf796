#include "detect/analysis/analyze_file.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>

#include "detect/angular/tacho.hpp"
#include "detect/spectral/welch.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/open_recording.hpp"
#include "diag/io/recording_frames.hpp"
#include "diag/util/parallel_for.hpp"
#include "kinematics.hpp"
#include "stages.hpp"

namespace detect {

std::string RecordingInput::name() const { return path.empty() ? "recording" : path.string(); }

namespace {

using analysis_stages::fmt;

diag::ReadLimits limits_of(std::uint64_t samples) {
  diag::ReadLimits limits;
  limits.max_samples = samples;
  limits.kept_channel_samples = std::min(samples, kKeptChannelSamples);
  limits.max_channel_samples = std::min(samples, kMaxChannelSamples);
  return limits;
}

// A recording as the request gives it: read with the limits, or a copy of the one in memory
// (prepare_channels changes it).
diag::OpenedRecording read_input(const RecordingInput& in, const std::optional<double>& fs_hz,
                                 const diag::ReadLimits& limits) {
  if (in.recording) return {*in.recording, "memory", false};
  if (in.opened.frames) {  // the first part within the limits, as open_recording_as reads
    const diag::RecordingFrames& frames = *in.opened.frames;
    const double duration = frames.duration_s();
    const double within = std::min(duration, frames.frame_seconds(limits));
    return {frames.frame(0, within < duration ? within : HUGE_VAL), in.opened.format,
            within < duration};
  }
  diag::OpenOptions o;
  o.fs_hz = fs_hz;
  o.limits = limits;
  return diag::open_recording_as(in.path, o);
}

diag::OpenedFrames open_frames(const RecordingInput& in, const std::optional<double>& fs_hz) {
  if (in.recording) return {std::make_shared<const diag::RecordingFrames>(in.recording), "memory"};
  if (in.opened.frames) return in.opened;
  diag::OpenOptions o;
  o.fs_hz = fs_hz;
  return diag::open_recording_frames(in.path, o);
}

// The message of `e` with `prefix` before it, unless it already names the file.
diag::InputError naming(const std::string& prefix, const std::string& file,
                        const diag::InputError& e) {
  const std::string what = e.what();
  return diag::InputError(
      prefix + (what.find(file) != std::string::npos || file.empty() ? what : file + ": " + what));
}

// What makes two frames' findings the same fault in the same place.
std::string finding_key(const Finding& f) {
  std::string key =
      f.kind + "|" + std::string(diag::to_string(f.fault)) + "|" + f.shaft + "|" + f.bearing + "|";
  for (const std::string& g : f.gears) key += g + ",";
  return key;
}

// The most confident finding of a frame's result (0 without one).
double top_confidence(const AnalysisResult& r) {
  double c = 0;
  for (const Finding& f : r.findings) c = std::max(c, f.confidence);
  return c;
}

struct MergedFinding {
  Finding finding;
  std::vector<std::size_t> frames;  // the frames that show it, in order
};

// Where in the log a finding is seen, said in its note: a log of several frames only.
std::string placement(const MergedFinding& m, const std::vector<AnalysisSegment>& segments,
                      std::size_t examined) {
  const Finding& f = m.finding;
  std::string s = "seen in " + std::to_string(m.frames.size()) + " of " + std::to_string(examined) +
                  " frames examined, " + fmt(f.first_s, 4) + "-" + fmt(f.last_s, 4) + " s";
  std::size_t last_examined = 0;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    if (segments[k].verdict != "not examined") last_examined = k;
  }
  const bool contiguous = m.frames.back() - m.frames.front() + 1 == m.frames.size();
  if (m.frames.size() == 1 && examined > 2 && m.frames.front() != last_examined) {
    s += ": in one frame only, a transient rather than a lasting fault";
  } else if (contiguous && m.frames.back() == last_examined && m.frames.front() > 0) {
    s += ": from " + fmt(f.first_s, 4) + " s to the end of the log";
  } else if (!contiguous) {
    s += ": intermittent";
  }
  return s;
}

// Why a frame cannot be analysed as it is, or empty: a channel with NaN or infinite samples (a
// gap a logger filled so). The time is the recording's.
std::string non_finite(const diag::Recording& frame, double t0) {
  for (const auto* group : {&frame.signals, &frame.tachos}) {
    for (const diag::Signal& s : *group) {
      std::size_t bad = 0, first = 0;
      for (std::size_t i = 0; i < s.samples.size(); ++i) {
        if (!std::isfinite(s.samples[i]) && bad++ == 0) first = i;
      }
      if (bad > 0) {
        return "channel '" + s.name + "': " + std::to_string(bad) +
               " NaN or infinite samples, the first at " +
               fmt(t0 + static_cast<double>(first) / s.fs_hz, 6) + " s";
      }
    }
  }
  return {};
}

// A sensor channel clipped in the frame (the sensor or the converter saturated, and the impacts a
// fault makes are cut off), or empty: at least kClipSamples samples, and one in 10^4, exactly at
// the frame's largest or smallest value, yet under a tenth of the frame (more: a signal of a few
// levels, not a clipped vibration). A continuous signal reaches its extreme once; a quantised one
// a few times.
std::string clipped(const diag::Recording& frame, double t0) {
  constexpr std::size_t kClipSamples = 16;
  for (std::size_t c : sensor_channels(frame)) {
    const diag::Signal& s = frame.signals[c];
    const std::size_t n = s.samples.size();
    if (n < 2) continue;
    const auto [lo, hi] = std::minmax_element(s.samples.begin(), s.samples.end());
    if (*lo == *hi) continue;  // a constant channel: the analysis says what it can
    for (const double extreme : {*lo, *hi}) {
      std::size_t held = 0, first = n;
      for (std::size_t i = 0; i < n; ++i) {
        if (s.samples[i] == extreme && held++ == 0) first = i;
      }
      if (held >= kClipSamples && held * 10000 >= n && 10 * held < n) {
        return "channel '" + s.name + "': clipped at " + fmt(extreme, 6) + " (" +
               std::to_string(held) + " samples held there, the first at " +
               fmt(t0 + static_cast<double>(first) / s.fs_hz, 6) + " s)";
      }
    }
  }
  return {};
}

// The (upper) median of v[a, b) (a < b).
double median_of(const std::vector<double>& v, std::size_t a, std::size_t b) {
  std::vector<double> w(v.begin() + static_cast<std::ptrdiff_t>(a),
                        v.begin() + static_cast<std::ptrdiff_t>(b));
  const auto m = w.begin() + static_cast<std::ptrdiff_t>(w.size() / 2);
  std::nth_element(w.begin(), m, w.end());
  return *m;
}

// The median of the `side` values on each side of v[i], v[i] itself left out (fewer at the ends).
double median_around(const std::vector<double>& v, std::size_t i, std::size_t side) {
  std::vector<double> w;
  for (std::size_t j = i > side ? i - side : 0; j < std::min(v.size(), i + side + 1); ++j) {
    if (j != i) w.push_back(v[j]);
  }
  return median_of(w, 0, w.size());
}

// A tacho that drops out in the frame, or empty: a stretch without pulses longer than three
// times the intervals around it and than one revolution (one or two missed pulses are repaired
// by the kinematics, a longer silence would be filled with guessed revolutions), inside the frame
// or at its ends. The intervals are compared with their neighbours' (the median of the four on
// each side), so that a run-up's lengthening intervals are not a dropout. `ppr`: the pulses per
// revolution asked for (0: each tacho's own).
std::string tacho_dropout(const diag::Recording& frame, double t0, int ppr) {
  constexpr std::size_t kSide = 4;
  for (const diag::Signal& t : frame.tachos) {
    TachoOptions o;
    o.pulses_per_rev = ppr > 0 ? ppr : diag::pulses_per_rev(t);
    o.repair = false;
    const std::vector<double> p = tacho_pulses(t.samples, t.fs_hz, o).pulse_times_s;
    if (p.size() < 4) continue;  // too few to tell a dropout (the kinematics says so)
    std::vector<double> d(p.size() - 1);
    for (std::size_t i = 0; i + 1 < p.size(); ++i) d[i] = p[i + 1] - p[i];
    const double factor = std::max(3.0, static_cast<double>(o.pulses_per_rev));
    const auto dropout = [&](double gap, double from, double local) {
      return "tacho '" + t.name + "' drops out for " + fmt(gap, 3) + " s from " +
             fmt(t0 + from, 6) + " s (" + fmt(gap / local, 3) + " pulse intervals)";
    };
    if (p.front() > factor * d.front()) return dropout(p.front(), 0, d.front());
    for (std::size_t i = 0; i < d.size(); ++i) {
      const double local = median_around(d, i, kSide);
      if (d[i] > factor * local) return dropout(d[i], p[i], local);
    }
    const double tail = t.duration_s() - p.back();
    if (tail > factor * d.back()) return dropout(tail, p.back(), d.back());
  }
  return {};
}

// Where the operating state changes inside a frame, so that the frame is cut there: a time [s
// from the frame's start] and what changed.
struct StateCut {
  double t_s = 0;
  std::string what;
  // A step's median speeds [rpm] of the profile's shaft before and after it (0 for a splice).
  double before_rpm = 0, after_rpm = 0;
};

constexpr std::size_t kStatePoints = 8;      // speed points fitted on each side
constexpr std::size_t kMinStatePoints = 16;  // speed points kept on each side of a cut
constexpr double kStepFraction = 0.02;
constexpr double kSpliceFraction = 0.1;

// What a profile is of: its name in a cut's words, the factor from the profile's values to the
// unit said, the unit, and the relative step that cuts.
struct ProfileKind {
  std::string quantity = "speed";
  double scale = 60;  // revolutions per second -> rpm
  std::string unit = "rpm";
  double step_fraction = kStepFraction;
};

// The cuts of a profile (a speed's unless `kind` says otherwise): `rate` [rev/s] at times `t`
// (increasing), `partial` marking the points that are no speed of the shaft (a tacho's partial
// revolution). At each point the speed fitted over the kStatePoints whole points before it and the
// kStatePoints after it (straight lines: a run-up's steady ramp is no change) are compared where
// they meet; more than kStepFraction apart is a speed step (a load or set-point change). A partial
// point where they agree is a splice. A cut leaves at least kMinStatePoints points on each side;
// the strongest cuts are kept first. `name` says whose speed it is in the reasons.
std::vector<StateCut> profile_cuts(const std::vector<double>& t, const std::vector<double>& rate,
                                   const std::vector<char>& partial, double t0,
                                   const std::string& name, const ProfileKind& kind = {}) {
  const std::size_t n = t.size();
  if (n < 2 * kMinStatePoints + 1) return {};
  // The least-squares line through the kStatePoints whole points next to point i (before it, or
  // after it), at t[i]; NaN when there are not so many.
  const auto fitted = [&](std::size_t i, bool before) {
    double st = 0, sv = 0, stt = 0, stv = 0, m = 0;
    for (std::size_t step = 1; m < kStatePoints; ++step) {
      if (before ? step > i : i + step >= n) break;
      const std::size_t j = before ? i - step : i + step;
      if (partial[j]) continue;
      const double x = t[j] - t[i];
      st += x, sv += rate[j], stt += x * x, stv += x * rate[j], m += 1;
    }
    if (m < kStatePoints) return std::numeric_limits<double>::quiet_NaN();
    const double den = m * stt - st * st;
    return den > 0 ? (sv * stt - st * stv) / den : sv / m;
  };
  // The median speed of points [a, b) [rpm].
  const auto median_rpm = [&](std::size_t a, std::size_t b) {
    return kind.scale * median_of(rate, a, b);
  };
  struct Candidate {
    double score;
    std::size_t i;
    std::string what;
    double before_rpm = 0, after_rpm = 0;
  };
  std::vector<Candidate> found;
  for (std::size_t i = kMinStatePoints; i + kMinStatePoints <= n; ++i) {
    const double before = fitted(i, true);
    const double after = fitted(i, false);
    const double mean = 0.5 * (before + after);
    if (!(mean > 0)) continue;
    const double step = std::abs(after - before) / mean;
    if (step > kind.step_fraction) {
      // Said as the median speeds of the kMinStatePoints points on each side (the fitted lines
      // meet inside the change).
      const double from_rpm = median_rpm(i - kMinStatePoints, i);
      const double to_rpm = median_rpm(i + 1, std::min(n, i + 1 + kMinStatePoints));
      found.push_back({step / kind.step_fraction, i,
                       "a " + kind.quantity + " step, " + fmt(from_rpm, 5) + " to " +
                           fmt(to_rpm, 5) + " " + kind.unit + " of " + name + " at " +
                           fmt(t0 + t[i], 6) + " s",
                       from_rpm, to_rpm});
    } else if (partial[i]) {
      found.push_back({std::abs(rate[i] / mean - 1) / kSpliceFraction, i,
                       "a splice of " + name + " at " + fmt(t0 + t[i], 6) + " s (a revolution of " +
                           fmt(mean / rate[i], 3) + " times the speed's)"});
    }
  }
  // The strongest first, each kMinStatePoints from those kept (ties: the earlier).
  std::stable_sort(found.begin(), found.end(),
                   [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  std::vector<Candidate> kept;
  for (Candidate& c : found) {
    bool apart = true;
    for (const Candidate& k : kept) {
      apart = apart && (c.i > k.i ? c.i - k.i : k.i - c.i) >= kMinStatePoints;
    }
    if (apart) kept.push_back(std::move(c));
  }
  std::sort(kept.begin(), kept.end(),
            [](const Candidate& a, const Candidate& b) { return a.i < b.i; });
  std::vector<StateCut> cuts;
  for (Candidate& c : kept) cuts.push_back({t[c.i], std::move(c.what), c.before_rpm, c.after_rpm});
  return cuts;
}

// The cuts a frame's first tacho shows: its once-per-revolution pulses, each revolution's speed
// at the middle of its interval; an interval further than kSpliceFraction from the median of the
// kStatePoints on each side is a partial revolution (a speed step spreads over several
// revolutions and moves that median with it). Without a tacho, or with too few revolutions: none.
std::vector<StateCut> tacho_cuts(const diag::Recording& frame, double t0, int ppr) {
  if (frame.tachos.empty()) return {};
  const diag::Signal& tacho = frame.tachos.front();
  TachoOptions o;
  o.pulses_per_rev = ppr > 0 ? ppr : diag::pulses_per_rev(tacho);
  o.repair = false;
  const std::vector<double> p = tacho_pulses(tacho.samples, tacho.fs_hz, o).pulse_times_s;
  std::vector<double> once;
  for (std::size_t i = 0; i < p.size(); i += static_cast<std::size_t>(o.pulses_per_rev)) {
    once.push_back(p[i]);
  }
  if (once.size() < 2) return {};
  const std::size_t n = once.size() - 1;  // revolution intervals
  std::vector<double> mid(n), rate(n);
  for (std::size_t i = 0; i < n; ++i) {
    mid[i] = 0.5 * (once[i] + once[i + 1]);
    rate[i] = 1 / (once[i + 1] - once[i]);
  }
  std::vector<char> partial(n, 0);
  for (std::size_t i = 0; n > 1 && i < n; ++i) {
    partial[i] = std::abs(rate[i] / median_around(rate, i, kStatePoints) - 1) > kSpliceFraction;
  }
  std::vector<StateCut> cuts = profile_cuts(mid, rate, partial, t0, "tacho '" + tacho.name + "'");
  // The parts take their speed from the tacho: the frame's nominal speed serves them all.
  for (StateCut& c : cuts) c.before_rpm = c.after_rpm = 0;
  return cuts;
}

// A load channel's level: its RMS over windows of kLoadWindowS (at least), a step of more than
// kLoadStepFraction of it between the lines fitted on each side cuts the frame.
constexpr double kLoadWindowS = 0.05;
constexpr double kLoadStepFraction = 0.05;
constexpr double kNearCutS = 1.0;

// The cuts a frame's load channel shows: its RMS level over windows of kLoadWindowS, its steps
// found as a speed's are (kMinStatePoints windows kept on each side of a cut: 0.8 s).
// The parts keep the frame's speed (before_rpm = after_rpm = 0).
std::vector<StateCut> load_cuts(const diag::Recording& frame, const std::string& channel,
                                double t0) {
  const diag::Signal* load = nullptr;
  for (const diag::Signal& s : frame.signals) {
    if (s.name == channel) load = &s;
  }
  if (load == nullptr) {
    std::string names;
    for (const diag::Signal& s : frame.signals) names += (names.empty() ? "" : ", ") + s.name;
    throw diag::InputError("no such channel (its channels: " + names + ")");
  }
  const auto per_window =
      static_cast<std::size_t>(std::max(1.0, std::ceil(kLoadWindowS * load->fs_hz)));
  const std::size_t windows = load->samples.size() / per_window;
  if (windows < 2 * kMinStatePoints + 1) return {};
  std::vector<double> t(windows), level(windows);
  for (std::size_t w = 0; w < windows; ++w) {
    double sum = 0;
    for (std::size_t i = w * per_window; i < (w + 1) * per_window; ++i) {
      sum += load->samples[i] * load->samples[i];
    }
    level[w] = std::sqrt(sum / static_cast<double>(per_window));
    t[w] = (static_cast<double>(w) + 0.5) * static_cast<double>(per_window) / load->fs_hz;
  }
  const ProfileKind kind{"load", 1.0, load->unit.empty() ? "(RMS)" : load->unit + " RMS",
                         kLoadStepFraction};
  std::vector<StateCut> cuts =
      profile_cuts(t, level, std::vector<char>(windows, 0), t0, "channel '" + channel + "'", kind);
  for (StateCut& c : cuts) c.before_rpm = c.after_rpm = 0;
  return cuts;
}

// Pieces of a frame halved no further than this [s] in search of a speed step.
constexpr double kMinBisectS = 0.5;
constexpr int kMaxBisectDepth = 5;
// A step of the speed followed in a frame larger than this is taken for the line lost.
constexpr double kBisectStepFraction = 0.1;

double record_duration(const diag::Recording& rec) {
  double duration = 0;
  for (const diag::Signal& s : rec.signals) duration = std::max(duration, s.duration_s());
  return duration;
}

// The speed the vibration gives over a record, as kinematics.hpp measures it for the analysis
// (nullopt: a tacho, the nominal speed, or an error: the analysis says why).
std::optional<ShaftKinematics> vibration_speed(const diag::Recording& rec, const diag::Gearbox& gb,
                                               const AnalyzeOptions& opt) {
  std::vector<std::string> notes;
  try {
    ShaftKinematics k = shaft_kinematics(rec, gb, record_duration(rec), opt, notes);
    if (k.speed.source == "vibration") return k;
  } catch (const diag::InputError&) {
  }
  return std::nullopt;
}

// The input shaft's speed [rpm] of a speed measured on the reference shaft.
double input_rpm(const diag::Gearbox& gb, const std::string& reference_shaft, double rpm) {
  const int ref = gb.shaft_index(reference_shaft);
  const double ratio =
      ref >= 0 ? std::abs(gb.shafts()[static_cast<std::size_t>(ref)].speed_ratio) : 0.0;
  return ratio > 0 ? rpm / ratio : 0.0;
}

// A piece of a frame and the input speed the vibration gives in it [rpm] (0: none measured).
struct SpeedPiece {
  double from_s = 0, to_s = 0, rpm = 0;
};

// A frame whose speed the vibration does not give as a whole: a step too large for one line to be
// followed across it (the nominal speed near one side of it and beyond the search band of the
// other). Its halves are measured, and the halves not measured or not steady halved again, down
// to kMinBisectS; the pieces' speeds then place the step between two of them. Only when a half
// is measured at all (else the frame's speed is simply not in its vibration).
void bisect_speed(const diag::RecordingFrames& frame, double from, double to,
                  const diag::Gearbox& gb, const AnalyzeOptions& opt, int depth,
                  std::vector<SpeedPiece>& out) {
  const double mid = 0.5 * (from + to);
  std::array<SpeedPiece, 2> halves{SpeedPiece{from, mid, 0}, SpeedPiece{mid, to, 0}};
  std::array<bool, 2> steady{false, false};
  for (std::size_t h = 0; h < 2; ++h) {
    std::optional<ShaftKinematics> k;
    try {
      k = vibration_speed(frame.frame(halves[h].from_s, halves[h].to_s), gb, opt);
    } catch (const diag::InputError&) {  // a piece that cannot be cut out: not measured
    }
    if (!k) continue;
    halves[h].rpm = input_rpm(gb, k->speed.reference_shaft, k->speed.mean_rpm);
    steady[h] = k->speed.stationary;
  }
  if (depth == 1 && halves[0].rpm == 0 && halves[1].rpm == 0) return;
  for (std::size_t h = 0; h < 2; ++h) {
    const bool deeper = !steady[h] && depth < kMaxBisectDepth &&
                        halves[h].to_s - halves[h].from_s >= 2 * kMinBisectS;
    if (deeper) {
      bisect_speed(frame, halves[h].from_s, halves[h].to_s, gb, opt, depth + 1, out);
    } else {
      out.push_back(halves[h]);
    }
  }
}

// The cuts between the pieces of bisect_speed: where two measured pieces' speeds part by more
// than kStepFraction, and around a stretch not measured when the frame steps (its speed is then
// unknown: a part of its own, analysed at the frame's nominal speed; in a frame of one measured
// speed such a stretch is taken for that speed, a cut there only when the speed is that far
// from the nominal). Consecutive pieces of one speed are one part.
std::vector<StateCut> piece_cuts(const std::vector<SpeedPiece>& pieces, double t0,
                                 const diag::Gearbox& gb) {
  const double nominal = gb.shaft_speed_rpm(gb.input_shaft());
  const auto apart = [](double a, double b) { return std::abs(b / a - 1) > kStepFraction; };
  bool steps = false;
  for (const SpeedPiece& p : pieces) {
    for (const SpeedPiece& q : pieces) {
      steps = steps || (p.rpm > 0 && q.rpm > 0 && apart(p.rpm, q.rpm));
    }
  }
  const auto cut_at = [&](double a, double b) {
    if (a > 0 && b > 0) return apart(a, b);
    if (a > 0 || b > 0) return steps || apart(nominal, a + b);
    return false;
  };
  std::vector<StateCut> cuts;
  for (std::size_t i = 1; i < pieces.size(); ++i) {
    const double a = pieces[i - 1].rpm, b = pieces[i].rpm;
    if (!cut_at(a, b)) continue;
    const double t = pieces[i].from_s;
    std::string what =
        a > 0 && b > 0 ? "a speed step, " + fmt(a, 5) + " to " + fmt(b, 5) + " rpm"
        : b > 0 ? "the speed " + fmt(b, 5) + " rpm measured from here (not before: the nominal " +
                      fmt(nominal, 5) + " rpm)"
                : "the speed not measured from here (" + fmt(a, 5) + " rpm before: the nominal " +
                      fmt(nominal, 5) + " rpm assumed)";
    what += " of the " + gb.shafts()[static_cast<std::size_t>(gb.input_shaft())].name +
            " shaft (from the vibration of the frame's halves) at " + fmt(t0 + t, 6) + " s";
    cuts.push_back({t, std::move(what), a, b});
  }
  return cuts;
}

// The cuts the vibration shows in a frame without a tacho: the reference shaft's speed measured
// from a mesh (or shaft) line over the frame (kinematics.hpp, as the analysis measures it), its
// steps as a tacho's. When the frame as a whole gives no speed, its halves are measured
// (bisect_speed).
std::vector<StateCut> vibration_cuts(const diag::Recording& frame, const diag::Gearbox& gb,
                                     double t0, const AnalyzeOptions& opt) {
  const double duration = record_duration(frame);
  std::vector<std::string> notes;
  ShaftKinematics k;
  try {
    k = shaft_kinematics(frame, gb, duration, opt, notes);
  } catch (const diag::InputError&) {
    return {};  // the analysis says why
  }
  const auto bisected = [&] {
    // A view of the frame, not a copy (the aliasing constructor: nothing owned).
    const diag::RecordingFrames view(
        std::shared_ptr<const diag::Recording>(std::shared_ptr<const void>(), &frame));
    std::vector<SpeedPiece> pieces;
    bisect_speed(view, 0.0, duration, gb, opt, 1, pieces);
    return piece_cuts(pieces, t0, gb);
  };
  const bool can_bisect = duration >= 2 * kMinBisectS;
  if (k.speed.source != "vibration") return can_bisect ? bisected() : std::vector<StateCut>{};
  if (k.speed.stationary) return {};
  std::vector<double> rate;
  for (double rpm : k.speed.speed_rpm) rate.push_back(rpm / 60);
  std::vector<StateCut> cuts =
      profile_cuts(k.speed.time_s, rate, std::vector<char>(rate.size(), 0), t0,
                   "the " + k.speed.reference_shaft + " shaft (from the vibration)");
  // A step larger than the ridge follows (its bounded step, the band searched around the nominal
  // speed) shows as a jump of the line followed to another line: the halves are measured instead.
  for (const StateCut& c : cuts) {
    if (can_bisect && std::abs(c.after_rpm / c.before_rpm - 1) > kBisectStepFraction) {
      return bisected();
    }
  }
  // The speeds as the input shaft's: each part is analysed at its own (the nominal speed of the
  // frame may be far from a part's after a step).
  for (StateCut& c : cuts) {
    c.before_rpm = input_rpm(gb, k.speed.reference_shaft, c.before_rpm);
    c.after_rpm = input_rpm(gb, k.speed.reference_shaft, c.after_rpm);
  }
  return cuts;
}

// The gear baseline's revolution averages (--gear-baseline, a history's reference): from its
// tacho as the locator takes them (gear_damage_baseline); a baseline without a tacho, from the
// angles the analysis finds in its vibration (shaft_kinematics and refine_tsa_pulses at its own
// speed), exactly as a recording without a tacho gets its own revolutions (gear_damage_stage),
// so that both averages are taken the same way.
GearDamageBaseline gear_baseline_of(const diag::Recording& healthy, const diag::Gearbox& gb,
                                    const diag::ChannelSetup& channels, const AnalyzeOptions& opt) {
  if (!healthy.tachos.empty()) return gear_damage_baseline(healthy, gb, opt.gear_damage);
  std::vector<std::string> notes;
  const diag::Gearbox at = diag::gearbox_at_speed(gb, healthy, channels, notes);
  double duration_s = 0;
  for (const diag::Signal& s : healthy.signals) duration_s = std::max(duration_s, s.duration_s());
  ShaftKinematics k = shaft_kinematics(healthy, at, duration_s, opt, notes);
  refine_tsa_pulses(healthy, at, opt, k, notes);
  if (k.tsa_reference.empty() || k.tsa_reference_pulses.size() < 3) {
    std::string why;
    for (const std::string& n : notes) why += (why.empty() ? "" : "; ") + n;
    throw diag::InputError("no tacho, and no revolutions found in the vibration" +
                           (why.empty() ? std::string() : ": " + why));
  }
  GearDamageOptions o = opt.gear_damage;  // as gear_damage_stage: the pulses are corrected once
  o.pulse_fit_degree = 0;
  o.refine_speed = false;
  return gear_damage_baseline(healthy, at, k.tsa_reference, k.tsa_reference_pulses, o);
}

// A gear baseline read (`healthy`, named `name`) prepared for `gb` and its averages taken.
std::shared_ptr<const GearDamageBaseline> prepared_gear_baseline(diag::Recording healthy,
                                                                 const std::string& name,
                                                                 const diag::Gearbox& gb,
                                                                 const diag::ChannelSetup& channels,
                                                                 const AnalyzeOptions& opt) {
  try {
    diag::prepare_channels(healthy, &gb, channels);
    return std::make_shared<const GearDamageBaseline>(gear_baseline_of(healthy, gb, channels, opt));
  } catch (const diag::InputError& e) {
    throw diag::InputError("--gear-baseline " + name + ": " + e.what());
  }
}

}  // namespace

std::shared_ptr<const GearDamageBaseline> gear_damage_baseline_of(const AnalyzeRequest& request,
                                                                  const RecordingInput& healthy,
                                                                  const diag::Gearbox& gearbox) {
  diag::Recording r;
  try {
    r = read_input(healthy, request.fs_hz, limits_of(request.frame_samples)).recording;
  } catch (const diag::InputError& e) {
    throw naming("--gear-baseline ", healthy.recording ? healthy.name() : "", e);
  }
  return prepared_gear_baseline(std::move(r), healthy.name(), gearbox, request.channels,
                                request.options);
}

FileAnalysis analyze_file(const AnalyzeRequest& request) {
  AnalyzeOptions opt = request.options;
  if (request.frame_samples == 0) {
    throw diag::InputError("analyze: frame_samples: must be > 0");
  }
  if (!(request.frame_s >= 0 && std::isfinite(request.frame_s))) {
    throw diag::InputError("analyze: frame_s: must be a duration >= 0 s");
  }
  FileAnalysis out;
  out.source = request.recording.name();
  const auto read_start = std::chrono::steady_clock::now();
  const diag::OpenedFrames opened = open_frames(request.recording, request.fs_hz);
  const double open_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
  const diag::RecordingFrames& frames = *opened.frames;
  out.format = opened.format;

  // The frames: equal stretches no longer than the frame limit, over what is examined (all of
  // it, or the first part within max_samples).
  const double duration = frames.duration_s();
  double examined_until = duration;
  AnalysisCoverage coverage;
  coverage.duration_s = duration;
  if (request.max_samples != 0) {
    examined_until = std::min(duration, frames.frame_seconds(limits_of(request.max_samples)));
    if (examined_until < duration) {
      out.cut = true;
      coverage.not_examined.push_back(fmt(examined_until, 6) + "-" + fmt(duration, 6) +
                                      " s: beyond the limit asked for (max_samples " +
                                      std::to_string(request.max_samples) + ")");
    }
  }
  double longest = frames.frame_seconds(limits_of(request.frame_samples));
  if (request.frame_s > 0) longest = std::min(longest, request.frame_s);
  const std::size_t n_frames =
      longest > 0 && examined_until > longest
          ? static_cast<std::size_t>(std::ceil(examined_until / longest * (1 - 1e-12)))
          : 1;
  coverage.frames = n_frames;
  coverage.frame_s = examined_until / static_cast<double>(n_frames);
  // Each frame in flight holds its recording and transforms (~85 MiB at 2^20 samples): a long
  // recording runs at most 2 frames at a time unless told otherwise, so that the memory bound
  // holds.
  if (n_frames > 1 && opt.threads == 0) opt.threads = 2;

  // Every input is read before anything is analysed: a bad baseline file stops the run with its
  // name and no result. A baseline longer than a frame is compared on its first frame.
  const diag::ReadLimits frame_limits = limits_of(request.frame_samples);
  std::vector<diag::Recording> healthy;
  std::vector<std::string> healthy_names;
  for (const RecordingInput& b : request.baseline) {
    try {
      healthy.push_back(read_input(b, request.fs_hz, frame_limits).recording);
    } catch (const diag::InputError& e) {
      throw naming("--baseline ", b.recording ? b.name() : "", e);
    }
    healthy_names.push_back(b.name());
  }
  if (!request.more_gear_baselines.empty() && !request.gear_baseline) {
    throw diag::InputError("analyze: more_gear_baselines: given without a gear baseline");
  }
  std::optional<diag::Recording> gear_healthy;
  std::vector<diag::Recording> more_gear_healthy;
  if (request.gear_baseline && !opt.gear_damage.baseline) {
    try {
      gear_healthy = read_input(*request.gear_baseline, request.fs_hz, frame_limits).recording;
    } catch (const diag::InputError& e) {
      throw naming("--gear-baseline ",
                   request.gear_baseline->recording ? request.gear_baseline->name() : "", e);
    }
    for (const RecordingInput& m : request.more_gear_baselines) {
      try {
        more_gear_healthy.push_back(read_input(m, request.fs_hz, frame_limits).recording);
      } catch (const diag::InputError& e) {
        throw naming("--gear-baseline ", m.recording ? m.name() : "", e);
      }
    }
  }

  // The description: given, else the recording's own (an empty frame holds it).
  std::optional<diag::Gearbox> gb = request.gearbox;
  if (!gb) {
    const diag::Recording head = frames.frame(0, 0);
    if (!head.gearbox_json.empty()) {
      gb = diag::parse_gearbox_text(head.gearbox_json, out.source + ": /gearbox");
    }
  }
  if (!gb && request.channels.rpm != 0) {
    throw diag::InputError("--rpm: needs a gearbox description (--gearbox or the file's /gearbox)");
  }
  for (std::size_t i = 0; i < healthy.size(); ++i) {
    try {
      diag::prepare_channels(healthy[i], gb ? &*gb : nullptr, request.channels);
    } catch (const diag::InputError& e) {
      throw diag::InputError("--baseline " + healthy_names[i] + ": " + e.what());
    }
  }
  if (gear_healthy) {
    if (!gb) {
      throw diag::InputError(
          "--gear-baseline: needs a gearbox description (--gearbox or the file's /gearbox)");
    }
    opt.gear_damage.baseline = prepared_gear_baseline(
        std::move(*gear_healthy), request.gear_baseline->name(), *gb, request.channels, opt);
    gear_healthy.reset();
    for (std::size_t i = 0; i < more_gear_healthy.size(); ++i) {
      opt.gear_damage.more_baselines.push_back(prepared_gear_baseline(
          std::move(more_gear_healthy[i]), request.more_gear_baselines[i].name(), *gb,
          request.channels, opt));
    }
    more_gear_healthy.clear();
  }

  // Frame by frame, the frames on up to opt.threads threads (each frame's channels then one at a
  // time: the recording-level stages run in parallel too, and at most that many channels are in
  // flight, as before). Of each frame its segment, findings, moments and score are kept, and
  // which frame is the detail frame (the most confident finding's; the first frame without one):
  // it is read and analysed again at the end, so that no frame's recording or result is held
  // while the others run. Every choice is by frame index: the same bytes at any thread count.
  const bool framed = n_frames > 1;
  const int frame_threads = framed ? diag::parallel_threads(n_frames, opt.threads) : 1;
  AnalyzeOptions frame_opt = opt;
  if (framed) frame_opt.traces = false;  // the detail frame is analysed again with them
  frame_opt.keep_spectra = framed && request.average_spectra;  // their spectra averaged
  if (frame_threads > 1) frame_opt.threads = 1;
  struct PartOutcome {
    AnalysisSegment seg;
    std::vector<Finding> findings;
    std::string baseline_error;
  };
  // A channel's Welch PSD summed over segments (value x segments), for the whole log's.
  struct PsdSum {
    double resolution_hz = 0;
    std::vector<double> frequency_hz, weighted;
    std::size_t segments = 0;
  };
  // A channel's amplitude or envelope power spectrum (amplitude^2) summed over parts of one
  // layout (the first's: bins resolution_hz apart, as many), single precision; parts of another
  // layout (the last frame, a part cut where the state changed) are left out and counted.
  struct PowerSum {
    double resolution_hz = 0;
    std::vector<float> power;
    std::size_t parts = 0, skipped = 0;
  };
  struct FrameOutcome {
    std::vector<PartOutcome> parts;  // the frame, or its parts where the operating state changed
    std::map<std::string, MomentAccumulator> moments;
    std::map<std::string, PsdSum> psd;  // its time-domain parts' (merged in frame order)
    // Its steady parts' amplitude and envelope power spectra (merged in frame order).
    std::map<std::string, PowerSum> spectrum, envelope;
    bool merged = false;
    std::map<std::string, double> timing;
    double read_s = 0;
  };
  std::vector<FrameOutcome> outcome(n_frames);
  // A part's power spectrum added to a sum (taken over when the sum is empty).
  const auto add_power = [](PowerSum& sum, std::vector<float>&& power, double resolution_hz) {
    if (power.empty()) return;
    if (sum.parts == 0) {
      sum.resolution_hz = resolution_hz;
      sum.power = std::move(power);
      sum.parts = 1;
      return;
    }
    if (resolution_hz != sum.resolution_hz || power.size() != sum.power.size()) {
      ++sum.skipped;
      return;
    }
    for (std::size_t b = 0; b < power.size(); ++b) sum.power[b] += power[b];
    ++sum.parts;
  };
  using PartId = std::pair<std::size_t, std::size_t>;  // (frame, part of it)
  struct Detail {
    PartId at{0, 0};
    double confidence = -1;
    std::optional<AnalysisResult> result;
    std::optional<diag::Recording> rec;
    std::optional<diag::Gearbox> gb;
    std::vector<std::string> notes;
  } detail;
  struct TopScore {
    PartId at{0, 0};
    std::optional<AnalysisBaseline> baseline;
  } top;
  std::mutex read_lock, keep_lock, progress_lock;
  const auto frame_start = [&](std::size_t k) { return static_cast<double>(k) * coverage.frame_s; };
  const auto frame_end = [&](std::size_t k) {
    return k + 1 == n_frames ? examined_until : static_cast<double>(k + 1) * coverage.frame_s;
  };
  // Frame k as read; the last frame of a recording examined whole ends after its last sample
  // (the duration times the rate may round below the sample count).
  const auto read_frame = [&](std::size_t k) {
    const bool to_end = k + 1 == n_frames && examined_until >= duration;
    return frames.frame(frame_start(k),
                        to_end ? std::numeric_limits<double>::infinity() : frame_end(k));
  };
  // In the loop the frames are read one at a time and in order (a file read row by row goes on
  // from where it stopped): frame k waits for frame k - 1's read, or for a failure (parallel_for
  // then skips the frames after it, which would never read).
  std::condition_variable read_turn;
  std::size_t next_read = 0;
  bool stopped = false;
  const auto read_in_turn = [&](std::size_t k) {
    std::unique_lock<std::mutex> lock(read_lock);
    read_turn.wait(lock, [&] { return next_read == k || stopped; });
    struct Done {  // the next frame's turn, however this read ends
      std::size_t& next;
      std::condition_variable& turn;
      ~Done() {
        ++next;
        turn.notify_all();
      }
    } done{next_read, read_turn};
    return read_frame(k);
  };
  // What the channels are (channel map, tachos, inference) and the speed the data says, before
  // any analysis.
  const auto set_up = [&](diag::Recording& rec, std::vector<std::string>& notes) {
    std::optional<diag::Gearbox> at;
    if (gb) at = diag::gearbox_at_speed(*gb, rec, request.channels, notes);
    for (std::string& n : diag::prepare_channels(rec, at ? &*at : nullptr, request.channels)) {
      notes.push_back(std::move(n));
    }
    return at;
  };
  // A frame of a long log cut where the operating state changes (its tacho's cuts, else the
  // vibration's when the speed is measured from it), each part analysed
  // as a segment of its own; a recording of one frame is analysed whole. The parts' times are
  // from the frame's start (the last part's end infinite: the frame's end).
  struct Part {
    diag::Recording rec;
    double start_s = 0, end_s = std::numeric_limits<double>::infinity();
    std::string cut;
    double input_rpm = 0;  // the input speed measured in it (a vibration cut's), 0: the frame's
  };
  // The description a part is analysed with: the frame's, at the part's own speed when measured.
  const auto part_gearbox = [](const std::optional<diag::Gearbox>& at, const Part& part) {
    return at && part.input_rpm > 0 ? std::optional(at->with_input_speed_rpm(part.input_rpm)) : at;
  };
  const auto cut_frame = [&](diag::Recording rec, double t0, const diag::Gearbox* at,
                             const AnalyzeOptions& o) {
    std::vector<Part> parts;
    std::vector<StateCut> cuts;
    if (framed && !rec.tachos.empty()) {
      cuts = tacho_cuts(rec, t0, request.options.tacho_pulses_per_rev);
    } else if (framed && at != nullptr) {
      cuts = vibration_cuts(rec, *at, t0, o);
    }
    if (!request.load_channel.empty()) {
      const std::vector<StateCut> load = [&] {  // checks that the channel is there
        try {
          return load_cuts(rec, request.load_channel, t0);
        } catch (const diag::InputError& e) {
          throw diag::InputError("--load " + request.load_channel + ": " + out.source + ": " +
                                 e.what());
        }
      }();
      if (!framed) {
        parts.push_back({std::move(rec), 0, std::numeric_limits<double>::infinity(), {}, 0});
        return parts;
      }
      // A load step as well; one within a second of a speed cut is that cut (a set-point change
      // moves both). Each part keeps the speed of the speed part it falls in.
      for (const StateCut& c : load) {
        const bool near = std::any_of(cuts.begin(), cuts.end(), [&](const StateCut& s) {
          return std::abs(s.t_s - c.t_s) < kNearCutS;
        });
        if (!near) cuts.push_back(c);
      }
      std::stable_sort(cuts.begin(), cuts.end(),
                       [](const StateCut& a, const StateCut& b) { return a.t_s < b.t_s; });
      double speed = cuts.empty() ? 0 : cuts.front().before_rpm;
      for (StateCut& c : cuts) {
        if (c.before_rpm == 0 && c.after_rpm == 0) {
          c.before_rpm = c.after_rpm = speed;
        } else {
          speed = c.after_rpm;
        }
      }
    }
    if (cuts.empty()) {
      parts.push_back({std::move(rec), 0, std::numeric_limits<double>::infinity(), {}, 0});
      return parts;
    }
    const diag::RecordingFrames whole(std::make_shared<const diag::Recording>(std::move(rec)));
    double from = 0, rpm = cuts.front().before_rpm;
    std::string why;
    for (const StateCut& c : cuts) {
      parts.push_back({whole.frame(from, c.t_s), from, c.t_s, why, rpm});
      from = c.t_s;
      why = c.what;
      rpm = c.after_rpm;
    }
    parts.push_back({whole.frame(from, std::numeric_limits<double>::infinity()), from,
                     std::numeric_limits<double>::infinity(), why, rpm});
    return parts;
  };
  const auto analyse_frame = [&](std::size_t k) {
    FrameOutcome& o = outcome[k];
    const double t0 = frame_start(k);
    AnalyzeOptions this_opt = frame_opt;
    if (framed && opt.progress) {
      const std::string frame = "frame " + std::to_string(k + 1) + "/" + std::to_string(n_frames);
      this_opt.progress = [&opt, &progress_lock, frame](const std::string& stage) {
        const std::lock_guard<std::mutex> lock(progress_lock);
        opt.progress(frame + " " + stage);
      };
    }
    std::vector<std::string> notes;
    std::optional<diag::Gearbox> frame_gb;
    std::optional<diag::Recording> rec;
    // A frame (or part) that cannot be read or analysed (a NaN sample, a clipped channel, too
    // short a frame for a stage that cannot be skipped): the others can. A recording of one
    // frame (or whose every frame fails) is an error, as its first frame's. The channel setup's
    // errors are the request's: thrown.
    const auto not_examined = [&](AnalysisSegment& seg, const diag::InputError& e) {
      if (!framed) throw naming("", out.source, e);
      seg.verdict = "not examined";
      seg.reason = e.what();
    };
    const auto frame_not_examined = [&](const diag::InputError& e) {
      PartOutcome part;
      part.seg.start_s = t0;
      part.seg.end_s = frame_end(k);
      not_examined(part.seg, e);
      o.parts.push_back(std::move(part));
    };
    try {
      const auto r0 = std::chrono::steady_clock::now();
      rec = read_in_turn(k);
      o.read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
      if (const std::string defect = non_finite(*rec, t0); !defect.empty()) {
        throw diag::InputError(defect);
      }
    } catch (const diag::InputError& e) {
      frame_not_examined(e);
      return;
    }
    frame_gb = set_up(*rec, notes);
    try {
      // A recording of one frame is analysed all the same, with a warning: there is no other
      // frame to examine instead.
      for (const std::string& defect :
           {clipped(*rec, t0), tacho_dropout(*rec, t0, request.options.tacho_pulses_per_rev)}) {
        if (defect.empty()) continue;
        if (framed) throw diag::InputError(defect);
        notes.push_back("warning: " + defect + ": analysed all the same (one frame)");
      }
    } catch (const diag::InputError& e) {
      frame_not_examined(e);
      return;
    }
    std::vector<Part> parts =
        cut_frame(std::move(*rec), t0, frame_gb ? &*frame_gb : nullptr, this_opt);
    rec.reset();
    for (std::size_t j = 0; j < parts.size(); ++j) {
      Part& part = parts[j];
      PartOutcome po;
      AnalysisSegment& seg = po.seg;
      seg.start_s = t0 + part.start_s;
      seg.end_s = std::isinf(part.end_s) ? frame_end(k) : t0 + part.end_s;
      seg.cut = part.cut;
      AnalysisResult res;
      try {
        const std::optional<diag::Gearbox> part_gb = part_gearbox(frame_gb, part);
        res = analyze_recording(part.rec, part_gb ? &*part_gb : nullptr, this_opt);
      } catch (const diag::InputError& e) {
        not_examined(seg, e);
        o.parts.push_back(std::move(po));
        continue;
      }
      for (const auto& [stage, t] : res.timing_s) o.timing[stage] += t;
      seg.verdict = res.findings.empty() ? "no finding" : "finding";
      if (frame_gb) {
        seg.speed_rpm = res.speed.mean_rpm;
        seg.speed_source = res.speed.source;
      }
      for (std::size_t i : sensor_channels(part.rec)) {
        const diag::Signal& sig = part.rec.signals[i];
        o.moments[sig.name].add(sig.samples);
        // The Welch PSD of a framed log is every steady part's (the channel stage's layout); the
        // values only where a plot draws them, the segment count always.
        if (!framed || res.speed.spectra_domain == "order" || sig.samples.size() < 64) continue;
        WelchOptions wo;
        wo.fs_hz = sig.fs_hz;
        wo.nperseg = analysis_stages::welch_segment(opt, sig.samples.size());
        if (wo.nperseg != opt.welch_nperseg) continue;  // a part too short for the layout
        PsdSum& sum = o.psd[sig.name];
        sum.resolution_hz = sig.fs_hz / static_cast<double>(wo.fft_length());
        if (!opt.traces) {
          sum.segments += wo.segments(sig.samples.size());
          continue;
        }
        const Psd psd = welch(sig.samples, wo);
        if (sum.weighted.empty()) {
          sum.frequency_hz = psd.frequency_hz;
          sum.weighted.assign(psd.value.size(), 0.0);
        }
        const double weight = static_cast<double>(psd.segments);
        for (std::size_t b = 0; b < psd.value.size(); ++b) {
          sum.weighted[b] += weight * psd.value[b];
        }
        sum.segments += psd.segments;
      }
      for (ChannelAnalysis& c : res.channels) {
        if (!c.sensor) continue;
        seg.channels.push_back(c.name);
        seg.indicators.push_back(c.time);
        // The spectra of a steady part (a part analysed in the order domain has order spectra).
        if (res.speed.spectra_domain == "order") continue;
        add_power(o.spectrum[c.name], std::move(c.spectrum_power), c.spectrum_resolution_hz);
        add_power(o.envelope[c.name], std::move(c.envelope_power), c.envelope_resolution_hz);
      }
      const PartId id{k, j};
      if (!healthy.empty()) {
        try {
          AnalysisBaseline b =
              score_against_baseline(part.rec, healthy, request.baseline_options, healthy_names);
          seg.anomaly_score = b.anomaly_score;
          const std::lock_guard<std::mutex> lock(keep_lock);
          if (!top.baseline || b.anomaly_score > top.baseline->anomaly_score ||
              (b.anomaly_score == top.baseline->anomaly_score && id < top.at)) {
            top.baseline = std::move(b);
            top.at = id;
          }
        } catch (const diag::InputError& e) {
          if (request.baseline_required) {
            throw diag::InputError(std::string("--baseline: ") + e.what());
          }
          po.baseline_error = std::string("baseline: ") + e.what();
        }
      }
      po.findings = res.findings;
      const double confidence = top_confidence(res);
      {
        const std::lock_guard<std::mutex> lock(keep_lock);
        if (confidence > detail.confidence || (confidence == detail.confidence && id < detail.at)) {
          detail.confidence = confidence;
          detail.at = id;
          if (!framed) {  // one frame: its result is the result
            detail.result = std::move(res);
            detail.rec = std::move(part.rec);
            detail.gb = part_gearbox(frame_gb, part);
            detail.notes = notes;
          }
        }
      }
      o.parts.push_back(std::move(po));
    }
  };
  // The frames' PSD sums merged in frame order as they complete (the same sums at any thread
  // count; only the frames in flight hold theirs).
  std::map<std::string, PsdSum> psd_total;
  std::size_t next_merge = 0;
  std::map<std::string, PowerSum> spectrum_total, envelope_total;
  const auto merge_power = [](std::map<std::string, PowerSum>& totals,
                              std::map<std::string, PowerSum>& parts) {
    for (auto& [name, part] : parts) {
      PowerSum& total = totals[name];
      if (total.parts == 0) {
        part.skipped += total.skipped;
        total = std::move(part);
      } else if (part.parts > 0 && part.resolution_hz == total.resolution_hz &&
                 part.power.size() == total.power.size()) {
        for (std::size_t b = 0; b < part.power.size(); ++b) total.power[b] += part.power[b];
        total.parts += part.parts;
        total.skipped += part.skipped;
      } else {
        total.skipped += part.parts + part.skipped;
      }
    }
    parts.clear();
  };
  const auto merge_psd = [&](std::size_t k) {
    const std::lock_guard<std::mutex> lock(keep_lock);
    outcome[k].merged = true;
    for (; next_merge < n_frames && outcome[next_merge].merged; ++next_merge) {
      for (auto& [name, part] : outcome[next_merge].psd) {
        PsdSum& total = psd_total[name];
        if (total.segments == 0) {
          total = std::move(part);
          continue;
        }
        for (std::size_t b = 0; b < total.weighted.size() && b < part.weighted.size(); ++b) {
          total.weighted[b] += part.weighted[b];
        }
        total.segments += part.segments;
      }
      outcome[next_merge].psd.clear();
      merge_power(spectrum_total, outcome[next_merge].spectrum);
      merge_power(envelope_total, outcome[next_merge].envelope);
    }
  };
  diag::parallel_for(n_frames, frame_threads, [&](std::size_t k) {
    try {
      analyse_frame(k);
      merge_psd(k);
    } catch (...) {
      {
        const std::lock_guard<std::mutex> lock(read_lock);
        stopped = true;
      }
      read_turn.notify_all();
      throw;
    }
  });

  // In order: what was examined, the moments, the timing, the first error; the frames' parts
  // are the segments.
  std::vector<AnalysisSegment> segments;
  std::vector<std::vector<Finding>> segment_findings;
  std::map<PartId, std::size_t> segment_of;
  std::map<std::string, MomentAccumulator> moments;
  std::map<std::string, double> timing;
  std::string first_error;
  double read_s = open_s;
  for (std::size_t k = 0; k < n_frames; ++k) {
    FrameOutcome& o = outcome[k];
    read_s += o.read_s;
    for (std::size_t j = 0; j < o.parts.size(); ++j) {
      PartOutcome& po = o.parts[j];
      if (po.seg.verdict == "not examined") {
        if (first_error.empty()) first_error = po.seg.reason;
      } else {
        ++coverage.frames_examined;
        coverage.analysed_s += po.seg.end_s - po.seg.start_s;
      }
      if (out.baseline_error.empty()) out.baseline_error = po.baseline_error;
      segment_of[{k, j}] = segments.size();
      segments.push_back(std::move(po.seg));
      segment_findings.push_back(std::move(po.findings));
    }
    for (auto& [name, m] : o.moments) moments[name].merge(m);
    for (const auto& [stage, t] : o.timing) timing[stage] += t;
  }
  outcome.clear();
  const std::size_t n_segments = segments.size();
  coverage.frames = n_segments;
  coverage.detail_frame = segment_of.at(detail.at);
  const std::size_t top_segment = top.baseline ? segment_of.at(top.at) : 0;
  const double detail_confidence = detail.confidence;
  std::optional<AnalysisBaseline> top_baseline = std::move(top.baseline);
  if (top_baseline && framed) {
    top_baseline->notes.push_back(
        "the frame that scores highest: " + fmt(segments[top_segment].start_s, 5) + "-" +
        fmt(segments[top_segment].end_s, 5) + " s (" + std::to_string(top_segment + 1) + " of " +
        std::to_string(n_segments) + ")");
  }
  if (coverage.frames_examined == 0) throw diag::InputError(out.source + ": " + first_error);

  // The detail segment read and analysed again, with the curves a plot draws when asked for (the
  // same findings and notes: AnalyzeOptions::traces changes nothing else).
  if (framed) {
    const auto t0 = std::chrono::steady_clock::now();
    diag::Recording rec = read_frame(detail.at.first);
    read_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    detail.gb = set_up(rec, detail.notes);
    std::vector<Part> parts = cut_frame(std::move(rec), frame_start(detail.at.first),
                                        detail.gb ? &*detail.gb : nullptr, frame_opt);
    detail.gb = part_gearbox(detail.gb, parts.at(detail.at.second));
    detail.rec = std::move(parts.at(detail.at.second).rec);
    detail.result = analyze_recording(*detail.rec, detail.gb ? &*detail.gb : nullptr, opt);
  }
  out.read_s = read_s;
  out.result = std::move(*detail.result);
  AnalysisResult& r = out.result;
  if (opt.timing) {
    if (framed) r.timing_s = timing;
    r.timing_s["read"] = read_s;  // the recording (HDF5 inflate, CSV parse)
  }
  r.notes.insert(r.notes.begin(), detail.notes.begin(), detail.notes.end());
  r.duration_s = duration;

  // One finding per fault and place, the most confident frame's.
  std::vector<MergedFinding> merged;
  std::map<std::string, std::size_t> index;
  for (std::size_t k = 0; k < n_segments; ++k) {
    for (const Finding& f : segment_findings[k]) {
      const auto [it, fresh] = index.emplace(finding_key(f), merged.size());
      if (fresh) merged.push_back({f, {}});
      MergedFinding& m = merged[it->second];
      if (m.frames.empty() || m.frames.back() != k) m.frames.push_back(k);
      if (f.confidence > m.finding.confidence) m.finding = f;
    }
  }
  if (top_baseline) {
    r.baseline = std::move(top_baseline);
    // The wear of each mesh, on the detail frame (a failure is an error, or, for a table of many
    // recordings, the reason kept beside what did succeed); its findings are that frame's.
    if (gb) {
      const std::size_t before = r.findings.size();
      try {
        wear_against_baseline(r, *detail.rec, detail.gb ? *detail.gb : *gb, healthy, opt,
                              healthy_names, request.baseline_options.wear_threshold_db);
      } catch (const diag::InputError& e) {
        if (request.baseline_required)
          throw diag::InputError(std::string("--baseline: ") + e.what());
        out.baseline_error = std::string("baseline: ") + e.what();
      }
      for (std::size_t i = before; i < r.findings.size(); ++i) {
        merged.push_back({r.findings[i], {coverage.detail_frame}});
      }
    }
    // The alarm is a finding, seen in the frames that score above the threshold.
    if (r.baseline->alarm) {
      std::map<std::string, double> fs_hz;
      for (const ChannelAnalysis& c : r.channels) fs_hz[c.name] = c.fs_hz;
      MergedFinding m{baseline_alarm_finding(*r.baseline, fs_hz, request.baseline_options), {}};
      for (std::size_t k = 0; k < n_segments; ++k) {
        if (segments[k].anomaly_score > r.baseline->threshold) m.frames.push_back(k);
      }
      if (m.frames.empty()) m.frames.push_back(top_segment);
      merged.push_back(std::move(m));
    }
  }
  // Most confident first, placed in time; a frame that shows one is a frame with a finding.
  std::stable_sort(merged.begin(), merged.end(),
                   [](const MergedFinding& a, const MergedFinding& b) {
                     return a.finding.confidence > b.finding.confidence;
                   });
  r.findings.clear();
  for (MergedFinding& m : merged) {
    Finding& f = m.finding;
    f.first_s = segments[m.frames.front()].start_s;
    f.last_s = segments[m.frames.back()].end_s;
    f.frames_seen = static_cast<int>(m.frames.size());
    f.frames_examined = static_cast<int>(coverage.frames_examined);
    if (framed) {
      f.note += (f.note.empty() ? "" : "; ") + placement(m, segments, coverage.frames_examined);
    }
    for (std::size_t k : m.frames) {
      segments[k].findings.push_back(r.findings.size());
      segments[k].verdict = "finding";
    }
    r.findings.push_back(std::move(f));
  }

  if (framed) {
    // The channels' time indicators over every sample examined (Pebay's one-pass moments merge
    // exactly), the rest the detail frame's.
    for (ChannelAnalysis& c : r.channels) {
      const auto it = moments.find(c.name);
      if (c.sensor && it != moments.end() && it->second.count() > 0) {
        c.time = analysis_stages::time_indicators(it->second.result());
      }
      // The Welch PSD over every steady part, where the detail's own is of the time domain and
      // of the same layout.
      const auto p = psd_total.find(c.name);
      if (!c.sensor || p == psd_total.end() || p->second.segments == 0 ||
          r.speed.spectra_domain == "order" || p->second.resolution_hz != c.psd_resolution_hz) {
        continue;
      }
      const PsdSum& sum = p->second;
      c.psd_segments = sum.segments;
      if (!opt.traces || sum.weighted.empty()) continue;
      std::vector<double> mean(sum.weighted.size());
      for (std::size_t b = 0; b < mean.size(); ++b) {
        mean[b] = sum.weighted[b] / static_cast<double>(sum.segments);
      }
      c.psd = decimate_for_plot(sum.frequency_hz, mean, static_cast<std::size_t>(opt.plot_points),
                                Decimation::kMax);
    }
    // The amplitude and envelope spectra averaged (their power) over the steady parts of the
    // detail frame's layout; the peaks sought on the average.
    for (ChannelAnalysis& c : r.channels) {
      if (!c.sensor || r.speed.spectra_domain == "order") continue;
      const auto average = [&](const PowerSum& sum) {
        Spectrum sp;
        sp.resolution_hz = sum.resolution_hz;
        sp.frequency_hz.resize(sum.power.size());
        sp.amplitude.resize(sum.power.size());
        for (std::size_t b = 0; b < sum.power.size(); ++b) {
          sp.frequency_hz[b] = static_cast<double>(b) * sum.resolution_hz;
          sp.amplitude[b] =
              std::sqrt(static_cast<double>(sum.power[b]) / static_cast<double>(sum.parts));
        }
        return sp;
      };
      const auto s = spectrum_total.find(c.name);
      if (s != spectrum_total.end() && s->second.parts > 0 &&
          s->second.resolution_hz == c.spectrum_resolution_hz) {
        Spectrum sp = average(s->second);
        sp.enbw_hz = c.spectrum_enbw_hz;
        c.spectrum_peaks = analysis_stages::largest_peaks(sp, opt.peaks_reported, 0.5 * c.fs_hz);
        c.spectrum_parts = s->second.parts;
        if (opt.traces) {
          c.spectrum =
              decimate_for_plot(sp.frequency_hz, sp.amplitude,
                                static_cast<std::size_t>(opt.plot_points), Decimation::kMax);
        }
      }
      const auto e = envelope_total.find(c.name);
      if (e != envelope_total.end() && e->second.parts > 0 && !c.envelope_peaks.empty()) {
        const Spectrum sp = average(e->second);
        c.envelope_peaks =
            analysis_stages::largest_peaks(sp, opt.peaks_reported, sp.frequency_hz.back());
        c.envelope_parts = e->second.parts;
        if (opt.traces) {
          c.envelope = analysis_stages::slice_for_plot(sp.frequency_hz, sp.amplitude, 0,
                                                       sp.frequency_hz.back(),
                                                       static_cast<std::size_t>(opt.plot_points));
        }
      }
    }
    const AnalysisSegment& d = segments[coverage.detail_frame];
    std::string note =
        "long recording analysed in " + std::to_string(n_frames) + " frames of " +
        fmt(coverage.frame_s, 4) + " s" +
        (n_segments > n_frames
             ? ", cut into " + std::to_string(n_segments) + " where the operating state changed"
             : "") +
        " (" + std::to_string(coverage.frames_examined) + " examined, " +
        fmt(coverage.analysed_s, 5) + " of " + fmt(duration, 5) +
        " s): findings are every frame's, the channels' time indicators over every sample " +
        "examined, their Welch PSD, amplitude and envelope spectra over the steady parts, the " +
        "order spectrum, kurtogram, sidebands, TSA and locator those of " + fmt(d.start_s, 5) +
        "-" + fmt(d.end_s, 5) + " s (frame " + std::to_string(coverage.detail_frame + 1) + ", " +
        (detail_confidence > 0 ? "where the most confident finding is seen"
                               : "the first examined") +
        ")";
    r.notes.insert(r.notes.begin() + static_cast<std::ptrdiff_t>(detail.notes.size()), note);
  }
  for (const AnalysisSegment& s : segments) {
    if (s.verdict == "not examined") {
      coverage.not_examined.push_back(fmt(s.start_s, 6) + "-" + fmt(s.end_s, 6) +
                                      " s: " + s.reason);
    }
  }
  r.segments = std::move(segments);
  r.coverage = std::move(coverage);

  out.metadata = std::move(detail.rec->metadata);
  return out;
}

}  // namespace detect
