// CSV and TSV measurements, plain or gzip-compressed (import.hpp says what is read and refused):
// read whole (import_recording) or frame by frame (open_recording_frames), the same rows either
// way.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "diag/io/import.hpp"
#include "diag/io/recording.hpp"
#include "diag/io/recording_frames.hpp"

namespace diag {

// The whole file; `where` names it in messages.
Recording import_csv(const std::filesystem::path& path, const std::string& where,
                     const ImportOptions& options);

// The file read row by row: a first pass counts the rows and checks the time column (uniform
// steps, the rate, as import_csv does), then each frame's rows are parsed when it is asked for
// (in order: a frame before the last one read opens the file again). A frame holds the rows as
// import_recording would give them (names made printable, roles left to inference); a row with
// another number of fields or a field that is not a number is an InputError naming its line; NaN
// and infinite values are kept (the caller sees them: a gap the logger filled so).
std::shared_ptr<const FrameSource> csv_frames(const std::filesystem::path& path,
                                              const ImportOptions& options);

}  // namespace diag
