// SPDX-License-Identifier: GPL-3.0-or-later
// Far stray points: a few points at wildly different magnitudes must neither
// slow the method down nor change the mesh of the rest of the cloud.
#include "core_test_support.h"
#include "far_points.h"
#include "threads.h"

#include <algorithm>
#include <chrono>
#include <random>

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

TEST(FarPoints, SelectionsMatchSortedValuesAtEverySize) {
  // The central box's sides and the centre are values of given ranks on
  // each axis; findFarPoints selects them in parts. Checked against sorted
  // copies, on one and two threads, at sizes around the ranks' edge cases
  // (one value, a tail rank of 0 or 1), with repeated values and stray points.
  std::mt19937 random(7);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  for (std::size_t n : {1u, 2u, 3u, 4u, 99u, 100u, 101u, 257u, 1000u, 4097u}) {
    std::vector<Eigen::Vector3f> points(n);
    for (Eigen::Vector3f &p : points)
      p = Eigen::Vector3f(uniform(random), std::round(uniform(random) * 4), uniform(random));
    if (n > 50) // a pair of strays at one place, and a lone one
      points[n / 3] = points[n / 5] = Eigen::Vector3f(1e6f, 0, 0);
    if (n > 60)
      points[n / 7] = Eigen::Vector3f(0, -3e5f, 2e5f);
    // The reference: sorted copies.
    const std::size_t tail = pcl_ms::detail::tailRank(n);
    Eigen::Vector3d low, high;
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<float> sorted;
      for (const Eigen::Vector3f &p : points)
        sorted.push_back(p[axis]);
      std::sort(sorted.begin(), sorted.end());
      low[axis] = sorted[tail];
      high[axis] = sorted[n - 1 - tail];
    }
    const double size = (high - low).norm();
    std::vector<Eigen::Vector3f> outside;
    std::vector<std::size_t> outside_index;
    for (std::size_t i = 0; i < n; ++i)
      if (pcl_ms::detail::outsideCentralBox(points[i], low, high, size)) {
        outside.push_back(points[i]);
        outside_index.push_back(i);
      }
    std::vector<bool> is_far(n, false);
    const std::vector<bool> isolated = pcl_ms::detail::isolatedOutside(outside, low, high, size);
    for (std::size_t k = 0; k < outside.size(); ++k)
      is_far[outside_index[k]] = isolated[k];
    Eigen::Vector3d median;
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<float> kept;
      for (std::size_t i = 0; i < n; ++i)
        if (!is_far[i])
          kept.push_back(points[i][axis]);
      std::sort(kept.begin(), kept.end());
      median[axis] = kept[kept.size() / 2];
    }
    for (int threads : {1, 2}) {
      const pcl_ms::detail::FarPoints far = pcl_ms::detail::withThreads(
          threads, [&] { return pcl_ms::detail::findFarPoints(points); });
      EXPECT_EQ(far.is_far, is_far) << n << " points, " << threads << " threads";
      EXPECT_EQ(far.median, median) << n << " points, " << threads << " threads";
    }
    if (n >= 1000) { // with enough points the lone stray is far, the pair is not
      EXPECT_TRUE(is_far[n / 7]) << n;
      EXPECT_FALSE(is_far[n / 3]) << n;
    }
  }
}

} // namespace
