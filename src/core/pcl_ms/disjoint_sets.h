// SPDX-License-Identifier: GPL-3.0-or-later
// The project's union-finds (docs/algorithm.md, "Code layout"): Boost's
// disjoint sets wherever plain sets do, and ParityForest where each element
// also carries whether it is flipped relative to its set (orientation).
// Internal: not installed.
#pragma once

#include <boost/pending/disjoint_sets.hpp>

#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

namespace pcl_ms {
namespace detail {

/// Elements 0..n-1: union_set(a, b), find_set(a). Which element is a set's
/// representative depends on the union order; callers number sets by their
/// smallest element when the numbers matter.
using DisjointSets = boost::disjoint_sets_with_storage<>;

/// Union-find that keeps each element's flip relative to its root. The
/// smaller index is always the root, so a set's root is its first element
/// whatever order the joins come in. Threads may join and find in sets that
/// no other thread touches: each call writes only its sets' entries.
class ParityForest {
public:
  enum class Join { joined, consistent, conflict };

  explicit ParityForest(std::size_t size) : parent_(size), flip_to_parent_(size, 0) {
    std::iota(parent_.begin(), parent_.end(), 0u);
  }

  /// The root of t, and whether t is flipped relative to it.
  std::pair<std::uint32_t, std::uint8_t> find(std::uint32_t t) {
    std::uint8_t flip = 0;
    std::uint32_t root = t;
    while (parent_[root] != root) {
      flip ^= flip_to_parent_[root];
      root = parent_[root];
    }
    // Path compression: point every element on the path at the root.
    for (std::uint8_t rest = flip; parent_[t] != t;) {
      const std::uint32_t next = parent_[t];
      const std::uint8_t step = flip_to_parent_[t];
      parent_[t] = root;
      flip_to_parent_[t] = rest;
      rest ^= step;
      t = next;
    }
    return {root, flip};
  }

  /// Puts t and u in one set with their flips differing by must_differ; when
  /// they already share a set, says whether their flips agree with that.
  Join join(std::uint32_t t, std::uint32_t u, bool must_differ) {
    const auto [t_root, t_flip] = find(t);
    const auto [u_root, u_flip] = find(u);
    if (t_root == u_root)
      return (t_flip ^ u_flip) == must_differ ? Join::consistent : Join::conflict;
    const std::uint32_t root = std::min(t_root, u_root);
    const std::uint32_t child = std::max(t_root, u_root);
    parent_[child] = root;
    flip_to_parent_[child] = static_cast<std::uint8_t>(t_flip ^ u_flip ^ must_differ);
    return Join::joined;
  }

private:
  std::vector<std::uint32_t> parent_;
  std::vector<std::uint8_t> flip_to_parent_;
};

} // namespace detail
} // namespace pcl_ms
