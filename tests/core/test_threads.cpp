// SPDX-License-Identifier: GPL-3.0-or-later
// The core's thread helpers (src/core/threads.h): one thread runs every loop
// on the caller without starting TBB; more threads run them in TBB's arena.
#include "core_test_support.h"
#include "threads.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <fstream>
#include <functional>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

using namespace pcl_ms;

namespace {

/// Whether TBB has started: it starts worker threads when it first runs
/// work on more than one thread, and keeps them, and the test process has
/// no thread of its own besides the main one. (Whether TBB's allocator
/// library is loaded told it too until the core linked that library for
/// CGAL's parallel triangulation.)
bool tbbStarted() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("Threads:", 0) == 0)
      return std::stoul(line.substr(8)) > 1;
  ADD_FAILURE() << "no thread count in /proc/self/status";
  return true;
}

/// Every n-th vertex of the bunny, as coordinates.
std::vector<float> everyNthBunnyVertex(std::size_t n) {
  const std::vector<float> bunny = pcl_ms_test::bunnyCoordinates();
  std::vector<float> xyz;
  for (std::size_t i = 0; i + 3 <= bunny.size(); i += 3 * n)
    xyz.insert(xyz.end(), bunny.begin() + i, bunny.begin() + i + 3);
  return xyz;
}

/// Meshes `xyz` with `without`, then with `with`: TBB must start only in
/// the second call (ctest runs each test in a process of its own), and both
/// must give the same mesh, of more than `min_triangles` triangles.
void expectTbbStartsOnlyWith(const std::vector<float> &xyz, const Parameters &without,
                             const Parameters &with, std::size_t min_triangles) {
  const Result first = reconstruct(pcl_ms_test::viewOf(xyz), without);
  EXPECT_GT(first.triangles.size(), min_triangles);
  EXPECT_FALSE(tbbStarted());
  const Result second = reconstruct(pcl_ms_test::viewOf(xyz), with);
  EXPECT_TRUE(tbbStarted());
  EXPECT_EQ(second.triangles, first.triangles);
}

/// Makes about 25 million accesses to `scratch`: ThreadSanitizer remembers
/// at most about 4 million per thread, so where the thread wrote before this
/// is forgotten. It records a repeated access only once between two of the
/// thread's releases, hence the release on each round.
void overwriteTsanHistory(std::vector<std::uint64_t> &scratch) {
  std::atomic<int> round{0};
  scratch.assign(4096, 1);
  while (round.fetch_add(1, std::memory_order_release) < 2000)
    for (std::size_t i = 1; i < scratch.size(); ++i)
      scratch[i] += scratch[i - 1];
}

} // namespace

TEST(Threads, OneThreadRunsEveryLoopOnTheCallerInOrder) {
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<std::size_t> order;
  bool others = false;
  std::vector<int> values(10000);
  std::iota(values.rbegin(), values.rend(), 0);
  const int sum = detail::withThreads(1, [&] {
    EXPECT_TRUE(detail::onOneThread());
    detail::parallelFor(std::size_t(3), std::size_t(2003), [&](std::size_t i) {
      others |= std::this_thread::get_id() != caller;
      order.push_back(i);
    });
    std::size_t calls = 0;
    detail::parallelFor(tbb::blocked_range<std::size_t>(0, 5000, 16),
                        [&](const tbb::blocked_range<std::size_t> &range) {
                          ++calls;
                          EXPECT_EQ(range.begin(), 0u);
                          EXPECT_EQ(range.end(), 5000u);
                        });
    EXPECT_EQ(calls, 1u);
    detail::parallelSort(values.begin(), values.end(), std::less<>());
    return detail::parallelReduce(
        tbb::blocked_range<std::size_t>(0, values.size(), 64), 0,
        [&](const tbb::blocked_range<std::size_t> &range, int total) {
          for (std::size_t i = range.begin(); i != range.end(); ++i)
            total += values[i] % 7;
          return total;
        },
        std::plus<>());
  });
  EXPECT_FALSE(others);
  ASSERT_EQ(order.size(), 2000u);
  for (std::size_t k = 0; k < order.size(); ++k)
    ASSERT_EQ(order[k], k + 3);
  EXPECT_TRUE(std::is_sorted(values.begin(), values.end()));
  int expected = 0;
  for (int value : values)
    expected += value % 7;
  EXPECT_EQ(sum, expected);
  EXPECT_FALSE(detail::onOneThread()) << "restored after the work";
}

