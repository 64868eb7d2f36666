// The parallel utility (core/parallel.hpp) and the list splitter (core/text.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "celc/core/parallel.hpp"
#include "celc/core/text.hpp"

using namespace celc;

namespace {

// Busy work of a length that depends on the index, so that jobs finish out of order.
void jitter(std::size_t i) {
  std::this_thread::sleep_for(std::chrono::microseconds((i * 7919) % 13 * 50));
}

}  // namespace

TEST(ParallelFor, VisitsEveryIndexOnce) {
  for (int threads : {1, 2, 3, 8, 0}) {
    const std::size_t n = 1000;
    std::vector<std::atomic<int>> visits(n);
    parallelFor(n, threads, [&](std::size_t i) { visits[i]++; });
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(visits[i].load(), 1) << "index " << i << ", threads " << threads;
  }
}

TEST(ParallelFor, ZeroJobsCallsNothing) {
  bool called = false;
  parallelFor(0, 4, [&](std::size_t) { called = true; });
  EXPECT_FALSE(called);
}

TEST(ParallelFor, MoreThreadsThanJobs) {
  std::vector<std::atomic<int>> visits(3);
  std::mutex mu;
  std::set<std::thread::id> ids;
  parallelFor(3, 16, [&](std::size_t i) {
    visits[i]++;
    std::lock_guard<std::mutex> lock(mu);
    ids.insert(std::this_thread::get_id());
  });
  for (auto& v : visits) EXPECT_EQ(v.load(), 1);
  EXPECT_LE(ids.size(), 3u);  // never more threads than jobs
}

TEST(ParallelFor, OneThreadOrOneJobRunsOnTheCallingThread) {
  const auto caller = std::this_thread::get_id();
  std::vector<std::size_t> order;
  parallelFor(5, 1, [&](std::size_t i) {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    order.push_back(i);
  });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4}));  // in index order
  parallelFor(1, 8, [&](std::size_t) { EXPECT_EQ(std::this_thread::get_id(), caller); });
}

TEST(ParallelFor, RethrowsTheFirstExceptionAfterAllWorkersJoin) {
  for (int threads : {1, 2, 4}) {
    std::atomic<int> running{0}, finished{0};
    try {
      parallelFor(200, threads, [&](std::size_t i) {
        ++running;
        jitter(i);
        if (i == 17) {
          --running;
          throw std::runtime_error("job 17 failed");
        }
        --running;
        ++finished;
      });
      FAIL() << "no exception, threads " << threads;
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "job 17 failed");
    }
    EXPECT_EQ(running.load(), 0) << "a job still running after the rethrow";
    EXPECT_LT(finished.load(), 199) << "the jobs after the failure should not all run";
  }
}

TEST(ParallelFor, ResolvesThreadCount) {
  EXPECT_EQ(resolveThreadCount(3), 3);
  EXPECT_GE(resolveThreadCount(0), 1);
  EXPECT_GE(resolveThreadCount(-2), 1);
}

namespace {

using IntMap = void (*)(int, std::size_t, const std::function<bool(int&)>&, const std::function<int(int&)>&,
                        const std::function<void(int&)>&);
constexpr IntMap intMap = &orderedParallelMap<int, int>;

struct Numbered {
  int index = -1;
  std::vector<int> payload;
};

// Produces `n` jobs; the results (index squared) are consumed into `out`.
void squares(int n, int threads, std::size_t in_flight, std::vector<int>& out, std::atomic<int>* peak = nullptr) {
  int next = 0;
  std::atomic<int> live{0};
  orderedParallelMap<Numbered, int>(
      threads, in_flight,
      [&](Numbered& job) {
        if (next == n) return false;
        job.index = next++;
        const int now = ++live;
        if (peak && now > peak->load()) *peak = now;
        return true;
      },
      [&](Numbered& job) {
        jitter(static_cast<std::size_t>(job.index));
        return job.index * job.index;
      },
      [&](int& result) {
        --live;
        out.push_back(result);
      });
}

}  // namespace

