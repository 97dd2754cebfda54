// SPDX-License-Identifier: GPL-3.0-or-later
// Far stray points: a few points at wildly different magnitudes must neither
// slow the method down nor change the mesh of the rest of the cloud.
#include "core_test_support.h"

#include <algorithm>
#include <chrono>

namespace {

struct TimedResult {
  pcl_ms::Result result;
  double seconds = 0;
};

TimedResult timedReconstruct(const std::vector<float> &xyz) {
  const auto start = std::chrono::steady_clock::now();
  TimedResult timed;
  timed.result = pcl_ms::reconstruct(pcl_ms_test::viewOf(xyz), pcl_ms::Parameters());
  timed.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return timed;
}

std::vector<pcl_ms::Triangle> sortedTriangles(std::vector<pcl_ms::Triangle> triangles) {
  for (auto &triangle : triangles)
    std::sort(triangle.begin(), triangle.end());
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

TEST(FarPoints, StrayPointsAtHugeMagnitudesLeaveTheBunnyAsItIs) {
  const std::vector<float> plain = pcl_ms_test::bunnyCoordinates();
  std::vector<float> with_strays = plain;
  // Appended, so the bunny's record indices stay the same.
  with_strays.insert(with_strays.end(),
                     {0.f, 0.f, 1.5e16f, 0.f, 0.05f, 2.1e31f, -3.6e24f, 0.1f, 0.f});

  const TimedResult reference = timedReconstruct(plain);
  const TimedResult strays = timedReconstruct(with_strays);
  EXPECT_EQ(strays.result.far_points, 3u);
  EXPECT_EQ(reference.result.far_points, 0u);
  EXPECT_EQ(sortedTriangles(strays.result.triangles), sortedTriangles(reference.result.triangles));
  // Generous for a shared machine: before the fix this took minutes.
  EXPECT_LT(strays.seconds, 5 * reference.seconds + 1.0);
  const pcl_ms::MeshTopologyReport report =
      pcl_ms::analyzeMesh(pcl_ms_test::positions(with_strays), strays.result.triangles);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_EQ(report.non_manifold_vertices, 0u);
}

TEST(FarPoints, ADistantGroupOfPointsIsMeshedNotDropped) {
  // A small sphere far from the bulk (fewer points than the 1 % tails), as
  // densely sampled: its points have neighbours, so it is a surface of its own.
  std::vector<float> xyz = pcl_ms_test::fibonacciSphere(2000, 1.0, {0, 0, 0});
  const std::vector<float> far_sphere = pcl_ms_test::fibonacciSphere(12, 0.15, {1e3, 0, 0});
  xyz.insert(xyz.end(), far_sphere.begin(), far_sphere.end());
  const pcl_ms::Result result = pcl_ms::reconstruct(pcl_ms_test::viewOf(xyz), pcl_ms::Parameters());
  EXPECT_EQ(result.far_points, 0u);
  EXPECT_EQ(result.used_points, 2012u);
  const bool far_sphere_meshed =
      std::any_of(result.triangles.begin(), result.triangles.end(),
                  [](const pcl_ms::Triangle &triangle) { return triangle[0] >= 2000; });
  EXPECT_TRUE(far_sphere_meshed);
}

TEST(FarPoints, OnlyTheLonePointIsLeftOut) {
  std::vector<float> xyz = pcl_ms_test::fibonacciSphere(500, 1.0, {0, 0, 0});
  xyz.insert(xyz.end(), {3e20f, -1e-30f, 7.f});
  const pcl_ms::Result result = pcl_ms::reconstruct(pcl_ms_test::viewOf(xyz), pcl_ms::Parameters());
  EXPECT_EQ(result.far_points, 1u);
  EXPECT_EQ(result.used_points, 500u);
  EXPECT_TRUE(result.boundary_loops.empty());
}

} // namespace
