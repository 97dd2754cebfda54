// SPDX-License-Identifier: GPL-3.0-or-later
// The core's insertion of indexed points (src/core/indexed_delaunay.h)
// against CGAL's own range insertion of (point, index) pairs.
#include "core_test_support.h"
#include "indexed_delaunay.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

using namespace pcl_ms;
using detail::Delaunay;
using detail::IndexedPoint;
using detail::KernelPoint;

namespace {

/// Each cell's corners as point indices (the infinite vertex as -1), in the
/// order the cell store lists the cells: what the scaffold reads, in its order.
std::vector<std::int64_t> cellCorners(const Delaunay &delaunay) {
  std::vector<std::int64_t> corners;
  for (const auto cell : delaunay.all_cell_handles())
    for (int i = 0; i <= delaunay.dimension(); ++i)
      corners.push_back(delaunay.is_infinite(cell->vertex(i)) ? -1 : cell->vertex(i)->info());
  return corners;
}

/// insertIndexed gives CGAL's triangulation, cell for cell, and each vertex
/// holds the index of its own point.
void expectSameAsCgal(const std::vector<Eigen::Vector3d> &points) {
  std::vector<IndexedPoint> input = detail::indexedPoints(points);
  const Delaunay reference(input.begin(), input.end());
  Delaunay ours;
  detail::insertIndexed(ours, input);
  ASSERT_TRUE(ours.is_valid());
  EXPECT_EQ(ours.dimension(), reference.dimension());
  EXPECT_EQ(ours.number_of_vertices(), points.size());
  EXPECT_EQ(ours.number_of_cells(), reference.number_of_cells());
  EXPECT_EQ(cellCorners(ours), cellCorners(reference));
  for (const auto vertex : ours.finite_vertex_handles()) {
    const Eigen::Vector3d &p = points[vertex->info()];
    EXPECT_EQ(vertex->point(), KernelPoint(p.x(), p.y(), p.z()));
  }
}

} // namespace

TEST(IndexedDelaunay, TheBunnyGivesCgalsTriangulation) {
  expectSameAsCgal(pcl_ms_test::positions(pcl_ms_test::bunnyCoordinates()));
}

TEST(IndexedDelaunay, CosphericalAndCoplanarPointsGiveCgalsTriangulation) {
  // A grid's cubes are co-spherical (and a sphere's float points nearly so):
  // there the symbolic perturbation decides which tetrahedra are built.
  expectSameAsCgal(pcl_ms_test::positions(pcl_ms_test::fibonacciSphere(2000)));
  std::vector<Eigen::Vector3d> grid;
  for (int x = 0; x < 12; ++x)
    for (int y = 0; y < 12; ++y)
      for (int z = 0; z < 3; ++z)
        grid.emplace_back(x, y, z);
  expectSameAsCgal(grid);
  std::vector<Eigen::Vector3d> plane;
  for (int x = 0; x < 30; ++x)
    for (int y = 0; y < 30; ++y)
      plane.emplace_back(0.5 * x, 0.25 * y, 1.0);
  expectSameAsCgal(plane);
}

TEST(IndexedDelaunay, RandomCloudsOfEverySizeGiveCgalsTriangulation) {
  // The spatial sort changes strategy with the count (small ranges are left
  // unsorted, larger ones split by medians at several scales).
  std::mt19937 random(20261204);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (std::size_t count : {5u, 40u, 700u, 30000u}) {
    std::vector<Eigen::Vector3d> points(count);
    for (Eigen::Vector3d &p : points)
      p = Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random));
    expectSameAsCgal(points);
  }
}

TEST(IndexedDelaunay, ChosenPointsKeepTheirOwnIndices) {
  const std::vector<Eigen::Vector3d> points =
      pcl_ms_test::positions(pcl_ms_test::fibonacciSphere(50));
  const std::vector<VertexIndex> chosen = {7, 3, 49, 0, 21};
  const std::vector<IndexedPoint> input = detail::indexedPoints(points, chosen);
  ASSERT_EQ(input.size(), chosen.size());
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    EXPECT_EQ(input[k].second, chosen[k]);
    const Eigen::Vector3d &p = points[chosen[k]];
    EXPECT_EQ(input[k].first, KernelPoint(p.x(), p.y(), p.z()));
  }
  EXPECT_TRUE(detail::indexedPoints(points, std::vector<VertexIndex>{}).empty());
}
