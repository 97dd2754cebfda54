// SPDX-License-Identifier: GPL-3.0-or-later
// Stray points (docs/algorithm.md section 1). In: distinct points. Out: the
// points far from the rest, and a centre they cannot move.
#include "far_points.h"
#include "populate_pages.h"
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
  Eigen::Vector3d central_low, central_high, median_of_all;
  // Each axis's median first (one thread per axis): it splits the values
  // into halves that hold the ranks below and above it, where the central
  // box's sides are then selected, six selections on half the values each.
  const std::size_t middle = n / 2, high_rank = n - 1 - tail;
  std::vector<float> values[3];
  auto select = [&](std::size_t axis, std::size_t begin, std::size_t rank, std::size_t end) {
    const auto first = values[axis].begin();
    std::nth_element(first + static_cast<std::ptrdiff_t>(begin),
                     first + static_cast<std::ptrdiff_t>(rank),
                     first + static_cast<std::ptrdiff_t>(end));
    return selectedValue(values[axis][rank]);
  };
  parallelFor(0, 3, [&](std::size_t axis) {
    resizeForWriting(values[axis], n);
    for (std::size_t i = 0; i < n; ++i)
      values[axis][i] = points[i][axis];
    median_of_all[axis] = select(axis, 0, middle, n);
  });
  parallelFor(0, 6, [&](std::size_t side) {
    const std::size_t axis = side / 2;
    if (side % 2 == 0)
      central_low[axis] = tail < middle ? select(axis, 0, tail, middle) : median_of_all[axis];
    else
      central_high[axis] =
          high_rank > middle ? select(axis, middle + 1, high_rank, n) : median_of_all[axis];
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
  if (far.count == 0) {
    far.median = median_of_all;
  } else {
    parallelFor(0, 3, [&](std::size_t axis) {
      values[axis].clear();
      for (std::size_t i = 0; i < n; ++i)
        if (!far.is_far[i])
          values[axis].push_back(points[i][axis]);
      far.median[axis] = select(axis, 0, values[axis].size() / 2, values[axis].size());
    });
  }
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
