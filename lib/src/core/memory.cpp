#include "celc/core/memory.hpp"

#include <cstdlib>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace celc {

void tuneHeapForLargeBuffers() {
#if defined(__GLIBC__)
  constexpr int kHeapBlockLimit = 64 << 20;      // [bytes] larger blocks are mmap'd
  constexpr int kKeptFree = 256 << 20;           // [bytes] freed memory the heap keeps
  constexpr std::size_t kAdvised = 60u << 20;    // [bytes] below kHeapBlockLimit: from the heap
  mallopt(M_MMAP_THRESHOLD, kHeapBlockLimit);
  mallopt(M_TRIM_THRESHOLD, kKeptFree);
  // Taken from the heap untouched, marked, and given back to it: the heap's
  // next 60 MB are those pages.
  if (void* p = std::malloc(kAdvised)) {
    adviseHugePages(p, kAdvised);
    std::free(p);
  }
#endif
}

void useOneMallocArena() {
#if defined(__GLIBC__)
  mallopt(M_ARENA_MAX, 1);
#endif
}

}  // namespace celc
