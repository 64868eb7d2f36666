#pragma once
/// \file parallel.hpp
/// The one way the library runs work on several threads.
///
/// - parallelFor: independent jobs 0..n-1, handed out one at a time from a
///   shared counter (dynamic scheduling); the calling thread works too.
/// - orderedParallelMap: a stream of jobs produced on the calling thread,
///   worked on in parallel, their results handed back on the calling thread
///   in production order, with a bounded number of jobs in flight (and
///   optionally a bound on their weight, e.g. the events they hold).
///
/// Which thread runs a job is unspecified: results must depend on the job
/// (its index, its data) only, never on the thread or on timing. That is what
/// keeps every study and every clustering identical for any thread count.
/// The first exception thrown by a job (or by the producer / consumer) stops
/// the handing out of further jobs and is rethrown on the calling thread once
/// every worker has finished.
#include <cstddef>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

namespace celc {

/// Threads to use when `requested` are asked for: `requested` when > 0, else
/// the hardware's concurrency (at least 1).
int resolveThreadCount(int requested);

/// Runs fn(i) once for every i in [0, n_jobs) on up to n_threads threads
/// (<= 0: hardware concurrency), never more threads than jobs. No thread is
/// started for one thread or one job: fn then runs on the calling thread in
/// index order.
void parallelFor(std::size_t n_jobs, int n_threads, const std::function<void(std::size_t)>& fn);

namespace detail {

/// The scheduling behind orderedParallelMap, on sequence numbers: the job of
/// sequence number s lives in slot s % max_in_flight. produce(slot) fills a
/// free slot and returns false when there is nothing more; work(slot) runs on
/// a worker; consume(slot) runs on the calling thread in sequence order.
/// Besides the count, a bound on the jobs' weights (weight(slot), taken once
/// the job is produced; max_weight 0 = none, weight then never called): a
/// job weighs from its production until work(slot) returns (work releases
/// the job's data). The next job is
/// produced only while the jobs weighing leave room for one as heavy as the
/// last produced, so they weigh at most max_weight together when the jobs
/// weigh alike; with none weighing, the next job is produced whatever it
/// weighs.
void orderedPipeline(int n_threads, std::size_t max_in_flight, std::size_t max_weight,
                     const std::function<std::size_t(std::size_t)>& weight,
                     const std::function<bool(std::size_t)>& produce,
                     const std::function<void(std::size_t)>& work,
                     const std::function<void(std::size_t)>& consume);

}  // namespace detail

/// Streams jobs through `n_threads` workers (<= 0: hardware concurrency) and
/// hands the results to `consume` in the order the jobs were produced.
///
/// produce(job) fills the next job and returns false when there are no more;
/// it and consume(result) run on the calling thread, interleaved: finished
/// results are consumed as soon as every earlier one has been. work(job)
/// returns the job's result and runs on a worker thread (with one thread:
/// on the calling thread, job after job). At most `max_in_flight` jobs
/// (>= 1) are produced and not yet consumed: this bounds the memory held.
template <typename Job, typename Result>
void orderedParallelMap(int n_threads, std::size_t max_in_flight,
                        const std::function<bool(Job&)>& produce,
                        const std::function<Result(Job&)>& work,
                        const std::function<void(Result&)>& consume);

/// A bound on what the jobs in flight hold, by a weight per job (e.g. a
/// window's events): see detail::orderedPipeline. max_weight 0 = none.
template <typename Job>
struct JobWeightBound {
  std::size_t max_weight = 0;
  std::function<std::size_t(const Job&)> weight;
};

/// orderedParallelMap with, besides the count, a bound on the weight of the
/// jobs produced and not yet worked on to the end (JobWeightBound): a job is
/// produced only while those leave room for one as heavy as the last; one
/// job always goes through, whatever it weighs. With one thread jobs run one
/// at a time and the bound changes nothing.
template <typename Job, typename Result>
void orderedParallelMap(int n_threads, std::size_t max_in_flight, const JobWeightBound<Job>& bound,
                        const std::function<bool(Job&)>& produce,
                        const std::function<Result(Job&)>& work,
                        const std::function<void(Result&)>& consume) {
  if (max_in_flight < 1) max_in_flight = 1;
  std::vector<std::optional<Job>> jobs(max_in_flight);
  std::vector<std::optional<Result>> results(max_in_flight);
  detail::orderedPipeline(
      n_threads, max_in_flight, bound.weight ? bound.max_weight : 0,
      [&](std::size_t slot) { return bound.weight(*jobs[slot]); },
      [&](std::size_t slot) {
        jobs[slot].emplace();
        if (produce(*jobs[slot])) return true;
        jobs[slot].reset();
        return false;
      },
      [&](std::size_t slot) {
        results[slot].emplace(work(*jobs[slot]));
        jobs[slot].reset();  // the job's data is no longer needed
      },
      [&](std::size_t slot) {
        consume(*results[slot]);
        results[slot].reset();
      });
}

template <typename Job, typename Result>
void orderedParallelMap(int n_threads, std::size_t max_in_flight,
                        const std::function<bool(Job&)>& produce,
                        const std::function<Result(Job&)>& work,
                        const std::function<void(Result&)>& consume) {
  orderedParallelMap<Job, Result>(n_threads, max_in_flight, JobWeightBound<Job>{}, produce, work, consume);
}

}  // namespace celc
