// SPDX-License-Identifier: GPL-3.0-or-later
// Corner points from their homes (points_from_homes.h; docs/algorithm.md,
// "Finishing in parts").
#include "points_from_homes.h"

#include "process_bytes.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace pcl_ms {
namespace detail {
namespace {

struct PointRequest {
  std::uint64_t vertex;
  std::uint32_t asker;
};

} // namespace

const Eigen::Vector3d &CornerPoints::of(VertexIndex v) const {
  return points[static_cast<std::size_t>(std::lower_bound(vertices.begin(), vertices.end(), v) -
                                         vertices.begin())];
}

CornerPoints cornerPointsFromHomes(const std::vector<Triangle> &mine,
                                   const std::vector<Eigen::Vector3d> &home,
                                   std::uint64_t home_first, ProcessGroup &group) {
  const auto processes = static_cast<std::size_t>(group.processes());
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

  const auto homeOf = [&](std::uint64_t vertex) { return runHolding(firsts, vertex); };
  std::vector<std::vector<PointRequest>> requests_out(processes);
  for (VertexIndex v : corners.vertices)
    requests_out[homeOf(v)].push_back({v, static_cast<std::uint32_t>(group.process())});
  // Each home answers its askers in the order they asked; the homes hold
  // ascending ranges and answers arrive in process order, so the points
  // come back in the order of `vertices`.
  std::vector<std::vector<std::array<double, 3>>> answers_out(processes);
  deliver(requests_out, group, [&](const PointRequest &request) {
    const Eigen::Vector3d &point = home[static_cast<std::size_t>(request.vertex - home_first)];
    answers_out[request.asker].push_back({point.x(), point.y(), point.z()});
  });
  corners.points.reserve(corners.vertices.size());
  deliver(answers_out, group, [&](const std::array<double, 3> &point) {
    corners.points.emplace_back(point[0], point[1], point[2]);
  });
  return corners;
}

} // namespace detail
} // namespace pcl_ms
