// Input files: one check before any reader opens a file, so that no reader can hang or read
// without end. A reader library (zlib, libsndfile, matio, HDF5) opens the file by name; what it
// may name is decided here first.
//
// Accepted: a regular file (symbolic links followed). Refused with InputError naming the file:
// a missing path, a directory, a FIFO (its open would wait for a writer forever), a character or
// block device (/dev/zero never ends), a socket, an empty file, and a file larger than the
// caller's limit.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace diag {

// No input of geardiag is larger than this [bytes] (1 TiB): a bound for every size read from a
// file header, so that a corrupted size field cannot make a reader allocate without limit.
inline constexpr std::uint64_t kMaxInputBytes = std::uint64_t{1} << 40;

// Checks that `path` names a non-empty regular file of at most `max_bytes`; returns its size.
// `what` names the input in messages (an option such as "--channels", or empty).
std::uint64_t check_input_file(const std::filesystem::path& path, const std::string& what = {},
                               std::uint64_t max_bytes = kMaxInputBytes);

// Reads a whole text input (JSON descriptions, channel maps) after check_input_file with
// `max_bytes`; refuses a file that changes size while read, and one holding a NUL byte (no
// text has one; a C-string parser would stop there and take the rest for absent).
std::string read_input_file(const std::filesystem::path& path, const std::string& what = {},
                            std::uint64_t max_bytes = std::uint64_t{64} << 20);

// The same for binary inputs (NUL bytes allowed).
std::string read_input_bytes(const std::filesystem::path& path, const std::string& what = {},
                             std::uint64_t max_bytes = std::uint64_t{64} << 20);

}  // namespace diag
