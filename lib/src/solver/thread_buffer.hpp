#pragma once
// Internal: vectors kept per thread between calls, so that the pages of a
// large buffer are mapped once per thread instead of once per window (on a
// virtual machine a page fault costs microseconds).
#include <vector>

#include "celc/core/memory.hpp"

namespace celc::detail {

/// The calling thread's spare vector for `Owner` (one per owner type and T).
template <typename Owner, typename T>
std::vector<T>& threadSpare() {
  thread_local std::vector<T> spare;
  return spare;
}

/// Takes the thread's spare vector into v (emptied; v must be empty). A
/// second borrower on the same thread while the first holds it gets an
/// empty vector.
template <typename Owner, typename T>
void borrowThreadVector(std::vector<T>& v) {
  v.swap(threadSpare<Owner, T>());
  v.clear();
}

/// Gives v's memory back as the thread's spare when it is larger than the
/// spare the thread holds.
template <typename Owner, typename T>
void returnThreadVector(std::vector<T>& v) {
  if (v.capacity() > threadSpare<Owner, T>().capacity()) v.swap(threadSpare<Owner, T>());
}

}  // namespace celc::detail
