// Output files: one place that checks an output path before the work starts and writes it so that
// a failed run never leaves a half-written file. Used by every geardiag subcommand and by
// write_recording.
//
// What a path may name, after following symbolic links (a link stays a link; its final target is
// written):
//   "-", /dev/stdout        standard output (also /dev/fd/1, /proc/self/fd/1)
//   a regular file or none  write_output_file: written as an anonymous file (O_TMPFILE) in the
//                           target's directory, then linked to the target (or to
//                           "<target>.tmp-<pid>" renamed over an existing target), so a killed
//                           run leaves nothing; falls back to a named "<target>.tmp-<pid>" where
//                           O_TMPFILE or /proc is missing. write_output_file_via (HDF5, which
//                           opens files by name): the named temporary file, removed on any error
//                           and on SIGINT/SIGTERM/SIGHUP; one left by a run killed with SIGKILL is
//                           removed by the next write to the same target. An existing file's
//                           permission bits are kept.
//   a FIFO or a device      opened and written in place: no temporary file, no rename (a FIFO's
//                           open waits for a reader); so is an open file named through /proc
//                           (/dev/stderr, /dev/fd/N)
//   a directory, a socket   refused
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace diag {

enum class OutputKind {
  kStdout,   // "-"
  kRegular,  // a regular file, or none yet: temporary name and rename
  kStream,   // a FIFO, character or block device: written in place
};

struct OutputTarget {
  std::filesystem::path path;    // as given
  std::filesystem::path target;  // symbolic links followed; the file actually written
  OutputKind kind = OutputKind::kRegular;
};

// Checks that `path` can be written, before any long work: for a new or regular file, that the
// target's directory exists and is writable and the target is not a directory; for a FIFO or
// device, that it is writable. `what` names the output in messages (an option such as "--html",
// or empty). Throws InputError "what: path: reason". Does not create or open anything.
OutputTarget check_output_path(const std::filesystem::path& path, const std::string& what = {});

// Writes `bytes` to `path` as described above. Throws InputError naming `what` and the path.
void write_output_file(const std::filesystem::path& path, std::string_view bytes,
                       const std::string& what = {});

// For writers that need a file name of their own (HDF5): `write_file(file)` must create the
// complete file `file`. For a regular target, `file` is the temporary name beside it, renamed into
// place afterwards; for stdout, a FIFO or a device, a temporary file in the system's temporary
// directory whose bytes are then copied to the output and which is always deleted. Exceptions from
// `write_file` propagate after the temporary file is removed.
void write_output_file_via(const std::filesystem::path& path,
                           const std::function<void(const std::filesystem::path& file)>& write_file,
                           const std::string& what = {});

}  // namespace diag
