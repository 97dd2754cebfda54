// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 5: turning the accepted triangles into a usable surface: holes of up
// to k edges closed, each component oriented consistently where possible,
// boundary loops traced. Works on a plain 2-manifold triangle list.
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl_ms {

struct FinishedSurface {
  std::vector<Triangle> triangles;
  std::vector<std::vector<VertexIndex>> boundary_loops;
  std::vector<std::uint32_t> triangle_component;
  std::vector<bool> component_orientable;
  std::size_t holes_filled = 0;
};

/// Cyclic boundary loops of a 2-manifold triangle list, each starting at its
/// smallest vertex, in order of that vertex.
std::vector<std::vector<VertexIndex>> traceBoundaryLoops(const std::vector<Triangle> &triangles);

/// Closes loops of at most max_edges edges with triangles of the Delaunay
/// triangulation of the loop's vertices (minimum total P / C^2, no edge
/// that the mesh already has inside the hole, sides below max_side except
/// for a triangular hole). Returns the holes closed.
std::size_t fillHoles(std::vector<Triangle> &triangles, const std::vector<Eigen::Vector3d> &points,
                      int max_edges, double max_side);

/// Orients every component consistently by a breadth-first walk over shared
/// edges (outward for closed components: positive signed volume); a
/// component where no consistent orientation exists is reported and kept.
void orientComponents(std::vector<Triangle> &triangles, const std::vector<Eigen::Vector3d> &points,
                      std::vector<std::uint32_t> &triangle_component,
                      std::vector<bool> &component_orientable);

/// All of the above in order.
FinishedSurface finishSurface(std::vector<Triangle> triangles,
                              const std::vector<Eigen::Vector3d> &points, int fill_holes_max_edges,
                              double max_side);

} // namespace pcl_ms
