// SPDX-License-Identifier: GPL-3.0-or-later
// Corner points from their homes (points_from_homes.h; docs/algorithm.md,
// "Finishing in parts").
#include "points_from_homes.h"

#include "sort_unique.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace pcl_ms {
namespace detail {

const Eigen::Vector3d &CornerPoints::of(VertexIndex v) const {
  return points[static_cast<std::size_t>(std::lower_bound(vertices.begin(), vertices.end(), v) -
                                         vertices.begin())];
}

namespace {

/// The corners of mine[from...], ascending, each once.
std::vector<VertexIndex> cornersOf(const std::vector<Triangle> &mine, std::size_t from) {
  std::vector<VertexIndex> vertices;
  vertices.reserve(3 * (mine.size() - from));
  for (std::size_t t = from; t < mine.size(); ++t)
    vertices.insert(vertices.end(), mine[t].begin(), mine[t].end());
  detail::sortUnique(vertices);
  return vertices;
}

/// Collective. The positions of `vertices` (ascending) from their homes;
/// `firsts` is runFirsts() of the home slices.
std::vector<Eigen::Vector3d> pointsFromHomes(const std::vector<VertexIndex> &vertices,
                                             const std::vector<std::uint64_t> &firsts,
                                             const std::vector<Eigen::Vector3d> &home,
                                             std::uint64_t home_first, ProcessGroup &group) {
  const bool beyond = !vertices.empty() && vertices.back() >= firsts.back();
  if (totalOver(beyond ? 1 : 0, group) > 0)
    throw std::invalid_argument("cornerPointsFromHomes: a triangle has a corner beyond the points");
  const std::vector<std::array<double, 3>> values = valuesFromHomes<std::array<double, 3>>(
      vertices, firsts, home_first,
      [&](std::size_t i) {
        return std::array<double, 3>{home[i].x(), home[i].y(), home[i].z()};
      },
      group);
  std::vector<Eigen::Vector3d> points;
  points.reserve(values.size());
  for (const std::array<double, 3> &value : values)
    points.emplace_back(value[0], value[1], value[2]);
  return points;
}

} // namespace

CornerPoints cornerPointsFromHomes(const std::vector<Triangle> &mine,
                                   const std::vector<Eigen::Vector3d> &home,
                                   std::uint64_t home_first, ProcessGroup &group) {
  const std::vector<std::uint64_t> firsts =
      runFirsts(home.size(), home_first, group, "cornerPointsFromHomes (points)");
  CornerPoints corners;
  corners.vertices = cornersOf(mine, 0);
  corners.points = pointsFromHomes(corners.vertices, firsts, home, home_first, group);
  return corners;
}

void addCornerPointsFromHomes(CornerPoints &corners, const std::vector<Triangle> &mine,
                              std::size_t first_new, const std::vector<Eigen::Vector3d> &home,
                              std::uint64_t home_first, ProcessGroup &group) {
  const std::vector<std::uint64_t> firsts =
      runFirsts(home.size(), home_first, group, "cornerPointsFromHomes (points)");
  if (totalOver(first_new > mine.size() ? 1 : 0, group) > 0)
    throw std::invalid_argument("addCornerPointsFromHomes: no such triangles");
  std::vector<VertexIndex> missing;
  for (VertexIndex v : cornersOf(mine, first_new))
    if (!std::binary_search(corners.vertices.begin(), corners.vertices.end(), v))
      missing.push_back(v);
  const std::vector<Eigen::Vector3d> found =
      pointsFromHomes(missing, firsts, home, home_first, group);
  if (missing.empty())
    return;
  CornerPoints merged;
  merged.vertices.reserve(corners.vertices.size() + missing.size());
  merged.points.reserve(merged.vertices.capacity());
  for (std::size_t i = 0, j = 0; i < corners.vertices.size() || j < missing.size();) {
    if (j == missing.size() || (i < corners.vertices.size() && corners.vertices[i] < missing[j])) {
      merged.vertices.push_back(corners.vertices[i]);
      merged.points.push_back(corners.points[i++]);
    } else {
      merged.vertices.push_back(missing[j]);
      merged.points.push_back(found[j++]);
    }
  }
  corners = std::move(merged);
}

} // namespace detail
} // namespace pcl_ms
