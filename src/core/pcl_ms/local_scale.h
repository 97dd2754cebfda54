// SPDX-License-Identifier: GPL-3.0-or-later
// The local scale: how long a triangle's sides may be where it lies
// (docs/algorithm.md, "Local scale").
#pragma once

#include <pcl_ms/types.h>

#include <algorithm>
#include <vector>

namespace pcl_ms {

/// The local scale of a triangle: the largest of its corners' scales, so
/// that a triangle joining sparse and dense sampling may be as large as the
/// sparse side needs. (A stray point's scale is that of the surface around
/// it, so this does not let outliers in.)
inline double triangleScale(const std::vector<float> &point_scale, const Triangle &corners) {
  return std::max({point_scale[corners[0]], point_scale[corners[1]], point_scale[corners[2]]});
}

/// Triangle sides stay below rho times the triangle's local scale.
struct SideLimit {
  const std::vector<float> *point_scale = nullptr; // one entry per point
  double rho = 0;

  double maxSide(const Triangle &corners) const {
    return rho * triangleScale(*point_scale, corners);
  }
};

} // namespace pcl_ms
