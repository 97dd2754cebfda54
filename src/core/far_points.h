// SPDX-License-Identifier: GPL-3.0-or-later
// Stray points far from the rest of a cloud, and a centre for the cloud that
// they cannot move. Internal to the library: not installed.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace pcl_ms {
namespace detail {

struct FarPoints {
  /// One flag per input point: true for a far isolated point.
  std::vector<bool> is_far;
  std::size_t count = 0;
  /// Bounding box of the points that are not far.
  Eigen::Vector3d low = Eigen::Vector3d::Zero(), high = Eigen::Vector3d::Zero();
  /// Per-axis median of the points that are not far: one of the input coordinates on each
  /// axis, so subtracting it from the cloud's coordinates is exact in
  /// double. The bounding box centre of a cloud with a point at 1e31 would
  /// round every other point onto one line.
  Eigen::Vector3d median = Eigen::Vector3d::Zero();
};

/// Finds the points that no surface of the cloud can reach: farther than
/// twice the cloud's size from the box holding the central 98 % of its
/// points on each axis, and with no other point within that size (the box's
/// diagonal). A distant group of points is kept; a lone stray point is not.
FarPoints findFarPoints(const std::vector<Eigen::Vector3f> &points);

} // namespace detail
} // namespace pcl_ms
