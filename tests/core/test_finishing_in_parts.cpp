// SPDX-License-Identifier: GPL-3.0-or-later
// Finishing steps over a triangle list held in parts by several processes
// (src/core/edges_in_parts.h, components_in_parts.h, points_from_homes.h,
// sides_in_parts.h, twists_in_parts.h): each process must get exactly its
// share of what one process finds, for any split, threads standing in for
// processes.
#include "components_in_parts.h"
#include "core_test_support.h"
#include "edges_in_parts.h"
#include "exact_signs.h"
#include "finish_steps.h"
#include "parts_test_support.h"
#include "points_from_homes.h"
#include "sides_in_parts.h"
#include "thread_processes.h"
#include "twist_bending.h"
#include "twists_in_parts.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <pcl_ms/costs.h>
#include <pcl_ms/disjoint_sets.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

using namespace pcl_ms;

namespace {

/// A patch of the bunny's reference mesh with holes (every 31st triangle
/// taken out): boundary edges along its cut and round the holes, manifold
/// edges elsewhere.
std::vector<Triangle> holedBunnyPatch() {
  return pcl_ms_test::bunnyPatchWithout([](std::size_t t) { return t % 31 == 0; });
}

std::uint64_t vertexCount() { return pcl_ms_test::bunnyReference().vertices.size(); }

/// moebiusBand(), or the same band glued without the half twist.
void moebiusBandOrRing(int segments, bool twisted, std::vector<Eigen::Vector3d> &points,
                       std::vector<Triangle> &triangles) {
  pcl_ms_test::moebiusBand(segments, 0.2, points, triangles);
  if (!twisted) {
    // The last quad joins the ends the other way round.
    Triangle &first = triangles[triangles.size() - 2], &second = triangles.back();
    first[2] = 1;
    second[1] = 1;
    second[2] = 0;
  }
}

/// Checks each process's part of a scan, process p holding the triangles
/// [cuts[p], cuts[p + 1]), against its share of one process's scan `whole`.
void expectShares(const detail::MeshEdges &whole, const std::vector<detail::MeshEdgesPart> &parts,
                  const std::vector<std::size_t> &cuts) {
  const int processes = static_cast<int>(cuts.size()) - 1;
  ASSERT_EQ(parts.size(), cuts.size() - 1);
  std::vector<std::pair<detail::EdgeKey, std::uint64_t>> boundary_of_parts;
  for (int p = 0; p < processes; ++p) {
    SCOPED_TRACE("process " + std::to_string(p) + " of " + std::to_string(processes));
    const detail::MeshEdgesPart &part = parts[static_cast<std::size_t>(p)];
    EXPECT_EQ(part.crowded, whole.crowded);
    ASSERT_EQ(part.neighbours.size(), 3 * (cuts[p + 1] - cuts[p]));
    for (std::size_t t = cuts[p]; t < cuts[p + 1]; ++t)
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint32_t expected = whole.neighbours[3 * t + k];
        ASSERT_EQ(part.neighbours[3 * (t - cuts[p]) + k], expected == detail::no_neighbour
                                                              ? detail::no_neighbour_in_parts
                                                              : std::uint64_t{expected})
            << "triangle " << t << " slot " << k;
      }
    ASSERT_EQ(part.boundary.size(), part.boundary_triangle.size());
    EXPECT_TRUE(std::is_sorted(part.boundary.begin(), part.boundary.end()));
    for (std::size_t e = 0; e < part.boundary.size(); ++e) {
      EXPECT_GE(part.boundary_triangle[e], cuts[p]);
      EXPECT_LT(part.boundary_triangle[e], cuts[p + 1]);
      boundary_of_parts.emplace_back(part.boundary[e], part.boundary_triangle[e]);
    }
  }
  // Together the parts hold the whole scan's boundary, each edge once.
  std::sort(boundary_of_parts.begin(), boundary_of_parts.end());
  ASSERT_EQ(boundary_of_parts.size(), whole.boundary.size());
  for (std::size_t e = 0; e < whole.boundary.size(); ++e) {
    EXPECT_EQ(boundary_of_parts[e].first, whole.boundary[e]);
    EXPECT_EQ(boundary_of_parts[e].second, whole.boundary_triangle[e]);
  }
}

/// Runs the scan on `cuts.size() - 1` processes, process p holding the
/// triangles [cuts[p], cuts[p + 1]), `records_per_round` records a round,
/// and checks each against one scan of the whole list.
void expectSharesOfTheWholeScan(const std::vector<Triangle> &triangles,
                                const std::vector<std::size_t> &cuts,
                                std::size_t records_per_round = std::size_t{1} << 21) {
  const int processes = static_cast<int>(cuts.size()) - 1;
  std::vector<detail::MeshEdgesPart> parts(static_cast<std::size_t>(processes));
  pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
    const auto p = static_cast<std::size_t>(group.process());
    const std::vector<Triangle> mine = pcl_ms_test::sliceOf(triangles, cuts[p], cuts[p + 1]);
    parts[p] = detail::meshEdgesInParts(mine, cuts[p], vertexCount(), group, records_per_round);
  });
  expectShares(detail::meshEdges(triangles, true), parts, cuts);
}

