#pragma once
/// \file memory.hpp
/// Large buffers that are mapped in fewer page faults. A fresh page costs a
/// fault on first touch; on a virtual machine that is microseconds, and the
/// megabytes of a window's events and terms made faults a tenth of a run.
#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace celc {

/// Process-wide malloc settings for long runs; call once, first thing in
/// main (glibc only, elsewhere nothing):
/// - blocks below 64 MB come from the heap, and up to 256 MB of freed memory
///   stays there (a window's events, megabytes allocated on one thread and
///   freed on another, were each a fresh mmap faulted in page by page);
/// - the first 60 MB of the heap are advised into huge pages
///   (adviseHugePages), so the buffers carved from them fault once per 2 MB.
void tuneHeapForLargeBuffers();

/// Every thread allocates from the one heap of tuneHeapForLargeBuffers (its
/// huge pages) instead of an arena of its own; call before the threads
/// start. For runs over windows, whose threads allocate megabytes: measured
/// faster there, slower where threads make many small allocations at once
/// (the simulation studies' Ceres problems). glibc only.
void useOneMallocArena();

/// Asks the kernel to back the whole 2 MB blocks inside [p, p + bytes) with
/// transparent huge pages where it allows them on request ("madvise"): one
/// fault per 2 MB instead of 512. Only memory not yet touched is affected; a
/// kernel without them ignores the request.
inline void adviseHugePages(const void* p, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
  const std::uintptr_t a = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t b = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (b > a) ::madvise(reinterpret_cast<void*>(a), b - a, MADV_HUGEPAGE);
#else
  (void)p, (void)bytes;
#endif
}

/// Room for n elements. A vector that must grow takes a quarter more than
/// asked (grown to the exact size, windows a few events larger each took
/// fresh memory), in huge pages where it is large.
template <typename T>
void reserveWithHeadroom(std::vector<T>& v, std::size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n + n / 4);
  adviseHugePages(v.data(), v.capacity() * sizeof(T));
}

/// Room for exactly n elements (a vector handed on, as a window's events),
/// in huge pages where it is large.
template <typename T>
void reserveLarge(std::vector<T>& v, std::size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n);
  adviseHugePages(v.data(), v.capacity() * sizeof(T));
}

}  // namespace celc
