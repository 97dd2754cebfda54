// SPDX-License-Identifier: GPL-3.0-or-later
// The greedy's queue (candidate_queue.h): whatever way entries arrive (a
// large batch sorted into the run, with or without a rest of the run to
// merge with, or a few pushed onto the heap), they come out cheapest first,
// ties by candidate index, none lost and none repeated.
#include "candidate_queue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
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
