// SPDX-License-Identifier: GPL-3.0-or-later
// A cloud's typical spacing, estimated cheaply: the median distance from a
// few evenly spread sample points to their nearest neighbour, by brute
// force. Used for the buckets' margins and by the tools' check on rounded
// coordinates. Internal to the library: not installed.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace pcl_ms {
namespace detail {

/// The median over min(samples, count) sample points (every count/samples-th)
/// of the distance to the nearest of the `count` points at another position;
/// `position(i)` gives point i. Non-finite points are skipped, as samples and
/// as neighbours. 0 when no sample has a neighbour.
template <typename Position>
double medianSpacing(std::size_t count, std::size_t samples, const Position &position) {
  std::vector<double> nearest;
  samples = std::min(samples, count);
  for (std::size_t s = 0; s < samples; ++s) {
    const Eigen::Vector3d query = position(s * count / samples);
    if (!query.allFinite())
      continue;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < count; ++i) {
      const double distance = (position(i) - query).squaredNorm();
      if (distance > 0 && distance < best) // NaN compares false
        best = distance;
    }
    if (std::isfinite(best))
      nearest.push_back(std::sqrt(best));
  }
  if (nearest.empty())
    return 0;
  const auto middle = nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2);
  std::nth_element(nearest.begin(), middle, nearest.end());
  return *middle;
}

} // namespace detail
} // namespace pcl_ms
