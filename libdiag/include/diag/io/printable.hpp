// Text read from files made safe for a terminal (docs/limits.md): channel names, units,
// locations, metadata and file names reach the screen in messages, lists and reports.
#pragma once

#include <string>
#include <string_view>

#include "diag/io/recording.hpp"

namespace diag {

// Text read from a file (a channel name, unit, location, metadata, a file name) made safe for a
// terminal: control characters (C0, DEL and, in UTF-8, C1: the escape sequences that recolour or
// rewrite a terminal) written as \xNN. Text without them is returned unchanged.
std::string printable_text(std::string_view text);
bool has_control_characters(std::string_view text);

// Every name, unit, location, shaft, mesh and metadata key and value of `rec` through
// printable_text (imports of CSV, WAV and MAT files, whose names are not looked up again).
void make_printable(Recording& rec);

}  // namespace diag