TEST(Threads, SeveralThreadsCoverEveryIndexOnceAndNestedOneThreadRestores) {
  std::vector<std::atomic<int>> visits(20000);
  std::atomic<int> nested_on_one{0}, restored{0};
  detail::withThreads(2, [&] {
    EXPECT_FALSE(detail::onOneThread());
    detail::parallelFor(std::size_t(0), visits.size(), [&](std::size_t i) {
      ++visits[i];
      if (i % 1000 == 0) {
        // A bucket meshed on one thread inside a parallel run.
        detail::withThreads(1, [&] { nested_on_one += detail::onOneThread(); });
        restored += !detail::onOneThread();
      }
    });
  });
  for (const std::atomic<int> &count : visits)
    ASSERT_EQ(count.load(), 1);
  EXPECT_EQ(nested_on_one.load(), 20);
  EXPECT_EQ(restored.load(), 20);
}

// Items fed while running (seam zones made ready by their buckets) run once
// each; on one thread, each right after the call that fed it.
TEST(Threads, FedItemsRunOnceAndOnOneThreadRightAfterTheirFeeder) {
  // Item i < 100 feeds 100 + i when i is even; fed items feed nothing.
  std::vector<int> items(100);
  std::iota(items.begin(), items.end(), 0);
  auto body = [](auto record) {
    return [record](int item, const auto &feed) {
      record(item);
      if (item < 100 && item % 2 == 0)
        feed(100 + item);
    };
  };
  std::vector<int> order;
  detail::withThreads(1, [&] {
    detail::parallelForEachFed(items, body([&](int item) { order.push_back(item); }));
  });
  std::vector<int> expected;
  for (int i = 0; i < 100; ++i) {
    expected.push_back(i);
    if (i % 2 == 0)
      expected.push_back(100 + i);
  }
  EXPECT_EQ(order, expected);

  std::vector<std::atomic<int>> runs(200);
  detail::withThreads(
      2, [&] { detail::parallelForEachFed(items, body([&](int item) { ++runs[item]; })); });
  for (int i = 0; i < 200; ++i)
    ASSERT_EQ(runs[i].load(), i < 100 || i % 2 == 0 ? 1 : 0) << i;
}

// Plain outputs written in the loops' tasks and read by the caller after
// the loop, once the workers' stacks have left ThreadSanitizer's history
// (a bucket's figures read after every seam is meshed): the loops must tell
// TSan that TBB ordered them, or the sanitizer job (which runs this test)
// reports a race that its suppression for TBB cannot match.
TEST(Threads, TaskWritesAreOrderedBeforeTheCallerAfterTheLoop) {
  const std::size_t items = 8;
  std::vector<std::vector<std::uint64_t>> scratch(5 * items);
  std::vector<std::size_t> by_index(items), by_range(items), fed(2 * items), reduced(items);
  const std::size_t sum = detail::withThreads(2, [&] {
    detail::parallelFor(std::size_t(0), items, [&](std::size_t i) {
      by_index[i] = i + 1;
      overwriteTsanHistory(scratch[i]);
    });
    detail::parallelFor(tbb::blocked_range<std::size_t>(0, items, 1),
                        [&](const tbb::blocked_range<std::size_t> &range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i) {
                            by_range[i] = i + 1;
                            overwriteTsanHistory(scratch[items + i]);
                          }
                        });
    std::vector<std::size_t> first(items);
    std::iota(first.begin(), first.end(), 0);
    // The fed item reads what its feeder wrote.
    detail::parallelForEachFed(first, [&](std::size_t item, const auto &feed) {
      if (item < items) {
        fed[item] = item + 1;
        overwriteTsanHistory(scratch[2 * items + item]);
        feed(item + items);
      } else {
        fed[item] = fed[item - items] + 1;
        overwriteTsanHistory(scratch[2 * items + item]);
      }
    });
    return detail::parallelReduce(
        tbb::blocked_range<std::size_t>(0, items, 1), std::size_t(0),
        [&](const tbb::blocked_range<std::size_t> &range, std::size_t total) {
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            reduced[i] = i + 1;
            total += i + 1;
            overwriteTsanHistory(scratch[4 * items + i]);
          }
          return total;
        },
        [](std::size_t left, std::size_t right) { return left + right; });
  });
  for (std::size_t i = 0; i < items; ++i) {
    EXPECT_EQ(by_index[i], i + 1);
    EXPECT_EQ(by_range[i], i + 1);
    EXPECT_EQ(fed[i], i + 1);
    EXPECT_EQ(fed[items + i], i + 2);
    EXPECT_EQ(reduced[i], i + 1);
  }
  EXPECT_EQ(sum, items * (items + 1) / 2);
}

