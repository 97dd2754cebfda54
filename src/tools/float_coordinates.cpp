// SPDX-License-Identifier: GPL-3.0-or-later
// Coordinates rounded to float, and whether that harmed the cloud.
#include "float_coordinates.h"

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

/// The median distance from sample points to their nearest point at another
/// position, or 0 when no point has a neighbour.
double medianSpacing(const std::vector<Eigen::Vector3f> &points) {
  std::vector<double> nearest;
  const std::size_t samples = std::min(spacing_samples, points.size());
  for (std::size_t s = 0; s < samples; ++s) {
    const Eigen::Vector3f &query = points[s * points.size() / samples];
    if (!query.allFinite())
      continue;
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3f &other : points) {
      const double distance = (other.cast<double>() - query.cast<double>()).squaredNorm();
      if (distance > 0 && distance < best) // NaN compares false
        best = distance;
    }
    if (std::isfinite(best))
      nearest.push_back(std::sqrt(best));
  }
  if (nearest.empty())
    return 0;
  auto middle = nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2);
  std::nth_element(nearest.begin(), middle, nearest.end());
  return *middle;
}

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
  const double spacing = medianSpacing(points);
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
