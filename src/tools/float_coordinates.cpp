// SPDX-License-Identifier: GPL-3.0-or-later
// Coordinates rounded to float, and whether that harmed the cloud.
#include "float_coordinates.h"

#include "median_spacing.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace pcl_ms {
namespace io_detail {
namespace {

// Below this share of the bounding-box diagonal, rounding cannot matter
// unless the cloud has over a million points across it: no spacing needed.
constexpr double negligible_rounding_per_size = 1e-6;

// Points whose nearest neighbour gives the spacing estimate.
constexpr std::size_t spacing_samples = 64;

} // namespace

float CoordinateRounding::round(double value, int axis) {
  const auto rounded = static_cast<float>(value);
  if (std::isfinite(value)) {
    largest_shift_ = std::max(largest_shift_, std::abs(static_cast<double>(rounded) - value));
    largest_magnitude_ = std::max(largest_magnitude_, std::abs(value));
    low_[axis] = std::min(low_[axis], value);
    high_[axis] = std::max(high_[axis], value);
  }
  return rounded;
}

bool CoordinateRounding::harmless(std::size_t count,
                                  const std::function<Eigen::Vector3f(std::size_t)> &rounded,
                                  std::string &reason) const {
  if (largest_shift_ == 0)
    return true;
  // One position as read (or none): nothing to harm; the core reports it.
  const double size = (high_ - low_).norm();
  if (!(size > 0) || largest_shift_ <= negligible_rounding_per_size * size)
    return true;
  std::vector<Eigen::Vector3f> points(count);
  for (std::size_t i = 0; i < count; ++i)
    points[i] = rounded(i);
  const double spacing = detail::medianSpacing(
      count, spacing_samples, [&](std::size_t i) { return points[i].cast<double>().eval(); });
  if (spacing > 0 && largest_shift_ <= max_rounding_per_spacing * spacing)
    return true;
  std::ostringstream message;
  message.precision(4);
  message << "coordinates as large as " << largest_magnitude_ << " move by up to " << largest_shift_
          << " when stored as float (as PCL's point types hold them)";
  if (spacing > 0)
    message << ", " << 100 * largest_shift_ / spacing << " % of the points' typical spacing "
            << spacing;
  else
    message << ", which puts all points at one position";
  message << ": shift the cloud near the origin first (subtract an offset)";
  reason = message.str();
  return false;
}

} // namespace io_detail
} // namespace pcl_ms
