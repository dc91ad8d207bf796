#include "sound.hpp"

#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/input_file.hpp"
#include "import_common.hpp"

namespace diag {

namespace {

using namespace import_detail;

std::uint32_t little_u32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}

// A RIFF/WAVE file whose "data" chunk declares more bytes than the file holds is refused:
// libsndfile would read the samples present and report that many frames, taking a cut file for
// a short recording. The sizes 0 and 0xFFFFFFFF mean "unknown length" (written while streaming)
// and are left to libsndfile. Other formats are not inspected.
void check_wav_chunks(const std::filesystem::path& path, const std::string& where,
                      std::uint64_t file_size) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[12] = {};
  if (!in.read(reinterpret_cast<char*>(head), sizeof head)) return;
  if (std::memcmp(head, "RIFF", 4) != 0 || std::memcmp(head + 8, "WAVE", 4) != 0) return;
  std::uint64_t offset = 12;
  // Each chunk advances by at least 8 bytes: at most file_size / 8 iterations.
  while (offset + 8 <= file_size) {
    unsigned char chunk[8];
    in.seekg(static_cast<std::streamoff>(offset));
    if (!in.read(reinterpret_cast<char*>(chunk), sizeof chunk)) return;
    const std::uint64_t size = little_u32(chunk + 4);
    const std::uint64_t body = offset + 8;
    if (std::memcmp(chunk, "data", 4) == 0) {
      if (size != 0 && size != 0xFFFFFFFFu && body + size > file_size) {
        throw InputError(format_error(where, "data chunk",
                                      "truncated: the header declares " + std::to_string(size) +
                                          " bytes of samples, the file holds " +
                                          std::to_string(file_size - body)));
      }
      return;
    }
    offset = body + size + (size & 1);  // chunks are padded to an even length
  }
}

struct SoundFileCloser {
  void operator()(SNDFILE* f) const { sf_close(f); }
};
using SoundFile = std::unique_ptr<SNDFILE, SoundFileCloser>;

// The file opened, its header checked: at least one channel and one frame, no more frames than
// its bytes can hold, the data chunk whole.
struct Opened {
  SoundFile file;
  SF_INFO info{};
  std::size_t frames = 0, channels = 0;
};

Opened open_sound(const std::filesystem::path& path, const std::string& where,
                  std::uint64_t file_size) {
  check_wav_chunks(path, where, file_size);
  Opened o;
  o.file.reset(sf_open(path.string().c_str(), SFM_READ, &o.info));
  if (!o.file) {
    throw InputError(format_error(where, "",
                                  std::string("unrecognised format (expected .csv, .csv.gz, .mat, "
                                              ".h5 or a sound file libsndfile reads): ") +
                                      sf_strerror(nullptr)));
  }
  o.frames = static_cast<std::size_t>(std::max<sf_count_t>(o.info.frames, 0));
  o.channels = static_cast<std::size_t>(std::max(o.info.channels, 0));
  // A header's frame count is believed only as far as the file could hold it: 1024 samples per
  // byte bounds even a lossless coder on silence (FLAC's constant subframes), so a corrupted
  // count cannot make this allocate without limit.
  if (o.channels == 0 || o.frames > file_size * 1024 / o.channels) {
    throw InputError(format_error(where, "",
                                  "the header declares " + std::to_string(o.frames) +
                                      " frames of " + std::to_string(o.channels) +
                                      " channels, more than the " + std::to_string(file_size) +
                                      "-byte file can hold"));
  }
  return o;
}

// Frames [first, first + count) of the open file, interleaved; a short read is an InputError.
std::vector<double> read_frames(const Opened& o, const std::string& where, std::size_t first,
                                std::size_t count) {
  std::vector<double> interleaved(count * o.channels);
  if (sf_seek(o.file.get(), static_cast<sf_count_t>(first), SEEK_SET) < 0) {
    throw InputError(format_error(
        where, "",
        "cannot seek to frame " + std::to_string(first) + ": " + sf_strerror(o.file.get())));
  }
  const sf_count_t read =
      sf_readf_double(o.file.get(), interleaved.data(), static_cast<sf_count_t>(count));
  if (read != static_cast<sf_count_t>(count)) {
    throw InputError(format_error(
        where, "",
        "truncated: read " +
            std::to_string(first + static_cast<std::size_t>(std::max<sf_count_t>(read, 0))) +
            " of " + std::to_string(o.frames) + " frames"));
  }
  return interleaved;
}

