// Internal to libdiag's readers: the crash guard. The HDF5 library (1.10) can crash or loop on a
// corrupted file, e.g. on a global-heap entry behind a variable-length string attribute; no check
// of ours can come before its own reads. So every untrusted HDF5 file is first read by a forked
// child process (run_guarded): a child killed by a signal, or not done within kGuardSeconds,
// means the file would crash or hang this process, and the file is refused. A child that merely
// finds an error lets the parent read on and report that error itself. The child reads the file
// through the descriptor the parent opened (hdf5_file.hpp), so both read the same file.
#pragma once

#include <functional>
#include <string>

namespace diag::hdf5_detail {

inline constexpr int kGuardSeconds = 30;

// Runs `body` (the reads of the file) in a forked child first. Returns true when the child ran
// `body` to its end without an error; false when it found an error (the parent then reads and
// reports it), or when called inside a guard's child (nothing to guard twice). Throws InputError
// naming `where` when the child crashed or hung, and when no child can be made (fork fails: the
// process limit reached): the file is then refused, not read without the guard.
bool run_guarded(const std::string& where, const std::function<void()>& body);

// True in a guard's child.
bool in_guard_child();

// Tests only: `fork_call` replaces fork() (nullptr: fork() again), and `before_fork` (when set)
// runs in this process before each fork, e.g. to rename another file over the one being read.
void set_guard_test_hooks(int (*fork_call)(), std::function<void()> before_fork);

}  // namespace diag::hdf5_detail
