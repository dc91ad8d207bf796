#include "diag/io/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <mutex>
#include <system_error>
#include <vector>

#include "diag/error.hpp"

namespace diag {

namespace fs = std::filesystem;

namespace {

// POSIX allows 8 levels; Linux follows 40 before ELOOP.
constexpr int kMaxSymlinkHops = 40;

std::string where_of(const fs::path& path, const std::string& what) {
  return what.empty() ? path.string() : what + ": " + path.string();
}

[[noreturn]] void fail_output(const fs::path& path, const std::string& what,
                              const std::string& reason) {
  throw InputError(format_error(where_of(path, what), "", reason));
}

bool under_proc(const fs::path& p) { return p.string().rfind("/proc/", 0) == 0; }

// The final target of a chain of symbolic links (the path itself when it is not a link). The target
// may not exist yet: a dangling link is written through, creating its target. Stops at a link of
// /proc (/dev/stderr -> /proc/self/fd/2 -> "pipe:[123]"): its text is no path, only open() follows
// it.
fs::path follow_links(const fs::path& path, const std::string& what) {
  fs::path p = path;
  for (int hops = 0;; ++hops) {
    std::error_code ec;
    const fs::file_status st = fs::symlink_status(p, ec);
    if (st.type() != fs::file_type::symlink || under_proc(p)) return p;
    if (hops == kMaxSymlinkHops) fail_output(path, what, "too many levels of symbolic links");
    const fs::path link = fs::read_symlink(p, ec);
    if (ec)
      fail_output(path, what, "cannot read the symbolic link " + p.string() + ": " + ec.message());
    p = link.is_absolute() ? link : p.parent_path() / link;
  }
}

std::string errno_text() { return std::strerror(errno); }

// Writes every byte to `fd`, retrying short writes and interrupted calls; false on an error
// (errno set).
bool write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

// Closes a file descriptor (when >= 0) at the end of its scope.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;

 private:
  int fd_;
};

// Named temporary files removed by SIGINT, SIGTERM and SIGHUP: the handler unlinks every
// registered name (unlink is async-signal-safe), restores the default action and re-raises, so
// the process still dies of the signal. Installed only where the program left the default
// action. SIGKILL cannot be caught: that is why named temporaries are the fallback only
// (write_output_file) or live for the write alone.
constexpr int kCleanupSlots = 16;
constexpr std::size_t kCleanupPathBytes = 4096;

struct CleanupSlot {
  std::atomic<bool> claimed{false};
  std::atomic<bool> armed{false};
  char path[kCleanupPathBytes];
};
CleanupSlot cleanup_slots[kCleanupSlots];

extern "C" void remove_temporaries_and_die(int sig) {
  for (CleanupSlot& slot : cleanup_slots) {
    if (slot.armed.load()) ::unlink(slot.path);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

void install_cleanup_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      if (::sigaction(sig, nullptr, &old) != 0 || old.sa_handler != SIG_DFL) continue;
      struct sigaction sa {};
      sa.sa_handler = remove_temporaries_and_die;
      sigemptyset(&sa.sa_mask);
      ::sigaction(sig, &sa, nullptr);
    }
  });
}

// Registers `path` for removal on a signal; -1 when every slot is taken or the path too long.
int arm_cleanup(const fs::path& path) {
  install_cleanup_handlers();
  const std::string& text = path.native();
  if (text.size() >= kCleanupPathBytes) return -1;
  for (int i = 0; i < kCleanupSlots; ++i) {
    CleanupSlot& slot = cleanup_slots[i];
    if (slot.claimed.exchange(true)) continue;
    std::memcpy(slot.path, text.c_str(), text.size() + 1);
    slot.armed.store(true);
    return i;
  }
  return -1;
}

void disarm_cleanup(int slot) {
  if (slot < 0) return;
  cleanup_slots[slot].armed.store(false);
  cleanup_slots[slot].claimed.store(false);
}

