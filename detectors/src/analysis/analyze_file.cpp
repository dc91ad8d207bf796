#include "detect/analysis/analyze_file.hpp"

#include <chrono>
#include <utility>

#include "diag/error.hpp"
#include "diag/io/open_recording.hpp"

namespace detect {

std::string RecordingInput::name() const { return path.empty() ? "recording" : path.string(); }

namespace {

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

// The message of `e` with `prefix` before it, unless it already names the file.
diag::InputError naming(const std::string& prefix, const std::string& file,
                        const diag::InputError& e) {
  const std::string what = e.what();
  return diag::InputError(
      prefix + (what.find(file) != std::string::npos || file.empty() ? what : file + ": " + what));
}

}  // namespace

FileAnalysis analyze_file(const AnalyzeRequest& request) {
  AnalyzeOptions opt = request.options;
  diag::ReadLimits limits;
  if (request.max_samples != 0) {
    limits.max_samples = request.max_samples;
    limits.kept_channel_samples = std::min(request.max_samples, kKeptChannelSamples);
    limits.max_channel_samples = std::min(request.max_samples, kMaxChannelSamples);
  }
  FileAnalysis out;
  out.source = request.recording.name();
  const auto read_start = std::chrono::steady_clock::now();
  diag::OpenedRecording opened = read_input(request.recording, request.fs_hz, limits);
  out.read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
  diag::Recording& rec = opened.recording;
  out.format = opened.format;
  out.cut = opened.cut;
  // Each channel in flight holds its transforms (~35 MiB at 2^18 samples): a long recording runs
  // at most 2 channels at a time unless told otherwise, so that the memory bound holds.
  if (opened.cut && opt.threads == 0) opt.threads = 2;
  // What is a mean over time (indicators, PSD, envelope spectra) is then accumulated over the
  // whole file, block by block.
  if (opened.cut) opt.whole_recording = request.recording.path;

  // Every input is read before anything is analysed: a bad baseline file stops the run with its
  // name and no result.
  std::vector<diag::Recording> healthy;
  std::vector<std::string> healthy_names;
  for (const RecordingInput& b : request.baseline) {
    try {
      healthy.push_back(read_input(b, request.fs_hz, limits).recording);
    } catch (const diag::InputError& e) {
      throw naming("--baseline ", b.recording ? b.name() : "", e);
    }
    healthy_names.push_back(b.name());
  }
  std::optional<diag::Recording> gear_healthy;
  if (request.gear_baseline && !opt.gear_damage.baseline) {
    try {
      gear_healthy = read_input(*request.gear_baseline, request.fs_hz, limits).recording;
    } catch (const diag::InputError& e) {
      throw naming("--gear-baseline ",
                   request.gear_baseline->recording ? request.gear_baseline->name() : "", e);
    }
  }

  std::optional<diag::Gearbox> gb = request.gearbox;
  if (!gb && !rec.gearbox_json.empty()) {
    gb = diag::parse_gearbox_text(rec.gearbox_json, out.source + ": /gearbox");
  }
  // What the channels are (channel map, tachos, inference) and the speed the data says, before
  // any analysis; the baselines are the same machine's channels.
  std::vector<std::string> notes;
  if (gb) {
    gb = diag::gearbox_at_speed(*gb, rec, request.channels, notes);
  } else if (request.channels.rpm != 0) {
    throw diag::InputError("--rpm: needs a gearbox description (--gearbox or the file's /gearbox)");
  }
  for (std::string& n : diag::prepare_channels(rec, gb ? &*gb : nullptr, request.channels)) {
    notes.push_back(std::move(n));
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

  try {
    out.result = analyze_recording(rec, gb ? &*gb : nullptr, opt);
  } catch (const diag::InputError& e) {
    throw diag::InputError(out.source + ": " + e.what());
  }
  AnalysisResult& r = out.result;
  if (opt.timing) r.timing_s["read"] = out.read_s;  // the recording (HDF5 inflate, CSV parse)
  r.notes.insert(r.notes.begin(), notes.begin(), notes.end());
  if (!healthy.empty()) {
    // Scored first, then the wear of each mesh; either failing is an error, or (a table of many
    // recordings) the reason kept beside what did succeed.
    try {
      r.baseline = score_against_baseline(rec, healthy, request.baseline_options, healthy_names);
      if (gb) wear_against_baseline(r, rec, *gb, healthy, opt, healthy_names);
    } catch (const diag::InputError& e) {
      if (request.baseline_required) throw diag::InputError(std::string("--baseline: ") + e.what());
      out.baseline_error = std::string("baseline: ") + e.what();
    }
  }
  out.metadata = std::move(rec.metadata);
  return out;
}

}  // namespace detect