/// Scans `before` in parts, adds `added` to the last run with
/// addTrianglesToEdgesInParts and checks the parts against one process's
/// scan of `before` updated by addFilling().
void expectSharesOfTheUpdatedScan(const std::vector<Triangle> &before,
                                  const std::vector<Triangle> &added,
                                  const std::vector<std::size_t> &cuts_before) {
  std::vector<Triangle> after = before;
  after.insert(after.end(), added.begin(), added.end());
  detail::MeshEdges whole = detail::meshEdges(before, true);
  detail::addFilling(whole, after, before.size());
  std::vector<std::size_t> cuts = cuts_before;
  cuts.back() = after.size();
  const int processes = static_cast<int>(cuts.size()) - 1;
  std::vector<detail::MeshEdgesPart> parts(static_cast<std::size_t>(processes));
  pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
    const auto p = static_cast<std::size_t>(group.process());
    std::vector<Triangle> mine = pcl_ms_test::sliceOf(before, cuts[p], cuts_before[p + 1]);
    parts[p] = detail::meshEdgesInParts(mine, cuts[p], vertexCount(), group);
    const std::size_t first_new = mine.size();
    if (p + 1 == parts.size())
      mine.insert(mine.end(), added.begin(), added.end());
    detail::addTrianglesToEdgesInParts(parts[p], mine, cuts[p], first_new, group);
  });
  expectShares(whole, parts, cuts);
}

/// Scans `triangles` in parts, drops the marked ones with
/// dropFromEdgesInParts and checks the parts against one process's scan
/// updated by dropFromMeshEdges().
void expectSharesAfterDropping(const std::vector<Triangle> &triangles,
                               const std::vector<bool> &drop,
                               const std::vector<std::size_t> &cuts) {
  detail::MeshEdges whole = detail::meshEdges(triangles, true);
  ASSERT_TRUE(detail::dropFromMeshEdges(whole, triangles, drop));
  std::vector<std::size_t> kept_cuts(cuts.size(), 0);
  for (std::size_t p = 0; p + 1 < cuts.size(); ++p)
    kept_cuts[p + 1] =
        kept_cuts[p] + static_cast<std::size_t>(std::count(
                           drop.begin() + static_cast<std::ptrdiff_t>(cuts[p]),
                           drop.begin() + static_cast<std::ptrdiff_t>(cuts[p + 1]), false));
  const int processes = static_cast<int>(cuts.size()) - 1;
  std::vector<detail::MeshEdgesPart> parts(static_cast<std::size_t>(processes));
  pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
    const auto p = static_cast<std::size_t>(group.process());
    const std::vector<Triangle> mine = pcl_ms_test::sliceOf(triangles, cuts[p], cuts[p + 1]);
    parts[p] = detail::meshEdgesInParts(mine, cuts[p], vertexCount(), group);
    std::vector<std::size_t> dropped;
    for (std::size_t t = 0; t < mine.size(); ++t)
      if (drop[cuts[p] + t])
        dropped.push_back(t);
    detail::dropFromEdgesInParts(parts[p], mine, cuts[p], dropped, group);
  });
  expectShares(whole, parts, kept_cuts);
}

} // namespace

TEST(EdgesInParts, DroppedTrianglesUpdateTheScanAsOneProcessDoes) {
  // Scattered triangles, pairs of neighbours, and a run of them: edges that
  // open, edges that go with both triangles, boundary edges that go.
  const std::vector<Triangle> triangles = holedBunnyPatch();
  const std::size_t n = triangles.size();
  const detail::MeshEdges scan = detail::meshEdges(triangles, true);
  std::vector<bool> drop(n, false);
  for (std::size_t t = 0; t < n; t += 53) {
    drop[t] = true;
    if (t % 2 == 0 && scan.neighbours[3 * t] != detail::no_neighbour)
      drop[scan.neighbours[3 * t]] = true;
  }
  for (std::size_t t = n / 2; t < n / 2 + 40; ++t)
    drop[t] = true;
  const std::vector<std::vector<std::size_t>> splits = {{0, n},
                                                        {0, n / 2, n},
                                                        {0, n / 5, n / 5, n},
                                                        {0, 0, n / 3, 2 * n / 3, n},
                                                        {0, 1, n - 1, n, n}};
  for (const std::vector<std::size_t> &cuts : splits) {
    SCOPED_TRACE(std::to_string(cuts.size() - 1) + " processes");
    expectSharesAfterDropping(triangles, drop, cuts);
  }
}

