// SPDX-License-Identifier: GPL-3.0-or-later
// The medial axis that a reconstructed surface leaves: A1^4 nodes and A1^3
// shock curves of the medial scaffold that the surface did not consume
// (docs/algorithm.md, "Medial axis output").
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <vector>

namespace pcl_ms {

/// The poles of `points` (per point the farthest Voronoi vertex of its cell
/// on each side, after Amenta's power crust) whose ball touches the points
/// at two places at least 45 degrees apart, as nodes with their ball radii;
/// the Voronoi edges between two nodes whose Delaunay triangle is not in
/// `surface` as curves; and each node's side of the surface's closed
/// components (flood from infinity through the Delaunay tetrahedra, the
/// closed components' triangles as walls). `surface` indexes `points`; exact duplicate points stand
/// for one another. Fewer than four points not on one plane give no nodes. Nodes are sorted by
/// their tetrahedron's corners (as points, not indices), so the result does not depend on the order
/// of `points`. Throws ReconstructionError (reconstruct.h) for a non-finite point or a triangle
/// with an index outside `points`.
MedialAxis computeMedialAxis(const std::vector<Eigen::Vector3d> &points,
                             const std::vector<Triangle> &surface);

} // namespace pcl_ms
