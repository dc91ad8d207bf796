// The MAT row of the format table: a MATLAB .mat file (levels 4, 5 and 7.3) as a Recording.
// Every numeric real vector variable with more than one element is a channel named after the
// variable; scalar numeric variables go to the metadata, a positive one named ...rpm to the
// recorded speed; CWRU's variable names give their sensor's location (import.hpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "diag/io/import.hpp"
#include "diag/io/recording.hpp"
#include "diag/io/recording_frames.hpp"

namespace diag {

// `where` names the file in errors; `file_size` is its size in bytes (check_input_file).
// Throws InputError: no channel, no sampling rate given, a non-finite sample, and the
// decoder's damage checks (mat_file.hpp).
Recording import_mat(const std::filesystem::path& path, const std::string& where,
                     const ImportOptions& options, std::uint64_t file_size);

// A level 5 or 7.3 file frame by frame (mat_file.hpp's level5_frames and mat73_frames: memory
// holds a frame, not the file), the same channels, metadata and speed as import_mat; null for
// level 4, read whole. Throws InputError as import_mat.
std::shared_ptr<const FrameSource> mat_frames(const std::filesystem::path& path,
                                              const std::string& where,
                                              const ImportOptions& options,
                                              std::uint64_t file_size);

}  // namespace diag