TEST(EdgesInParts, EachProcessGetsItsShareOfTheWholeScanForAnySplit) {
  const std::vector<Triangle> triangles = holedBunnyPatch();
  const std::size_t n = triangles.size();
  {
    const detail::MeshEdges whole = detail::meshEdges(triangles, true);
    ASSERT_GT(whole.boundary.size(), 1000u);
    ASSERT_FALSE(whole.crowded);
  }
  const std::vector<std::vector<std::size_t>> splits = {
      {0, n},
      {0, n / 2, n},
      {0, n / 5, n / 5, n},        // an empty run in the middle
      {0, 0, n / 3, 2 * n / 3, n}, // an empty first run
      {0, 1, n - 1, n, n},         // runs of one triangle, an empty last run
  };
  for (const std::vector<std::size_t> &cuts : splits) {
    SCOPED_TRACE(std::to_string(cuts.size() - 1) + " processes");
    expectSharesOfTheWholeScan(triangles, cuts);
    // In rounds of a few hundred records, which mix the judges' answers.
    expectSharesOfTheWholeScan(triangles, cuts, 300);
  }
}

TEST(EdgesInParts, AddedTrianglesUpdateTheScanAsOneProcessDoes) {
  // The holes' triangles (every 31st of the patch, some next to each
  // other), then a triangle on a boundary edge that opens two new edges.
  const std::vector<Triangle> whole =
      pcl_ms_test::bunnyPatchWithout([](std::size_t) { return false; });
  std::vector<Triangle> before, added;
  for (std::size_t t = 0; t < whole.size(); ++t)
    (t % 31 == 0 || t % 31 == 1 ? added : before).push_back(whole[t]);
  const detail::MeshEdges scan = detail::meshEdges(before, true);
  ASSERT_FALSE(scan.crowded);
  const detail::EdgeKey open = scan.boundary.front();
  VertexIndex far_corner = 0;
  while (far_corner == detail::lowVertex(open) || far_corner == detail::highVertex(open))
    ++far_corner;
  added.push_back({detail::lowVertex(open), detail::highVertex(open), far_corner});
  const std::size_t n = before.size();
  const std::vector<std::vector<std::size_t>> splits = {
      {0, n}, {0, n / 2, n}, {0, n / 5, n / 5, n}, {0, 0, n / 3, 2 * n / 3, n}, {0, 1, n, n}};
  for (const std::vector<std::size_t> &cuts : splits) {
    SCOPED_TRACE(std::to_string(cuts.size() - 1) + " processes");
    expectSharesOfTheUpdatedScan(before, added, cuts);
  }
}

TEST(EdgesInParts, TwoAddedTrianglesOnABoundaryEdgeMakeTheListCrowdedOnEveryProcess) {
  const std::vector<Triangle> before = holedBunnyPatch();
  const detail::MeshEdges scan = detail::meshEdges(before, true);
  const detail::EdgeKey open = scan.boundary[scan.boundary.size() / 2];
  const VertexIndex low = detail::lowVertex(open), high = detail::highVertex(open);
  std::vector<Triangle> added;
  for (VertexIndex corner = 0; added.size() < 2; ++corner)
    if (corner != low && corner != high)
      added.push_back({low, high, corner});
  std::vector<Triangle> after = before;
  after.insert(after.end(), added.begin(), added.end());
  detail::MeshEdges whole = detail::meshEdges(before, true);
  detail::addFilling(whole, after, before.size());
  ASSERT_TRUE(whole.crowded);
  const std::size_t n = before.size();
  expectSharesOfTheUpdatedScan(before, added, {0, n / 3, n});
  expectSharesOfTheUpdatedScan(before, added, {0, n - 1, n});
}

TEST(EdgesInParts, AnEdgeOfThreeTrianglesIsCrowdedOnEveryProcess) {
  // A third triangle on an edge the patch's first two share: the edge gets
  // no slots and is no boundary edge, as in one scan, and every process
  // learns that the list is crowded.
  std::vector<Triangle> triangles = holedBunnyPatch();
  const detail::MeshEdges before = detail::meshEdges(triangles, true);
  const std::uint32_t u = before.neighbours[3];
  ASSERT_NE(u, detail::no_neighbour);
  const detail::EdgeKey shared = detail::sharedEdge(triangles[1], triangles[u]);
  VertexIndex third_corner = 0;
  for (VertexIndex v : triangles.back())
    if (v != detail::lowVertex(shared) && v != detail::highVertex(shared))
      third_corner = v;
  triangles.push_back({detail::lowVertex(shared), detail::highVertex(shared), third_corner});
  ASSERT_TRUE(detail::meshEdges(triangles, true).crowded);
  const std::size_t n = triangles.size();
  expectSharesOfTheWholeScan(triangles, {0, n / 3, n});
  expectSharesOfTheWholeScan(triangles, {0, 2, n / 2, n - 1, n});
}

