// Import of measured data into a Recording: CSV (optionally gzip-compressed, ".csv.gz"), WAV and
// other formats libsndfile reads, MATLAB .mat (levels 4, 5 and 7.3), and geardiag HDF5 recordings.
//
// CSV: a header row of column names, then one row of numbers per sample; every row must have as
// many fields as the header. A column named time, t, time_s or time_sec (any case) gives the
// sampling rate (the samples must be uniformly spaced within 0.1 %); otherwise options.fs_hz must
// be given. When both are given and disagree by more than 0.1 % the import is refused.
// MAT: every numeric real vector variable with more than one element becomes a channel named
// after the variable; scalar numeric variables go to the recording's metadata (e.g. X097RPM).
// The sampling rate is not stored in .mat files: options.fs_hz is required.
// Variables named as in the CWRU bearing data (X<nnn>_DE_time, _FE_time, _BA_time) get the
// location drive_end, fan_end, base (a note says so); nothing else is read from a name.
// WAV: one channel per audio channel, named ch0, ch1, ...; fs from the file unless overridden.
//
// Damage is refused, never read as data (docs/limits.md): a path that is not a
// regular file (FIFO, device, directory) before any reader opens it; CSV lines holding a NUL byte;
// a corrupt or truncated gzip stream, or a ".gz" that is not gzip; a WAV "data" chunk shorter than
// its header says; a .mat file whose declared sizes (dimensions, byte counts, compressed sizes) the
// bytes present do not bear out (levels 4 and 5 are decoded by mat_file.cpp, level 7.3, an HDF5
// file, by mat73.cpp through the checks every HDF5 file passes: docs/limits.md).
#pragma once

#include <filesystem>
#include <optional>

#include "diag/io/recording.hpp"

namespace diag {

struct ImportOptions {
  std::optional<double> fs_hz;  // sampling rate [Hz], > 0; required when the file has none
};

// open_recording(path, {options.fs_hz}) (open_recording.hpp): the format table chooses the reader
// from the content (HDF5 signature) and the file name ending. Throws InputError naming the file
// and the reason: empty file, ragged CSV rows, non-numeric fields, NaN/Inf samples, missing or
// non-positive sampling rate, unreadable format, and the damage above.
Recording import_recording(const std::filesystem::path& path, const ImportOptions& options = {});

}  // namespace diag
