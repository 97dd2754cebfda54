// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's choice of side for each orientable component, for a triangle
// list held in parts by the processes of a ProcessGroup (docs/algorithm.md,
// "Finishing in parts"): outward for closed surfaces, towards the viewpoint
// for open ones when there is one, a fixed choice otherwise, as one
// process's orientation decides it. Internal to the library: not installed.
#pragma once

#include "components_in_parts.h"
#include "edges_in_parts.h"
#include "points_from_homes.h"

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

/// Collective. `mine` from whole-list number `first` on, with its edge
/// scan, components and corners (edges_in_parts.h, components_in_parts.h,
/// points_from_homes.h). Returns per triangle of the run whether to turn
/// it (swap its last two corners): in orientable components, to agree with
/// the component's first triangle and then to face the component's side;
/// never in the others. Each process sums its triangles' terms per
/// component; the sums go to the process holding the component's first
/// triangle, which decides by their exact signs and answers. Only a sum
/// too close to zero for its rounding bound needs its terms sent there.
std::vector<std::uint8_t> sideTurnsInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                                           const MeshEdgesPart &edges,
                                           const ComponentsPart &components,
                                           const CornerPoints &corners,
                                           const Eigen::Vector3d *viewpoint, ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
