// SPDX-License-Identifier: GPL-3.0-or-later
// What the buckets of one process (buckets.cpp) and those shared by
// processes (shared_buckets.cpp) measure alike (docs/algorithm.md section 5):
// regions, margins and seam slabs. Internal to the library: not installed.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <limits>

namespace pcl_ms {
namespace detail {

/// meshBucket's error for a unit of fewer than 3 points.
constexpr const char *too_few_unit_points = "fewer than 3 points";

/// Nearest-neighbour samples per bucket for the spacing estimate.
constexpr std::size_t spacing_samples_per_bucket = 32;

/// A bucket's margin around its region, from its median spacing: a triangle
/// is up to rho local scales long, and a sparse bucket's scale is larger.
/// The margin is (rho + 6) estimated d_med wide, beyond the seam width, so
/// that the triangles a seam keeps fixed were decided with points around.
/// d_med is estimated as 0.75 spacings: the true ratio is 0.88 on the
/// bunny's vertices and 1.6 on uniform random samplings of it; 0.75, below
/// both, makes the margin 8.25 spacings at rho 5, i.e. 5.2 to 9.4 d_med on
/// these two, above the seam width d_max. With it the seams reproduce
/// 99.999 % of the one-piece mesh on 300k points.
inline double bucketMargin(double rho, double spacing) {
  constexpr double margin_context_in_d_med = 6;
  constexpr double d_med_per_spacing = 0.75;
  return (rho + margin_context_in_d_med) * d_med_per_spacing * spacing;
}

struct Box {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());

  bool contains(const Eigen::Vector3d &p) const {
    return (p.array() >= low.array()).all() && (p.array() <= high.array()).all();
  }
  bool intersects(const Box &other) const {
    return (low.array() <= other.high.array()).all() && (other.low.array() <= high.array()).all();
  }
  Box expanded(double width) const {
    Box box = *this;
    box.low.array() -= width;
    box.high.array() += width;
    return box;
  }
};

/// The slab of a seam zone: `region` (the zone's node) grown by the larger
/// of its buckets' widest margin and `half_width`, cut to `half_width` on
/// each side of the split plane.
inline Box zoneSlab(const Box &region, int axis, double split, double margin, double half_width) {
  Box slab = region.expanded(std::max(margin, half_width));
  slab.low[axis] = std::max(slab.low[axis], split - half_width);
  slab.high[axis] = std::min(slab.high[axis], split + half_width);
  return slab;
}

} // namespace detail
} // namespace pcl_ms
