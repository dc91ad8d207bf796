// A recording read frame by frame: the unit of a whole-log analysis (detect::analyze_file). An
// HDF5 recording stays open and each frame is read from it by blocks; a CSV file (plain or gzip)
// is read row by row, each frame parsed when it is asked for; a sound file (WAV, FLAC...) is kept
// open and each frame read after a seek; a MAT file of level 5 or 7.3 is kept open and each
// frame read from its vector variables (mat_file.hpp); memory holds one frame whatever the file's
// length. A MAT file of level 4 (read whole by its reader) or a recording already in memory is
// cut in frames in memory.
//
// A frame [t0, t1) holds the samples floor(t0 fs) ... floor(t1 fs) - 1 of every channel (tachos
// too), so consecutive frames hold every sample once; it carries the recording's gearbox, truth,
// metadata, recorded speed and the reader's notes (what it inferred of the channels).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "diag/io/hdf5.hpp"
#include "diag/io/open_recording.hpp"
#include "diag/io/recording.hpp"

namespace diag {

// Where frames come from: a reader of one format.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Every channel's length and rate, signals then tachos.
  virtual std::vector<ChannelExtent> extents() const = 0;
  // The frame [t0_s, t1_s) (t1_s may be infinite: to the end). Throws InputError naming the file,
  // the channel or line and the reason. Not for concurrent calls (a caller reading frames on
  // several threads reads them one at a time).
  virtual Recording frame(double t0_s, double t1_s) const = 0;
};

class RecordingFrames {
 public:
  // A recording in memory.
  explicit RecordingFrames(std::shared_ptr<const Recording> recording);
  // An HDF5 recording read by blocks from `reader`.
  explicit RecordingFrames(std::shared_ptr<const RecordingReader> reader);
  // Any other source.
  explicit RecordingFrames(std::shared_ptr<const FrameSource> source);

  // The longest channel's duration [s].
  double duration_s() const;
  // The longest frame whose samples keep within the limits (seconds_within_limits); the
  // duration when the whole recording does.
  double frame_seconds(const ReadLimits& limits) const;
  // The frame [t0_s, t1_s). Throws InputError as the source does.
  Recording frame(double t0_s, double t1_s) const { return source_->frame(t0_s, t1_s); }

 private:
  std::shared_ptr<const FrameSource> source_;
  std::vector<ChannelExtent> extents_;
};

// What open_recording_frames opened and how.
struct OpenedFrames {
  std::shared_ptr<const RecordingFrames> frames;
  std::string format;  // the row of open_recording's format table that read it
};

// Opens `path` with the reader its format calls for (open_recording's table and errors): an HDF5
// recording, a sound file or a MAT file of level 5 or 7.3 is kept open and read frame by frame,
// a CSV file row by row, a MAT file of level 4 is read whole. OpenOptions::limits is not used
// (the frames are).
OpenedFrames open_recording_frames(const std::filesystem::path& path,
                                   const OpenOptions& options = {});

}  // namespace diag
