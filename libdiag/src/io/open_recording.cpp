#include "diag/io/open_recording.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string_view>

#include "csv.hpp"
#include "diag/error.hpp"
#include "diag/io/import.hpp"
#include "diag/io/recording_frames.hpp"
#include "sound.hpp"

namespace diag {

namespace {

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

// What a row decides from: the file name in lower case and whether the content is HDF5.
struct Probe {
  std::string name;
  bool hdf5 = false;
};

struct Format {
  const char* name;
  bool (*reads)(const Probe&);
  OpenedRecording (*open)(const std::filesystem::path&, const OpenOptions&);
  // Frame by frame without reading the whole file (null: the recording read whole, in frames).
  std::shared_ptr<const RecordingFrames> (*open_frames)(const std::filesystem::path&,
                                                        const OpenOptions&) = nullptr;
};

// The file's rate is the measurement's: a --fs that contradicts it is refused (as the import of
// an HDF5 file does), never silently ignored.
void check_given_rate(const std::filesystem::path& path, const std::string& channel, double fs_hz,
                      const OpenOptions& o) {
  if (o.fs_hz && std::abs(fs_hz - *o.fs_hz) > 1e-3 * fs_hz) {
    throw InputError(format_error(path.string(), "fs_hz",
                                  "the given " + number_text(*o.fs_hz) +
                                      " Hz disagrees with channel " + channel + "'s " +
                                      number_text(fs_hz) + " Hz by more than 0.1 %"));
  }
}

OpenedRecording imported(const std::filesystem::path& path, const OpenOptions& options,
                         const char* format) {
  ImportOptions io;
  io.fs_hz = options.fs_hz;
  return {import_recording(path, io), format, false};
}

bool is_table(const Probe& p) {
  for (const char* e : {".csv", ".tsv", ".txt"}) {
    if (ends_with(p.name, e) || ends_with(p.name, std::string(e) + ".gz")) return true;
  }
  return false;
}

// In the order tried. A .mat file goes to the MAT reader even when it is HDF5 inside (level 7.3
// files are: matio reads them, with their variables' names); any other HDF5 file is a geardiag
// recording. The sound row takes what no other row does: libsndfile knows its formats by content.
constexpr std::array<Format, 4> kFormats = {{
    {"mat", [](const Probe& p) { return ends_with(p.name, ".mat"); },
     [](const std::filesystem::path& path, const OpenOptions& o) {
       return imported(path, o, "mat");
     }},
    {"hdf5", [](const Probe& p) { return p.hdf5; },
     [](const std::filesystem::path& path, const OpenOptions& o) {
       OpenedRecording r;
       r.format = "hdf5";
       r.recording = read_recording(path, o.limits, &r.cut);
       for (const auto* group : {&r.recording.signals, &r.recording.tachos}) {
         for (const Signal& s : *group) check_given_rate(path, s.name, s.fs_hz, o);
       }
       return r;
     },
     [](const std::filesystem::path& path, const OpenOptions& o) {
       auto reader = std::make_shared<const RecordingReader>(path);
       for (const ChannelInfo& c : reader->channels()) check_given_rate(path, c.name, c.fs_hz, o);
       return std::make_shared<const RecordingFrames>(std::move(reader));
     }},
    {"csv", is_table,
     [](const std::filesystem::path& path, const OpenOptions& o) {
       return imported(path, o, "csv");
     },
     [](const std::filesystem::path& path, const OpenOptions& o) {
       ImportOptions io;
       io.fs_hz = o.fs_hz;
       return std::make_shared<const RecordingFrames>(csv_frames(path, io));
     }},
    {"sound", [](const Probe&) { return true; },
     [](const std::filesystem::path& path, const OpenOptions& o) {
       return imported(path, o, "sound");
     },
     [](const std::filesystem::path& path, const OpenOptions& o) {
       ImportOptions io;
       io.fs_hz = o.fs_hz;
       return std::make_shared<const RecordingFrames>(sound_frames(path, io));
     }},
}};

// The first row of the table that reads `path`, called with `open(row)`; every error names the
// file as the user gave it.
template <typename Open>
auto with_format(const std::filesystem::path& path, const OpenOptions& options, Open&& open)
    -> decltype(open(kFormats[0])) {
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
  probe.hdf5 = is_hdf5_file(path);
  for (const Format& f : kFormats) {
    if (!f.reads(probe)) continue;
    try {
      return open(f);
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
  return with_format(path, options, [&](const Format& f) { return f.open(path, options); });
}

OpenedFrames open_recording_frames(const std::filesystem::path& path, const OpenOptions& options) {
  return with_format(path, options, [&](const Format& f) {
    if (f.open_frames) return OpenedFrames{f.open_frames(path, options), f.name};
    OpenOptions whole = options;
    whole.limits = {};
    auto rec = std::make_shared<const Recording>(f.open(path, whole).recording);
    return OpenedFrames{std::make_shared<const RecordingFrames>(std::move(rec)), f.name};
  });
}

Recording open_recording(const std::filesystem::path& path, const OpenOptions& options) {
  return open_recording_as(path, options).recording;
}

std::vector<std::string> recording_formats() {
  std::vector<std::string> names;
  for (const Format& f : kFormats) names.emplace_back(f.name);
  return names;
}

}  // namespace diag
