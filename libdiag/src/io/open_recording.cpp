#include "diag/io/open_recording.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <memory>
#include <new>
#include <string_view>

#include "csv.hpp"
#include "diag/error.hpp"
#include "diag/io/import.hpp"
#include "diag/io/input_file.hpp"
#include "diag/io/printable.hpp"
#include "diag/io/recording_frames.hpp"
#include "diag/util/number_format.hpp"
#include "import_common.hpp"
#include "mat.hpp"
#include "sound.hpp"

namespace diag {

namespace {

using import_detail::ends_with;

// What a row decides from: the file name in lower case and whether the content is HDF5; and the
// file's size (check_input_file).
struct Probe {
  std::string name;
  bool hdf5 = false;
  std::uint64_t size = 0;
};

struct Format {
  const char* name;
  bool (*reads)(const Probe&);
  OpenedRecording (*open)(const std::filesystem::path&, const Probe&, const OpenOptions&);
  // Frame by frame without reading the whole file (null: the recording read whole, in frames).
  std::shared_ptr<const RecordingFrames> (*open_frames)(const std::filesystem::path&, const Probe&,
                                                        const OpenOptions&) = nullptr;
};

// The file's rate is the measurement's: a --fs that contradicts it is refused, never silently
// ignored.
void check_given_rate(const std::filesystem::path& path, const std::string& channel, double fs_hz,
                      const OpenOptions& o) {
  if (o.fs_hz && !import_detail::rates_agree(*o.fs_hz, fs_hz)) {
    throw InputError(format_error(path.string(), "fs_hz",
                                  "the given " + format_shortest(*o.fs_hz) +
                                      " Hz disagrees with channel " + channel + "'s " +
                                      format_shortest(fs_hz) + " Hz by more than 0.1 %"));
  }
}

// What every whole read ends with: the file named as the recording's source (unless it names
// one), names and labels made printable (no escape sequence from a file reaches a terminal).
OpenedRecording finished(const std::filesystem::path& path, Recording rec, const char* format,
                         bool cut = false) {
  rec.metadata.try_emplace("source", path.filename().string());
  make_printable(rec);
  return {std::move(rec), format, cut};
}

// A measured format read whole by `read(path, where, options, file_size)`. Measured files say
// nothing of what their columns are: vibration until a channel map, --tacho or tacho inference
// (channels.hpp) says otherwise.
template <typename Read>
OpenedRecording measured(const std::filesystem::path& path, const Probe& probe,
                         const OpenOptions& options, const char* format, Read&& read) {
  ImportOptions io;
  io.fs_hz = options.fs_hz;
  Recording rec;
  try {
    rec = read(path, path.string(), io, probe.size);
  } catch (const std::bad_alloc&) {
    // What a file declares was checked against its bytes; a file that is all data can still be
    // larger than this machine's memory.
    throw InputError(format_error(path.string(), "",
                                  std::to_string(probe.size) +
                                      " bytes whose samples do not fit in memory; cut the file "
                                      "or use a machine with more memory"));
  }
  rec.roles_stated = false;
  return finished(path, std::move(rec), format);
}

// HDF5 by content, or by name: a file named .h5 or .hdf5 that is not HDF5 (or is truncated) is
// refused as such.
bool is_hdf5_named(const Probe& p) {
  return p.hdf5 || ends_with(p.name, ".h5") || ends_with(p.name, ".hdf5");
}

void require_hdf5(const std::filesystem::path& path, const Probe& p) {
  if (!p.hdf5) throw InputError(format_error(path.string(), "", "not an HDF5 file (or truncated)"));
}

bool is_table(const Probe& p) {
  for (const char* e : {".csv", ".tsv", ".txt"}) {
    if (ends_with(p.name, e) || ends_with(p.name, std::string(e) + ".gz")) return true;
  }
  return false;
}

// In the order tried. A .mat file goes to the MAT reader even when it is HDF5 inside (level 7.3
// files are: mat73.cpp reads them, with their variables' names); any other HDF5 file is a
// geardiag recording. The sound row takes what no other row does: libsndfile knows its formats
// by content. A file named .h5 or .hdf5 whose content is not HDF5 is said to be so by the HDF5
// row rather than handed to the sound reader.
constexpr std::array<Format, 4> kFormats = {{
    {"mat", [](const Probe& p) { return ends_with(p.name, ".mat"); },
     [](const std::filesystem::path& path, const Probe& p, const OpenOptions& o) {
       return measured(path, p, o, "mat", import_mat);
     },
     [](const std::filesystem::path& path, const Probe& p, const OpenOptions& o) {
       ImportOptions io;
       io.fs_hz = o.fs_hz;
       if (auto frames = mat_frames(path, path.string(), io, p.size)) {  // levels 5 and 7.3
         return std::make_shared<const RecordingFrames>(std::move(frames));
       }
       auto rec =
           std::make_shared<const Recording>(measured(path, p, o, "mat", import_mat).recording);
       return std::make_shared<const RecordingFrames>(std::move(rec));
     }},
    {"hdf5", is_hdf5_named,
     [](const std::filesystem::path& path, const Probe& p, const OpenOptions& o) {
       require_hdf5(path, p);
       bool cut = false;
       Recording rec = read_recording(path, o.limits, &cut);
       for (const auto* group : {&rec.signals, &rec.tachos}) {
         for (const Signal& s : *group) check_given_rate(path, s.name, s.fs_hz, o);
       }
       return finished(path, std::move(rec), "hdf5", cut);
     },
     [](const std::filesystem::path& path, const Probe& p, const OpenOptions& o) {
       require_hdf5(path, p);
       auto reader = std::make_shared<const RecordingReader>(path);
       for (const ChannelInfo& c : reader->channels()) check_given_rate(path, c.name, c.fs_hz, o);
       return std::make_shared<const RecordingFrames>(std::move(reader));
     }},
    {"csv", is_table,
     [](const std::filesystem::path& path, const Probe& p, const OpenOptions& o) {
       return measured(
           path, p, o, "csv",
           [](const std::filesystem::path& f, const std::string& where, const ImportOptions& io,
              std::uint64_t) { return import_csv(f, where, io); });
     },
     [](const std::filesystem::path& path, const Probe&, const OpenOptions& o) {
       ImportOptions io;
       io.fs_hz = o.fs_hz;
       return std::make_shared<const RecordingFrames>(csv_frames(path, io));
     }},
    {"sound", [](const Probe&) { return true; },
     [](const std::filesystem::path& path, const Probe& p, const OpenOptions& o) {
       return measured(path, p, o, "sound", import_sound);
     },
     [](const std::filesystem::path& path, const Probe&, const OpenOptions& o) {
       ImportOptions io;
       io.fs_hz = o.fs_hz;
       return std::make_shared<const RecordingFrames>(sound_frames(path, io));
     }},
}};

// The first row of the table that reads `path`, called with `open(row)`; every error names the
// file as the user gave it.
template <typename Open>
auto with_format(const std::filesystem::path& path, const OpenOptions& options, Open&& open)
    -> decltype(open(kFormats[0], Probe{})) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(file + ": no such file");
  if (options.fs_hz && !(*options.fs_hz > 0 && std::isfinite(*options.fs_hz))) {
    throw InputError(format_error(file, "fs_hz", "must be a sampling rate > 0 Hz"));
  }
  Probe probe;
  probe.name = path.filename().string();
  std::transform(probe.name.begin(), probe.name.end(), probe.name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  // A FIFO, a device (/dev/zero, also through a link), a directory: refused before any reader
  // opens them, so that none can wait or read without end.
  probe.size = check_input_file(path);
  probe.hdf5 = is_hdf5_file(path);
  for (const Format& f : kFormats) {
    if (!f.reads(probe)) continue;
    try {
      return open(f, probe);
    } catch (const InputError& e) {
      const std::string what = e.what();
      if (what.find(file) != std::string::npos) throw;
      throw InputError(file + ": " + what);
    }
  }
  throw InputError(file + ": no reader for this file");  // unreachable: the sound row takes all
}

}  // namespace

OpenedRecording open_recording_as(const std::filesystem::path& path, const OpenOptions& options) {
  return with_format(path, options,
                     [&](const Format& f, const Probe& p) { return f.open(path, p, options); });
}

OpenedFrames open_recording_frames(const std::filesystem::path& path, const OpenOptions& options) {
  return with_format(path, options, [&](const Format& f, const Probe& p) {
    if (f.open_frames) return OpenedFrames{f.open_frames(path, p, options), f.name};
    OpenOptions whole = options;
    whole.limits = {};
    auto rec = std::make_shared<const Recording>(f.open(path, p, whole).recording);
    return OpenedFrames{std::make_shared<const RecordingFrames>(std::move(rec)), f.name};
  });
}

Recording open_recording(const std::filesystem::path& path, const OpenOptions& options) {
  return open_recording_as(path, options).recording;
}

Recording import_recording(const std::filesystem::path& path, const ImportOptions& options) {
  OpenOptions o;
  o.fs_hz = options.fs_hz;
  return open_recording(path, o);
}

std::vector<std::string> recording_formats() {
  std::vector<std::string> names;
  for (const Format& f : kFormats) names.emplace_back(f.name);
  return names;
}

}  // namespace diag
