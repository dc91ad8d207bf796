// Running the geardiag binary from the CLI tests, and their scratch files.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <system_error>

namespace cli_test {

struct Run {
  int code;         // exit code, -1 when killed by a signal
  std::string out;  // stdout and stderr together
};

// Runs a shell command line as it is (stdout only unless it redirects stderr).
inline Run run_command(const std::string& cmd) {
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (std::size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// With kill_after_s > 0 the binary is killed after that many seconds (`timeout -s KILL`), so that
// a hang fails the test instead of stopping the test binary.
inline Run run(const std::string& args, int kill_after_s = 0) {
  const std::string prefix =
      kill_after_s > 0 ? "timeout -s KILL " + std::to_string(kill_after_s) + " " : "";
  return run_command(prefix + std::string(GEARDIAG_BINARY) + " " + args + " 2>&1");
}

// geardiag under `mpirun -np 2` (GEARDIAG_MPIRUN; the caller skips when it is empty). As root
// OpenMPI needs --allow-run-as-root. Leak detection is off for it: OpenMPI's start-up leaks by
// design, which LeakSanitizer would report in the sanitizer build.
inline Run run_mpi(const std::string& args) {
  return run_command("ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" " +
                     std::string(GEARDIAG_MPIRUN) + " -np 2 --oversubscribe " +
                     (::geteuid() == 0 ? "--allow-run-as-root " : "") + GEARDIAG_BINARY + " " +
                     args + " 2>&1");
}

// A file in a per-process folder under $GEARDIAG_TMP (set by CTest) or the system temp folder;
// the folders are removed when the test process exits.
inline std::filesystem::path scratch(const std::string& prefix, const std::string& name) {
  struct Folders {
    std::map<std::string, std::filesystem::path> dirs;
    ~Folders() {
      std::error_code ec;
      for (const auto& [prefix, dir] : dirs) std::filesystem::remove_all(dir, ec);
    }
  };
  static Folders folders;
  auto [it, added] = folders.dirs.try_emplace(prefix);
  if (added) {
    const char* base = std::getenv("GEARDIAG_TMP");
    it->second =
        std::filesystem::path(base ? base : std::filesystem::temp_directory_path().string()) /
        (prefix + "_" + std::to_string(::getpid()));
  }
  std::filesystem::create_directories(it->second);
  return it->second / name;
}

}  // namespace cli_test