TEST(OrderedParallelMap, DeliversInProductionOrder) {
  for (int threads : {1, 2, 4}) {
    std::vector<int> out;
    squares(300, threads, 6, out);
    ASSERT_EQ(out.size(), 300u);
    for (int i = 0; i < 300; ++i) ASSERT_EQ(out[static_cast<std::size_t>(i)], i * i) << "threads " << threads;
  }
}

TEST(OrderedParallelMap, BoundsJobsInFlight) {
  for (std::size_t cap : {1u, 2u, 5u}) {
    std::vector<int> out;
    std::atomic<int> peak{0};
    squares(100, 3, cap, out, &peak);
    EXPECT_EQ(out.size(), 100u);
    EXPECT_LE(peak.load(), static_cast<int>(cap));
  }
}

namespace {

// Jobs of the given weights through orderedParallelMap with a weight bound;
// returns the largest weight held at once (from production to the end of
// work) and checks the results' order. `at_produce` gets, for each job, the
// weight held when it was produced.
std::size_t heaviestHeld(const std::vector<std::size_t>& weights, int threads, std::size_t max_weight,
                         std::vector<std::size_t>* at_produce = nullptr) {
  std::mutex mu;
  std::size_t held = 0, peak = 0;
  std::size_t next = 0;
  std::vector<std::size_t> out;
  orderedParallelMap<Numbered, std::size_t>(
      threads, 8, JobWeightBound<Numbered>{max_weight, [&](const Numbered& job) { return job.payload.size(); }},
      [&](Numbered& job) {
        if (next == weights.size()) return false;
        job.index = static_cast<int>(next);
        job.payload.assign(weights[next++], 1);
        std::lock_guard<std::mutex> lock(mu);
        if (at_produce) at_produce->push_back(held);
        held += job.payload.size();
        peak = std::max(peak, held);
        return true;
      },
      [&](Numbered& job) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1 + job.index % 3));
        std::lock_guard<std::mutex> lock(mu);
        held -= job.payload.size();  // the pipeline releases the job after this
        return static_cast<std::size_t>(job.index);
      },
      [&](std::size_t& index) { out.push_back(index); });
  EXPECT_EQ(out.size(), weights.size());
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i], i);
  return peak;
}

}  // namespace

TEST(OrderedParallelMap, WeightBoundLimitsTheJobsHeld) {
  // Jobs of 7 under a bound of 20: two held at once, never three, whatever
  // the number of threads.
  const std::vector<std::size_t> sevens(40, 7);
  for (int threads : {2, 4}) {
    const std::size_t peak = heaviestHeld(sevens, threads, 20);
    EXPECT_LE(peak, 20u) << threads << " threads";
    EXPECT_EQ(peak, 14u) << threads << " threads: the bound admits two";
  }
  // Without a bound the count alone limits them (8 in flight).
  EXPECT_GT(heaviestHeld(sevens, 4, 0), 14u);
}

TEST(OrderedParallelMap, AJobHeavierThanTheBoundGoesThroughAlone) {
  std::vector<std::size_t> at_produce;
  const std::size_t peak = heaviestHeld(std::vector<std::size_t>(10, 30), 3, 20, &at_produce);
  EXPECT_EQ(peak, 30u);
  for (std::size_t held : at_produce) EXPECT_EQ(held, 0u);  // each produced once the last is done
}

TEST(OrderedParallelMap, WeightBoundJudgesTheNextJobByTheLast) {
  // Weights that change: a job is produced only when the held ones leave
  // room for one as heavy as the last produced (or none is held).
  const std::vector<std::size_t> weights = {5, 5, 5, 12, 3, 3, 3, 3, 9, 1, 1, 1, 1, 1, 1, 8, 8};
  std::vector<std::size_t> at_produce;
  heaviestHeld(weights, 4, 16, &at_produce);
  ASSERT_EQ(at_produce.size(), weights.size());
  for (std::size_t i = 1; i < weights.size(); ++i)
    EXPECT_TRUE(at_produce[i] == 0 || at_produce[i] + weights[i - 1] <= 16)
        << "job " << i << " produced with " << at_produce[i] << " held";
}

TEST(OrderedParallelMap, NoJobs) {
  std::vector<int> out;
  squares(0, 2, 4, out);
  EXPECT_TRUE(out.empty());
}

