#include "crash_guard.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

#include "diag/error.hpp"
#include "hdf5_handle.hpp"

namespace diag::hdf5_detail {

namespace {

bool in_child = false;
constexpr int kChildFoundAnError = 97;  // the child's exit code for an exception it caught
int (*test_fork)() = nullptr;
std::function<void()>& test_before_fork() {
  static std::function<void()> hook;
  return hook;
}

}  // namespace

bool in_guard_child() { return in_child; }

void set_guard_test_hooks(int (*fork_call)(), std::function<void()> before_fork) {
  test_fork = fork_call;
  test_before_fork() = std::move(before_fork);
}

bool run_guarded(const std::string& where, const std::function<void()>& body) {
  if (in_child) return false;
  if (test_before_fork()) test_before_fork()();
  // Made with the library held: no other thread is inside it, so the child finds it in order.
  auto library = hold_hdf5();
  std::fflush(nullptr);
  const pid_t pid = test_fork != nullptr ? test_fork() : ::fork();
  if (pid == 0) {
    (void)library.release();  // the child's copy names the parent's thread: never unlocked
  } else {
    library = {};
  }
  if (pid < 0) {
    const int err = errno;
    throw InputError(format_error(
        where, "",
        std::string("cannot start the process that reads the file first (fork: ") +
            std::strerror(err) +
            "), so a damaged file could crash geardiag: refused; retry with fewer processes"));
  }
  if (pid == 0) {
    in_child = true;
    // The child ends itself after kGuardSeconds (SIGALRM's default action), so the parent can
    // wait for it without polling.
    ::signal(SIGALRM, SIG_DFL);
    sigset_t alarm_only;
    sigemptyset(&alarm_only);
    sigaddset(&alarm_only, SIGALRM);
    ::sigprocmask(SIG_UNBLOCK, &alarm_only, nullptr);
    ::alarm(kGuardSeconds);
    int code = 0;
    try {
      body();
    } catch (...) {
      code = kChildFoundAnError;
    }
    ::_exit(code);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      throw InputError(format_error(where, "",
                                    std::string("lost the process that reads the file first (") +
                                        std::strerror(errno) + "); refused"));
    }
  }
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) {
    throw InputError(format_error(where, "",
                                  "the HDF5 library did not finish reading the file within " +
                                      std::to_string(kGuardSeconds) +
                                      " s (corrupted file?); refused"));
  }
  // Any other end (a signal, or a sanitizer's exit code) is a crash.
  if (WIFSIGNALED(status)) {
    throw InputError(format_error(where, "",
                                  "corrupted file: the HDF5 library crashed reading it (signal " +
                                      std::to_string(WTERMSIG(status)) + "); refused"));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) != 0 && WEXITSTATUS(status) != kChildFoundAnError) {
    throw InputError(format_error(where, "",
                                  "corrupted file: reading it failed in the HDF5 library (exit " +
                                      std::to_string(WEXITSTATUS(status)) + "); refused"));
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace diag::hdf5_detail
