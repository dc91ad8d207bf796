// Output helpers shared by the subcommands.
#pragma once

#include <filesystem>
#include <string>

namespace geardiag {

// Writes to "<path>.tmp-<pid>" and renames into place: never a half-written file. Throws
// diag::InputError naming the path when it cannot.
void write_text_atomic(const std::filesystem::path& path, const std::string& text);

}  // namespace geardiag
