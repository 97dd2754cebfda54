// SPDX-License-Identifier: GPL-3.0-or-later
// The bending by which the twist repair's spanning forest orders the edges
// (docs/algorithm.md, section 4, "Orientation"), shared by one process's
// orientation and the one in parts. Internal to the library: not installed.
#pragma once

#include <pcl_ms/costs.h>

#include <Eigen/Core>

#include <cmath>

namespace pcl_ms {
namespace detail {

// Edges bending less than this (about 30 degrees) are joined before the
// rest without sorting; any value gives the same orientation, this one
// leaves few edges to sort on a smooth surface.
inline constexpr double kruskal_flat_bending = 0.5;

/// The bending across edge pq (p the lower vertex) between the triangles
/// with apexes t and s, or 0 where it is surely below kruskal_flat_bending:
/// most edges are flat, and this spares them the arctangent. Edges at 0
/// and the rest below kruskal_flat_bending are the flat ones.
inline double kruskalBending(const Eigen::Vector3d &p, const Eigen::Vector3d &q,
                             const Eigen::Vector3d &t, const Eigen::Vector3d &s) {
  static const double flat_tan = std::tan(kruskal_flat_bending);
  return bendsSurelyLessThan(p, q, t, s, flat_tan * flat_tan) ? 0.0 : bendingAngle(p, q, t, s);
}

} // namespace detail
} // namespace pcl_ms
