// SPDX-License-Identifier: GPL-3.0-or-later
// A seam zone's reach along its plane (bucket_parts.h, ZoneReach): every
// corner of every triangle that may cross the plane must be in the zone,
// and where the scales near the plane are small the zone must be narrower
// than the widest reach.
#include "bucket_parts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace {

using pcl_ms::detail::Box;
using pcl_ms::detail::ZoneReach;

struct ScaledPoint {
  Eigen::Vector3d position;
  float scale;
};

// Points on both sides of the plane x = 0; their scales jump tenfold at
// y = 0.5 and vary by a fifth around that.
std::vector<ScaledPoint> stepCloud(std::size_t count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<ScaledPoint> cloud;
  for (std::size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d p(0.2 * unit(random) - 0.1, unit(random), 0.05 * unit(random));
    const double base = p.y() < 0.5 ? 0.004 : 0.04;
    cloud.push_back({p, static_cast<float>(base * (0.9 + 0.2 * unit(random)))});
  }
  return cloud;
}

TEST(ZoneReach, ReachesEveryCornerOfATriangleAcrossThePlane) {
  constexpr double rho = 2;
  const std::vector<ScaledPoint> cloud = stepCloud(700, 5);
  Box bounds = pcl_ms::detail::emptyBox();
  float largest = 0;
  for (const ScaledPoint &point : cloud) { // all lie within a margin of 0.1
    bounds.extend(point.position);
    largest = std::max(largest, point.scale);
  }
  ZoneReach reach(bounds, 0, 0.0, rho, largest);
  for (const ScaledPoint &point : cloud)
    reach.addScale(point.position, point.scale);

  // Every triangle across the plane whose sides are shorter than rho times
  // its largest corner scale: the triangles a seam may have to decide.
  std::size_t across = 0, missed = 0;
  const double longest = rho * largest;
  for (std::size_t a = 0; a < cloud.size(); ++a)
    for (std::size_t b = a + 1; b < cloud.size(); ++b) {
      if ((cloud[a].position - cloud[b].position).norm() >= longest)
        continue;
      for (std::size_t c = b + 1; c < cloud.size(); ++c) {
        const std::size_t corners[3] = {a, b, c};
        double low = 1, high = -1, side = 0;
        float scale = 0;
        for (int k = 0; k < 3; ++k) {
          const ScaledPoint &p = cloud[corners[k]], &q = cloud[corners[(k + 1) % 3]];
          low = std::min(low, p.position.x());
          high = std::max(high, p.position.x());
          side = std::max(side, (p.position - q.position).norm());
          scale = std::max(scale, p.scale);
        }
        if (!(low < 0 && high > 0) || side >= rho * scale)
          continue;
        ++across;
        for (std::size_t corner : corners)
          missed += !reach.reaches(cloud[corner].position);
      }
    }
  EXPECT_GT(across, 1000u);
  EXPECT_EQ(missed, 0u);

  // Where the scales are small the zone is narrower than the widest reach.
  std::size_t in_widest_slab = 0, left_out = 0;
  for (const ScaledPoint &point : cloud) {
    if (std::abs(point.position.x()) > longest || point.position.y() > 0.3)
      continue;
    ++in_widest_slab;
    left_out += !reach.reaches(point.position);
  }
  EXPECT_GT(in_widest_slab, 100u);
  EXPECT_GT(left_out, in_widest_slab / 2);
}

TEST(ZoneReach, PointsBeyondTheTilesCountInTheNearest) {
  Box bounds = pcl_ms::detail::emptyBox();
  bounds.extend(Eigen::Vector3d(-0.1, 0, 0));
  bounds.extend(Eigen::Vector3d(0.1, 1, 1));
  ZoneReach reach(bounds, 0, 0.0, 5.0, 0.01f);
  reach.addScale(Eigen::Vector3d(0.0, 1.0, 1.0), 0.01f); // the far corner's tile
  EXPECT_TRUE(reach.reaches(Eigen::Vector3d(0.04, 1.02, 1.03)));
  EXPECT_FALSE(reach.reaches(Eigen::Vector3d(0.06, 1.02, 1.03)));
  EXPECT_FALSE(reach.reaches(Eigen::Vector3d(0.01, 0.0, 0.0))); // no scale there
  EXPECT_TRUE(reach.reaches(Eigen::Vector3d(0.0, 0.0, 0.0)));   // on the plane
}

TEST(ZoneReach, NoPointsNearThePlaneReachOnlyThePlane) {
  ZoneReach reach(pcl_ms::detail::emptyBox(), 2, 1.0, 5.0, 0.0f);
  EXPECT_EQ(reach.tileScales().size(), 1u);
  EXPECT_TRUE(reach.reaches(Eigen::Vector3d(3, 4, 1.0)));
  EXPECT_FALSE(reach.reaches(Eigen::Vector3d(3, 4, 1.0 + 1e-12)));
  // Unbounded along the plane (a tree region at the cloud's edge): one tile.
  Box unbounded;
  ZoneReach wide(unbounded, 1, 0.0, 5.0, 0.5f);
  EXPECT_EQ(wide.tileScales().size(), 1u);
  wide.addScale(Eigen::Vector3d(1e9, 0, -1e9), 0.5f);
  EXPECT_TRUE(wide.reaches(Eigen::Vector3d(-7, 2.5, 3)));
  EXPECT_FALSE(wide.reaches(Eigen::Vector3d(-7, 2.6, 3)));
}

} // namespace
