// SPDX-License-Identifier: GPL-3.0-or-later
// Hole filling over a triangle list held in parts (src/core/holes_in_parts.h):
// the fillings and the loops left must be one process's, for any split of
// the triangles and of the points, threads standing in for processes.
#include "core_test_support.h"
#include "edges_in_parts.h"
#include "finish_steps.h"
#include "holes_in_parts.h"
#include "parts_test_support.h"
#include "thread_processes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

using namespace pcl_ms;

namespace {

/// A patch of the bunny's reference mesh with holes of one to a few
/// triangles (every 31st taken out, and runs of three every 97), which
/// fill or not by their size and shape, beside the patch's long cut.
std::vector<Triangle> bunnyPatchWithHoles() {
  return pcl_ms_test::bunnyPatchWithout([](std::size_t t) { return t % 31 == 0 || t % 97 < 3; });
}

struct FilledInOneProcess {
  std::vector<Triangle> filling;
  std::size_t filled = 0;
  std::vector<std::vector<VertexIndex>> loops; // after the filling
};

FilledInOneProcess fillInOneProcess(std::vector<Triangle> triangles,
                                    const std::vector<Eigen::Vector3d> &points,
                                    const std::vector<float> &scales, int max_edges, double rho,
                                    const std::vector<bool> *only_around) {
  FilledInOneProcess result;
  detail::MeshEdges edges = detail::meshEdges(triangles, true);
  result.filled =
      detail::fillLoops(triangles, detail::boundaryLoops(edges.boundary), points, max_edges,
                        SideLimit{&scales, rho}, only_around, result.filling);
  const std::size_t first_new = triangles.size();
  triangles.insert(triangles.end(), result.filling.begin(), result.filling.end());
  detail::addFilling(edges, triangles, first_new);
  result.loops = detail::boundaryLoops(edges.boundary);
  return result;
}

} // namespace

TEST(HolesInParts, FillingsAndLoopsAreThoseOfOneProcessForAnySplit) {
  const std::vector<Triangle> triangles = bunnyPatchWithHoles();
  const std::vector<Eigen::Vector3d> &points = pcl_ms_test::bunnyReference().vertices;
  const std::vector<float> scales = pcl_ms_test::varyingScales(points.size());
  const std::size_t n = triangles.size(), point_count = points.size();
  constexpr int max_edges = 12;
  constexpr double rho = 5;
  // Marked vertices for fillings only around them: every 5th corner.
  std::vector<bool> marks(point_count, false);
  for (const Triangle &t : triangles)
    if (t[0] % 5 == 0)
      marks[t[0]] = true;
  const std::vector<std::vector<std::size_t>> splits = {
      {0, n}, {0, n / 2, n}, {0, n / 5, n / 5, n}, {0, 0, n / 3, 2 * n / 3, n}, {0, 1, n - 1, n, n},
  };
  for (const bool only_around : {false, true}) {
    SCOPED_TRACE(only_around ? "only around marked vertices" : "all loops");
    const FilledInOneProcess expected =
        fillInOneProcess(triangles, points, scales, max_edges, rho, only_around ? &marks : nullptr);
    // Some loops filled, some small ones refused (by the limit or the marks).
    ASSERT_GT(expected.filled, 50u);
    ASSERT_GT(std::count_if(expected.loops.begin(), expected.loops.end(),
                            [&](const std::vector<VertexIndex> &loop) {
                              return loop.size() <= static_cast<std::size_t>(max_edges);
                            }),
              10);
    for (const std::vector<std::size_t> &cuts : splits) {
      const int processes = static_cast<int>(cuts.size()) - 1;
      SCOPED_TRACE(std::to_string(processes) + " processes");
      std::vector<detail::HolesPart> parts(static_cast<std::size_t>(processes));
      pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
        const auto p = static_cast<std::size_t>(group.process());
        const std::vector<Triangle> mine = pcl_ms_test::sliceOf(triangles, cuts[p], cuts[p + 1]);
        // Home slices cut elsewhere than the runs, the first one empty.
        const pcl_ms_test::HomeSlice home =
            pcl_ms_test::homeSlice(points, p, processes, pcl_ms_test::HomeCut::uneven, scales);
        // The processes before the last mark a share of the vertices each;
        // the last (of several) gives no list.
        const std::size_t listing = processes > 1 ? static_cast<std::size_t>(processes) - 1 : 1;
        const bool gives_list = only_around && p < listing;
        std::vector<VertexIndex> around;
        for (VertexIndex v = 0; v < point_count && gives_list; ++v)
          if (marks[v] && v % listing == p)
            around.push_back(v);
        const detail::MeshEdgesPart edges =
            detail::meshEdgesInParts(mine, cuts[p], point_count, group);
        parts[p] = detail::fillHolesInParts(mine, edges, home.points, home.scales, home.begin,
                                            max_edges, rho, gives_list ? &around : nullptr, group);
      });
      for (int p = 0; p < processes; ++p) {
        SCOPED_TRACE("process " + std::to_string(p));
        const detail::HolesPart &part = parts[static_cast<std::size_t>(p)];
        EXPECT_EQ(part.filled, expected.filled);
        if (p + 1 == processes)
          EXPECT_EQ(part.filling, expected.filling);
        else
          EXPECT_TRUE(part.filling.empty());
        if (p == 0)
          EXPECT_EQ(part.loops, expected.loops);
        else
          EXPECT_TRUE(part.loops.empty());
      }
    }
  }
}

