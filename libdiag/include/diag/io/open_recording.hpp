// One door for reading a recording, whatever its format: a table of formats (open_recording.cpp,
// one row each) chooses the reader from the file's content (the HDF5 signature) and its name's
// ending, and every reader gives the same diag::Recording.
//
//   format       | file                                   | reader (libdiag/src/io/)
//   MAT          | .mat (levels 4, 5 and 7.3)             | mat.cpp (mat_file.cpp, mat73.cpp)
//   HDF5         | a geardiag recording (the signature)   | read_recording (hdf5.hpp), by blocks
//   CSV          | .csv .tsv .txt, each also .gz          | csv.cpp
//   sound        | .wav and whatever libsndfile reads     | sound.cpp
//
// Every row's recording ends the same way: the file named in the metadata as `source`, names
// made printable; a measured format's channels have no stated role (Recording::roles_stated).
// What each format reads and refuses: import.hpp.
//
// Only an HDF5 recording can be read in part (OpenOptions::limits: its first seconds, read by
// blocks so that memory stays bounded); the other formats are read whole. Frame by frame
// (recording_frames.hpp), HDF5, CSV, sound and MAT (level 5 and 7.3) files are read a frame at
// a time.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "diag/io/hdf5.hpp"
#include "diag/io/recording.hpp"

namespace diag {

struct OpenOptions {
  // Sampling rate [Hz], > 0: needed by CSV files without a time column and by MAT files (which
  // store none); checked against the file's own rate when it has one (import.hpp).
  std::optional<double> fs_hz;
  // The part of a long HDF5 recording kept in memory (hdf5.hpp, ReadLimits); the default keeps
  // all of it. Other formats are read whole whatever the limits.
  ReadLimits limits;
};

// What open_recording read and how.
struct OpenedRecording {
  Recording recording;
  std::string format;  // the row of the format table that read it: "hdf5", "mat", "csv", "sound"
  bool cut = false;    // only the first part of an HDF5 recording was read (OpenOptions::limits)
};

// Reads `path` with the reader its format calls for. Throws InputError naming the file (the path
// as given) and the reason: no such file, not a regular file, a format none of the rows reads,
// and every error of the format's reader.
OpenedRecording open_recording_as(const std::filesystem::path& path,
                                  const OpenOptions& options = {});

// The recording alone: open_recording_as(path, options).recording.
Recording open_recording(const std::filesystem::path& path, const OpenOptions& options = {});

// The names of the format table's rows, in the order they are tried.
std::vector<std::string> recording_formats();

}  // namespace diag
