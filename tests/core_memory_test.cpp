// Large-buffer helpers (core/memory.hpp) and the solvers' per-thread buffers
// (solver/thread_buffer.hpp).
#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "celc/core/memory.hpp"
#include "solver/thread_buffer.hpp"

namespace {

using namespace celc;

TEST(CoreMemory, GrowingTakesAQuarterMoreAndEnoughRoomIsKept) {
  std::vector<double> v;
  reserveWithHeadroom(v, 1000);
  EXPECT_GE(v.capacity(), 1250u);
  const double* data = v.data();
  const std::size_t capacity = v.capacity();
  // A window a few events larger than the last fits: no new memory.
  reserveWithHeadroom(v, 1010);
  EXPECT_EQ(v.data(), data);
  EXPECT_EQ(v.capacity(), capacity);
  reserveWithHeadroom(v, 10);
  EXPECT_EQ(v.capacity(), capacity);
  // Past the room: grows again with headroom, keeping the elements.
  v.assign(1000, 2.5);
  reserveWithHeadroom(v, 4000);
  EXPECT_GE(v.capacity(), 5000u);
  ASSERT_EQ(v.size(), 1000u);
  EXPECT_EQ(v[999], 2.5);
}

TEST(CoreMemory, ExactReserveAndHugePageAdviceKeepTheContents) {
  std::vector<float> v(10, 1.0f);
  reserveLarge(v, 3u << 20);  // 12 MB: whole 2 MB blocks inside are advised
  EXPECT_GE(v.capacity(), std::size_t(3u << 20));
  ASSERT_EQ(v.size(), 10u);
  EXPECT_EQ(v[9], 1.0f);
  v.resize(3u << 20, 7.0f);  // the advised pages are usable memory
  EXPECT_EQ(v.back(), 7.0f);
  adviseHugePages(nullptr, 0);  // nothing inside: no call, no effect
  adviseHugePages(v.data(), 100);
  EXPECT_EQ(v[5], 1.0f);
}

struct Owner {};
struct OtherOwner {};

TEST(SpareBuffer, MemoryIsKeptPerOwnerAndSharedByTheThreads) {
  std::vector<int> a;
  detail::borrowSpareVector<Owner>(a);
  EXPECT_TRUE(a.empty());
  reserveWithHeadroom(a, 100);
  a.assign(50, 3);
  const int* data = a.data();
  detail::returnSpareVector<Owner>(a);
  EXPECT_EQ(a.capacity(), 0u);
  // The next borrower gets the same memory, emptied.
  std::vector<int> b;
  detail::borrowSpareVector<Owner>(b);
  EXPECT_EQ(b.data(), data);
  EXPECT_TRUE(b.empty());
  EXPECT_GE(b.capacity(), 100u);
  // A second borrower while b holds it gets an empty vector; another owner
  // type has its own spares.
  std::vector<int> c, d;
  detail::borrowSpareVector<Owner>(c);
  detail::borrowSpareVector<OtherOwner>(d);
  EXPECT_EQ(c.capacity(), 0u);
  EXPECT_EQ(d.capacity(), 0u);
  // Both given back (c grown smaller than b): the larger is handed out first.
  c.reserve(10);
  detail::returnSpareVector<Owner>(c);
  detail::returnSpareVector<Owner>(b);
  std::vector<int> e, f;
  detail::borrowSpareVector<Owner>(e);
  detail::borrowSpareVector<Owner>(f);
  EXPECT_EQ(e.data(), data);
  EXPECT_GE(f.capacity(), 10u);
  EXPECT_LT(f.capacity(), 100u);
  detail::returnSpareVector<Owner>(f);
  detail::returnSpareVector<Owner>(e);
  // Another thread borrows the same memory: the spares are the process's.
  const int* other_data = nullptr;
  std::thread([&] {
    std::vector<int> g;
    detail::borrowSpareVector<Owner>(g);
    other_data = g.data();
    detail::returnSpareVector<Owner>(g);
  }).join();
  EXPECT_EQ(other_data, data);
}

}  // namespace