TEST(EdgesInParts, RunsThatDoNotFollowEachOtherOrCornersBeyondThePointsFailOnEveryProcess) {
  const std::vector<Triangle> triangles = holedBunnyPatch();
  const std::size_t half = triangles.size() / 2;
  const std::vector<Triangle> first_half(triangles.begin(),
                                         triangles.begin() + static_cast<std::ptrdiff_t>(half));
  const std::vector<Triangle> second_half(triangles.begin() + static_cast<std::ptrdiff_t>(half),
                                          triangles.end());
  // Each case: process 1's first triangle number, and the vertex count.
  const std::vector<std::pair<std::uint64_t, std::uint64_t>> cases = {
      {half + 1, vertexCount()}, // a gap between the runs
      {0, vertexCount()},        // both runs from triangle 0
      {half, 100},               // corners beyond the points
  };
  for (const auto &one_case : cases) {
    // Named copies: clang 14 cannot capture structured bindings.
    const std::uint64_t second_first = one_case.first, vertex_count = one_case.second;
    std::vector<int> failed(2, 0);
    pcl_ms_test::onThreadProcesses(2, [&](ProcessGroup &group) {
      const int p = group.process();
      try {
        detail::meshEdgesInParts(p == 0 ? first_half : second_half, p == 0 ? 0 : second_first,
                                 vertex_count, group);
      } catch (const std::invalid_argument &) {
        failed[static_cast<std::size_t>(p)] = 1;
      }
    });
    EXPECT_EQ(failed, std::vector<int>({1, 1})) << second_first << " " << vertex_count;
  }
}

namespace {

/// The bunny patch with a fixed random third of its triangles turned over,
/// then a Moebius band of 400 triangles (non-orientable) and a band without
/// the twist (orientable), both on points after the bunny's. Returns the
/// points of all.
std::vector<Eigen::Vector3d> mixedSurfaces(std::vector<Triangle> &triangles) {
  triangles = holedBunnyPatch();
  std::mt19937 random(20261202);
  for (Triangle &t : triangles)
    if (random() % 3 == 0)
      std::swap(t[1], t[2]);
  std::vector<Eigen::Vector3d> points = pcl_ms_test::bunnyReference().vertices;
  for (bool twisted : {true, false}) {
    std::vector<Eigen::Vector3d> band_points;
    std::vector<Triangle> band;
    moebiusBandOrRing(200, twisted, band_points, band);
    const auto offset = static_cast<VertexIndex>(points.size());
    for (Triangle t : band) {
      for (VertexIndex &v : t)
        v += offset;
      triangles.push_back(t);
    }
    points.insert(points.end(), band_points.begin(), band_points.end());
  }
  return points;
}

} // namespace

TEST(ComponentsInParts, ComponentsTurnsAndOrientabilityAreThoseOfOneProcessForAnySplit) {
  std::vector<Triangle> triangles;
  const std::vector<Eigen::Vector3d> points = mixedSurfaces(triangles);
  const std::size_t n = triangles.size();
  // One process: the finishing's own orientation, on a copy it may turn.
  std::vector<Triangle> oriented = triangles;
  std::vector<std::uint32_t> component;
  std::vector<bool> orientable;
  detail::orientAlongNeighbours(oriented, detail::meshEdges(oriented, true).neighbours, points,
                                component, orientable, nullptr);
  std::vector<std::uint64_t> first_of(orientable.size(), n);
  for (std::size_t t = 0; t < n; ++t)
    first_of[component[t]] = std::min<std::uint64_t>(first_of[component[t]], t);
  ASSERT_GE(orientable.size(), 3u);
  ASSERT_EQ(std::count(orientable.begin(), orientable.end(), false), 1); // the Moebius band

  const std::vector<std::vector<std::size_t>> splits = {
      {0, n},
      {0, n / 2, n},
      {0, n / 5, n / 5, n - 300, n}, // the bands cut between runs
      {0, 7, n - 399, n - 200, n - 1, n},
  };
  for (const std::vector<std::size_t> &cuts : splits) {
    const int processes = static_cast<int>(cuts.size()) - 1;
    SCOPED_TRACE(std::to_string(processes) + " processes");
    std::vector<detail::ComponentsPart> parts(static_cast<std::size_t>(processes));
    pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
      const auto p = static_cast<std::size_t>(group.process());
      const std::vector<Triangle> mine = pcl_ms_test::sliceOf(triangles, cuts[p], cuts[p + 1]);
      const detail::MeshEdgesPart edges =
          detail::meshEdgesInParts(mine, cuts[p], points.size(), group);
      parts[p] = detail::componentsInParts(mine, cuts[p], edges, group);
    });
    // Per component: whether the parts' turns give the one process's
    // triangles as they are or all turned over (a whole component may be
    // turned outward afterwards).
    std::map<std::uint32_t, bool> same_way;
    for (int p = 0; p < processes; ++p) {
      const detail::ComponentsPart &part = parts[static_cast<std::size_t>(p)];
      ASSERT_EQ(part.component.size(), cuts[p + 1] - cuts[p]);
      for (std::size_t t = cuts[p]; t < cuts[p + 1]; ++t) {
        const std::size_t i = t - cuts[p];
        const std::uint32_t c = component[t];
        ASSERT_EQ(part.component[i], first_of[c]) << "triangle " << t;
        ASSERT_EQ(part.orientable[i] != 0, orientable[c]) << "triangle " << t;
        if (!orientable[c])
          continue;
        Triangle turned = triangles[t];
        if (part.flipped[i])
          std::swap(turned[1], turned[2]);
        const bool same = turned == oriented[t];
        if (!same) {
          std::swap(turned[1], turned[2]);
          ASSERT_EQ(turned, oriented[t]) << "triangle " << t; // the corners' order is kept
        }
        const auto [entry, added] = same_way.emplace(c, same);
        ASSERT_EQ(entry->second, same) << "triangle " << t << " turned against its component";
        (void)added;
      }
    }
    EXPECT_EQ(same_way.size(), orientable.size() - 1);
  }
}

