// Output helpers shared by the subcommands. The checks and writers themselves live in
// diag/io/output_file.hpp (shared with write_recording).
#pragma once

#include <filesystem>
#include <iostream>
#include <streambuf>
#include <string>
#include <vector>

#include "diag/io/output_file.hpp"

namespace geardiag {

// Checks an output path given to `option` before the work starts (exit 2 at once, not after a
// long analysis). Returns true when the output is stdout ("-").
bool check_output(const std::string& path, const std::string& option);

// Writes `text` to `path` (see diag/io/output_file.hpp: temporary name and rename for a regular
// file, written through a symbolic link, in place for a FIFO or device, "-" for stdout). Throws
// diag::InputError naming `option` and the path.
void write_output(const std::string& path, const std::string& text, const std::string& option = {});

// The former name, kept for existing callers.
void write_text_atomic(const std::filesystem::path& path, const std::string& text);

// Prints each warning as "geardiag <command>: warning: <text>" to stderr.
void print_warnings(const std::vector<std::string>& warnings, const std::string& command);

// While alive (and `active`), std::cout prints to stderr, so that a report sent to stdout ("-")
// is not mixed with the readable summary.
class CoutToStderr {
 public:
  explicit CoutToStderr(bool active)
      : saved_(active ? std::cout.rdbuf(std::cerr.rdbuf()) : nullptr) {}
  ~CoutToStderr() {
    if (saved_) std::cout.rdbuf(saved_);
  }
  CoutToStderr(const CoutToStderr&) = delete;
  CoutToStderr& operator=(const CoutToStderr&) = delete;

 private:
  std::streambuf* saved_;
};

}  // namespace geardiag
