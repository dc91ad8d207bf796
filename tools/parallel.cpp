#include "parallel.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "diag/error.hpp"
#include "diag/util/parallel_for.hpp"

#if GEARDIAG_WITH_MPI
#include <mpi.h>
#endif

namespace geardiag {

namespace {

// The number of ranks mpirun (OpenMPI, or a PMI launcher) says this process is one of; 0 when not
// launched by one.
int launched_ranks() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    if (const char* v = std::getenv(var)) return std::atoi(v);
  }
  return std::getenv("PMIX_RANK") ? 1 : 0;
}

std::mutex progress_mutex;

}  // namespace

MpiWorld::MpiWorld(int* argc, char*** argv) {
  const int ranks = launched_ranks();
#if GEARDIAG_WITH_MPI
  if (ranks > 0) {
    int provided = 0;
    // Only the main thread calls MPI; the workers never do.
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    started_ = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
#else
  (void)argc;
  (void)argv;
  if (ranks > 1) {
    throw diag::InputError(
        "launched by mpirun as one of " + std::to_string(ranks) +
        " ranks, but this geardiag was built without MPI (cmake -DGEARDIAG_WITH_MPI=ON); every "
        "rank would do all the work: run it without mpirun, or rebuild with MPI");
  }
#endif
}

MpiWorld::~MpiWorld() {
#if GEARDIAG_WITH_MPI
  if (started_) MPI_Finalize();
#endif
}

void MpiWorld::barrier() const {
#if GEARDIAG_WITH_MPI
  if (started_) MPI_Barrier(MPI_COMM_WORLD);
#endif
}

#if GEARDIAG_WITH_MPI
namespace {
long all_reduce(long value, MPI_Op op) {
  long out = value;
  MPI_Allreduce(&value, &out, 1, MPI_LONG, op, MPI_COMM_WORLD);
  return out;
}
}  // namespace
#endif

long MpiWorld::max(long value) const {
#if GEARDIAG_WITH_MPI
  if (started_) return all_reduce(value, MPI_MAX);
#endif
  return value;
}

long MpiWorld::sum(long value) const {
#if GEARDIAG_WITH_MPI
  if (started_) return all_reduce(value, MPI_SUM);
#endif
  return value;
}

void MpiWorld::broadcast(std::string& text) const {
#if GEARDIAG_WITH_MPI
  if (started_) {
    long n = static_cast<long>(text.size());
    MPI_Bcast(&n, 1, MPI_LONG, 0, MPI_COMM_WORLD);
    if (n > 2000000000L) throw std::runtime_error("MPI broadcast: more than 2 GB");
    text.resize(static_cast<std::size_t>(n));
    MPI_Bcast(text.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD);
  }
#else
  (void)text;
#endif
}

std::vector<std::string> MpiWorld::gather(const std::string& text) const {
#if GEARDIAG_WITH_MPI
  if (started_) {
    const long n = static_cast<long>(text.size());
    std::vector<long> sizes(rank_ == 0 ? static_cast<std::size_t>(size_) : 0);
    MPI_Gather(&n, 1, MPI_LONG, sizes.data(), 1, MPI_LONG, 0, MPI_COMM_WORLD);
    std::vector<int> counts, offsets;
    std::string all;
    if (rank_ == 0) {
      long total = 0;
      for (long s : sizes) {
        if (total + s > 2000000000L) throw std::runtime_error("MPI gather: more than 2 GB");
        counts.push_back(static_cast<int>(s));
        offsets.push_back(static_cast<int>(total));
        total += s;
      }
      all.resize(static_cast<std::size_t>(total));
    }
    MPI_Gatherv(text.data(), static_cast<int>(n), MPI_CHAR, all.data(), counts.data(),
                offsets.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
    std::vector<std::string> out;
    for (std::size_t r = 0; r < counts.size(); ++r) {
      out.push_back(
          all.substr(static_cast<std::size_t>(offsets[r]), static_cast<std::size_t>(counts[r])));
    }
    return out;
  }
#endif
  return {text};
}

int default_jobs() {
  const int hw = static_cast<int>(std::thread::hardware_concurrency());
  int local = 1;
  if (const char* v = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE")) local = std::max(1, std::atoi(v));
  return std::max(1, (hw > 0 ? hw : 1) / local);
}

int resolve_jobs(int jobs) {
  if (jobs == 0) return default_jobs();
  if (jobs < 0 || jobs > 1024) {
    throw diag::InputError("--jobs: " + std::to_string(jobs) +
                           " is not 0 (all cores) or a thread count 1..1024");
  }
  return jobs;
}

void run_in_rounds(std::size_t items, int jobs, const std::function<void(std::size_t)>& serial,
                   const std::function<void(std::size_t)>& task) {
  const std::size_t round = static_cast<std::size_t>(std::max(1, jobs));
  for (std::size_t first = 0; first < items; first += round) {
    const std::size_t n = std::min(round, items - first);
    for (std::size_t j = 0; j < n; ++j) serial(first + j);
    diag::parallel_for(n, jobs, [&](std::size_t j) { task(first + j); });
  }
}

Progress::Progress(std::string what, std::size_t total, bool enabled)
    : what_(std::move(what)),
      total_(total),
      enabled_(enabled && ::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

Progress::~Progress() { finish(); }

void Progress::tick() {
  const std::lock_guard<std::mutex> lock(progress_mutex);
  ++done_;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (done_ < total_ && now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  const double s = std::chrono::duration<double>(now - start_).count();
  const double rate = s > 0 ? done_ / s : 0.0;
  const long left = rate > 0 ? static_cast<long>((total_ - done_) / rate + 0.5) : 0;
  std::fprintf(stderr, "\r%s %zu/%zu, %.2f/s, %ld:%02ld:%02ld left   ", what_.c_str(), done_,
               total_, rate, left / 3600, left / 60 % 60, left % 60);
  std::fflush(stderr);
}

void Progress::finish() {
  const std::lock_guard<std::mutex> lock(progress_mutex);
  if (!enabled_) return;
  std::fprintf(stderr, "\r%-70s\r", "");
  std::fflush(stderr);
  enabled_ = false;
}

}  // namespace geardiag