// Channel c of `interleaved` as the import names it.
Signal channel(const Opened& o, const std::vector<double>& interleaved, std::size_t c,
               const ImportOptions& options) {
  Signal s;
  s.name = "ch" + std::to_string(c);
  s.fs_hz = options.fs_hz.value_or(static_cast<double>(o.info.samplerate));
  const std::size_t n = interleaved.size() / o.channels;
  s.samples.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.samples[i] = interleaved[i * o.channels + c];
  return s;
}

class SoundFrames : public FrameSource {
 public:
  SoundFrames(const std::filesystem::path& path, const ImportOptions& options)
      : where_(path.string()), options_(options) {
    const std::uint64_t file_size = check_input_file(path);
    opened_ = open_sound(path, where_, file_size);
    if (opened_.frames == 0) throw InputError(format_error(where_, "", "empty file (no samples)"));
    check_option_fs(where_, options);
    source_ = path.filename().string();
  }
  std::vector<ChannelExtent> extents() const override {
    const double fs = options_.fs_hz.value_or(static_cast<double>(opened_.info.samplerate));
    return std::vector<ChannelExtent>(opened_.channels, ChannelExtent{opened_.frames, fs});
  }
  Recording frame(double t0_s, double t1_s) const override {
    const double fs = options_.fs_hz.value_or(static_cast<double>(opened_.info.samplerate));
    const std::size_t first = samples_within(opened_.frames, fs, t0_s);
    const std::size_t end = std::max<std::size_t>(first, samples_within(opened_.frames, fs, t1_s));
    // The header's rate places the samples; --fs only renames it (check_option_fs: they agree).
    const std::vector<double> interleaved = read_frames(opened_, where_, first, end - first);
    Recording rec;
    for (std::size_t c = 0; c < opened_.channels; ++c) {
      rec.signals.push_back(channel(opened_, interleaved, c, options_));
    }
    rec.metadata["source_fs_hz"] = std::to_string(opened_.info.samplerate);
    rec.metadata["source"] = source_;
    rec.roles_stated = false;
    return rec;
  }

 private:
  std::string where_;
  ImportOptions options_;
  Opened opened_;
  std::string source_;
};

}  // namespace

Recording import_sound(const std::filesystem::path& path, const std::string& where,
                       const ImportOptions& options, std::uint64_t file_size) {
  const Opened o = open_sound(path, where, file_size);
  const std::vector<double> interleaved = read_frames(o, where, 0, o.frames);
  if (o.frames == 0) throw InputError(format_error(where, "", "empty file (no samples)"));
  check_option_fs(where, options);

  Recording rec;
  for (std::size_t c = 0; c < o.channels; ++c) {
    Signal s = channel(o, interleaved, c, options);
    require_finite(where, "channel " + s.name, 0, s.samples);
    rec.signals.push_back(std::move(s));
  }
  rec.metadata["source_fs_hz"] = std::to_string(o.info.samplerate);
  return rec;
}

std::shared_ptr<const FrameSource> sound_frames(const std::filesystem::path& path,
                                                const ImportOptions& options) {
  // What import_recording says of a file named as HDF5 that is not (the sound reader is the
  // last resort of the format table).
  const std::string name = lower(path.filename().string());
  if (ends_with(name, ".h5") || ends_with(name, ".hdf5")) {
    check_input_file(path);
    throw InputError(format_error(path.string(), "", "not an HDF5 file (or truncated)"));
  }
  return std::make_shared<const SoundFrames>(path, options);
}

}  // namespace diag
