// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's spanning forest of the twist repair for a triangle list held in
// parts by the processes of a ProcessGroup (docs/algorithm.md, "Finishing
// in parts"): in each component without a consistent orientation, the
// triangles turned along a maximum spanning forest on flatness, and the
// edges still inconsistent after, as one process's orientation finds them.
// Internal to the library: not installed.
#pragma once

#include "components_in_parts.h"
#include "edge_key.h"
#include "edges_in_parts.h"
#include "points_from_homes.h"

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

/// A manifold edge whose triangles t < u (whole-list numbers) disagree.
struct TwistConflict {
  EdgeKey key;
  std::uint64_t t, u;
  bool operator<(const TwistConflict &other) const { return key < other.key; }
};

struct TwistsPart {
  /// Per triangle of the run: 1 where the forest turns it (twisted
  /// components only).
  std::vector<std::uint8_t> flipped;
  /// The edges of twisted components left inconsistent, each on the process
  /// holding its triangle t, in key order.
  std::vector<TwistConflict> conflicts;
};

/// Collective. `mine` from whole-list number `first` on, with its edge
/// scan, components and corners. Each process joins its flat edges (below
/// kruskal_flat_bending) in a parity forest; its bent edges and the edges
/// to other runs go to process 0, which joins the runs' pieces along the
/// flat ones, then along the bent ones flattest first, and answers each
/// piece's turn. Where a cycle of flat edges is twisted the flat edges
/// need Kruskal's order too: then every edge of the twisted components
/// goes to process 0 (a real Moebius band, which bends gently throughout;
/// a crumple's twist crosses bent edges).
TwistsPart twistForestInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                              const MeshEdgesPart &edges, const ComponentsPart &components,
                              const CornerPoints &corners, ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