TEST(OrderedParallelMap, ProducerAndConsumerRunOnTheCallingThread) {
  const auto caller = std::this_thread::get_id();
  int next = 0;
  int consumed = 0;
  intMap(
      3, 4,
      [&](int& job) {
        EXPECT_EQ(std::this_thread::get_id(), caller);
        job = next;
        return next++ < 50;
      },
      [&](int& job) { return job; },
      [&](int& result) {
        EXPECT_EQ(std::this_thread::get_id(), caller);
        EXPECT_EQ(result, consumed++);
      });
  EXPECT_EQ(consumed, 50);
}

TEST(OrderedParallelMap, WorkerExceptionStopsTheRunAndIsRethrown) {
  for (int threads : {1, 2, 4}) {
    int next = 0;
    std::vector<int> out;
    EXPECT_THROW(intMap(
                     threads, 4,
                     [&](int& job) {
                       job = next++;
                       return job < 1000;
                     },
                     [&](int& job) {
                       if (job == 20) throw std::runtime_error("job 20 failed");
                       return job;
                     },
                     [&](int& r) { out.push_back(r); }),
                 std::runtime_error);
    ASSERT_LE(out.size(), 20u);  // nothing after the failed job is consumed
    for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i], static_cast<int>(i));
    EXPECT_LT(next, 1000);  // production stopped
  }
}

TEST(OrderedParallelMap, ProducerAndConsumerExceptionsAreRethrown) {
  for (int threads : {1, 3}) {
    int next = 0;
    EXPECT_THROW(intMap(
                     threads, 4,
                     [&](int& job) {
                       if (next == 10) throw std::logic_error("no more input");
                       job = next++;
                       return true;
                     },
                     [&](int& job) { return job; }, [&](int&) {}),
                 std::logic_error);
    next = 0;
    EXPECT_THROW(intMap(
                     threads, 4,
                     [&](int& job) {
                       job = next++;
                       return job < 100;
                     },
                     [&](int& job) { return job; },
                     [&](int& r) {
                       if (r == 7) throw std::out_of_range("sink full");
                     }),
                 std::out_of_range);
  }
}

TEST(SplitList, KeepsEveryField) {
  using V = std::vector<std::string>;
  EXPECT_EQ(splitList("celc,ce3lc"), (V{"celc", "ce3lc"}));
  EXPECT_EQ(splitList("a,,b,"), (V{"a", "", "b", ""}));
  EXPECT_EQ(splitList(",a"), (V{"", "a"}));
  EXPECT_EQ(splitList(" 1, 2 "), (V{" 1", " 2 "}));  // not trimmed
  EXPECT_EQ(splitList("x"), (V{"x"}));
  EXPECT_TRUE(splitList("").empty());
  EXPECT_EQ(splitList("a.b.c", '.'), (V{"a", "b", "c"}));
}

TEST(SplitList, TrimBlanks) {
  EXPECT_EQ(trimBlanks("  a b\t\r"), "a b");
  EXPECT_EQ(trimBlanks(" \t"), "");
  EXPECT_EQ(trimBlanks(""), "");
}

// The HDF5 reader's messages print byte counts computed in double from sizes
// in the file; the fuzz target found one beyond 2^64, whose conversion to an
// integer was undefined behaviour (UBSan, float-cast-overflow).
TEST(SplitList, ByteCountTextNeverOverflows) {
  EXPECT_EQ(byteCountText(0.0), "0");
  EXPECT_EQ(byteCountText(1952382976.0), "1952382976");
  EXPECT_EQ(byteCountText(18446744073709549568.0), "18446744073709549568");  // the largest double below 2^64
  EXPECT_EQ(byteCountText(18446744073709551616.0), "more than 2^64");        // 2^64
  EXPECT_EQ(byteCountText(1e300), "more than 2^64");
  EXPECT_EQ(byteCountText(std::numeric_limits<double>::infinity()), "more than 2^64");
  EXPECT_EQ(byteCountText(-1.0), "an invalid number of");
  EXPECT_EQ(byteCountText(std::nan("")), "an invalid number of");
}
