// SPDX-License-Identifier: GPL-3.0-or-later
// Parameters::num_threads, and the parallel loops of the core. Internal to the
// library: not installed.
//
// With one thread the loops run on the caller and TBB is never started:
// starting it (its allocator, its thread pool, looking for a resource
// manager) cost 7 ms and 4 MB in a process that had loaded PCL, about 15 %
// of meshing a 2,000-point scan (docs/algorithm.md, "Code layout", "Threads").
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_for_each.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <vector>

#if defined(__SANITIZE_THREAD__)
#define PCL_MS_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define PCL_MS_THREAD_SANITIZER 1
#endif
#endif
#ifdef PCL_MS_THREAD_SANITIZER
#include <sanitizer/tsan_interface.h>
#endif

namespace pcl_ms {
namespace detail {

/// Tells ThreadSanitizer about an ordering that TBB guarantees: Debian's TBB
/// is not built with it, so it cannot see that a loop's tasks start after
/// the caller's writes and that the caller resumes after every task's. A
/// worker's write read by the caller long after the loop was reported as a
/// race when the worker's stack had aged out of TSan's history (and with it
/// the TBB frames that tests/sanitizers/tsan.supp matches). Empty in other
/// builds.
class HandOff {
public:
#ifdef PCL_MS_THREAD_SANITIZER
  void release() { __tsan_release(this); }
  void acquire() { __tsan_acquire(this); }
#else
  void release() {}
  void acquire() {}
#endif
};

/// The hand-offs of one parallel loop, made before it starts: the caller's
/// writes so far go to every task, and when it goes out of scope, after the
/// loop, every task's writes come back to the caller.
class LoopOrder {
public:
  /// Held by a task for as long as it runs: it starts after the caller's
  /// writes and after every feed so far, and hands its writes back.
  class Task {
  public:
    explicit Task(LoopOrder &order) : order_(order) {
      order_.start_.acquire();
      order_.fed_.acquire();
    }
    ~Task() { order_.done_.release(); }
    Task(const Task &) = delete;
    Task &operator=(const Task &) = delete;

  private:
    LoopOrder &order_;
  };

  LoopOrder() { start_.release(); }
  ~LoopOrder() { done_.acquire(); }
  LoopOrder(const LoopOrder &) = delete;
  LoopOrder &operator=(const LoopOrder &) = delete;

  /// Before a task feeds an item: the item starts after what it wrote.
  void feeding() { fed_.release(); }
  /// Before a join: it reads the values of the tasks it joins.
  void joining() { done_.acquire(); }

private:
  HandOff start_, fed_, done_;
};

/// Whether the calling thread runs work limited to one thread (see
/// withThreads): the loops below then run on it, in order.
inline bool &onOneThread() {
  thread_local bool one_thread = false;
  return one_thread;
}

/// Adds one to a count that other threads may add to as well, and returns
/// the count before. For counts and slots taken from parallel loops: the
/// order the slots are taken in depends on the threads, so callers sort what
/// they put in them. On one thread no other thread can add: a plain addition.
template <typename Count> Count countUp(Count &count) {
  if (onOneThread())
    return count++;
  return __atomic_fetch_add(&count, Count{1}, __ATOMIC_RELAXED);
}

/// Runs work() with at most num_threads threads for the loops below, or
/// TBB's default when it is 0 (automatic), and returns its result. With one
/// thread it runs on the caller without TBB.
template <typename Work> decltype(auto) withThreads(int num_threads, Work &&work) {
  struct Restore {
    bool before = onOneThread();
    ~Restore() { onOneThread() = before; }
  } restore;
  onOneThread() = num_threads == 1;
  if (num_threads == 1)
    return work();
  tbb::task_arena arena(num_threads > 0 ? num_threads : tbb::task_arena::automatic);
  LoopOrder order;
  return arena.execute([&]() -> decltype(auto) {
    const LoopOrder::Task task(order);
    return work();
  });
}

/// Calls body(range) for subranges that cover `range`, in parallel unless
/// on one thread. Each call must touch only its own outputs, so the result
/// does not depend on the number of threads.
template <typename Body>
void parallelFor(const tbb::blocked_range<std::size_t> &range, const Body &body) {
  if (onOneThread()) {
    body(range);
    return;
  }
  LoopOrder order;
  tbb::parallel_for(range, [&](const tbb::blocked_range<std::size_t> &part) {
    const LoopOrder::Task task(order);
    body(part);
  });
}

/// Calls body(i) for every i in [begin, end), as parallelFor above.
template <typename Body> void parallelFor(std::size_t begin, std::size_t end, const Body &body) {
  if (onOneThread()) {
    for (std::size_t i = begin; i < end; ++i)
      body(i);
    return;
  }
  LoopOrder order;
  tbb::parallel_for(begin, end, [&](std::size_t i) {
    const LoopOrder::Task task(order);
    body(i);
  });
}

/// Calls body(item, feed) for every item of `items` and every item passed to
/// feed, in parallel unless on one thread; on one thread in order, each fed
/// item right after the call that fed it (TBB too tends to run a fed item
/// next on the thread that fed it). For work that makes more work ready as
/// it goes; body must not wait for other items.
template <typename Item, typename Body>
void parallelForEachFed(const std::vector<Item> &items, const Body &body) {
  if (onOneThread()) {
    std::vector<Item> fed;
    auto feed = [&](const Item &item) { fed.push_back(item); };
    for (const Item &item : items) {
      body(item, feed);
      while (!fed.empty()) {
        const Item next = fed.back();
        fed.pop_back();
        body(next, feed);
      }
    }
    return;
  }
  LoopOrder order;
  tbb::parallel_for_each(items.begin(), items.end(),
                         [&](const Item &item, tbb::feeder<Item> &feeder) {
                           const LoopOrder::Task task(order);
                           body(item, [&](const Item &next) {
                             order.feeding();
                             feeder.add(next);
                           });
                         });
}

/// join over body(subrange, identity) for subranges that cover `range`.
template <typename Value, typename Body, typename Join>
Value parallelReduce(const tbb::blocked_range<std::size_t> &range, const Value &identity,
                     const Body &body, const Join &join) {
  if (onOneThread())
    return body(range, identity);
  LoopOrder order;
  return tbb::parallel_reduce(
      range, identity,
      [&](const tbb::blocked_range<std::size_t> &part, const Value &value) -> Value {
        const LoopOrder::Task task(order);
        return body(part, value);
      },
      [&](const Value &left, const Value &right) -> Value {
        order.joining();
        const LoopOrder::Task task(order);
        return join(left, right);
      });
}

/// Sorts [first, last) by `less`, which must order every pair of distinct
/// items: then any thread count gives the same order.
template <typename Iterator, typename Less>
void parallelSort(Iterator first, Iterator last, const Less &less) {
  if (onOneThread())
    std::sort(first, last, less);
  else
    tbb::parallel_sort(first, last, less);
}

} // namespace detail
} // namespace pcl_ms
