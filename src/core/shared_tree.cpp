// SPDX-License-Identifier: GPL-3.0-or-later
// The bucket tree across processes (shared_tree.h). In: this process's
// slice of the prepared points. Out: the nodes and leaves one process would
// have, and the leaf of each point of the slice. Every process recurses
// through the same nodes; a node's count, bounding box and median are
// collective, so all take the same branches.
#include "shared_tree.h"

#include "process_bytes.h"

#include <pcl_ms/buckets.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <utility>

namespace pcl_ms {
namespace {

using detail::Box;
using detail::totalOver;
using Node = detail::TreeNode;

/// Orders doubles as integers: negative below positive, -0 as +0 (one
/// process's comparison finds them equal and breaks the tie by index).
std::uint64_t orderKey(double value) {
  if (value == 0)
    value = 0.0;
  std::uint64_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits & (std::uint64_t{1} << 63) ? ~bits : bits | (std::uint64_t{1} << 63);
}

/// (coordinate, index) as one process's median split orders points.
struct SplitKey {
  std::uint64_t coordinate;
  VertexIndex index;
  bool operator<(const SplitKey &other) const {
    return coordinate < other.coordinate || (coordinate == other.coordinate && index < other.index);
  }
};

class TreeBuilder {
public:
  TreeBuilder(const std::vector<Eigen::Vector3d> &positions, std::size_t first,
              const Parameters &parameters, ProcessGroup &group)
      : positions_(positions), first_(first), parameters_(parameters), group_(group) {
    tree_.home_leaf.assign(positions.size(), 0);
  }

  SharedTree build() {
    std::vector<std::uint32_t> all(positions_.size());
    for (std::size_t i = 0; i < all.size(); ++i)
      all[i] = static_cast<std::uint32_t>(i);
    const int grid = parameters_.grid_buckets;
    if (grid > 0) {
      const auto [low, high] = boundsOf(all);
      grid_low_ = low;
      grid_cell_ = ((high - low) / grid).cwiseMax(Eigen::Vector3d::Constant(1e-300));
      tree_.root = buildGrid(std::move(all), Box(), {0, 0, 0}, {grid, grid, grid}, 0);
    } else {
      tree_.root = buildMedian(std::move(all), Box(), 0);
    }
    numberLeaves();
    for (const Node &node : tree_.nodes)
      if (node.axis >= 0)
        tree_.max_depth = std::max(tree_.max_depth, node.depth);
    return std::move(tree_);
  }

private:
  VertexIndex globalIndex(std::size_t home) const {
    return static_cast<VertexIndex>(first_ + home);
  }

  /// The bounding box of all processes' `members`.
  std::pair<Eigen::Vector3d, Eigen::Vector3d> boundsOf(const std::vector<std::uint32_t> &members) {
    std::vector<double> low(3, std::numeric_limits<double>::infinity());
    std::vector<double> high(3, -std::numeric_limits<double>::infinity());
    for (std::uint32_t i : members)
      for (int a = 0; a < 3; ++a) {
        low[a] = std::min(low[a], positions_[i][a]);
        high[a] = std::max(high[a], positions_[i][a]);
      }
    group_.minimum(low);
    group_.maximum(high);
    return {Eigen::Vector3d(low[0], low[1], low[2]), Eigen::Vector3d(high[0], high[1], high[2])};
  }

  /// The key of rank `rank` among all processes' members on `axis`: a radix
  /// selection, 8 bits a round, 12 rounds (64-bit coordinate, 32-bit index).
  SplitKey selectSplit(const std::vector<std::uint32_t> &members, int axis, std::uint64_t rank) {
    std::vector<SplitKey> candidates;
    candidates.reserve(members.size());
    for (std::uint32_t i : members)
      candidates.push_back({orderKey(positions_[i][axis]), globalIndex(i)});
    SplitKey chosen{0, 0};
    for (int round = 0; round < 12; ++round) {
      auto digitOf = [&](const SplitKey &key) {
        return round < 8 ? static_cast<unsigned>(key.coordinate >> (56 - 8 * round)) & 0xffu
                         : static_cast<unsigned>(key.index >> (24 - 8 * (round - 8))) & 0xffu;
      };
      std::vector<std::uint64_t> histogram(256, 0);
      for (const SplitKey &key : candidates)
        ++histogram[digitOf(key)];
      group_.sum(histogram);
      unsigned digit = 0;
      while (digit < 255 && histogram[digit] <= rank)
        rank -= histogram[digit++];
      if (round < 8)
        chosen.coordinate |= static_cast<std::uint64_t>(digit) << (56 - 8 * round);
      else
        chosen.index |= static_cast<VertexIndex>(digit) << (24 - 8 * (round - 8));
      candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                      [&](const SplitKey &key) { return digitOf(key) != digit; }),
                       candidates.end());
    }
    return chosen;
  }

