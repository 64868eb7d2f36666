#pragma once
// Internal: large vectors kept between calls, so that the pages of a buffer
// are mapped once instead of once per window (on a virtual machine a page
// fault costs microseconds). The spares are shared by all threads: the
// process keeps as many of them as were borrowed at once, not one per
// thread that ever borrowed one.
#include <algorithm>
#include <mutex>
#include <vector>

#include "celc/core/memory.hpp"

namespace celc::detail {

/// The spare vectors of `Owner` (one pool per owner type and T).
template <typename Owner, typename T>
struct SparePool {
  std::mutex mu;
  std::vector<std::vector<T>> spares;
};

template <typename Owner, typename T>
SparePool<Owner, T>& sparePool() {
  static SparePool<Owner, T> pool;
  return pool;
}

/// Takes the largest spare vector into v (emptied; v must be empty); an
/// empty vector when every spare is borrowed.
template <typename Owner, typename T>
void borrowSpareVector(std::vector<T>& v) {
  SparePool<Owner, T>& pool = sparePool<Owner, T>();
  {
    std::lock_guard<std::mutex> lock(pool.mu);
    if (!pool.spares.empty()) {
      auto largest = std::max_element(pool.spares.begin(), pool.spares.end(),
                                      [](const auto& a, const auto& b) { return a.capacity() < b.capacity(); });
      v.swap(*largest);
      pool.spares.erase(largest);
    }
  }
  v.clear();
}

/// Gives v's memory back to the spares (v is left empty).
template <typename Owner, typename T>
void returnSpareVector(std::vector<T>& v) {
  if (v.capacity() == 0) return;
  SparePool<Owner, T>& pool = sparePool<Owner, T>();
  std::lock_guard<std::mutex> lock(pool.mu);
  pool.spares.emplace_back();
  pool.spares.back().swap(v);
}

}  // namespace celc::detail
