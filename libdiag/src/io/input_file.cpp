#include "diag/io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "diag/error.hpp"

namespace diag {

namespace {

std::string where_of(const std::filesystem::path& path, const std::string& what) {
  return what.empty() ? path.string() : what + ": " + path.string();
}

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory, not a file";
  if (S_ISFIFO(mode))
    return "is a FIFO (named pipe), not a regular file: reading it could wait "
           "for a writer forever; copy the data to a file first";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "is a device, not a regular file";
  if (S_ISSOCK(mode)) return "is a socket, not a regular file";
  return "is not a regular file";
}

void check_stat(const struct stat& st, const std::string& where, std::uint64_t max_bytes) {
  if (!S_ISREG(st.st_mode)) throw InputError(format_error(where, "", kind_of(st.st_mode)));
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size == 0) throw InputError(format_error(where, "", "empty file"));
  if (size > max_bytes) {
    throw InputError(format_error(where, "",
                                  std::to_string(size) + " bytes is larger than the " +
                                      std::to_string(max_bytes) + " bytes this input may have"));
  }
}

}  // namespace

std::uint64_t check_input_file(const std::filesystem::path& path, const std::string& what,
                               std::uint64_t max_bytes) {
  const std::string where = where_of(path, what);
  if (path.empty()) throw InputError(format_error(where, "", "empty file name"));
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    throw InputError(format_error(
        where, "", err == ENOENT ? std::string("no such file") : std::string(std::strerror(err))));
  }
  check_stat(st, where, max_bytes);
  return static_cast<std::uint64_t>(st.st_size);
}

std::string read_input_bytes(const std::filesystem::path& path, const std::string& what,
                             std::uint64_t max_bytes) {
  const std::string where = where_of(path, what);
  check_input_file(path, what, max_bytes);
  // O_NONBLOCK: should the path have become a FIFO since the check, open returns at once.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0)
    throw InputError(format_error(where, "", std::string("cannot open: ") + std::strerror(errno)));
  struct stat st {};
  std::string text;
  try {
    if (::fstat(fd, &st) != 0) {
      throw InputError(
          format_error(where, "", std::string("cannot stat: ") + std::strerror(errno)));
    }
    check_stat(st, where, max_bytes);
    text.resize(static_cast<std::size_t>(st.st_size));
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::read(fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        throw InputError(
            format_error(where, "", std::string("read failed: ") + std::strerror(errno)));
      }
      if (n == 0) break;
      done += static_cast<std::size_t>(n);
    }
    char extra = 0;
    if (done != text.size() || ::read(fd, &extra, 1) != 0) {
      throw InputError(format_error(where, "", "the file changed size while it was read"));
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return text;
}

std::string read_input_file(const std::filesystem::path& path, const std::string& what,
                            std::uint64_t max_bytes) {
  std::string text = read_input_bytes(path, what, max_bytes);
  if (const auto nul = text.find('\0'); nul != std::string::npos) {
    throw InputError(format_error(where_of(path, what), "byte " + std::to_string(nul),
                                  "a NUL byte: binary data, not text"));
  }
  return text;
}

}  // namespace diag
