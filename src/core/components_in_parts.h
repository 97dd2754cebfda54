// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's components and consistent orientation for a triangle list held
// in parts by the processes of a ProcessGroup (docs/algorithm.md, "Finishing
// in parts"). In: each process's run of the list and its edge scan
// (edges_in_parts.h). Out: per triangle of the run, its component, its turn
// to agree with the component's first triangle, and whether the component
// has a consistent orientation: what one process's parity forest gives.
// Internal to the library: not installed.
#pragma once

#include "edges_in_parts.h"

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

struct ComponentsPart {
  /// Per triangle of the run: the whole-list number of its component's
  /// first triangle (components are joined across manifold edges).
  std::vector<std::uint64_t> component;
  /// Per triangle: 1 where turning it makes it agree with that first
  /// triangle. Only meaningful in orientable components.
  std::vector<std::uint8_t> flipped;
  /// Per triangle: 1 where its component has a consistent orientation
  /// (no cycle of manifold edges reverses it).
  std::vector<std::uint8_t> orientable;
};

/// Collective. `mine`, from whole-list number `first` on, and `edges` as
/// given to and returned by meshEdgesInParts. Each process joins the edges
/// within its run; the edges between runs (along the cuts between the
/// runs, few where the runs are compact in space, as buckets' subtrees are)
/// go to process 0, which joins the runs' pieces and answers each process
/// for its pieces.
ComponentsPart componentsInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                                 const MeshEdgesPart &edges, ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