TEST(HolesInParts, NothingToFillLeavesTheLoopsAsTraced) {
  const std::vector<Triangle> triangles = bunnyPatchWithHoles();
  const std::vector<Eigen::Vector3d> &points = pcl_ms_test::bunnyReference().vertices;
  const std::vector<float> scales = pcl_ms_test::varyingScales(points.size());
  const std::size_t n = triangles.size();
  const std::vector<std::vector<VertexIndex>> traced =
      detail::boundaryLoops(detail::meshEdges(triangles, false).boundary);
  ASSERT_GT(traced.size(), 100u);
  // Loops of at most two edges do not exist; an empty list of marks leaves
  // none to fill either.
  for (const bool marks_none : {false, true}) {
    std::vector<detail::HolesPart> parts(2);
    pcl_ms_test::onThreadProcesses(2, [&](ProcessGroup &group) {
      const auto p = static_cast<std::size_t>(group.process());
      const std::size_t begin = p * n / 2, end = (p + 1) * n / 2;
      const std::vector<Triangle> mine(triangles.begin() + static_cast<std::ptrdiff_t>(begin),
                                       triangles.begin() + static_cast<std::ptrdiff_t>(end));
      const detail::MeshEdgesPart edges =
          detail::meshEdgesInParts(mine, begin, points.size(), group);
      const std::vector<VertexIndex> no_marks;
      parts[p] = detail::fillHolesInParts(
          mine, edges, p == 0 ? points : std::vector<Eigen::Vector3d>(),
          p == 0 ? scales : std::vector<float>(), p == 0 ? 0 : points.size(), marks_none ? 12 : 2,
          5, marks_none ? &no_marks : nullptr, group);
    });
    SCOPED_TRACE(marks_none ? "no vertex marked" : "at most two edges");
    EXPECT_EQ(parts[0].loops, traced);
    for (const detail::HolesPart &part : parts) {
      EXPECT_EQ(part.filled, 0u);
      EXPECT_TRUE(part.filling.empty());
    }
  }
}

TEST(HolesInParts, SlicesThatDoNotFollowEachOtherOrLackScalesFailOnEveryProcess) {
  const std::vector<Triangle> triangles = bunnyPatchWithHoles();
  const std::vector<Eigen::Vector3d> &points = pcl_ms_test::bunnyReference().vertices;
  const std::vector<float> scales = pcl_ms_test::varyingScales(points.size());
  const std::size_t half = points.size() / 2;
  // Each case: where process 1's slice starts, and whether it lacks a scale.
  const std::vector<std::pair<std::size_t, bool>> cases = {
      {half + 1, false}, // a gap between the slices
      {0, false},        // both slices from point 0
      {half, true},      // one scale fewer than points
  };
  for (const auto &one_case : cases) {
    const std::size_t second_first = one_case.first;
    const bool lacks_scale = one_case.second;
    std::vector<int> failed(2, 0);
    pcl_ms_test::onThreadProcesses(2, [&](ProcessGroup &group) {
      const auto p = static_cast<std::size_t>(group.process());
      const std::vector<Triangle> mine = p == 0 ? triangles : std::vector<Triangle>();
      const std::size_t home_first = p == 0 ? 0 : second_first,
                        home_end = p == 0 ? half : points.size();
      const std::vector<Eigen::Vector3d> home(
          points.begin() + static_cast<std::ptrdiff_t>(home_first),
          points.begin() + static_cast<std::ptrdiff_t>(home_end));
      std::vector<float> home_scales(scales.begin() + static_cast<std::ptrdiff_t>(home_first),
                                     scales.begin() + static_cast<std::ptrdiff_t>(home_end));
      if (lacks_scale && p == 1)
        home_scales.pop_back();
      const detail::MeshEdgesPart edges =
          detail::meshEdgesInParts(mine, p == 0 ? 0 : triangles.size(), points.size(), group);
      try {
        detail::fillHolesInParts(mine, edges, home, home_scales, home_first, 12, 5, nullptr, group);
      } catch (const std::invalid_argument &) {
        failed[p] = 1;
      }
    });
    EXPECT_EQ(failed, std::vector<int>({1, 1})) << "process 1 from " << second_first;
  }
}