// Starting TBB cost 7 ms and 4 MB in a process with PCL loaded: a whole
// one-thread reconstruction must not start it. ctest runs each test in its
// own process, where TBB has not started before.
TEST(Threads, OneThreadReconstructionDoesNotStartTbb) {
  if (tbbStarted())
    GTEST_SKIP() << "TBB started earlier in this process (run the test alone)";
  const std::vector<float> xyz = pcl_ms_test::bunnyCoordinates();
  Parameters parameters;
  parameters.num_threads = 1;
  const Result one_piece = reconstruct(pcl_ms_test::viewOf(xyz), parameters);
  EXPECT_GT(one_piece.triangles.size(), 60000u);
  parameters.bucket_points = 10000;
  const Result bucketed = reconstruct(pcl_ms_test::viewOf(xyz), parameters);
  EXPECT_GT(bucketed.bucket_statistics.buckets, 1u);
  EXPECT_GT(bucketed.triangles.size(), 60000u);
  EXPECT_FALSE(tbbStarted());
  // The check sees TBB when it does start.
  std::atomic<int> done{0};
  detail::withThreads(2, [&] {
    detail::parallelFor(std::size_t(0), std::size_t(1000), [&](std::size_t) { ++done; });
  });
  EXPECT_EQ(done.load(), 1000);
  EXPECT_TRUE(tbbStarted());
}

// A cloud meshed in one piece below Parameters::min_points_for_threads runs
// on one thread whatever num_threads says: on 2 cores, TBB's start cost more
// than the second thread saved below about 5,000 points.
TEST(Threads, SmallCloudDoesNotStartTbb) {
  if (tbbStarted())
    GTEST_SKIP() << "TBB started earlier in this process (run the test alone)";
  const std::vector<float> xyz = everyNthBunnyVertex(8); // about 4,500 points
  ASSERT_LT(xyz.size() / 3, Parameters().min_points_for_threads);
  Parameters two_threads;
  two_threads.num_threads = 2;
  Parameters however_few = two_threads;
  however_few.min_points_for_threads = 0;
  expectTbbStartsOnlyWith(xyz, two_threads, however_few, 7000);
}

// From Parameters::min_points_for_threads points on, the threads start: on
// 2 cores they saved 3-14 % from 6,000 points on (docs/algorithm.md,
// "Threads"). The mesh is the one-thread mesh.
TEST(Threads, CloudAtTheThresholdStartsTbb) {
  if (tbbStarted())
    GTEST_SKIP() << "TBB started earlier in this process (run the test alone)";
  const std::vector<float> xyz = everyNthBunnyVertex(4); // about 9,000 points
  ASSERT_GE(xyz.size() / 3, Parameters().min_points_for_threads);
  Parameters one_thread;
  one_thread.num_threads = 1;
  Parameters two_threads;
  two_threads.num_threads = 2;
  expectTbbStartsOnlyWith(xyz, one_thread, two_threads, 15000);
}

// The preparation counts the points the indices select, not the whole
// cloud: 4,500 of the bunny's 35,947 vertices are a small cloud too.
TEST(Threads, FewIndexedPointsDoNotStartTbb) {
  if (tbbStarted())
    GTEST_SKIP() << "TBB started earlier in this process (run the test alone)";
  const std::vector<float> xyz = pcl_ms_test::bunnyCoordinates();
  ASSERT_GE(xyz.size() / 3, Parameters().min_points_for_threads);
  std::vector<std::int32_t> every_eighth;
  for (std::size_t i = 0; i < xyz.size() / 3; i += 8)
    every_eighth.push_back(static_cast<std::int32_t>(i));
  ASSERT_LT(every_eighth.size(), Parameters().min_points_for_threads);
  PointView view = pcl_ms_test::viewOf(xyz);
  view.indices = IndexList(every_eighth);
  Parameters parameters;
  parameters.num_threads = 2;
  const Result small = reconstruct(view, parameters);
  EXPECT_GT(small.triangles.size(), 7000u);
  EXPECT_FALSE(tbbStarted());
}
