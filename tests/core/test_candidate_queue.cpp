// SPDX-License-Identifier: GPL-3.0-or-later
// The greedy's queue (candidate_queue.h): whatever way entries arrive (a
// large batch sorted into the run, with or without a rest of the run to
// merge with, a few pushed onto the heap, or delayed ones into their own
// run), they come out cheapest first, ties by candidate index, none lost and
// none repeated.
#include "candidate_queue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

namespace {

using pcl_ms::detail::CandidateQueue;
using pcl_ms::detail::QueueEntry;

struct Pushed {
  float cost;
  pcl_ms::CandidateIndex candidate;
  bool operator<(const Pushed &other) const {
    return cost != other.cost ? cost < other.cost : candidate < other.candidate;
  }
};

// Costs from a few values, so that many tie and the index decides.
float randomCost(std::mt19937 &random) {
  std::uniform_int_distribution<int> step(0, 40);
  return 0.25f * static_cast<float>(step(random));
}

} // namespace

TEST(CandidateQueue, EntriesComeOutCheapestFirstThroughEveryPath) {
  std::mt19937 random(20261205);
  CandidateQueue queue;
  std::vector<Pushed> waiting; // pushed, not popped: the reference
  pcl_ms::CandidateIndex next_candidate = 0;
  auto pushBatch = [&](std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      const Pushed entry{randomCost(random), next_candidate++};
      waiting.push_back(entry);
      queue.push(QueueEntry(entry.cost, entry.candidate));
    }
  };
  std::size_t popped = 0;
  auto popAndCheck = [&](std::size_t count) {
    for (std::size_t i = 0; i < count && !waiting.empty(); ++i) {
      ASSERT_FALSE(queue.empty());
      const auto cheapest = std::min_element(waiting.begin(), waiting.end());
      const QueueEntry top = queue.top();
      ASSERT_EQ(top.cost(), cheapest->cost) << "pop " << popped;
      ASSERT_EQ(top.candidate(), cheapest->candidate) << "pop " << popped;
      queue.pop();
      waiting.erase(cheapest);
      ++popped;
    }
  };
  pushBatch(5000); // a batch into an empty run: it becomes the run
  popAndCheck(1000);
  pushBatch(3000); // a batch merged with the rest of the run
  popAndCheck(500);
  pushBatch(50); // a few: onto the heap, beside the run
  popAndCheck(20);
  pushBatch(2000); // merged again, with the heap holding entries
  popAndCheck(100000);
  ASSERT_TRUE(queue.empty());
  pushBatch(4000); // everything popped: a batch into an emptied run
  popAndCheck(100000);
  EXPECT_TRUE(waiting.empty());
  EXPECT_TRUE(queue.empty());
  EXPECT_EQ(popped, 14050u);
  EXPECT_EQ(queue.size(), 0u);
}

// A pass as the greedy runs it: each popped candidate may come back delayed
// at a higher cost (mostly rising, so most extend the delayed run; some lower
// than the run's last, so they take the ordinary path), while changed costs
// arrive as ordinary pushes and compaction drops outdated entries.
TEST(CandidateQueue, DelayedEntriesComeOutInOrderWithTheRest) {
  std::mt19937 random(20261206);
  CandidateQueue queue;
  std::multiset<Pushed> waiting; // the reference
  pcl_ms::CandidateIndex next_candidate = 0;
  auto push = [&](float cost, bool delayed) {
    const Pushed entry{cost, next_candidate++};
    waiting.insert(entry);
    if (delayed)
      queue.pushDelayed(QueueEntry(entry.cost, entry.candidate));
    else
      queue.push(QueueEntry(entry.cost, entry.candidate));
  };
  for (int i = 0; i < 20000; ++i)
    push(randomCost(random), false);
  std::uniform_int_distribution<int> dice(0, 99);
  std::size_t popped = 0, compactions = 0;
  while (!waiting.empty()) {
    ASSERT_FALSE(queue.empty());
    const Pushed cheapest = *waiting.begin();
    const QueueEntry top = queue.top();
    ASSERT_EQ(top.cost(), cheapest.cost) << "pop " << popped;
    ASSERT_EQ(top.candidate(), cheapest.candidate) << "pop " << popped;
    queue.pop();
    waiting.erase(waiting.begin());
    ++popped;
    if (next_candidate >= 60000)
      continue; // drain
    const int roll = dice(random);
    if (roll < 50)
      push(cheapest.cost * 1.2f + 0.01f, true);
    else if (roll < 55)
      push(cheapest.cost * 0.5f, true); // below the delayed run's last entry
    else if (roll < 75)
      push(cheapest.cost + 0.25f * static_cast<float>(dice(random) % 4), false);
    if (popped % 9000 == 0) {
      auto isCurrent = [](const QueueEntry &entry) { return entry.candidate() % 7 != 3; };
      queue.compact(isCurrent);
      for (auto it = waiting.begin(); it != waiting.end();)
        it = isCurrent(QueueEntry(it->cost, it->candidate)) ? std::next(it) : waiting.erase(it);
      ++compactions;
      ASSERT_EQ(queue.size(), waiting.size());
    }
  }
  EXPECT_TRUE(queue.empty());
  EXPECT_EQ(queue.size(), 0u);
  EXPECT_GT(compactions, 3u);
  EXPECT_GT(popped, 50000u);
}