// Removes a temporary file when it goes out of scope, unless released; removed on SIGINT and
// SIGTERM too.
class TempFile {
 public:
  explicit TempFile(fs::path path) : path_(std::move(path)), slot_(arm_cleanup(path_)) {}
  ~TempFile() {
    if (!path_.empty()) {
      std::error_code ignored;
      fs::remove(path_, ignored);
    }
    disarm_cleanup(slot_);
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const fs::path& path() const { return path_; }
  void release() {
    path_.clear();
    disarm_cleanup(slot_);
    slot_ = -1;
  }

 private:
  fs::path path_;
  int slot_;
};

fs::path temp_beside(const fs::path& target) {
  fs::path tmp = target;
  tmp += ".tmp-" + std::to_string(::getpid());
  return tmp;
}

// The permission bits of an existing regular file, kept by its replacement; -1 when new.
int existing_mode(const fs::path& target) {
  struct stat st {};
  if (::stat(target.c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
    return static_cast<int>(st.st_mode & 07777);
  }
  return -1;
}

void rename_into_place(const TempFile& tmp, const OutputTarget& t, const std::string& what,
                       int mode) {
  if (mode >= 0 && ::chmod(tmp.path().c_str(), static_cast<mode_t>(mode)) != 0) {
    fail_output(t.path, what,
                "cannot set the permissions of " + tmp.path().string() + ": " + errno_text());
  }
  std::error_code ec;
  fs::rename(tmp.path(), t.target, ec);
  if (ec) {
    fail_output(t.path, what,
                "cannot move " + tmp.path().string() + " into place: " + ec.message());
  }
}

// Opens stdout, a FIFO or a device for writing; the caller closes a descriptor other than 1.
int open_stream(const OutputTarget& t, const std::string& what) {
  if (t.kind == OutputKind::kStdout) {
    // Anything the program already printed must come first.
    std::cout.flush();
    std::fflush(stdout);
    return STDOUT_FILENO;
  }
  int fd;
  do {
    fd = ::open(t.target.c_str(), O_WRONLY | O_CLOEXEC);
  } while (fd < 0 && errno == EINTR);
  if (fd < 0) fail_output(t.path, what, "cannot open for writing: " + errno_text());
  return fd;
}

void close_stream(int fd, const OutputTarget& t, const std::string& what) {
  if (fd == STDOUT_FILENO) return;
  if (::close(fd) != 0) fail_output(t.path, what, "write failed: " + errno_text());
}

// Makes a regular file as an anonymous file (O_TMPFILE) in the target's directory, filled by
// `fill(fd)`, and only then gives it a name: linkat straight to the target when there is none,
// else to "<target>.tmp-<pid>" renamed over the target at once. A run killed while writing
// leaves nothing: the kernel frees an anonymous file with its last descriptor. The one exception
// is a SIGKILL (which no handler sees) in the instant between that linkat and the rename: the
// complete file is left as "<target>.tmp-<pid>", and the next write of the target removes it
// (remove_stale_temporaries). False, with
// nothing done, where the file system or kernel has no O_TMPFILE or no /proc: the caller then
// writes a named temporary file.
bool write_anonymous(const OutputTarget& t, const std::string& what, int mode,
                     const std::function<void(int fd)>& fill) {
  fs::path dir = t.target.parent_path();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0666);
  if (fd < 0) return false;
  const Descriptor closer(fd);
  const std::string self = "/proc/self/fd/" + std::to_string(fd);
  if (::access(self.c_str(), F_OK) != 0) return false;  // no /proc: linkat could not name it
  fill(fd);
  if (mode >= 0 && ::fchmod(fd, static_cast<mode_t>(mode)) != 0) {
    fail_output(t.path, what, "cannot set the permissions: " + errno_text());
  }
  if (mode < 0) {
    if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, t.target.c_str(), AT_SYMLINK_FOLLOW) == 0) {
      return true;
    }
    if (errno != EEXIST) {
      fail_output(t.path, what, "cannot create the file: " + errno_text());
    }
  }
  TempFile tmp(temp_beside(t.target));
  if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, tmp.path().c_str(), AT_SYMLINK_FOLLOW) != 0) {
    const int err = errno;
    tmp.release();  // not created here (or, for EEXIST, not ours)
    fail_output(t.path, what, "cannot create " + tmp.path().string() + ": " + std::strerror(err));
  }
  rename_into_place(tmp, t, what, -1);
  tmp.release();
  return true;
}

// Removes "<target>.tmp-<pid>" files left beside `target` by runs that were killed (SIGKILL cannot
// be caught) while writing a file through a name (write_output_file_via): those whose process no
// longer exists. A running writer's file is left alone.
void remove_stale_temporaries(const fs::path& target) {
  const std::string prefix = target.filename().string() + ".tmp-";
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const auto pid = static_cast<pid_t>(std::stol(digits));
    if (pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    std::error_code ignored;
    if (it->is_regular_file(ignored)) fs::remove(it->path(), ignored);
  }
}

}  // namespace

