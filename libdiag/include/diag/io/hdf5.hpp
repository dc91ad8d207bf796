// Recordings on disk: HDF5, readable by h5py and MATLAB without this project.
//
//   /                      attributes: format ("geardiag-recording"), format_version (2),
//                          creator ("geardiag <version>"), git_revision, input_speed_rpm (double,
//                          when known), roles_stated (int: 0 when an import left channel roles
//                          to inference, Recording::roles_stated), plus Recording::metadata
//   /signals/<name>        float64 1-D, chunked, deflate-compressed; attributes fs_hz (double),
//                          unit, direction, location, role, shaft, mesh (strings), ppr (int)
//   /tacho/<name>          same layout, role "tacho", ppr >= 1 (format 1: named after the shaft)
//
// Format 1 (no role, shaft, mesh, ppr) is still read: /tacho channels are once-per-revolution
// tachos of the shaft in `location`; direction "angle" is an angle; a direction along/normal to
// a line of action, horizontal or vertical is vibration; a channel without direction is vibration
// in an imported file and, in a simulator file, a force (unit N), displacement (m) or other (the
// contact state); the simulator's location "<shaft>_bearing<k>" gives the shaft and its name
// suffix "_<mesh>" the mesh. Recording::notes says so.
//   /gearbox               string dataset: the gearbox description JSON (absent when unknown)
//   /truth                 string dataset: ground truth JSON (simulated recordings only)
//
// Writing: the file is made in memory and its bytes written by write_output_file
// (diag/io/output_file.hpp): a regular file is written as a temporary file beside the target and
// renamed into place, so a failed write (a full disk included) leaves no half-written file under
// the requested name, the previous file intact and no temporary file; a symbolic link is written
// through, a FIFO, device or "-" (stdout) receives the bytes of the finished file.
//
// Reading treats every file as untrusted (docs/limits.md): the file is opened once and read
// through that descriptor, by a forked child first (the crash guard: a crash or endless loop inside
// the HDF5 library refuses the file instead of killing or hanging the program; when no child can
// be made, the file is refused) and then by this process. FIFOs and devices are refused before
// anything opens them; external links, external storage and virtual datasets (data kept in other
// files), chunks never written, declared sizes the stored bytes cannot hold, soft links,
// zero-length or non-1-D channels, a /gearbox or /truth that is not JSON, an empty /signals and any
// HDF5 error on the read path are InputErrors naming the file and object (exit 2). When the samples
// are at most 16 MiB the child decodes them into memory shared with the parent, which copies them
// instead of decoding them again. Channels stored as geardiag writes them (float64, shuffle +
// deflate) are decoded by geardiag from their chunks' stored bytes, with libdeflate when built in
// (diag/io/hdf5_inflate.hpp); a chunk whose stored bytes do not decode to its size is refused.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "diag/io/recording.hpp"

