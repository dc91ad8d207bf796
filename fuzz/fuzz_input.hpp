// Shared by the libFuzzer targets (fuzz/README in FUZZING.md): the readers take file names, so
// each input is written to a file in /dev/shm (or the temporary directory) with the extension
// the reader dispatches on. An InputError is the expected answer to a bad input; any other
// exception is a finding (the CLI would exit 3) and aborts, as do crashes, leaks and undefined
// behaviour (AddressSanitizer, UndefinedBehaviorSanitizer).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "diag/error.hpp"
#include "diag/io/recording_frames.hpp"

namespace fuzz {

inline std::filesystem::path input_file(const char* extension, const std::uint8_t* data,
                                        std::size_t size) {
  static const std::filesystem::path dir = std::filesystem::is_directory("/dev/shm")
                                               ? std::filesystem::path("/dev/shm")
                                               : std::filesystem::temp_directory_path();
  const std::filesystem::path path =
      dir / ("geardiag-fuzz-" + std::to_string(::getpid()) + extension);
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

// Opens `path` frame by frame (fs_hz > 0: the rate given) and reads its frames out of order:
// the second half, the first half, the whole.
inline void read_in_frames(const std::filesystem::path& path, double fs_hz) {
  diag::OpenOptions o;
  if (fs_hz > 0) o.fs_hz = fs_hz;
  const diag::OpenedFrames opened = diag::open_recording_frames(path, o);
  const double d = opened.frames->duration_s();
  const double end = std::numeric_limits<double>::infinity();
  opened.frames->frame(0.5 * d, end);
  opened.frames->frame(0, 0.5 * d);
  opened.frames->frame(0, end);
}

template <typename F>
void expect_input_error_only(F&& f) {
  try {
    f();
  } catch (const diag::InputError&) {
    // the expected refusal
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: not an InputError (the CLI would exit 3): %s\n", e.what());
    std::abort();
  }
}

}  // namespace fuzz
