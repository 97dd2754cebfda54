// SPDX-License-Identifier: GPL-3.0-or-later
// The twist repair's choice of triangles to cut over a triangle list held
// in parts (src/core/conflicts_in_parts.h): the same triangles as one
// process, for any split, with and without a viewpoint, threads standing in
// for processes.
#include "components_in_parts.h"
#include "conflicts_in_parts.h"
#include "core_test_support.h"
#include "edges_in_parts.h"
#include "finish_steps.h"
#include "parts_test_support.h"
#include "points_from_homes.h"
#include "thread_processes.h"
#include "twists_in_parts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

using namespace pcl_ms;

namespace {

/// Appends a k × k grid of points in the plane z = 0 from `origin`, with
/// its triangles; returns two boundary edges of it, far apart.
std::array<std::array<VertexIndex, 2>, 2> appendGrid(int k, const Eigen::Vector3d &origin,
                                                     double spacing,
                                                     std::vector<Eigen::Vector3d> &points,
                                                     std::vector<Triangle> &triangles) {
  const auto offset = static_cast<VertexIndex>(points.size());
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      points.push_back(origin + spacing * Eigen::Vector3d(i, j, 0));
  const auto at = [&](int i, int j) { return offset + static_cast<VertexIndex>(i * k + j); };
  for (int i = 0; i + 1 < k; ++i)
    for (int j = 0; j + 1 < k; ++j) {
      triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  // Each on the second triangle of cell (0, 0) or (0, k - 2) only.
  return {{{at(0, 0), at(0, 1)}, {at(0, k - 2), at(0, k - 1)}}};
}

/// Appends a Moebius band of `segments` segments moved by `offset` (with
/// jitter, if given), its triangles turned at random; with `glue`, joined to
/// that boundary edge by two triangles, so that it is one component with
/// the edge's surface.
void appendBand(int segments, const Eigen::Vector3d &offset, double jitter,
                const std::array<VertexIndex, 2> *glue, std::mt19937 &random,
                std::vector<Eigen::Vector3d> &points, std::vector<Triangle> &triangles) {
  std::vector<Eigen::Vector3d> band_points;
  std::vector<Triangle> band;
  pcl_ms_test::moebiusBand(segments, 0.3, band_points, band);
  std::uniform_real_distribution<double> shake(-jitter, jitter);
  const auto first = static_cast<VertexIndex>(points.size());
  for (const Eigen::Vector3d &point : band_points)
    points.push_back(point + offset + Eigen::Vector3d(shake(random), shake(random), shake(random)));
  for (Triangle t : band) {
    for (VertexIndex &v : t)
      v += first;
    if (random() % 3 == 0)
      std::swap(t[1], t[2]);
    triangles.push_back(t);
  }
  if (glue) {
    // On the band's rail from its vertex 0 to 2, and on the glued edge.
    triangles.push_back({first, first + 2, (*glue)[0]});
    triangles.push_back({first, (*glue)[0], (*glue)[1]});
  }
}

/// Surfaces whose twists each rule decides: a grid with a band of 40
/// segments glued on (a twist closed by a long walk only), a band of 200
/// alone (a real twist: no walk closes it), a grid with bands of 200 and 40
/// glued on (the long walks in key order, a failed one stopping the rest),
/// a jittered band of 6 segments (short walks) and one of 200 so jittered
/// that the twist is left at a sharp fold, which no walk closes.
std::vector<Eigen::Vector3d> twistedSurfaces(std::vector<Triangle> &triangles) {
  std::vector<Eigen::Vector3d> points;
  std::mt19937 random(20261205);
  const auto first_grid = appendGrid(60, Eigen::Vector3d(-1, -1, -0.5), 0.05, points, triangles);
  appendBand(40, Eigen::Vector3d(0, 0, 0), 0, &first_grid[0], random, points, triangles);
  appendBand(200, Eigen::Vector3d(5, 0, 0), 0, nullptr, random, points, triangles);
  const auto second_grid = appendGrid(60, Eigen::Vector3d(9, -1, -0.5), 0.05, points, triangles);
  appendBand(200, Eigen::Vector3d(10, 0, 0), 0, &second_grid[0], random, points, triangles);
  appendBand(40, Eigen::Vector3d(10, 0, 1), 0, &second_grid[1], random, points, triangles);
  appendBand(6, Eigen::Vector3d(15, 0, 0), 0.05, nullptr, random, points, triangles);
  appendBand(200, Eigen::Vector3d(20, 0, 0), 0.05, nullptr, random, points, triangles);
  return points;
}

} // namespace

TEST(ConflictsInParts, CutsAreThoseOfOneProcessForAnySplitWithOrWithoutAViewpoint) {
  std::vector<Triangle> triangles;
  const std::vector<Eigen::Vector3d> points = twistedSurfaces(triangles);
  const std::size_t n = triangles.size();
  const std::vector<std::uint32_t> neighbours = detail::meshEdges(triangles, true).neighbours;
  const Eigen::Vector3d viewpoint(3, 2, 10);
  for (const Eigen::Vector3d *view : {static_cast<const Eigen::Vector3d *>(nullptr), &viewpoint}) {
    SCOPED_TRACE(view ? "with a viewpoint" : "without a viewpoint");
    std::vector<Triangle> oriented = triangles;
    std::vector<std::uint32_t> component;
    std::vector<bool> orientable;
    std::vector<std::uint32_t> one_process =
        detail::orientAlongNeighbours(oriented, neighbours, points, component, orientable, view);
    std::vector<std::uint64_t> expected(one_process.begin(), one_process.end());
    std::sort(expected.begin(), expected.end());
    expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
    ASSERT_EQ(std::count(orientable.begin(), orientable.end(), false), 5);
    ASSERT_FALSE(expected.empty());

    const std::vector<std::vector<std::size_t>> splits = {
        {0, n},
        {0, n / 2, n},
        {0, n / 5, n / 5, 2 * n / 3, n},
        {0, 1, n / 3, n - 50, n - 1, n},
    };
    for (const std::vector<std::size_t> &cuts : splits) {
      const int processes = static_cast<int>(cuts.size()) - 1;
      SCOPED_TRACE(std::to_string(processes) + " processes");
      std::vector<std::vector<std::uint64_t>> chosen(static_cast<std::size_t>(processes));
      pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
        const auto p = static_cast<std::size_t>(group.process());
        const pcl_ms_test::OrientationInputs inputs = pcl_ms_test::orientationInputs(
            triangles, cuts, points, pcl_ms_test::HomeCut::even, group);
        const std::vector<Triangle> &mine = inputs.mine;
        const detail::MeshEdgesPart &edges = inputs.edges;
        const detail::ComponentsPart &components = inputs.components;
        const detail::CornerPoints &corners = inputs.corners;
        const detail::TwistsPart twists =
            detail::twistForestInParts(mine, cuts[p], edges, components, corners, group);
        std::vector<Triangle> turned = mine;
        for (std::size_t t = 0; t < turned.size(); ++t)
          if (components.orientable[t] ? components.flipped[t] : twists.flipped[t])
            std::swap(turned[t][1], turned[t][2]);
        chosen[p] = detail::conflictCutsInParts(turned, cuts[p], edges, components, corners,
                                                twists.conflicts, view, group);
      });
      std::vector<std::uint64_t> in_parts;
      for (const std::vector<std::uint64_t> &some : chosen)
        in_parts.insert(in_parts.end(), some.begin(), some.end());
      std::sort(in_parts.begin(), in_parts.end());
      in_parts.erase(std::unique(in_parts.begin(), in_parts.end()), in_parts.end());
      EXPECT_EQ(in_parts, expected);
    }
  }
}