OutputTarget check_output_path(const fs::path& path, const std::string& what) {
  OutputTarget t;
  t.path = path;
  if (path.empty()) fail_output(path, what, "empty output path");
  // The names of stdout are stdout itself, whatever fd 1 is (a terminal, a pipe, a regular file
  // the shell opened: renaming over that file would leave the shell's output unlinked).
  if (path == "-" || path == "/dev/stdout" || path == "/dev/fd/1" || path == "/proc/self/fd/1") {
    t.kind = OutputKind::kStdout;
    t.target = path;
    return t;
  }
  t.target = follow_links(path, what);
  if (under_proc(t.target) && fs::is_symlink(t.target)) {
    // An open file of a process (/dev/stderr, /dev/fd/N): written in place, never renamed over.
    t.target = path;
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec) fail_output(path, what, "cannot inspect the path: " + ec.message());
    if (st.type() == fs::file_type::directory)
      fail_output(path, what, "is a directory, not a file");
    t.kind = OutputKind::kStream;
    if (::access(path.c_str(), W_OK) != 0) {
      fail_output(path, what, "cannot write to it: " + errno_text());
    }
    return t;
  }
  const std::string via = t.target == path
                              ? std::string()
                              : " (the target of the symbolic link is " + t.target.string() + ")";
  std::error_code ec;
  const fs::file_status st = fs::status(t.target, ec);
  if (ec && st.type() != fs::file_type::not_found) {
    fail_output(path, what, "cannot inspect the path: " + ec.message() + via);
  }
  switch (st.type()) {
    case fs::file_type::not_found:
    case fs::file_type::regular:
      t.kind = OutputKind::kRegular;
      break;
    case fs::file_type::fifo:
    case fs::file_type::character:
    case fs::file_type::block:
      t.kind = OutputKind::kStream;
      if (::access(t.target.c_str(), W_OK) != 0) {
        fail_output(path, what, "cannot write to it: " + errno_text() + via);
      }
      return t;
    case fs::file_type::directory:
      fail_output(path, what, "is a directory, not a file" + via);
    default:
      fail_output(path, what, "is a socket or other special file, not a file" + via);
  }
  // A regular file is written beside its target and renamed: its directory must take new files.
  fs::path dir = t.target.parent_path();
  if (dir.empty()) dir = ".";
  const fs::file_status ds = fs::status(dir, ec);
  if (ds.type() == fs::file_type::not_found) {
    fail_output(path, what, "the directory " + dir.string() + " does not exist" + via);
  }
  if (ds.type() != fs::file_type::directory) {
    fail_output(path, what, dir.string() + " is not a directory" + via);
  }
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    fail_output(path, what,
                "cannot create files in the directory " + dir.string() + ": " + errno_text() + via);
  }
  return t;
}

void write_output_file(const fs::path& path, std::string_view bytes, const std::string& what) {
  const OutputTarget t = check_output_path(path, what);
  if (t.kind != OutputKind::kRegular) {
    const int fd = open_stream(t, what);
    const bool ok = write_all(fd, bytes.data(), bytes.size());
    const std::string reason = ok ? std::string() : errno_text();
    if (!ok) {
      if (fd != STDOUT_FILENO) ::close(fd);
      fail_output(path, what, "write failed: " + reason);
    }
    close_stream(fd, t, what);
    return;
  }
  const int mode = existing_mode(t.target);
  const bool anonymous = write_anonymous(t, what, mode, [&](int fd) {
    if (!write_all(fd, bytes.data(), bytes.size())) {
      fail_output(path, what, "write failed: " + errno_text());
    }
  });
  if (anonymous) return;
  TempFile tmp(temp_beside(t.target));
  // O_NOFOLLOW: never write through a link someone placed at the temporary name.
  const int fd =
      ::open(tmp.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    const std::string reason = std::strerror(err);
    // A link at the temporary name was not created here: not ours to remove.
    if (err == ELOOP) tmp.release();
    fail_output(path, what, "cannot create " + tmp.path().string() + ": " + reason);
  }
  const bool ok = write_all(fd, bytes.data(), bytes.size());
  const std::string reason = ok ? std::string() : errno_text();
  if (::close(fd) != 0 && ok) fail_output(path, what, "write failed: " + errno_text());
  if (!ok) fail_output(path, what, "write failed: " + reason);
  rename_into_place(tmp, t, what, mode);
  tmp.release();
}

void write_output_file_via(const fs::path& path,
                           const std::function<void(const fs::path& file)>& write_file,
                           const std::string& what) {
  const OutputTarget t = check_output_path(path, what);
  if (t.kind == OutputKind::kRegular) {
    const int mode = existing_mode(t.target);
    remove_stale_temporaries(t.target);
    TempFile tmp(temp_beside(t.target));
    write_file(tmp.path());
    rename_into_place(tmp, t, what, mode);
    tmp.release();
    return;
  }
  // A FIFO, a device or stdout cannot be renamed onto, and writers such as HDF5 seek: the file is
  // made in the temporary directory, then streamed.
  static std::atomic<unsigned> counter{0};
  std::error_code ec;
  const fs::path tmpdir = fs::temp_directory_path(ec);
  if (ec) {
    // A missing TMPDIR is the environment's fault, not an internal error.
    fail_output(path, what, "no temporary directory to build the output in: " + ec.message());
  }
  const TempFile named(tmpdir / ("geardiag-" + std::to_string(::getpid()) + "-" +
                                 std::to_string(counter++) + ".tmp"));
  write_file(named.path());
  const int src = ::open(named.path().c_str(), O_RDONLY | O_CLOEXEC);
  if (src < 0) fail_output(path, what, "cannot read back " + named.path().string());
  const Descriptor source(src);
  const int fd = open_stream(t, what);
  std::vector<char> buf(1 << 16);
  std::string reason;
  for (off_t offset = 0;;) {
    const ssize_t n = ::pread(src, buf.data(), buf.size(), offset);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      reason = "cannot read back the temporary file: " + errno_text();
      break;
    }
    if (n == 0) break;
    if (!write_all(fd, buf.data(), static_cast<std::size_t>(n))) {
      reason = errno_text();
      break;
    }
    offset += n;
  }
  if (!reason.empty()) {
    if (fd != STDOUT_FILENO) ::close(fd);
    fail_output(path, what, "write failed: " + reason);
  }
  close_stream(fd, t, what);
}

}  // namespace diag
