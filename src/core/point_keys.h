// SPDX-License-Identifier: GPL-3.0-or-later
// The order of the prepared points (docs/algorithm.md section 1): one key
// per finite record, (Morton code, coordinates, record), shared by the
// preparation of one process and that of processes sharing a cloud, so that
// both put the points in the same order. Internal: not installed.
#pragma once

#include "morton.h"

#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <tuple>

namespace pcl_ms {
namespace detail {

/// Record `record` of an array of records `stride` bytes apart.
inline const float *recordAt(const float *base, std::size_t stride, std::size_t record) {
  return reinterpret_cast<const float *>(reinterpret_cast<const char *>(base) + record * stride);
}

/// Distinct for distinct records, so any sort gives the one order; exact
/// duplicates end up next to each other, the earliest record first.
struct PointKey {
  std::uint64_t morton;
  std::array<float, 3> coordinates;
  VertexIndex record;
  bool operator<(const PointKey &other) const {
    return std::tie(morton, coordinates, record) <
           std::tie(other.morton, other.coordinates, other.record);
  }
};

/// Morton codes of points quantised to 2^21 cells per axis of the box
/// [low, high] (the points kept, far ones left out).
class MortonCells {
public:
  MortonCells(const Eigen::Vector3d &low, const Eigen::Vector3d &high)
      : low_(low), extent_((high - low).cwiseMax(Eigen::Vector3d::Constant(1e-300))) {}

  PointKey key(const float *p, VertexIndex record) const {
    return {mortonCode(cell(p[0], 0), cell(p[1], 1), cell(p[2], 2)), {p[0], p[1], p[2]}, record};
  }

private:
  std::uint32_t cell(double value, int axis) const {
    constexpr double cells_per_axis = 1 << 21;
    const double unit = std::clamp((value - low_[axis]) / extent_[axis], 0.0, 1.0);
    return static_cast<std::uint32_t>(std::min(unit * cells_per_axis, cells_per_axis - 1));
  }

  Eigen::Vector3d low_, extent_;
};

/// The unit normal of a record, or zero when unusable: a zero normal
/// neither helps nor penalises.
inline Eigen::Vector3f unitNormalOrZero(const float *n) {
  const Eigen::Vector3f normal(n[0], n[1], n[2]);
  const float length = normal.norm();
  return std::isfinite(length) && length > 0 ? Eigen::Vector3f(normal / length)
                                             : Eigen::Vector3f::Zero();
}

} // namespace detail
} // namespace pcl_ms
