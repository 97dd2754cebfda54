// SPDX-License-Identifier: GPL-3.0-or-later
// The bending by which the twist repair's spanning forest orders the edges,
// and the rules by which it repairs the twists left (docs/algorithm.md,
// section 4, "Orientation"), shared by one process's orientation and the
// one in parts. Internal to the library: not installed.
#pragma once

#include <pcl_ms/costs.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>

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

// An inconsistent edge that bends by more than this (90 degrees) is a fold,
// cut whatever its twist: a crumpled spot, never the gentle twist of a real
// Moebius band, which is kept and reported.
inline constexpr double max_untwist_bending = M_PI / 2;
// A twist that an orientation-reversing walk of at most this many triangles
// closes is a crumple: the two triangles of its inconsistent edge are cut out
// and the hole refilled.
inline constexpr int max_local_twist_steps = 32;
// Or a walk of at most this many times the square root of the component's
// triangle count: a component's diameter in triangles is about that root.
// A real Moebius band reverses only all the way round, which is several
// times its root (10,000-point sampling: 823 steps, root 140); the longest
// twists left in PCL's scans closed within 109 steps (car6, root 118).
inline constexpr double max_twist_steps_per_root = 2.0;

/// The longest orientation-reversing walk tried in a component of `size`
/// triangles.
inline int longTwistSteps(std::uint64_t size) {
  return static_cast<int>(max_twist_steps_per_root * std::sqrt(static_cast<double>(size)));
}

/// How squarely triangle abc faces `viewpoint`: |cos| of the angle between
/// its normal and the direction to the viewpoint from its centre, 0 for a
/// degenerate one. Of a fold's two triangles, the one facing it less goes.
inline double facingOf(const Eigen::Vector3d &a, const Eigen::Vector3d &b, const Eigen::Vector3d &c,
                       const Eigen::Vector3d &viewpoint) {
  const Eigen::Vector3d normal = (b - a).cross(c - a);
  const Eigen::Vector3d to_viewpoint = viewpoint - (a + b + c) / 3;
  const double lengths = normal.norm() * to_viewpoint.norm();
  return lengths > 0 ? std::abs(normal.dot(to_viewpoint)) / lengths : 0.0;
}

} // namespace detail
} // namespace pcl_ms
