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

// The pieces of findFarPoints that processes sharing a cloud run alike
// (prepare_together.cpp): they select the same values across processes.

/// The rank, among n values of one axis, of the central box's low side; its
/// high side is the value of rank n - 1 - tailRank(n).
std::size_t tailRank(std::size_t n);

/// A selected coordinate as the box and centre use it: -0 becomes +0, so
/// that the result does not depend on which of two equal values a
/// selection returns.
inline double selectedValue(float value) { return static_cast<double>(value) + 0.0; }

/// Whether p is farther than `size` from the central box: only such points
/// can be far, or a far point's neighbour (size: the box's diagonal).
bool outsideCentralBox(const Eigen::Vector3f &p, const Eigen::Vector3d &low,
                       const Eigen::Vector3d &high, double size);

/// For each point outside the central box: whether it is far, i.e. beyond
/// twice `size` from the box with no other of them within `size`. Does not
/// depend on their order.
std::vector<bool> isolatedOutside(std::vector<Eigen::Vector3f> outside, const Eigen::Vector3d &low,
                                  const Eigen::Vector3d &high, double size);

} // namespace detail
} // namespace pcl_ms