namespace diag {

struct Hdf5WriteOptions {
  std::size_t chunk_samples = 65536;  // chunk length [samples], >= 1 (capped at the length)
  int deflate_level = 4;              // gzip level, 0 (off) ... 9
};

void write_recording(const std::filesystem::path& path, const Recording& rec,
                     const Hdf5WriteOptions& options = {});

// Reads everything into memory. Throws InputError naming the file for a missing, truncated or
// non-HDF5 file, a file that is not a geardiag recording, or NaN/Inf samples.
Recording read_recording(const std::filesystem::path& path);

// A bound on the samples read_recording(path, limits) keeps in memory.
struct ReadLimits {
  std::uint64_t max_samples = UINT64_MAX;          // all channels together (tachos included) ...
  std::uint64_t kept_channel_samples = 0;          // ... unless no channel is longer than this
  std::uint64_t max_channel_samples = UINT64_MAX;  // any one channel, always
};

// The recording's first T seconds, every channel (tachos too) cut at its first
// min(length, floor(T fs)) samples: T is the longest duration with no channel over
// max_channel_samples and either at most max_samples in all or no channel over
// kept_channel_samples (so that many short channels are not cut: memory then grows with the
// channel count, not with the length), or the whole record when it fits (then the result equals
// read_recording(path)). Memory is bounded by the limits whatever the file's length: the samples
// are read by hyperslab (read_block), never the whole channel. When cut, rec.notes says so (the
// excerpt's and the record's durations) and *cut (when given) is set.
Recording read_recording(const std::filesystem::path& path, const ReadLimits& limits,
                         bool* cut = nullptr);

// A channel's length [samples] and rate [Hz]: what the limits are applied to.
struct ChannelExtent {
  std::uint64_t length = 0;
  double fs_hz = 0;
};

// The samples of a channel of `length` samples at fs_hz within its first t seconds: floor(t fs)
// within [0, length], all of them when t is infinite. Sample n is at n / fs_hz, so the samples of
// [t0, t1) are [samples_within(t0), samples_within(t1)): consecutive spans hold each sample once.
std::uint64_t samples_within(std::uint64_t length, double fs_hz, double t);

// The longest duration T [s] whose first floor(T fs) samples of every channel keep within the
// limits (as read_recording(path, limits) applies them); infinite when every sample does.
double seconds_within_limits(std::span<const ChannelExtent> channels, const ReadLimits& limits);

// A channel of a file: what it is (format 1: role inferred, infer_format1_roles), where, how long.
struct ChannelInfo : ChannelIdentity {
  std::string group;         // "signals" or "tacho"
  std::uint64_t length = 0;  // samples
};

struct SurveyedSamples;
struct DecodedChunk;
namespace hdf5_detail {
class Hdf5Source;
}

// Streaming access: channel metadata without loading samples, and reading by blocks so that
// detectors can process files larger than memory.
class RecordingReader {
 public:
  explicit RecordingReader(const std::filesystem::path& path);  // throws InputError
  ~RecordingReader();
  RecordingReader(const RecordingReader&) = delete;
  RecordingReader& operator=(const RecordingReader&) = delete;

  const std::vector<ChannelInfo>& channels() const { return channels_; }
  // `name` is a channel name, looked up in /signals then /tacho, or "signals/NAME" or
  // "tacho/NAME" to pick the group. Throws InputError when unknown.
  const ChannelInfo& channel(const std::string& name) const;
  std::string gearbox_json() const;
  std::string truth_json() const;
  std::map<std::string, std::string> metadata() const;
  // The format's own root attributes as stored (format, format_version, creator, git_revision),
  // as text; absent ones are left out.
  std::map<std::string, std::string> format_attributes() const;
  int format_version() const { return format_version_; }
  double speed_rpm() const;   // 0 when the file stores none
  bool roles_stated() const;  // the root's roles_stated (format 2; true when absent)
  // Reads samples [offset, offset + out.size()) of a channel into `out`. Throws InputError when
  // the range is past the end or a sample is NaN/Inf. One call at a time per reader (HDF5 is not
  // thread-safe; the reader keeps the last chunk it decoded for the next block).
  void read_block(const std::string& name, std::uint64_t offset, std::span<double> out) const;
  const std::filesystem::path& path() const { return path_; }

 private:
  void open_file();
  void open_channels();
  void read_samples(const std::string& what, std::uint64_t offset, std::span<double> out) const;

  std::filesystem::path path_;
  // The file, opened once (hdf5_file.hpp): HDF5 reads it through this descriptor.
  std::shared_ptr<const hdf5_detail::Hdf5Source> source_;
  std::int64_t file_ = -1;  // hid_t
  std::vector<ChannelInfo> channels_;
  int format_version_ = 1;
  // The samples the survey child read and checked (crash_guard.hpp), when it read
  // them: read_block copies from there instead of decoding the file a second time.
  std::shared_ptr<const SurveyedSamples> surveyed_;
  // The last chunk decoded, for the next block (read_block is not for concurrent use, as HDF5).
  std::shared_ptr<DecodedChunk> decoded_;
};

// The samples [floor(t0_s fs), floor(t1_s fs)) of every channel of the reader's file (tachos too;
// a channel shorter than that, what it holds of them), with the file's gearbox, truth, metadata
// and speed: one frame of a long recording, read by blocks. Throws InputError as read_recording.
Recording read_recording_span(const RecordingReader& reader, double t0_s, double t1_s);

// True when the file starts with the HDF5 signature.
bool is_hdf5_file(const std::filesystem::path& path);

}  // namespace diag