  int makeLeaf(std::vector<std::uint32_t> &&members, const Box &region, int depth) {
    Node node;
    node.region = region;
    node.depth = depth;
    tree_.nodes.push_back(node);
    leaf_members_.push_back(std::move(members));
    leaf_node_.push_back(static_cast<int>(tree_.nodes.size() - 1));
    return static_cast<int>(tree_.nodes.size() - 1);
  }

  int makeInner(const Box &region, int axis, double split, int depth, int left, int right) {
    return detail::addInner(tree_.nodes, region, axis, split, depth, left, right);
  }

  /// As one process splits (buckets.cpp, BucketTree::buildMedian): at the
  /// median of the longest side, ties by index.
  int buildMedian(std::vector<std::uint32_t> &&members, const Box &region, int depth) {
    const std::uint64_t count = totalOver(members.size(), group_);
    if (count == 0)
      return -1;
    if (count <= bucket_points_)
      return makeLeaf(std::move(members), region, depth);
    const auto [low, high] = boundsOf(members);
    int axis = 0;
    (high - low).maxCoeff(&axis);
    const SplitKey middle = selectSplit(members, axis, count / 2);
    // The split is the middle point's own coordinate (its sign of zero too).
    std::vector<double> split{std::numeric_limits<double>::infinity()};
    std::vector<std::uint32_t> left_members, right_members;
    for (std::uint32_t i : members) {
      const SplitKey key{orderKey(positions_[i][axis]), globalIndex(i)};
      if (key.index == middle.index && key.coordinate == middle.coordinate)
        split[0] = positions_[i][axis];
      (key < middle ? left_members : right_members).push_back(i);
    }
    std::vector<std::uint32_t>().swap(members);
    group_.minimum(split);
    Box left_region = region, right_region = region;
    left_region.high[axis] = split[0];
    right_region.low[axis] = split[0];
    const int left = buildMedian(std::move(left_members), left_region, depth + 1);
    const int right = buildMedian(std::move(right_members), right_region, depth + 1);
    return makeInner(region, axis, split[0], depth, left, right);
  }

  /// As BucketTree::buildGrid: the grid's cell ranges halved, points on the
  /// side of the plane their coordinate lies on.
  int buildGrid(std::vector<std::uint32_t> &&members, const Box &region, std::array<int, 3> first,
                std::array<int, 3> last, int depth) {
    if (totalOver(members.size(), group_) == 0)
      return -1;
    const detail::GridHalves halves = detail::halveGrid(region, first, last, grid_low_, grid_cell_);
    if (halves.leaf)
      return makeLeaf(std::move(members), region, depth);
    std::vector<std::uint32_t> left_members, right_members;
    for (std::uint32_t i : members)
      (positions_[i][halves.axis] < halves.split ? left_members : right_members).push_back(i);
    std::vector<std::uint32_t>().swap(members);
    const int left =
        buildGrid(std::move(left_members), halves.left_region, first, halves.left_last, depth + 1);
    const int right = buildGrid(std::move(right_members), halves.right_region, halves.right_first,
                                last, depth + 1);
    return makeInner(region, halves.axis, halves.split, depth, left, right);
  }

  /// Depth-first, as one process numbers them: a subtree's leaves form a range.
  void numberLeaves() {
    tree_.leaves = detail::numberLeaves(tree_.nodes, tree_.root);
    for (std::size_t k = 0; k < leaf_node_.size(); ++k) {
      const std::uint32_t leaf = tree_.nodes[static_cast<std::size_t>(leaf_node_[k])].first_leaf;
      for (std::uint32_t i : leaf_members_[k])
        tree_.home_leaf[i] = leaf;
    }
    std::vector<std::vector<std::uint32_t>>().swap(leaf_members_);
  }

  const std::vector<Eigen::Vector3d> &positions_;
  const std::size_t first_;
  const Parameters &parameters_;
  ProcessGroup &group_;
  const std::size_t bucket_points_ =
      parameters_.bucket_points > 0 ? parameters_.bucket_points : default_bucket_points;
  SharedTree tree_;
  std::vector<int> leaf_node_; // while building: node of each leaf made
  std::vector<std::vector<std::uint32_t>> leaf_members_;
  Eigen::Vector3d grid_low_ = Eigen::Vector3d::Zero(), grid_cell_ = Eigen::Vector3d::Ones();
};

} // namespace

SharedTree buildSharedTree(const std::vector<Eigen::Vector3d> &positions, std::size_t first,
                           const Parameters &parameters, ProcessGroup &group) {
  return TreeBuilder(positions, first, parameters, group).build();
}

} // namespace pcl_ms
