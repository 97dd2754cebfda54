// SPDX-License-Identifier: GPL-3.0-or-later
// The points a process's triangles need, from the processes that hold them
// (docs/algorithm.md, "Finishing in parts"): each process holds a slice of
// the points (its "home" points), the slices following each other in
// process order. Internal to the library: not installed.
#pragma once

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

/// The corners of a run of triangles and their positions.
struct CornerPoints {
  std::vector<VertexIndex> vertices; // ascending, each once
  std::vector<Eigen::Vector3d> points;

  /// The position of corner v (one of `vertices`).
  const Eigen::Vector3d &of(VertexIndex v) const;
};

/// Collective. `home` holds the points from number `home_first` on. Every
/// process asks the homes of its triangles' corners for them, one request
/// per distinct corner. Throws std::invalid_argument on every process when
/// the slices do not follow each other from point 0 or a corner is beyond
/// the points.
CornerPoints cornerPointsFromHomes(const std::vector<Triangle> &mine,
                                   const std::vector<Eigen::Vector3d> &home,
                                   std::uint64_t home_first, ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