namespace {

/// A closed torus of `rings` × `around` quads round the axis through
/// `centre` along z, two triangles each, appended with its points; a fixed
/// random half of its triangles turned over.
void appendTorus(int rings, int around, const Eigen::Vector3d &centre,
                 std::vector<Eigen::Vector3d> &points, std::vector<Triangle> &triangles) {
  const auto offset = static_cast<VertexIndex>(points.size());
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < around; ++j) {
      const double u = 2 * pi * i / rings, v = 2 * pi * j / around;
      points.push_back(centre + Eigen::Vector3d((1 + 0.3 * std::cos(v)) * std::cos(u),
                                                (1 + 0.3 * std::cos(v)) * std::sin(u),
                                                0.3 * std::sin(v)));
    }
  const auto at = [&](int i, int j) {
    return offset + static_cast<VertexIndex>((i % rings) * around + j % around);
  };
  std::mt19937 random(20261203);
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < around; ++j)
      for (Triangle t : {Triangle{at(i, j), at(i + 1, j), at(i + 1, j + 1)},
                         Triangle{at(i, j), at(i + 1, j + 1), at(i, j + 1)}}) {
        if (random() % 2 == 0)
          std::swap(t[1], t[2]);
        triangles.push_back(t);
      }
}

/// A flat k × k grid of points in the plane x + y + z = 0, symmetric
/// about the origin, appended with its triangles. The point reflection
/// through the origin maps each triangle, corners in the order stored, to
/// another, and negates its terms of the signed volume and of the facing of
/// a viewpoint at the origin exactly, so those sums are rounding noise
/// round an exact zero: their signs need the exact pass. With k odd, a
/// `nudge` moves the middle point, at the origin, off the plane by that
/// much: the terms at it no longer cancel, so a nudge far below the other
/// terms' rounding makes exact sums that are not zero but still within
/// their rounding bound.
void appendGridThroughOrigin(int k, std::vector<Eigen::Vector3d> &points,
                             std::vector<Triangle> &triangles, double nudge = 0) {
  const auto offset = static_cast<VertexIndex>(points.size());
  const Eigen::Vector3d along = Eigen::Vector3d(1, -1, 0).normalized(),
                        across = Eigen::Vector3d(1, 1, -2).normalized();
  const double centre = (k - 1) / 2.0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      points.push_back(0.01 * ((i - centre) * along + (j - centre) * across));
  if (k % 2 == 1)
    points[offset + static_cast<std::size_t>(k * k / 2)] += nudge * Eigen::Vector3d(1, 1, 1);
  const auto at = [&](int i, int j) { return offset + static_cast<VertexIndex>(i * k + j); };
  for (int i = 0; i + 1 < k; ++i)
    for (int j = 0; j + 1 < k; ++j) {
      triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      // The reflection of the first kind at (k - 2 - i, k - 2 - j).
      triangles.push_back({at(i + 1, j + 1), at(i, j + 1), at(i, j)});
    }
}

} // namespace

