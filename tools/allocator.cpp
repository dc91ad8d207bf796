// Allocator settings for the analysing commands (docs/performance.md, bench/RESULTS.md).
//
// analyze allocates and frees record-length buffers (a few MB each) per channel and per stage.
// By default glibc serves each from a fresh mmap (above its dynamic threshold) or returns it to
// the kernel by trimming the heap, and the next buffer faults its pages in again: on the 10 s,
// 39-channel recording 168 000 page faults, a sixth of the command's CPU (kernel page clearing).
// Serving buffers up to 64 MiB from the heap and trimming only above 512 MiB of free top keeps
// freed pages for the next buffer: the page faults are then the first touch of the peak.
// The frames of a long recording run on several threads, and glibc gives each thread its own
// arena, where the settings above do not keep freed pages as well: one arena for the command (the
// buffers are few and large, so the lock is rarely waited on) halves the system time of two
// threads on the 0.28 GB bench recording and keeps 1.9x from 1 to 2 threads.
//
// The first touch of the peak is itself costly: 41 000 faults of 4 KiB pages for the 180 MB peak
// of that recording, a third of the command's CPU on a virtual machine, where each fault exits to
// the hypervisor. Transparent huge pages cut them to about 2 500 (2 MiB pages). Linux gives them
// to a mapping that asks (madvise), and the heap grows by sbrk into a mapping that never asked:
// the heap is therefore grown once, up front, by kHeapReserve (address space only: a page counts
// in the resident set when first written), and that range is advised MADV_HUGEPAGE. The peak
// resident set is unchanged to within a few huge pages; what the heap needs beyond the range
// gets ordinary pages. Where THP is disabled (or "never") the advice is ignored.
#include "allocator.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdlib>

#ifdef __GLIBC__
#include <malloc.h>
#endif
#ifdef __linux__
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace geardiag {

namespace {

#ifdef __GLIBC__
constexpr int kMmapThreshold = 64 << 20;
constexpr int kTrimThreshold = 512 << 20;
constexpr int kHeapReserve = 384 << 20;
constexpr int kDefaultTopPad = 128 << 10;  // glibc's M_TOP_PAD default

#ifdef __linux__
void advise_heap_huge_pages() {
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  // A request larger than the heap's free top makes glibc call sbrk for it plus M_TOP_PAD: the
  // heap's top then holds kHeapReserve of untouched address space, kept after the free (below the
  // trim threshold).
  mallopt(M_TOP_PAD, kHeapReserve);
  void* grow = std::malloc(std::size_t{1} << 20);
  mallopt(M_TOP_PAD, kDefaultTopPad);
  if (grow == nullptr) return;
  const auto begin = (reinterpret_cast<std::uintptr_t>(grow) + kHuge - 1) & ~(kHuge - 1);
  std::free(grow);
  void* top = sbrk(0);
  if (top == reinterpret_cast<void*>(-1)) return;
  const auto end = reinterpret_cast<std::uintptr_t>(top) & ~(kHuge - 1);
  if (end > begin) {
    // Advice only: a kernel without THP refuses it, and the heap is then as it would have been.
    (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
}
#endif
#endif

}  // namespace

void tune_allocator_for_recordings() {
#ifdef __GLIBC__
  mallopt(M_MMAP_THRESHOLD, kMmapThreshold);
  mallopt(M_TRIM_THRESHOLD, kTrimThreshold);
  mallopt(M_ARENA_MAX, 1);
#ifdef __linux__
  advise_heap_huge_pages();
#endif
#endif
}

}  // namespace geardiag
