// Running the geardiag binary from the CLI tests, and their scratch files.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace cli_test {

struct Run {
  int code;         // exit code, -1 when killed by a signal
  std::string out;  // stdout and stderr together
};

inline Run run(const std::string& args) {
  const std::string cmd = std::string(GEARDIAG_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (std::size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// A file in a per-process folder under $GEARDIAG_TMP (set by CTest) or the system temp folder.
inline std::filesystem::path scratch(const std::string& prefix, const std::string& name) {
  const char* base = std::getenv("GEARDIAG_TMP");
  std::filesystem::path dir =
      std::filesystem::path(base ? base : std::filesystem::temp_directory_path().string()) /
      (prefix + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

}  // namespace cli_test
