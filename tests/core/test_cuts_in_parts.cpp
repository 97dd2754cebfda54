// SPDX-License-Identifier: GPL-3.0-or-later
// The twist repair's cut and the bow-tie split over a triangle list held in
// parts (src/core/cuts_in_parts.h): the triangles left and the vertices
// touched must be one process's, for any split, threads standing in for
// processes.
#include "core_test_support.h"
#include "cuts_in_parts.h"
#include "finish_steps.h"
#include "parts_test_support.h"
#include "thread_processes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

using namespace pcl_ms;

TEST(CutsInParts, KeptTrianglesAndTouchedVerticesAreThoseOfOneProcessForAnySplit) {
  const std::vector<Triangle> &all = pcl_ms_test::bunnyReference().triangles;
  const std::vector<Triangle> triangles(all.begin(), all.begin() + 20000);
  const std::size_t n = triangles.size(),
                    point_count = pcl_ms_test::bunnyReference().vertices.size();
  // Scattered cuts leave vertices with two fans or more, whose split takes
  // more triangles, whose corners are checked in turn.
  std::mt19937 random(20261203);
  std::vector<std::uint64_t> to_cut;
  for (std::uint64_t t = 0; t < n; ++t)
    if (random() % 40 == 0)
      to_cut.push_back(t);

  std::vector<Triangle> expected = triangles;
  std::vector<bool> drop(n, false), touched(point_count, false);
  for (std::uint64_t t : to_cut)
    drop[t] = true;
  detail::dropTriangles(expected, drop, touched);
  const std::size_t split_off =
      detail::splitBowTies(expected, point_count, touched, nullptr, nullptr);
  ASSERT_GT(split_off, 100u);

  const std::vector<std::vector<std::size_t>> splits = {
      {0, n}, {0, n / 2, n}, {0, n / 5, n / 5, n}, {0, 0, n / 3, 2 * n / 3, n}, {0, 1, n - 1, n, n},
  };
  for (const std::vector<std::size_t> &cuts : splits) {
    const int processes = static_cast<int>(cuts.size()) - 1;
    SCOPED_TRACE(std::to_string(processes) + " processes");
    std::vector<detail::CutPart> parts(static_cast<std::size_t>(processes));
    pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
      const auto p = static_cast<std::size_t>(group.process());
      const std::vector<Triangle> mine = pcl_ms_test::sliceOf(triangles, cuts[p], cuts[p + 1]);
      // The numbers to cut given round-robin, mostly not on their holders.
      std::vector<std::uint64_t> mine_to_cut;
      for (std::size_t i = p; i < to_cut.size(); i += static_cast<std::size_t>(processes))
        mine_to_cut.push_back(to_cut[i]);
      parts[p] = detail::cutInParts(mine, cuts[p], mine_to_cut, group);
    });
    std::vector<Triangle> kept, kept_by_place;
    std::vector<bool> touched_in_parts(point_count, false);
    for (int p = 0; p < processes; ++p) {
      const detail::CutPart &part = parts[static_cast<std::size_t>(p)];
      EXPECT_EQ(part.first, kept.size()) << "process " << p;
      EXPECT_EQ(part.split_off, split_off) << "process " << p;
      EXPECT_TRUE(std::is_sorted(part.touched.begin(), part.touched.end()));
      kept.insert(kept.end(), part.kept.begin(), part.kept.end());
      // The places of what went leave exactly the kept triangles.
      ASSERT_TRUE(std::is_sorted(part.dropped.begin(), part.dropped.end()));
      for (std::size_t t = cuts[static_cast<std::size_t>(p)], d = 0;
           t < cuts[static_cast<std::size_t>(p) + 1]; ++t) {
        if (d < part.dropped.size() && part.dropped[d] + cuts[static_cast<std::size_t>(p)] == t)
          ++d;
        else
          kept_by_place.push_back(triangles[t]);
      }
      for (VertexIndex v : part.touched)
        touched_in_parts[v] = true;
    }
    EXPECT_EQ(kept, expected);
    EXPECT_EQ(kept_by_place, expected);
    EXPECT_EQ(touched_in_parts, touched);
  }
}

TEST(CutsInParts, RunsThatDoNotFollowEachOtherOrNumbersBeyondTheListFailOnEveryProcess) {
  const std::vector<Triangle> &all = pcl_ms_test::bunnyReference().triangles;
  const std::vector<Triangle> triangles(all.begin(), all.begin() + 1000);
  // Each case: where process 1's run starts, and a number to cut.
  const std::vector<std::pair<std::uint64_t, std::uint64_t>> cases = {
      {501, 3},    // a gap between the runs
      {0, 3},      // both runs from triangle 0
      {500, 1000}, // a number beyond the list
  };
  for (const auto &one_case : cases) {
    const std::uint64_t second_first = one_case.first, number = one_case.second;
    std::vector<int> failed(2, 0);
    pcl_ms_test::onThreadProcesses(2, [&](ProcessGroup &group) {
      const auto p = static_cast<std::size_t>(group.process());
      const std::vector<Triangle> mine(triangles.begin() + (p == 0 ? 0 : 500),
                                       p == 0 ? triangles.begin() + 500 : triangles.end());
      try {
        detail::cutInParts(
            mine, p == 0 ? 0 : second_first,
            p == 1 ? std::vector<std::uint64_t>{number} : std::vector<std::uint64_t>{}, group);
      } catch (const std::invalid_argument &) {
        failed[p] = 1;
      }
    });
    EXPECT_EQ(failed, std::vector<int>({1, 1})) << "process 1 from " << second_first;
  }
}
