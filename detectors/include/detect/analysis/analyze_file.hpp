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

namespace detect {

// A recording to analyse or to compare with: a file read with diag::open_recording, or a
// recording already in memory (then `path`, when given, only names it in messages and reports).
struct RecordingInput {
  std::filesystem::path path;
  std::shared_ptr<const diag::Recording> recording;  // null: read `path`

  RecordingInput() = default;
  RecordingInput(std::filesystem::path p) : path(std::move(p)) {}  // NOLINT: a path is an input
  RecordingInput(std::shared_ptr<const diag::Recording> r, std::filesystem::path name = {})
      : path(std::move(name)), recording(std::move(r)) {}
  // "recording" when neither a path nor a name was given.
  std::string name() const;
};

// The part of a long HDF5 recording held in memory by default (diag::ReadLimits): at most 2^20
// samples in all, or 2^18 per channel when there are many channels, never over 2^19 per channel.
// analyze peaks at 80-190 bytes per sample held (bench/analyze_memory.sh): a 1 GB, 8-channel
// recording in < 256 MB. What is a mean over time is then accumulated over the whole file, block
// by block (AnalyzeOptions::whole_recording).
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
  // A longer HDF5 recording is analysed on its first part holding at most this many samples in
  // all (kKeptChannelSamples and kMaxChannelSamples per channel, never more than this), and its
  // time indicators, Welch PSD and envelope spectra over the whole file, block by block; 0: the
  // whole recording in memory. Other formats are read whole.
  std::uint64_t max_samples = kDefaultMaxSamples;
  // options.threads 0 means one thread per core, except for a recording cut by max_samples: 2, so
  // that the memory bound holds on any machine (each channel in flight holds its transforms).
  AnalyzeOptions options;
};

struct FileAnalysis {
  AnalysisResult result;  // with the notes of the speed and channel setup first
  std::string source;     // the recording's name (RecordingInput::name)
  std::string format;     // the reader's (diag::recording_formats), "memory" for a recording given
  bool cut = false;       // only the first part of the recording was held in memory
  std::map<std::string, std::string> metadata;  // the recording's (timestamps, source file, ...)
  double read_s = 0;                            // wall time of reading the recording [s]
  std::string baseline_error;  // why the baselines could not score it (baseline_required false)
};

// Throws diag::InputError naming the file at fault: the recording ("<path>: ..."), a baseline
// ("--baseline <path>: ..."), the gear baseline ("--gear-baseline <path>: ..."), a speed given
// without a gearbox description, and every error of analyze_recording. Every input is read and
// checked before anything is analysed.
FileAnalysis analyze_file(const AnalyzeRequest& request);

}  // namespace detect
