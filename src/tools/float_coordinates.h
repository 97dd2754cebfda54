// SPDX-License-Identifier: GPL-3.0-or-later
// Coordinates read as double (text, mesh files, float64 PCD/PLY fields) and
// stored as the floats of PCL's point types. Rounding is harmless near the
// origin; far from it (georeferenced clouds: UTM northings of 5e6 round to
// half a metre) it would move points by a good part of their spacing, and
// the cloud is refused instead of meshed as garbage.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <functional>
#include <limits>
#include <string>

namespace pcl_ms {
namespace io_detail {

/// Rounding moves no point by more than this share of the cloud's typical
/// spacing (its median nearest-neighbour distance): about a scanner's noise
/// at that spacing. A site grid of 5 km at 1 cm spacing (2.4 %) or UTM at
/// 5 m (5 %) passes; UTM at 1 m (25 %) does not.
constexpr double max_rounding_per_spacing = 0.1;

/// Rounds coordinates to float, one at a time, and remembers how far the
/// farthest moved and the bounding box of the values as read.
class CoordinateRounding {
public:
  /// `value` as float, for axis 0, 1 or 2. The caller checks the range.
  float round(double value, int axis);

  /// Whether the rounding left the cloud's geometry alone; if not, `reason`
  /// says why and what to do. `rounded(i)` gives point i of `count` as
  /// stored; the spacing is measured on them only when the rounding is not
  /// negligible against the cloud's size (a sample of 64 points, each
  /// compared with all).
  bool harmless(std::size_t count, const std::function<Eigen::Vector3f(std::size_t)> &rounded,
                std::string &reason) const;

private:
  double largest_shift_ = 0;
  double largest_magnitude_ = 0;
  Eigen::Vector3d low_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high_ = -low_;
};

} // namespace io_detail
} // namespace pcl_ms
