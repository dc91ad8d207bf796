#include "detect/analysis/analyze_file.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "diag/error.hpp"
#include "diag/io/open_recording.hpp"
#include "diag/io/recording_frames.hpp"
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
  diag::OpenOptions o;
  o.fs_hz = fs_hz;
  o.limits = limits;
  return diag::open_recording_as(in.path, o);
}

diag::OpenedFrames open_frames(const RecordingInput& in, const std::optional<double>& fs_hz) {
  if (in.recording) return {std::make_shared<const diag::RecordingFrames>(in.recording), "memory"};
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
// fault makes are cut off), or empty: at least kClipRuns runs of kClipRun or more equal samples
// at the frame's largest or smallest value, those samples under a tenth of the frame (more: a
// signal of a few levels, not a clipped vibration). A continuous signal returns to an extreme
// rarely, and never holds it exactly.
std::string clipped(const diag::Recording& frame, double t0) {
  constexpr std::size_t kClipRun = 4, kClipRuns = 2;
  for (std::size_t c : sensor_channels(frame)) {
    const diag::Signal& s = frame.signals[c];
    if (s.samples.size() < 2) continue;
    const auto [lo, hi] = std::minmax_element(s.samples.begin(), s.samples.end());
    if (*lo == *hi) continue;  // a constant channel: the analysis says what it can
    for (const double extreme : {*lo, *hi}) {
      std::size_t runs = 0, run = 0, first_run = 0, held = 0;
      for (std::size_t i = 0; i < s.samples.size(); ++i) {
        run = s.samples[i] == extreme ? run + 1 : 0;
        held += run > 0 ? 1 : 0;
        if (run == kClipRun && runs++ == 0) first_run = i + 1 - kClipRun;
      }
      if (runs >= kClipRuns && 10 * held < s.samples.size()) {
        return "channel '" + s.name + "': clipped at " + fmt(extreme, 6) + " (" +
               std::to_string(runs) + " runs of " + std::to_string(kClipRun) +
               " or more samples held there, the first at " +
               fmt(t0 + static_cast<double>(first_run) / s.fs_hz, 6) + " s)";
      }
    }
  }
  return {};
}

}  // namespace

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
  double read_s =
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
  // Each channel in flight holds its transforms (~35 MiB at 2^18 samples): a long recording runs
  // at most 2 channels at a time unless told otherwise, so that the memory bound holds.
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
  std::optional<diag::Recording> gear_healthy;
  if (request.gear_baseline && !opt.gear_damage.baseline) {
    try {
      gear_healthy = read_input(*request.gear_baseline, request.fs_hz, frame_limits).recording;
    } catch (const diag::InputError& e) {
      throw naming("--gear-baseline ",
                   request.gear_baseline->recording ? request.gear_baseline->name() : "", e);
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
    try {
      diag::prepare_channels(*gear_healthy, &*gb, request.channels);
      opt.gear_damage.baseline = std::make_shared<const GearDamageBaseline>(
          gear_damage_baseline(*gear_healthy, *gb, opt.gear_damage));
    } catch (const diag::InputError& e) {
      throw diag::InputError("--gear-baseline " + request.gear_baseline->name() + ": " + e.what());
    }
    gear_healthy.reset();
  }

  // Frame by frame. The detail frame's recording and result are kept (the most confident
  // finding's frame; the first frame without one); of the others, their segment and findings.
  const bool framed = n_frames > 1;
  AnalyzeOptions frame_opt = opt;
  if (framed) frame_opt.traces = false;  // the detail frame is analysed again with them
  std::vector<AnalysisSegment> segments(n_frames);
  std::vector<std::vector<Finding>> frame_findings(n_frames);
  std::map<std::string, MomentAccumulator> moments;
  std::optional<diag::Recording> detail_rec;
  std::optional<diag::Gearbox> detail_gb;
  std::vector<std::string> detail_notes;
  std::optional<AnalysisResult> detail;
  double detail_confidence = -1;
  std::optional<AnalysisBaseline> top_baseline;
  std::string first_error;
  std::map<std::string, double> timing;
  for (std::size_t k = 0; k < n_frames; ++k) {
    AnalysisSegment& seg = segments[k];
    seg.start_s = static_cast<double>(k) * coverage.frame_s;
    seg.end_s = k + 1 == n_frames ? examined_until : static_cast<double>(k + 1) * coverage.frame_s;
    if (framed && opt.progress) {
      const std::string frame = "frame " + std::to_string(k + 1) + "/" + std::to_string(n_frames);
      frame_opt.progress = [&opt, frame](const std::string& stage) {
        opt.progress(frame + " " + stage);
      };
    }
    std::vector<std::string> notes;
    std::optional<diag::Gearbox> frame_gb;
    std::optional<diag::Recording> rec;
    AnalysisResult res;
    // A frame that cannot be read or analysed (a NaN sample, too short a frame for a stage that
    // cannot be skipped): the others can. A recording of one frame (or whose every frame fails)
    // is an error, as its first frame's. The channel setup's errors are the request's: thrown.
    const auto not_examined = [&](const diag::InputError& e) {
      if (!framed) throw naming("", out.source, e);
      if (first_error.empty()) first_error = e.what();
      seg.verdict = "not examined";
      seg.reason = e.what();
    };
    try {
      const auto t0 = std::chrono::steady_clock::now();
      // The last frame of a recording examined whole ends after its last sample (the duration
      // times the rate may round below the sample count).
      const bool to_end = k + 1 == n_frames && examined_until >= duration;
      rec = frames.frame(seg.start_s, to_end ? std::numeric_limits<double>::infinity() : seg.end_s);
      read_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (const std::string defect = non_finite(*rec, seg.start_s); !defect.empty()) {
        throw diag::InputError(defect);
      }
    } catch (const diag::InputError& e) {
      not_examined(e);
      continue;
    }
    // What the channels are (channel map, tachos, inference) and the speed the data says, before
    // any analysis.
    if (gb) frame_gb = diag::gearbox_at_speed(*gb, *rec, request.channels, notes);
    for (std::string& n :
         diag::prepare_channels(*rec, frame_gb ? &*frame_gb : nullptr, request.channels)) {
      notes.push_back(std::move(n));
    }
    try {
      if (const std::string defect = clipped(*rec, seg.start_s); !defect.empty()) {
        throw diag::InputError(defect);
      }
      res = analyze_recording(*rec, frame_gb ? &*frame_gb : nullptr, frame_opt);
    } catch (const diag::InputError& e) {
      not_examined(e);
      continue;
    }
    ++coverage.frames_examined;
    coverage.analysed_s += seg.end_s - seg.start_s;
    for (const auto& [stage, s] : res.timing_s) timing[stage] += s;
    seg.verdict = res.findings.empty() ? "no finding" : "finding";
    if (frame_gb) {
      seg.speed_rpm = res.speed.mean_rpm;
      seg.speed_source = res.speed.source;
    }
    const std::vector<std::size_t> sensors = sensor_channels(*rec);
    for (std::size_t i : sensors) {
      const diag::Signal& s = rec->signals[i];
      moments[s.name].add(s.samples);
    }
    for (const ChannelAnalysis& c : res.channels) {
      if (!c.sensor) continue;
      seg.channels.push_back(c.name);
      seg.indicators.push_back(c.time);
    }
    if (!healthy.empty() && !out.baseline_error.empty()) {
      // The baselines could not score an earlier frame: the same reason holds.
    } else if (!healthy.empty()) {
      try {
        AnalysisBaseline b =
            score_against_baseline(*rec, healthy, request.baseline_options, healthy_names);
        seg.anomaly_score = b.anomaly_score;
        if (!top_baseline || b.anomaly_score > top_baseline->anomaly_score) {
          top_baseline = std::move(b);
          if (framed) {
            top_baseline->notes.push_back("the frame that scores highest: " + fmt(seg.start_s, 5) +
                                          "-" + fmt(seg.end_s, 5) + " s (" + std::to_string(k + 1) +
                                          " of " + std::to_string(n_frames) + ")");
          }
        }
      } catch (const diag::InputError& e) {
        if (request.baseline_required) {
          throw diag::InputError(std::string("--baseline: ") + e.what());
        }
        out.baseline_error = std::string("baseline: ") + e.what();
      }
    }
    frame_findings[k] = res.findings;
    const double confidence = top_confidence(res);
    if (confidence > detail_confidence) {
      detail_confidence = confidence;
      coverage.detail_frame = k;
      detail = std::move(res);
      detail_rec = std::move(rec);
      detail_gb = std::move(frame_gb);
      detail_notes = std::move(notes);
    }
  }
  out.read_s = read_s;
  if (!detail) throw diag::InputError(out.source + ": " + first_error);

  // The detail frame with the curves a plot draws (the same findings and notes: AnalyzeOptions::
  // traces changes nothing else).
  if (framed && opt.traces) {
    detail = analyze_recording(*detail_rec, detail_gb ? &*detail_gb : nullptr, opt);
  }
  out.result = std::move(*detail);
  AnalysisResult& r = out.result;
  if (opt.timing) {
    if (framed) r.timing_s = timing;
    r.timing_s["read"] = read_s;  // the recording (HDF5 inflate, CSV parse)
  }
  r.notes.insert(r.notes.begin(), detail_notes.begin(), detail_notes.end());
  r.duration_s = duration;

  // One finding per fault and place, the most confident frame's, placed in time.
  std::vector<MergedFinding> merged;
  std::map<std::string, std::size_t> index;
  for (std::size_t k = 0; k < n_frames; ++k) {
    for (const Finding& f : frame_findings[k]) {
      const auto [it, fresh] = index.emplace(finding_key(f), merged.size());
      if (fresh) merged.push_back({f, {}});
      MergedFinding& m = merged[it->second];
      if (m.frames.empty() || m.frames.back() != k) m.frames.push_back(k);
      if (f.confidence > m.finding.confidence) m.finding = f;
    }
  }
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
    for (std::size_t k : m.frames) segments[k].findings.push_back(r.findings.size());
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
    }
    const AnalysisSegment& d = segments[coverage.detail_frame];
    std::string note =
        "long recording analysed in " + std::to_string(n_frames) + " frames of " +
        fmt(coverage.frame_s, 4) + " s (" + std::to_string(coverage.frames_examined) +
        " examined, " + fmt(coverage.analysed_s, 5) + " of " + fmt(duration, 5) +
        " s): findings are every frame's, the channels' time indicators over " +
        "every sample examined, the spectra, TSA and locator those of " + fmt(d.start_s, 5) + "-" +
        fmt(d.end_s, 5) + " s (frame " + std::to_string(coverage.detail_frame + 1) + ", " +
        (detail_confidence > 0 ? "where the most confident finding is seen"
                               : "the first examined") +
        ")";
    r.notes.insert(r.notes.begin() + static_cast<std::ptrdiff_t>(detail_notes.size()), note);
  }
  for (const AnalysisSegment& s : segments) {
    if (s.verdict == "not examined") {
      coverage.not_examined.push_back(fmt(s.start_s, 6) + "-" + fmt(s.end_s, 6) +
                                      " s: " + s.reason);
    }
  }
  r.segments = std::move(segments);
  r.coverage = std::move(coverage);

  if (top_baseline) {
    r.baseline = std::move(top_baseline);
    // The wear of each mesh, on the detail frame (a failure is an error, or, for a table of many
    // recordings, the reason kept beside what did succeed).
    if (gb) {
      try {
        wear_against_baseline(r, *detail_rec, detail_gb ? *detail_gb : *gb, healthy, opt,
                              healthy_names);
      } catch (const diag::InputError& e) {
        if (request.baseline_required)
          throw diag::InputError(std::string("--baseline: ") + e.what());
        out.baseline_error = std::string("baseline: ") + e.what();
      }
    }
  }
  out.metadata = std::move(detail_rec->metadata);
  return out;
}

}  // namespace detect
