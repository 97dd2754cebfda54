// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's scan of the edges for a triangle list held in parts by the
// processes of a ProcessGroup (docs/algorithm.md, "Across processes",
// "Finishing in parts"). In: each process's consecutive run of the list.
// Out: what meshEdges() finds for that run, with whole-list numbers; then
// that share updated as addFilling() and dropFromMeshEdges() update one
// process's scan.
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
/// edge of its own, so no process holds more than its share of the edges;
/// both go in rounds of at most `records_per_round` records a process, so
/// that the messages in flight stay small beside that share.
MeshEdgesPart meshEdgesInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                               std::uint64_t vertex_count, ProcessGroup &group,
                               std::size_t records_per_round = std::size_t{1} << 21);

/// Collective. Updates the scan `edges` of a list that was not crowded for
/// triangles added at the end of some runs (the fillings, on the last
/// process): `mine` is this process's run with its new triangles from
/// `first_new` on (mine.size() where it has none), numbered from `first`
/// as before. As addFilling() updates one process's scan: a new triangle's
/// edge that was a boundary edge links it to the triangle there, two new
/// triangles on an edge link to each other, a new edge used once opens,
/// three uses make the list crowded; linked triangles keep their slots in
/// the order of the edges' keys. Every process learns every new edge (the
/// fillings are small), so no scan runs again.
void addTrianglesToEdgesInParts(MeshEdgesPart &edges, const std::vector<Triangle> &mine,
                                std::uint64_t first, std::size_t first_new, ProcessGroup &group);

/// Collective. Updates the scan `edges` of a list that was not crowded for
/// the triangles that leave it: `mine` is this process's run before, from
/// `first` on, and `dropped` the places in it of those that go (ascending;
/// cutInParts' CutPart::dropped). As dropFromMeshEdges() updates one
/// process's scan: an edge between a triangle that goes and one that stays
/// opens on the one that stays (told by the holder of the one that goes),
/// an edge with no triangle left goes, and every number is that of the list
/// left (every process learns every number that goes: cuts are small).
void dropFromEdgesInParts(MeshEdgesPart &edges, const std::vector<Triangle> &mine,
                          std::uint64_t first, const std::vector<std::size_t> &dropped,
                          ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
