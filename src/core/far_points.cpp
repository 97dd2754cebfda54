// SPDX-License-Identifier: GPL-3.0-or-later
// Stray points (docs/algorithm.md section 1). In: distinct points. Out: the
// points far from the rest, and a centre they cannot move.
#include "far_points.h"
#include "threads.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace pcl_ms {
namespace detail {
namespace {

// Each tail of each axis left out of the central box: small enough that a
// far cluster of a few percent of the points stays inside it.
constexpr double tail_fraction = 0.01;

double distanceToBox(const Eigen::Vector3d &p, const Eigen::Vector3d &low,
                     const Eigen::Vector3d &high) {
  return (low - p).cwiseMax(p - high).cwiseMax(0.0).norm();
}

} // namespace

std::size_t tailRank(std::size_t n) {
  return static_cast<std::size_t>(tail_fraction * static_cast<double>(n));
}

bool outsideCentralBox(const Eigen::Vector3f &p, const Eigen::Vector3d &low,
                       const Eigen::Vector3d &high, double size) {
  return size > 0 && std::isfinite(size) && distanceToBox(p.cast<double>(), low, high) > size;
}

std::vector<bool> isolatedOutside(std::vector<Eigen::Vector3f> outside, const Eigen::Vector3d &low,
                                  const Eigen::Vector3d &high, double size) {
  // Swept along x: a neighbour within `size` is within `size` in x.
  std::vector<std::size_t> order(outside.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return outside[a].x() < outside[b].x(); });
  std::vector<bool> isolated(outside.size(), false);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Eigen::Vector3d p = outside[order[k]].cast<double>();
    if (distanceToBox(p, low, high) <= 2 * size)
      continue;
    bool has_neighbour = false;
    for (std::size_t j = k + 1; !has_neighbour && j < order.size(); ++j) {
      const Eigen::Vector3d q = outside[order[j]].cast<double>();
      if (q.x() - p.x() > size)
        break;
      has_neighbour = (q - p).norm() <= size;
    }
    for (std::size_t j = k; !has_neighbour && j-- > 0;) {
      const Eigen::Vector3d q = outside[order[j]].cast<double>();
      if (p.x() - q.x() > size)
        break;
      has_neighbour = (q - p).norm() <= size;
    }
    isolated[order[k]] = !has_neighbour;
  }
  return isolated;
}

FarPoints findFarPoints(const std::vector<Eigen::Vector3f> &points) {
  FarPoints far;
  far.is_far.assign(points.size(), false);
  if (points.empty())
    return far;
  const std::size_t n = points.size();
  const std::size_t tail = tailRank(n);
  Eigen::Vector3d central_low, central_high;
  // The axes are independent selections: one thread each.
  parallelFor(0, 3, [&](std::size_t axis) {
    std::vector<float> values(n);
    for (std::size_t i = 0; i < n; ++i)
      values[i] = points[i][axis];
    auto at = [&](std::size_t k) {
      std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k),
                       values.end());
      return selectedValue(values[k]);
    };
    central_low[axis] = at(tail);
    central_high[axis] = at(n - 1 - tail);
  });
  const double size = (central_high - central_low).norm();

  // Only points beyond `size` from the central box can be within `size` of a
  // candidate (beyond 2 size): every other point is farther than that.
  std::vector<std::size_t> outside;
  std::vector<Eigen::Vector3f> outside_points;
  for (std::size_t i = 0; i < n; ++i)
    if (outsideCentralBox(points[i], central_low, central_high, size)) {
      outside.push_back(i);
      outside_points.push_back(points[i]);
    }
  const std::vector<bool> isolated =
      isolatedOutside(std::move(outside_points), central_low, central_high, size);
  for (std::size_t k = 0; k < outside.size(); ++k)
    if (isolated[k]) {
      far.is_far[outside[k]] = true;
      ++far.count;
    }

  // The median of the points kept, so that far points change nothing.
  parallelFor(0, 3, [&](std::size_t axis) {
    std::vector<float> values;
    values.reserve(n - far.count);
    for (std::size_t i = 0; i < n; ++i)
      if (!far.is_far[i])
        values.push_back(points[i][axis]);
    auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    far.median[axis] = selectedValue(*middle);
  });
  far.low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  far.high = -far.low;
  for (std::size_t i = 0; i < n; ++i)
    if (!far.is_far[i]) {
      far.low = far.low.cwiseMin(points[i].cast<double>());
      far.high = far.high.cwiseMax(points[i].cast<double>());
    }
  return far;
}

} // namespace detail
} // namespace pcl_ms
