// Internal to libdiag's HDF5 code: the one owner of HDF5 identifiers and the error helpers every
// HDF5 reader and writer of the project shares (recordings, arrays, curves, MAT 7.3 files).
#pragma once

#include <hdf5.h>

#include <mutex>
#include <string>
#include <utility>

namespace diag::hdf5_detail {

// The HDF5 library is entered by one thread at a time, process-wide: every reader and writer holds
// this lock while it calls the library (a recursive lock, so nested calls are free). It keeps
// many files read at once on several threads (`geardiag batch`'s workers) apart, whether or not
// the installed library was built thread-safe, and it is held when the crash guard forks
// (crash_guard.hpp), so that no other thread is inside the library when the child is made. It
// also silences the library's own error printing on each thread that takes it (the printing is
// per thread in a thread-safe build). In a guard's child (one thread) it is not taken.
[[nodiscard]] std::unique_lock<std::recursive_mutex> hold_hdf5();

// Owns an HDF5 identifier and closes it with the matching H5?close (H5Fclose, H5Dclose, ...).
class Hid {
 public:
  using Closer = herr_t (*)(hid_t);
  Hid(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Hid() { close(); }
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  Hid(Hid&& other) noexcept : id_(std::exchange(other.id_, -1)), closer_(other.closer_) {}
  Hid& operator=(Hid&& other) noexcept {
    if (this != &other) {
      close();
      id_ = std::exchange(other.id_, -1);
      closer_ = other.closer_;
    }
    return *this;
  }

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Gives up ownership without closing.
  hid_t release() { return std::exchange(id_, -1); }
  // Returns the result of the close call (negative on failure; 0 when nothing to close).
  herr_t close() {
    herr_t result = 0;
    if (id_ >= 0) {
      const auto lock = hold_hdf5();
      result = closer_(id_);
    }
    id_ = -1;
    return result;
  }

 private:
  hid_t id_;
  Closer closer_;
};

// HDF5 prints its error stack to stderr by default; geardiag reports errors itself.
void silence_hdf5();

// The innermost message of the current HDF5 error stack ("" when empty), e.g. "unable to open
// file". Call it right after the failing HDF5 call.
std::string hdf5_error_detail();

// std::runtime_error "where: what: HDF5 error: <detail>" (readers turn it into an InputError).
[[noreturn]] void throw_hdf5(const std::string& where, const std::string& what);

inline void check(herr_t status, const std::string& where, const std::string& what) {
  if (status < 0) throw_hdf5(where, what);
}

inline Hid checked(hid_t id, Hid::Closer closer, const std::string& where,
                   const std::string& what) {
  if (id < 0) throw_hdf5(where, what);
  return Hid(id, closer);
}

}  // namespace diag::hdf5_detail