TEST(SidesInParts, TurnsAreThoseOfOneProcessForAnySplitWithOrWithoutAViewpoint) {
  std::vector<Triangle> triangles;
  std::vector<Eigen::Vector3d> points = mixedSurfaces(triangles);
  appendTorus(40, 16, Eigen::Vector3d(3, 0.5, -1), points, triangles);
  const std::size_t grid_first = triangles.size();
  appendGridThroughOrigin(30, points, triangles);
  const std::size_t nudged_first = triangles.size();
  appendGridThroughOrigin(21, points, triangles, -1e-28);
  const std::size_t n = triangles.size();
  // Both grids' sums are too close to zero for their rounding bound; the
  // first grid's are zero, the nudged one's not (its volume negative and
  // its facing of the origin positive: each turns the grid in one case).
  struct Grid {
    std::size_t first, end;
    int volume_sign;
  };
  for (const Grid &one : {Grid{grid_first, nudged_first, 0}, Grid{nudged_first, n, -1}}) {
    detail::ExactSigns grid(2);
    const auto forEachTerm = [&](const auto &add) {
      for (std::size_t t = one.first; t < one.end; ++t) {
        const Eigen::Vector3d &a = points[triangles[t][0]], &b = points[triangles[t][1]],
                              &c = points[triangles[t][2]];
        add(0, a.dot(b.cross(c)));
        add(1, (b - a).cross(c - a).dot(-a));
      }
    };
    forEachTerm([&](std::size_t k, double term) { grid.add(k, term); });
    ASSERT_TRUE(grid.needsExactPass());
    ASSERT_TRUE(grid.needsExactly(0));
    ASSERT_TRUE(grid.needsExactly(1));
    forEachTerm([&](std::size_t k, double term) { grid.addExactly(k, term); });
    ASSERT_EQ(grid.sign(0), one.volume_sign);
    ASSERT_EQ(grid.sign(1), -one.volume_sign);
  }
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d *viewpoint :
       {static_cast<const Eigen::Vector3d *>(nullptr), &origin}) {
    SCOPED_TRACE(viewpoint ? "viewpoint at the origin" : "no viewpoint");
    std::vector<Triangle> oriented = triangles;
    std::vector<std::uint32_t> component;
    std::vector<bool> orientable;
    detail::orientAlongNeighbours(oriented, detail::meshEdges(oriented, true).neighbours, points,
                                  component, orientable, viewpoint);
    ASSERT_EQ(std::count(orientable.begin(), orientable.end(), false), 1); // the Moebius band
    const std::vector<std::vector<std::size_t>> splits = {
        {0, n},
        {0, n / 2, n},
        {0, n / 5, n / 5, grid_first + 7, n},
        {0, 7, n - 2000, n - 899, n - 1, n},
    };
    for (const std::vector<std::size_t> &cuts : splits) {
      const int processes = static_cast<int>(cuts.size()) - 1;
      SCOPED_TRACE(std::to_string(processes) + " processes");
      std::vector<std::vector<std::uint8_t>> turned(static_cast<std::size_t>(processes));
      pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
        const auto p = static_cast<std::size_t>(group.process());
        // Home slices cut elsewhere than the runs, the first one empty.
        const pcl_ms_test::OrientationInputs inputs = pcl_ms_test::orientationInputs(
            triangles, cuts, points, pcl_ms_test::HomeCut::uneven, group);
        const std::vector<Triangle> &mine = inputs.mine;
        const detail::MeshEdgesPart &edges = inputs.edges;
        const detail::ComponentsPart &components = inputs.components;
        const detail::CornerPoints &corners = inputs.corners;
        turned[p] =
            detail::sideTurnsInParts(mine, cuts[p], edges, components, corners, viewpoint, group);
      });
      for (int p = 0; p < processes; ++p) {
        ASSERT_EQ(turned[static_cast<std::size_t>(p)].size(), cuts[p + 1] - cuts[p]);
        for (std::size_t t = cuts[p]; t < cuts[p + 1]; ++t) {
          if (!orientable[component[t]])
            continue;
          Triangle expected = triangles[t];
          if (turned[static_cast<std::size_t>(p)][t - cuts[p]])
            std::swap(expected[1], expected[2]);
          ASSERT_EQ(expected, oriented[t]) << "triangle " << t;
        }
      }
    }
  }
}

TEST(SidesInParts, PointSlicesThatDoNotFollowEachOtherOrCornersBeyondThemFailOnEveryProcess) {
  const std::vector<Triangle> triangles = holedBunnyPatch();
  const std::vector<Eigen::Vector3d> &points = pcl_ms_test::bunnyReference().vertices;
  const std::size_t half = points.size() / 2;
  // Each case: where process 1's slice starts, and how many points it holds.
  const std::vector<std::pair<std::size_t, std::size_t>> cases = {
      {half + 1, points.size() - half - 1}, // a gap between the slices
      {0, points.size() - half},            // both slices from point 0
      {half, 10},                           // too few points for the corners
  };
  for (const auto &one_case : cases) {
    const std::size_t second_first = one_case.first, second_count = one_case.second;
    std::vector<int> failed(2, 0);
    pcl_ms_test::onThreadProcesses(2, [&](ProcessGroup &group) {
      const int p = group.process();
      const std::size_t begin = p == 0 ? 0 : second_first,
                        end = p == 0 ? half : begin + second_count;
      const std::vector<Eigen::Vector3d> home(points.begin() + static_cast<std::ptrdiff_t>(begin),
                                              points.begin() + static_cast<std::ptrdiff_t>(end));
      try {
        detail::cornerPointsFromHomes(triangles, home, begin, group);
      } catch (const std::invalid_argument &) {
        failed[static_cast<std::size_t>(p)] = 1;
      }
    });
    EXPECT_EQ(failed, std::vector<int>({1, 1})) << second_first << " " << second_count;
  }
}

