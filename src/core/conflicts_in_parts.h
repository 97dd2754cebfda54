// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's repair of the twists the spanning forest leaves, for a
// triangle list held in parts by the processes of a ProcessGroup
// (docs/algorithm.md, "Finishing in parts"). In: each process's run, turned
// as the forest turns it, and the conflicts it holds. Out: the triangles to
// cut, as one process chooses them.
// Internal to the library: not installed.
#pragma once

#include "components_in_parts.h"
#include "edges_in_parts.h"
#include "points_from_homes.h"
#include "twists_in_parts.h"

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

/// Collective. `turned` is this process's run from whole-list number
/// `first` on, each triangle turned as the twist forest turns it; `edges`,
/// `components` and `corners` its edge scan, components and corner points;
/// `conflicts` the inconsistent edges it holds (twistForestInParts()).
/// Returns whole-list numbers of triangles to cut (for cutInParts()), the
/// same set over all processes as one process's orientAlongNeighbours():
/// with a viewpoint the more edge-on triangle of each conflict; without,
/// both where the edge folds by more than 90 degrees or a short
/// orientation-reversing walk closes the twist. The walks run on all
/// processes at once, a step a round, each triangle's state on its holder;
/// the long walks of a component follow each other in key order, as one
/// process's do (a failed one marks a real twist, which stops them).
std::vector<std::uint64_t>
conflictCutsInParts(const std::vector<Triangle> &turned, std::uint64_t first,
                    const MeshEdgesPart &edges, const ComponentsPart &components,
                    const CornerPoints &corners, const std::vector<TwistConflict> &conflicts,
                    const Eigen::Vector3d *viewpoint, ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
