// The one entry to the analysis of a recording as `geardiag analyze`, `geardiag batch` and the
// Python module's analyze() run it: read the recording (diag::open_recording, any format), take
// the gearbox description (given, else the file's own), set the speed the data says and what the
// channels are (diag/io/channel_setup.hpp), read and prepare the healthy baselines, run
// analyze_recording, and compare with the baselines. Every caller is a thin layer over it: the
// same request gives the same result, whichever door it came through.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/channel_setup.hpp"
#include "diag/io/recording.hpp"
#include "diag/io/recording_frames.hpp"

namespace detect {

// A recording to analyse or to compare with: a file read with diag::open_recording, a file
// already opened frame by frame (diag::open_recording_frames: opened on one thread, analysed on
// another), or a recording already in memory. With either of the last two, `path`, when given,
// only names it in messages and reports.
struct RecordingInput {
  std::filesystem::path path;
  std::shared_ptr<const diag::Recording> recording;  // null: read `opened`, else `path`
  diag::OpenedFrames opened;                         // frames null: read `path`

  RecordingInput() = default;
  RecordingInput(std::filesystem::path p) : path(std::move(p)) {}  // NOLINT: a path is an input
  RecordingInput(std::shared_ptr<const diag::Recording> r, std::filesystem::path name = {})
      : path(std::move(name)), recording(std::move(r)) {}
  RecordingInput(diag::OpenedFrames o, std::filesystem::path name)
      : path(std::move(name)), opened(std::move(o)) {}
  // "recording" when neither a path nor a name was given.
  std::string name() const;
};

// A recording is analysed whole, frame by frame: the frames are the longest stretches of equal
// length that keep within these limits (diag::ReadLimits: at most 2^20 samples in all, or 2^18
// per channel when there are many channels, never over 2^19 per channel), each read by blocks
// (HDF5) or cut from the recording in memory (the other formats), analysed by analyze_recording,
// and forgotten but for its summary (AnalysisSegment) and its findings. analyze peaks at 80-190
// bytes per sample of a frame (bench/analyze_memory.sh): memory does not grow with an HDF5
// recording's length.
inline constexpr std::uint64_t kDefaultMaxSamples = std::uint64_t{1} << 20;
inline constexpr std::uint64_t kKeptChannelSamples = std::uint64_t{1} << 18;
inline constexpr std::uint64_t kMaxChannelSamples = std::uint64_t{1} << 19;

struct AnalyzeRequest {
  RecordingInput recording;
  std::optional<double> fs_hz;  // sampling rate [Hz] of CSV files without a time column and of
                                // MAT files (the recording's and the baselines'); > 0
  // The gearbox description; absent: the recording's own (/gearbox), else none (then only the
  // unit-free indicators and spectra are computed).
  std::optional<diag::Gearbox> gearbox;
  diag::ChannelSetup channels;  // channel map, tachos and speed, applied to every recording read
  // A channel whose level is the machine's load (a torque, a motor current; any role): a long
  // log's frames are also cut where its RMS level steps (load_step_fraction). Empty: none. A name
  // the recording does not have is an error.
  std::string load_channel;
  // Healthy recordings of the same machine and channels: the anomaly score (score_against_
  // baseline) and, with a gearbox, the wear indicator per mesh (wear_against_baseline).
  std::vector<RecordingInput> baseline;
  BaselineComparisonOptions baseline_options;
  // A recording the baselines cannot score (another sampling rate, no common channel): true, an
  // error; false, the analysis is kept and FileAnalysis::baseline_error says why (a table of many
  // recordings keeps its row).
  bool baseline_required = true;
  // A healthy recording of the same gears at the same speed and load, with a tacho: the
  // damaged-shaft locator subtracts its revolution averages (gear_damage_baseline). Ignored when
  // options.gear_damage.baseline is already set (a caller analysing many files against one).
  std::optional<RecordingInput> gear_baseline;
  // More healthy recordings of the same gears beside gear_baseline (GearDamageOptions::
  // more_baselines: each shaft is kept against the one that explains it best). Needs
  // gear_baseline; ignored with it when options.gear_damage.baseline is already set.
  std::vector<RecordingInput> more_gear_baselines;
  // The frame limit: at most this many samples in all per frame (kKeptChannelSamples and
  // kMaxChannelSamples per channel, never more than this); > 0.
  std::uint64_t frame_samples = kDefaultMaxSamples;
  // The frames' length [s] when shorter than frame_samples allows (a finer timeline: findings
  // are placed to within a frame); 0: as long as frame_samples allows. >= 0.
  double frame_s = 0;
  // A long log's amplitude and envelope spectra (their peaks and plots) averaged over its steady
  // parts; false: the detail frame's, and the memory of two spectra per channel saved (a caller
  // that shows no spectrum: `batch` without its per-recording reports).
  bool average_spectra = true;
  // 0 (default): every sample is examined. Else an opt-in limit: only the first part holding at
  // most this many samples in all (the per-channel rules of frame_samples) is analysed; the rest
  // is reported as not examined (AnalysisCoverage::not_examined).
  std::uint64_t max_samples = 0;
  // options.threads: for a recording of several frames, the frames analysed at a time (each
  // frame's channels then one at a time); 0 is then 2, so that the memory bound holds on any
  // machine (each frame in flight holds its recording and transforms). For a recording of one
  // frame, its channels analysed at a time (0: one per core).
  AnalyzeOptions options;
};

// The revolution averages analyze_file takes of a gear baseline (`healthy`, as
// AnalyzeRequest::gear_baseline or one of more_gear_baselines of `request`: its first frame,
// prepared for `gearbox` and request.channels): computed once, they can be given to many
// requests as options.gear_damage.baseline and more_baselines, with the same result as each
// request taking them itself (`batch`: a history's reference recordings, for every later
// recording). Throws diag::InputError naming the baseline, as analyze_file would.
std::shared_ptr<const GearDamageBaseline> gear_damage_baseline_of(const AnalyzeRequest& request,
                                                                  const RecordingInput& healthy,
                                                                  const diag::Gearbox& gearbox);

struct FileAnalysis {
  AnalysisResult result;  // with the notes of the speed and channel setup first
  std::string source;     // the recording's name (RecordingInput::name)
  std::string format;     // the reader's (diag::recording_formats), "memory" for a recording given
  bool cut = false;       // only the first part was examined (AnalyzeRequest::max_samples)
  std::map<std::string, std::string> metadata;  // the recording's (timestamps, source file, ...)
  double read_s = 0;                            // wall time of reading the recording [s]
  std::string baseline_error;  // why the baselines could not score it (baseline_required false)
};

// A recording longer than one frame is analysed frame by frame (frame_samples): each frame's
// speed, channel setup and analysis are its own; the result is
//   - findings: every frame's, one per fault and place (kind, fault, shaft, gears, bearing),
//     the most confident frame's, with first_s / last_s and frames_seen / frames_examined;
//   - channels, meshes, TSA, two-direction rows, the locator's result, speed and notes: the
//     detail frame's (the one whose finding is most confident; the first without a finding),
//     except the channels' time indicators, which are over every sample examined;
//   - segments: one per frame; coverage: what was examined;
//   - baseline: the anomaly score of the frame that scores highest (each frame's in its
//     segment), the wear indicator of the detail frame.
// A frame that cannot be analysed (a NaN or infinite sample, a channel too short) is a segment
// "not examined" with the reason, the others are analysed; when none can be, the first frame's
// error is thrown. A recording of one frame gives analyze_recording's result with its segment.
//
// Throws diag::InputError naming the file at fault: the recording ("<path>: ..."), a baseline
// ("--baseline <path>: ..."), the gear baseline ("--gear-baseline <path>: ..."), a speed given
// without a gearbox description, and every error of analyze_recording. Every input is read and
// checked before anything is analysed.
FileAnalysis analyze_file(const AnalyzeRequest& request);

}  // namespace detect
