// SPDX-License-Identifier: GPL-3.0-or-later
// The bucket tree cut by processes that each hold a slice of the prepared
// points (docs/algorithm.md, "By owner, from slices"): the tree one process
// builds over all of them (buckets.cpp, BucketTree), with the medians found
// by exact selections across the processes. Internal to the library: not
// installed.
#pragma once

#include "bucket_parts.h"

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pcl_ms {

struct SharedTree {
  std::vector<detail::TreeNode> nodes;
  std::vector<int> leaves;              // the node of each leaf, by number
  std::vector<std::uint32_t> home_leaf; // the leaf of each of this process's points
  int root = -1, max_depth = 0;
};

/// The tree over all processes' points: `positions` are this process's,
/// whose indices in the whole cloud's prepared order start at `first`.
/// Collective.
SharedTree buildSharedTree(const std::vector<Eigen::Vector3d> &positions, std::size_t first,
                           const Parameters &parameters, ProcessGroup &group);

} // namespace pcl_ms
