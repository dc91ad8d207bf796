// Crash safety of the outputs (diag/io/output_file.hpp): `kill -9`, SIGTERM and SIGINT at several
// moments of `import`, `simulate` and `analyze` never leave a partial file at the output path and
// never damage an existing one: afterwards the output holds either its previous bytes or exactly
// the bytes of a complete run (writers are deterministic). SIGTERM and SIGINT leave no temporary
// file; a SIGKILL during an HDF5 write may leave "<output>.tmp-<pid>" (HDF5 needs a file name),
// which the next write to the same output removes. Text outputs (JSON, HTML) are anonymous files
// until complete: no kill leaves anything.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "cli_run.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Starts geardiag with `args`, its output discarded.
pid_t spawn(const std::vector<std::string>& args) {
  std::vector<std::string> all = {GEARDIAG_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

int wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

// Files in the output's folder other than the ones named.
std::vector<std::string> others(const fs::path& dir, const std::vector<std::string>& expected) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (std::find(expected.begin(), expected.end(), name) == expected.end()) out.push_back(name);
  }
  return out;
}

struct Job {
  std::vector<std::string> args;  // the command; writes `outputs`
  std::vector<fs::path> outputs;
  bool hdf5 = false;  // an HDF5 output: SIGKILL may leave a named temporary
};

// Runs `job` to completion once (the reference bytes and its duration), then for each signal and
// each moment (fractions of that duration) puts "previous" at every output, starts the job, sends
// the signal at that moment and checks what is left.
void check_kills(const Job& job) {
  const fs::path dir = job.outputs.front().parent_path();
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(wait_for(spawn(job.args)), 0) << "the reference run failed";
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::vector<std::string> complete, names;
  for (const fs::path& o : job.outputs) {
    complete.push_back(slurp(o));
    names.push_back(o.filename().string());
  }
  for (const int sig : {SIGKILL, SIGTERM, SIGINT}) {
    for (const double fraction : {0.05, 0.3, 0.6, 0.8, 0.95, 1.2}) {
      for (const fs::path& o : job.outputs) std::ofstream(o) << "previous";
      // What earlier SIGKILLs left (HDF5 temporaries) is not this run's doing.
      const std::vector<std::string> before = others(dir, names);
      const pid_t pid = spawn(job.args);
      ASSERT_GT(pid, 0);
      std::this_thread::sleep_for(std::chrono::duration<double>(fraction * seconds));
      ::kill(pid, sig);
      const int status = wait_for(pid);
      const std::string when = "signal " + std::to_string(sig) + " at " + std::to_string(fraction) +
                               " of " + std::to_string(seconds) + " s";
      for (std::size_t i = 0; i < job.outputs.size(); ++i) {
        const std::string now = slurp(job.outputs[i]);
        EXPECT_TRUE(now == "previous" || now == complete[i])
            << job.outputs[i] << " damaged (" << now.size() << " bytes) by " << when;
      }
      if (WIFSIGNALED(status) && sig == SIGKILL && job.hdf5) continue;
      // Nothing new (a run that reached its write may have removed what earlier ones left). One
      // exception, for SIGKILL only: a text output replacing an existing file is named
      // "<output>.tmp-<pid>" in the instant between linkat and rename (output_file.cpp: a
      // complete anonymous file, renamed over the target at once); a kill in that instant, which
      // a loaded machine can stretch to a scheduling quantum, leaves it, and the next run removes
      // it (checked below).
      for (const std::string& name : others(dir, names)) {
        bool named_instant = false;
        for (const std::string& out : names) {
          named_instant |= sig == SIGKILL && name == out + ".tmp-" + std::to_string(pid);
        }
        if (named_instant) continue;
        EXPECT_NE(std::find(before.begin(), before.end(), name), before.end())
            << name << " left behind by " << when;
      }
    }
  }
  // A complete run removes what killed runs left.
  ASSERT_EQ(wait_for(spawn(job.args)), 0);
  EXPECT_EQ(others(dir, names), std::vector<std::string>{});
  for (std::size_t i = 0; i < job.outputs.size(); ++i)
    EXPECT_EQ(slurp(job.outputs[i]), complete[i]);
}

fs::path big_csv() {
  const fs::path p = cli_test::scratch("crash_in", "big.csv");
  if (fs::exists(p)) return p;
  std::ofstream out(p);
  out << "time,a,b,c\n";
  char line[160];
  for (int i = 0; i < 300000; ++i) {
    std::snprintf(line, sizeof line, "%.6f,%.9g,%.9g,%.9g\n", i / 20000.0, std::sin(0.01 * i),
                  std::cos(0.013 * i), std::sin(0.2 * i));
    out << line;
  }
  return p;
}

const std::string kGearbox = (fs::path(GEARDIAG_TESTDATA_DIR) / "gearbox/three_shaft.json");

}  // namespace

TEST(CrashSafetyCli, KillingImportNeverDamagesTheOutput) {
  const fs::path out = cli_test::scratch("crash_import", "out.h5");
  check_kills({{"import", big_csv().string(), "-o", out.string()}, {out}, true});
}

TEST(CrashSafetyCli, KillingSimulateNeverDamagesTheOutput) {
  const fs::path out = cli_test::scratch("crash_simulate", "sim.h5");
  check_kills({{"simulate", "--gearbox", kGearbox, "--duration", "0.3", "--fs", "20000", "-o",
                out.string()},
               {out},
               true});
}

TEST(CrashSafetyCli, KillingAnalyzeNeverDamagesItsReports) {
  const fs::path rec = cli_test::scratch("crash_analyze_in", "rec.h5");
  ASSERT_EQ(cli_test::run("simulate --gearbox " + kGearbox + " --duration 0.5 --fs 20000 -o " +
                          rec.string())
                .code,
            0);
  const fs::path json = cli_test::scratch("crash_analyze", "a.json");
  const fs::path html = cli_test::scratch("crash_analyze", "a.html");
  check_kills({{"analyze", rec.string(), "--json", json.string(), "--html", html.string()},
               {json, html},
               false});
}
