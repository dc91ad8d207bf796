// Internal to libdiag's HDF5 code: how every HDF5 file is opened and made.
//
// Reading: an HDF5 file a user brings (a recording, a face-gear table, a MAT 7.3 file) is opened
// ONCE, as a descriptor (Hdf5Source), and HDF5 reads it through that descriptor (a small virtual
// file driver of ours: pread on the descriptor). The crash guard's child (crash_guard.hpp) and the
// parent read the same open file, so a file renamed over the path between the two is not read:
// neither by the child nor the parent (HDF5's own drivers open by name, and /proc/self/fd/N is a
// name, resolved again). Every open goes through Hdf5Source::open, which refuses, before anything
// reads data (check_structure):
//   - external links, user-defined links (they name other files),
//   - external storage (a dataset's bytes kept in other files: /etc/passwd, /dev/urandom, a FIFO),
//   - virtual datasets (their bytes come from other files' datasets),
//   - chunks that were never written (HDF5 would read its fill value, zeros, as data),
//   - declared sizes over kMaxInputBytes, or more than the bytes stored could hold (stored
//     bytes for unfiltered data, 1032 times them for filtered data: deflate's limit, RFC 1951).
//
// Writing: an HDF5 file is made in memory by the same driver (hdf5_file_bytes) and its bytes
// written by write_output_file (diag/io/output_file.hpp): HDF5 never writes to the disk, so a
// full disk fails the one write of the finished bytes (exit 2, the previous file intact, no
// temporary file left) instead of failing inside the HDF5 library, whose failed close leaves the
// file open and crashed its shutdown at exit.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "hdf5_handle.hpp"

namespace diag::hdf5_detail {

class Hdf5Source {
 public:
  // Opens `path` read-only after check_input_file (a regular file, not empty). With
  // `signature_at_start`, the file must begin with the HDF5 signature (MAT 7.3 files keep a
  // 512-byte header first). Throws InputError naming the file.
  Hdf5Source(const std::filesystem::path& path, bool signature_at_start);
  ~Hdf5Source();
  Hdf5Source(const Hdf5Source&) = delete;
  Hdf5Source& operator=(const Hdf5Source&) = delete;

  const std::string& where() const { return where_; }
  int fd() const { return fd_; }
  std::uint64_t size() const { return size_; }

  // The HDF5 file, read-only, read through the descriptor, after check_structure. Throws
  // InputError: not HDF5 (or truncated), or refused by check_structure.
  Hid open() const;

 private:
  std::string where_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// What Hdf5Source::open refuses (see above), for every object of the file. Throws InputError
// naming the file and the object.
void check_structure(hid_t file, const std::string& where, std::uint64_t file_size);

// Makes an HDF5 file in memory: `fill(file)` writes it (a file created with `fcpl` and the
// access properties `fapl`, whose driver is replaced by the in-memory one); the close is checked.
// Returns the file's bytes. `where` names the output in messages.
std::string hdf5_file_bytes(const std::string& where, hid_t fcpl, hid_t fapl,
                            const std::function<void(hid_t file)>& fill);

}  // namespace diag::hdf5_detail
