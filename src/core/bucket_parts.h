// SPDX-License-Identifier: GPL-3.0-or-later
// What the buckets of one process (buckets.cpp) and those shared by
// processes (shared_buckets.cpp) do alike (docs/algorithm.md section 5): the
// tree's nodes and how a grid is halved, margins, seam slabs, progress.
// Internal to the library: not installed.
#pragma once

#include <Eigen/Core>

#include <pcl_ms/reconstruct.h>
#include <pcl_ms/types.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

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
  void extend(const Eigen::Vector3d &p) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
};

/// A box that holds nothing until extended.
inline Box emptyBox() {
  Box box;
  std::swap(box.low, box.high);
  return box;
}

/// The slab of a seam zone: `region` (the zone's node) grown by the larger
/// of its buckets' widest margin and `half_width`, cut to `half_width` on
/// each side of the split plane.
inline Box zoneSlab(const Box &region, int axis, double split, double margin, double half_width) {
  Box slab = region.expanded(std::max(margin, half_width));
  slab.low[axis] = std::max(slab.low[axis], split - half_width);
  slab.high[axis] = std::min(slab.high[axis], split + half_width);
  return slab;
}

/// How far a seam zone reaches from its plane, tile by tile (docs/algorithm.md
/// section 5, "How wide a zone is"). A triangle across the plane has sides
/// shorter than rho times the largest scale of its corners, so each corner
/// lies within that distance of the plane and of the corner with that scale.
/// The plane is cut into square tiles at least as wide as the widest such
/// reach: that corner then lies in the tile of any other corner or in one of
/// the 8 around it (a point beyond the tiles counts in the nearest, as the
/// corner near the plane is within a tile of it). A point of the widest slab
/// belongs to the zone when it lies within rho times the largest scale near
/// the plane in its 3 x 3 tiles.
class ZoneReach {
public:
  /// `near_plane`: the bounds of the points within the margin of the plane,
  /// whose scales are added; `largest_scale`: the largest of them.
  ZoneReach(const Box &near_plane, int axis, double split, double rho, float largest_scale)
      : axis_(axis), split_(split), rho_(rho) {
    const double widest = rho * largest_scale;
    for (int k = 0; k < 2; ++k) {
      const int a = (axis + 1 + k) % 3;
      along_[k] = a;
      low_[k] = near_plane.low[a];
      const double extent = near_plane.high[a] - near_plane.low[a];
      tile_[k] = std::max(widest, extent / max_tiles_per_side);
      if (!std::isfinite(extent) || !(extent > 0) || !std::isfinite(tile_[k])) {
        tile_[k] = 1;
        count_[k] = 1;
        continue;
      }
      count_[k] = std::min(max_tiles_per_side, static_cast<std::size_t>(extent / tile_[k]) + 1);
    }
    scales_.assign(count_[0] * count_[1], 0.0f);
  }

  /// A point within the margin of the plane, with its scale.
  void addScale(const Eigen::Vector3d &point, float scale) {
    float &tile = scales_[tileOf(point)];
    tile = std::max(tile, scale);
  }

  /// Whether a point of the widest slab lies within its tiles' reach.
  bool reaches(const Eigen::Vector3d &point) const {
    const std::size_t i = cellOf(point, 0), j = cellOf(point, 1);
    float largest = 0;
    for (std::size_t ii = i > 0 ? i - 1 : 0; ii <= std::min(i + 1, count_[0] - 1); ++ii)
      for (std::size_t jj = j > 0 ? j - 1 : 0; jj <= std::min(j + 1, count_[1] - 1); ++jj)
        largest = std::max(largest, scales_[ii * count_[1] + jj]);
    const double half_width = rho_ * largest;
    return point[axis_] >= split_ - half_width && point[axis_] <= split_ + half_width;
  }

  /// The tiles' largest scales, to be joined with other processes'.
  std::vector<float> &tileScales() { return scales_; }

private:
  // Enough to follow the scales along a plane; bounds the processes' exchange.
  static constexpr std::size_t max_tiles_per_side = 256;

  std::size_t cellOf(const Eigen::Vector3d &point, int k) const {
    const double offset = (point[along_[k]] - low_[k]) / tile_[k];
    if (!(offset >= 1)) // NaN too
      return 0;
    const std::size_t last = count_[k] - 1;
    return offset >= static_cast<double>(last) ? last : static_cast<std::size_t>(offset);
  }
  std::size_t tileOf(const Eigen::Vector3d &point) const {
    return cellOf(point, 0) * count_[1] + cellOf(point, 1);
  }

  int axis_;
  double split_, rho_;
  std::array<int, 2> along_{};
  std::array<double, 2> low_{}, tile_{};
  std::array<std::size_t, 2> count_{};
  std::vector<float> scales_;
};

