// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4's hole filling for a triangle list held in parts by the processes
// of a ProcessGroup (docs/algorithm.md, "Finishing in parts"). In: each
// process's run of the list with its share of the edge scan, and its slice
// of the points and their local scales. Out: the fillings one process's
// fillLoops() makes, and the boundary loops left.
// Internal to the library: not installed.
#pragma once

#include "edges_in_parts.h"

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

/// What fillHolesInParts() gives each process.
struct HolesPart {
  /// On the last process: the filling triangles, in fillLoops()' order, to
  /// append to its run (one process appends them to the list).
  std::vector<Triangle> filling;
  /// On process 0: the boundary loops of the list with the filling, as
  /// boundaryLoops() traces them.
  std::vector<std::vector<VertexIndex>> loops;
  /// On every process: the holes closed.
  std::uint64_t filled = 0;
};

/// Collective. `mine` is this process's run of the list (the runs follow
/// each other in process order) and `edges` its meshEdgesInParts(); the
/// home slices `home_points` and `home_scales` (the points' local scales)
/// hold the points from number `home_first` on, following each other in
/// process order. `around`, if given, marks vertices on some processes: only
/// loops through one of them are filled (fillLoops' only_around).
/// The boundary edges go to process 0, which traces the loops and chooses
/// those to fill; the processes send it the edges and triangles among the
/// chosen loops' vertices, and their homes the vertices' points and scales;
/// process 0 fills the loops as one process does. The same fillings and
/// loops as one process, for any split. Throws std::invalid_argument on
/// every process when the slices do not follow each other from point 0 or
/// a slice's points and scales differ in number.
HolesPart fillHolesInParts(const std::vector<Triangle> &mine, const MeshEdgesPart &edges,
                           const std::vector<Eigen::Vector3d> &home_points,
                           const std::vector<float> &home_scales, std::uint64_t home_first,
                           int max_edges, double rho, const std::vector<VertexIndex> *around,
                           ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