TEST(SidesInParts, CornersAddedAfterACutAreEveryCornerOfTheNewRun) {
  // Each process's run loses every 7th triangle (a cut), then the last one
  // gets triangles of the others' runs (a filling), whose corners it lacks.
  const std::vector<Triangle> triangles = holedBunnyPatch();
  const std::vector<Eigen::Vector3d> &points = pcl_ms_test::bunnyReference().vertices;
  const std::size_t n = triangles.size(), m = points.size();
  const std::vector<std::size_t> cuts = {0, n / 5, n / 2, n};
  const std::vector<std::size_t> homes = {0, m / 2, m / 2 + 10, m}; // uneven slices
  std::vector<Triangle> added;
  for (std::size_t t = 3; t < n / 2; t += 97)
    added.push_back(triangles[t]);
  pcl_ms_test::onThreadProcesses(3, [&](ProcessGroup &group) {
    const auto p = static_cast<std::size_t>(group.process());
    const std::vector<Eigen::Vector3d> home(points.begin() + static_cast<std::ptrdiff_t>(homes[p]),
                                            points.begin() +
                                                static_cast<std::ptrdiff_t>(homes[p + 1]));
    const std::vector<Triangle> before = pcl_ms_test::sliceOf(triangles, cuts[p], cuts[p + 1]);
    detail::CornerPoints corners = detail::cornerPointsFromHomes(before, home, homes[p], group);
    const std::vector<VertexIndex> corners_before = corners.vertices;
    std::vector<Triangle> mine;
    for (std::size_t t = 0; t < before.size(); ++t)
      if (t % 7 != 0)
        mine.push_back(before[t]);
    const std::size_t first_new = mine.size();
    if (p == 2)
      mine.insert(mine.end(), added.begin(), added.end());
    detail::addCornerPointsFromHomes(corners, mine, first_new, home, homes[p], group);

    std::vector<VertexIndex> expected = corners_before;
    for (const Triangle &t : mine)
      expected.insert(expected.end(), t.begin(), t.end());
    std::sort(expected.begin(), expected.end());
    expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
    EXPECT_EQ(expected, corners.vertices) << "process " << p;
    // EXPECT, not ASSERT: a process that left early would leave the others
    // waiting in the last collective.
    EXPECT_EQ(corners.vertices.size(), corners.points.size());
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < std::min(corners.vertices.size(), corners.points.size()); ++i)
      wrong += points[corners.vertices[i]] != corners.points[i];
    EXPECT_EQ(0u, wrong) << "process " << p;
    if (p == 2) {
      EXPECT_GT(corners.vertices.size(), corners_before.size()); // the filling brought some
    }

    // Triangles that are not there fail on every process.
    bool failed = false;
    try {
      detail::addCornerPointsFromHomes(corners, mine, p == 1 ? mine.size() + 1 : mine.size(), home,
                                       homes[p], group);
    } catch (const std::invalid_argument &) {
      failed = true;
    }
    EXPECT_TRUE(failed) << "process " << p;
  });
}

namespace {

/// Moebius bands of 200 segments (gentle: a twisted cycle of flat edges,
/// so the forest needs Kruskal's order throughout) and of `few` segments,
/// jittered (the twist across bent edges), a fixed random third of their
/// triangles turned over; returns their points.
std::vector<Eigen::Vector3d> twistedBands(int few, std::vector<Triangle> &triangles) {
  std::vector<Eigen::Vector3d> points;
  std::mt19937 random(20261204);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  for (const int segments : {200, few}) {
    std::vector<Eigen::Vector3d> band_points;
    std::vector<Triangle> band;
    pcl_ms_test::moebiusBand(segments, 0.3, band_points, band);
    const auto offset = static_cast<VertexIndex>(points.size());
    for (Eigen::Vector3d &point : band_points)
      points.push_back(segments == 200
                           ? point
                           : point +
                                 Eigen::Vector3d(jitter(random), jitter(random), jitter(random)) +
                                 Eigen::Vector3d(3, 0, 0));
    for (Triangle t : band) {
      for (VertexIndex &v : t)
        v += offset;
      if (random() % 3 == 0)
        std::swap(t[1], t[2]);
      triangles.push_back(t);
    }
  }
  return points;
}

/// Whether some cycle of edges flatter than kruskal_flat_bending reverses
/// orientation, in the triangles [begin, end).
bool flatCycleTwisted(const std::vector<Triangle> &triangles,
                      const std::vector<Eigen::Vector3d> &points, std::size_t begin,
                      std::size_t end) {
  const detail::MeshEdges scan = detail::meshEdges(triangles, true);
  detail::ParityForest forest(triangles.size());
  bool twisted = false;
  for (std::size_t t = begin; t < end; ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t u = scan.neighbours[3 * t + k];
      if (u == detail::no_neighbour || u <= t)
        continue;
      const detail::EdgeKey key = detail::sharedEdge(triangles[t], triangles[u]);
      auto apex = [&](const Triangle &corners) {
        for (VertexIndex v : corners)
          if (v != detail::lowVertex(key) && v != detail::highVertex(key))
            return v;
        return corners[0];
      };
      const double bending =
          bendingAngle(points[detail::lowVertex(key)], points[detail::highVertex(key)],
                       points[apex(triangles[t])], points[apex(triangles[u])]);
      if (bending < detail::kruskal_flat_bending &&
          forest.join(static_cast<std::uint32_t>(t), u,
                      !detail::consistentlyOriented(triangles[t], triangles[u])) ==
              detail::ParityForest::Join::conflict)
        twisted = true;
    }
  return twisted;
}

} // namespace