/// A node of the bucket tree. Leaves are buckets; an inner node's split
/// plane is the seam between its two subtrees. Leaves are numbered in
/// depth-first order, so a subtree's leaves form a range.
struct TreeNode {
  Box region;
  int axis = -1; // -1 for a leaf
  double split = 0;
  int children[2] = {-1, -1};
  int depth = 0;
  std::uint32_t first_leaf = 0, end_leaf = 0;
};

/// Adds an inner node over `left` and `right` (-1: no node) and returns its
/// index; with one side empty there is no seam, and the other side stands
/// for the node.
template <typename Node>
int addInner(std::vector<Node> &nodes, const Box &region, int axis, double split, int depth,
             int left, int right) {
  if (left < 0 || right < 0)
    return left < 0 ? right : left;
  Node node;
  node.region = region;
  node.axis = axis;
  node.split = split;
  node.depth = depth;
  node.children[0] = left;
  node.children[1] = right;
  nodes.push_back(std::move(node));
  return static_cast<int>(nodes.size() - 1);
}

/// Numbers the leaves under `root` depth-first, sets every node's leaf
/// range, and returns the leaves' nodes by number.
template <typename Node> std::vector<int> numberLeaves(std::vector<Node> &nodes, int root) {
  std::vector<int> leaves;
  std::vector<std::pair<int, bool>> stack{{root, false}};
  while (!stack.empty()) {
    auto [current, children_done] = stack.back();
    stack.pop_back();
    Node &node = nodes[static_cast<std::size_t>(current)];
    if (node.axis < 0) {
      node.first_leaf = static_cast<std::uint32_t>(leaves.size());
      node.end_leaf = node.first_leaf + 1;
      leaves.push_back(current);
    } else if (children_done) {
      node.first_leaf = nodes[static_cast<std::size_t>(node.children[0])].first_leaf;
      node.end_leaf = nodes[static_cast<std::size_t>(node.children[1])].end_leaf;
    } else {
      stack.push_back({current, true});
      stack.push_back({node.children[1], false});
      stack.push_back({node.children[0], false});
    }
  }
  return leaves;
}

/// How a grid's cell range [first, last) is halved: along its longest side,
/// at the middle cell's plane; a range one cell long is a leaf.
struct GridHalves {
  bool leaf = false;
  int axis = 0;
  double split = 0;
  Box left_region, right_region;
  std::array<int, 3> left_last{}, right_first{};
};

inline GridHalves halveGrid(const Box &region, const std::array<int, 3> &first,
                            const std::array<int, 3> &last, const Eigen::Vector3d &grid_low,
                            const Eigen::Vector3d &grid_cell) {
  GridHalves halves;
  int &axis = halves.axis;
  for (int a = 1; a < 3; ++a)
    if (last[a] - first[a] > last[axis] - first[axis])
      axis = a;
  halves.leaf = last[axis] - first[axis] <= 1;
  if (halves.leaf)
    return halves;
  const int middle_cell = (first[axis] + last[axis]) / 2;
  halves.split = grid_low[axis] + middle_cell * grid_cell[axis];
  halves.left_region = halves.right_region = region;
  halves.left_region.high[axis] = halves.split;
  halves.right_region.low[axis] = halves.split;
  halves.left_last = last;
  halves.right_first = first;
  halves.left_last[axis] = middle_cell;
  halves.right_first[axis] = middle_cell;
  return halves;
}

/// The cloud's d_med: the median of the meshed buckets' (not empty).
inline double medianBucketDMed(std::vector<double> d_meds) {
  std::nth_element(d_meds.begin(), d_meds.begin() + d_meds.size() / 2, d_meds.end());
  return d_meds[d_meds.size() / 2];
}

/// When no bucket could be meshed: the first bucket's error, with a hint
/// when a few points in a fine grid left each margin without neighbours.
[[noreturn]] inline void throwNoBucketMeshed(std::string first_error) {
  if (first_error == too_few_unit_points)
    first_error += " with its margin (too many buckets for the cloud: use fewer or none)";
  throw ReconstructionError("no bucket could be meshed" +
                            (first_error.empty() ? std::string() : ": " + first_error));
}

/// Calls Parameters::progress one unit at a time, from whichever thread
/// finished one.
class ProgressReporter {
public:
  ProgressReporter(const Parameters &parameters, std::size_t total)
      : callback_(parameters.progress), total_(total) {}
  void unitDone() {
    if (!callback_)
      return;
    std::lock_guard<std::mutex> lock(mutex_);
    callback_(++done_, total_);
  }

private:
  const std::function<void(std::size_t, std::size_t)> &callback_;
  std::size_t total_;
  std::size_t done_ = 0;
  std::mutex mutex_;
};

} // namespace detail
} // namespace pcl_ms
