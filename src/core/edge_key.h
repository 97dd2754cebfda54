// SPDX-License-Identifier: GPL-3.0-or-later
// One key per undirected edge (docs/algorithm.md, "Code layout"). In: its two
// vertex indices, in either order. Out: a 64-bit key, smaller index in the
// high word, so keys sort like (smaller, larger) pairs. Internal to the
// library (not installed); the in-tree tools use it too.
#pragma once

#include <pcl_ms/types.h>

#include <cstdint>
#include <utility>

namespace pcl_ms {
namespace detail {

using EdgeKey = std::uint64_t;

inline EdgeKey edgeKey(VertexIndex a, VertexIndex b) {
  if (a > b)
    std::swap(a, b);
  return (static_cast<EdgeKey>(a) << 32) | b;
}

inline VertexIndex lowVertex(EdgeKey key) { return static_cast<VertexIndex>(key >> 32); }
inline VertexIndex highVertex(EdgeKey key) { return static_cast<VertexIndex>(key & 0xffffffffu); }

} // namespace detail
} // namespace pcl_ms
