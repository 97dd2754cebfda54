// SPDX-License-Identifier: GPL-3.0-or-later
// Corner points from their homes (points_from_homes.h; docs/algorithm.md,
// "Finishing in parts").
#include "points_from_homes.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace pcl_ms {
namespace detail {

const Eigen::Vector3d &CornerPoints::of(VertexIndex v) const {
  return points[static_cast<std::size_t>(std::lower_bound(vertices.begin(), vertices.end(), v) -
                                         vertices.begin())];
}

CornerPoints cornerPointsFromHomes(const std::vector<Triangle> &mine,
                                   const std::vector<Eigen::Vector3d> &home,
                                   std::uint64_t home_first, ProcessGroup &group) {
  const std::vector<std::uint64_t> firsts =
      runFirsts(home.size(), home_first, group, "cornerPointsFromHomes (points)");
  const std::uint64_t point_count = firsts.back();

  CornerPoints corners;
  corners.vertices.reserve(3 * mine.size());
  for (const Triangle &t : mine)
    corners.vertices.insert(corners.vertices.end(), t.begin(), t.end());
  std::sort(corners.vertices.begin(), corners.vertices.end());
  corners.vertices.erase(std::unique(corners.vertices.begin(), corners.vertices.end()),
                         corners.vertices.end());
  const bool beyond = !corners.vertices.empty() && corners.vertices.back() >= point_count;
  if (totalOver(beyond ? 1 : 0, group) > 0)
    throw std::invalid_argument("cornerPointsFromHomes: a triangle has a corner beyond the points");

  const std::vector<std::array<double, 3>> points = valuesFromHomes<std::array<double, 3>>(
      corners.vertices, firsts, home_first,
      [&](std::size_t i) {
        return std::array<double, 3>{home[i].x(), home[i].y(), home[i].z()};
      },
      group);
  corners.points.reserve(points.size());
  for (const std::array<double, 3> &point : points)
    corners.points.emplace_back(point[0], point[1], point[2]);
  return corners;
}

} // namespace detail
} // namespace pcl_ms
