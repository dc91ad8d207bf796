// Running many independent jobs (recordings to simulate or to analyse) on every core of one
// machine and, under `mpirun`, across the ranks of an MPI job: the work split shared by
// `geardiag dataset` and `geardiag batch`.
//
// MPI (OpenMPI; CMake option GEARDIAG_WITH_MPI) is started only when the process was launched by
// mpirun (OMPI_COMM_WORLD_SIZE, PMIX_RANK or PMI_SIZE in the environment), so that a plain
// `geardiag dataset ...` is one process with no MPI start-up at all. A binary built without MPI
// that finds itself launched as one of several ranks refuses to run (every rank would write
// every file) rather than silently duplicating the work.
//
// Work split: item i of n belongs to rank i mod size (static, so that each rank knows its share
// without messages); inside a rank, `jobs` threads take the rank's items in order from a shared
// counter (diag::parallel_for). Results must not depend on either: each item is computed from its
// index alone (dataset: a seed derived from (seed, index)).
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace geardiag {

class MpiWorld {
 public:
  // Starts MPI when launched by mpirun (and built with it). Throws diag::InputError when launched
  // as several ranks of a binary built without MPI.
  MpiWorld(int* argc, char*** argv);
  ~MpiWorld();  // MPI_Finalize when started
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  void barrier() const;
  // The largest `value` over every rank (every rank must call it; a collective).
  long max(long value) const;
  // The sum of `value` over every rank.
  long sum(long value) const;
  // Rank 0's `text` on every rank. A collective.
  void broadcast(std::string& text) const;
  // Every rank's `text`, in rank order, on rank 0 (empty on the others). A collective.
  std::vector<std::string> gather(const std::string& text) const;

 private:
  int rank_ = 0, size_ = 1;
  bool started_ = false;
};

// The default number of worker threads of one rank: the hardware threads shared by the ranks on
// this node (OMPI_COMM_WORLD_LOCAL_SIZE), at least 1.
int default_jobs();

// Checks a --jobs value: 0 = default_jobs(), else 1..1024. Throws diag::InputError.
int resolve_jobs(int jobs);

// diag::parallel_for (diag/util/parallel_for.hpp) in rounds of `jobs` items: serial(i) for each
// item of a round on the calling thread while no worker thread exists, then task(i) for them on
// the threads. For work that must
// run with one thread alive: the HDF5 reader forks a survey child (diag/io/hdf5), and a fork while
// another thread holds a lock (an allocator's, a library's) can deadlock the child (GCC 12's
// AddressSanitizer allocator did, in `batch` under ASan). serial must not throw (keep its errors
// for task).
void run_in_rounds(std::size_t items, int jobs, const std::function<void(std::size_t)>& serial,
                   const std::function<void(std::size_t)>& task);

// A progress line on stderr when it is a terminal: "<what> 12/100, 3.4/s, 0:26 left". Silent
// when stderr is piped or redirected, and on every rank but 0. Thread-safe.
class Progress {
 public:
  Progress(std::string what, std::size_t total, bool enabled);
  ~Progress();
  void tick();    // one item done
  void finish();  // clears the line
 private:
  std::string what_;
  std::size_t total_, done_ = 0;
  bool enabled_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace geardiag
