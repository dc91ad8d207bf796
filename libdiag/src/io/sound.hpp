// Sound files (WAV, FLAC, AIFF... whatever libsndfile reads; import.hpp says what is read and
// refused): read whole (import_recording) or frame by frame (open_recording_frames), the same
// samples either way.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "diag/io/import.hpp"
#include "diag/io/recording.hpp"
#include "diag/io/recording_frames.hpp"

namespace diag {

// The whole file, `file_size` bytes; `where` names it in messages.
Recording import_sound(const std::filesystem::path& path, const std::string& where,
                       const ImportOptions& options, std::uint64_t file_size);

// The file kept open and each frame read from it (a seek, then the frame's samples): memory holds
// one frame whatever the file's length. The header is checked as import_sound checks it; a frame
// holds the channels as import_recording names them (ch0, ch1, ...; roles left to inference).
// Non-finite samples (a float file) are kept: the caller sees them.
std::shared_ptr<const FrameSource> sound_frames(const std::filesystem::path& path,
                                                const ImportOptions& options);

}  // namespace diag
