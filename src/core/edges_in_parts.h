// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's scan of the edges for a triangle list held in parts by the
// processes of a ProcessGroup (docs/algorithm.md, "Across processes",
// "Finishing in parts"). In: each process's consecutive run of the list.
// Out: what meshEdges() finds for that run, with whole-list numbers.
// Internal to the library: not installed.
#pragma once

#include "edge_key.h"

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <cstdint>
#include <limits>
#include <vector>

namespace pcl_ms {
namespace detail {

/// "No triangle" in a slot of MeshEdgesPart::neighbours.
inline constexpr std::uint64_t no_neighbour_in_parts = std::numeric_limits<std::uint64_t>::max();

/// One process's share of meshEdges(whole list, true); triangles are
/// numbered in the whole list (a billion-point surface has more than 2^32).
struct MeshEdgesPart {
  /// The boundary edges whose triangle this process holds, in key order.
  std::vector<EdgeKey> boundary;
  std::vector<std::uint64_t> boundary_triangle;
  /// Three slots per triangle of the run: the triangles across its
  /// manifold edges in the order of those edges' keys, then
  /// no_neighbour_in_parts; the same as meshEdges' slots.
  std::vector<std::uint64_t> neighbours;
  /// Whether some edge of the whole list has three triangles or more (the
  /// same on every process).
  bool crowded = false;
};

/// Collective. `mine` is this process's run of the list, from whole-list
/// number `first` on; the runs follow each other in process order.
/// `vertex_count` (every corner is below it) is the same on every process.
/// Each edge is judged by one process, the owner of its lower vertex (the
/// vertices split in N equal ranges), which sees all its triangles: a
/// process sends out three records per triangle and gets back one per
/// edge of its own, so no process holds more than its share of the edges.
MeshEdgesPart meshEdgesInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                               std::uint64_t vertex_count, ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