TEST(TwistsInParts, ForestTurnsAndConflictsAreThoseOfOneProcessForAnySplit) {
  for (const int few : {6, 9, 16}) {
    SCOPED_TRACE("bands of 200 and " + std::to_string(few) + " segments");
    std::vector<Triangle> triangles;
    const std::vector<Eigen::Vector3d> points = twistedBands(few, triangles);
    const std::size_t n = triangles.size();
    ASSERT_TRUE(flatCycleTwisted(triangles, points, 0, 400));
    ASSERT_FALSE(flatCycleTwisted(triangles, points, 400, n));
    std::vector<Triangle> oriented = triangles;
    std::vector<std::uint32_t> component;
    std::vector<bool> orientable;
    const std::vector<std::uint32_t> neighbours = detail::meshEdges(oriented, true).neighbours;
    detail::orientAlongNeighbours(oriented, neighbours, points, component, orientable, nullptr);
    ASSERT_EQ(orientable, std::vector<bool>({false, false}));
    std::vector<detail::TwistConflict> expected_conflicts;
    for (std::uint32_t t = 0; t < n; ++t)
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint32_t u = neighbours[3 * t + k];
        if (u != detail::no_neighbour && u > t &&
            !detail::consistentlyOriented(oriented[t], oriented[u]))
          expected_conflicts.push_back({detail::sharedEdge(oriented[t], oriented[u]), t, u});
      }
    std::sort(expected_conflicts.begin(), expected_conflicts.end());
    ASSERT_GE(expected_conflicts.size(), 2u); // at least one per band

    const std::vector<std::vector<std::size_t>> splits = {
        {0, n},
        {0, n / 2, n},
        {0, 133, 133, 401, n},
        {0, 1, 399, 400, n - 3, n},
        // Conflicts between runs: cuts right after the first and the last
        // conflict's lower triangle.
        {0, expected_conflicts.front().t + 1, expected_conflicts.back().t + 1, n},
    };
    for (const std::vector<std::size_t> &cuts : splits) {
      const int processes = static_cast<int>(cuts.size()) - 1;
      SCOPED_TRACE(std::to_string(processes) + " processes");
      std::vector<detail::TwistsPart> parts(static_cast<std::size_t>(processes));
      pcl_ms_test::onThreadProcesses(processes, [&](ProcessGroup &group) {
        const auto p = static_cast<std::size_t>(group.process());
        // Home slices cut evenly, elsewhere than the runs.
        const pcl_ms_test::OrientationInputs inputs = pcl_ms_test::orientationInputs(
            triangles, cuts, points, pcl_ms_test::HomeCut::even, group);
        const std::vector<Triangle> &mine = inputs.mine;
        const detail::MeshEdgesPart &edges = inputs.edges;
        const detail::ComponentsPart &components = inputs.components;
        const detail::CornerPoints &corners = inputs.corners;
        parts[p] = detail::twistForestInParts(mine, cuts[p], edges, components, corners, group);
      });
      std::vector<detail::TwistConflict> conflicts;
      for (int p = 0; p < processes; ++p) {
        const detail::TwistsPart &part = parts[static_cast<std::size_t>(p)];
        ASSERT_EQ(part.flipped.size(), cuts[p + 1] - cuts[p]);
        for (std::size_t t = cuts[p]; t < cuts[p + 1]; ++t) {
          Triangle turned = triangles[t];
          if (part.flipped[t - cuts[p]])
            std::swap(turned[1], turned[2]);
          ASSERT_EQ(turned, oriented[t]) << "triangle " << t;
        }
        EXPECT_TRUE(std::is_sorted(part.conflicts.begin(), part.conflicts.end()));
        for (const detail::TwistConflict &conflict : part.conflicts) {
          EXPECT_GE(conflict.t, cuts[p]);
          EXPECT_LT(conflict.t, cuts[p + 1]);
          conflicts.push_back(conflict);
        }
      }
      std::sort(conflicts.begin(), conflicts.end());
      ASSERT_EQ(conflicts.size(), expected_conflicts.size());
      for (std::size_t c = 0; c < conflicts.size(); ++c) {
        EXPECT_EQ(conflicts[c].key, expected_conflicts[c].key);
        EXPECT_EQ(conflicts[c].t, expected_conflicts[c].t);
        EXPECT_EQ(conflicts[c].u, expected_conflicts[c].u);
      }
    }
  }
}
