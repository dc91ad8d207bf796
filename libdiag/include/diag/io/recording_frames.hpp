// A recording read frame by frame: the unit of a whole-log analysis (detect::analyze_file). An
// HDF5 recording stays open and each frame is read from it by blocks, so memory holds one frame
// whatever the file's length; a recording of any other format (CSV, sound, MAT: read whole by
// their readers) or already in memory is cut in frames in memory.
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

class RecordingFrames {
 public:
  // A recording in memory.
  explicit RecordingFrames(std::shared_ptr<const Recording> recording);
  // An HDF5 recording read by blocks from `reader`.
  explicit RecordingFrames(std::shared_ptr<const RecordingReader> reader);

  // The longest channel's duration [s].
  double duration_s() const;
  // The longest frame whose samples keep within the limits (seconds_within_limits); the
  // duration when the whole recording does.
  double frame_seconds(const ReadLimits& limits) const;
  // The frame [t0_s, t1_s). Throws InputError as the reader does (a NaN sample names the file,
  // the channel and the sample's index in the file).
  Recording frame(double t0_s, double t1_s) const;

 private:
  std::shared_ptr<const Recording> recording_;
  std::shared_ptr<const RecordingReader> reader_;
  std::vector<ChannelExtent> extents_;
};

// What open_recording_frames opened and how.
struct OpenedFrames {
  std::shared_ptr<const RecordingFrames> frames;
  std::string format;  // the row of open_recording's format table that read it
};

// Opens `path` with the reader its format calls for (open_recording's table and errors); an
// HDF5 recording is kept open and read frame by frame, the other formats are read whole.
// OpenOptions::limits is not used (the frames are).
OpenedFrames open_recording_frames(const std::filesystem::path& path,
                                   const OpenOptions& options = {});

}  // namespace diag
