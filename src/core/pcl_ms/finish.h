// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4 (docs/algorithm.md section 4): turning the accepted triangles into a usable surface:
// holes of up to k edges closed, each component oriented consistently where possible, boundary
// loops traced. Works on a plain 2-manifold triangle list.
#pragma once

#include <pcl_ms/local_scale.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace pcl_ms {

struct FinishedSurface {
  std::vector<Triangle> triangles;
  std::vector<std::vector<VertexIndex>> boundary_loops;
  std::vector<std::uint32_t> triangle_component;
  std::vector<bool> component_orientable;
  std::size_t holes_filled = 0;
  std::size_t twist_triangles_removed = 0;
};

/// Cyclic boundary loops of a 2-manifold triangle list, each starting at its
/// smallest vertex, in order of that vertex.
std::vector<std::vector<VertexIndex>> traceBoundaryLoops(const std::vector<Triangle> &triangles);

/// Orients every component consistently, spreading across the flattest
/// shared edges first: outward for closed components (positive signed
/// volume), towards the viewpoint (when given) for the others. A component
/// where no consistent orientation exists is reported and kept. Returns the
/// triangles where a repair should cut: with a viewpoint, the more edge-on
/// triangle of every inconsistent edge; without one, both triangles of each
/// inconsistent edge that folds by more than 90 degrees or whose twist is
/// local (a short orientation-reversing walk closes it).
std::vector<std::uint32_t> orientComponents(std::vector<Triangle> &triangles,
                                            const std::vector<Eigen::Vector3d> &points,
                                            std::vector<std::uint32_t> &triangle_component,
                                            std::vector<bool> &component_orientable,
                                            const Eigen::Vector3d *viewpoint = nullptr);

/// Keeps one fan at every touched vertex whose triangles form several (the
/// one with more `fixed` triangles, then the largest: fan_choice.h), until
/// none has more than one; the corners of removed triangles become touched.
/// `fixed` (null, or triangles with ascending corners, sorted) are never
/// removed: where two fans hold some, the vertex stays a pinch. Returns how
/// many triangles it removed.
std::size_t splitBowTies(std::vector<Triangle> &triangles, std::size_t vertex_count,
                         std::vector<bool> &touched, const std::vector<Triangle> *fixed = nullptr);

/// All of the above in order. `fixed_triangles` (null, or the user's fixed
/// initial triangles, any corner order) survive it: the twist repair keeps
/// every triangle at their corners, the bow-tie split keeps them.
FinishedSurface finishSurface(std::vector<Triangle> triangles,
                              const std::vector<Eigen::Vector3d> &points, int fill_holes_max_edges,
                              const SideLimit &limit,
                              const std::vector<Triangle> *fixed_triangles = nullptr,
                              const Eigen::Vector3d *viewpoint = nullptr);

/// The seam pass's triangles (docs/algorithm.md, "Seams (opt-in)") join a
/// surface finished from the greedy's `greedy` triangles: triangles the
/// finish added (hole fills) on their edges are removed, exact repeats left
/// out, each new
/// triangle takes the orientation of its sheet across edges with two
/// triangles (the finished ones keep theirs), components become the
/// manifold sheets (joined across edges with exactly two triangles) and
/// boundary loops are traced again. Returns the edges with three or more
/// triangles, smaller vertex first, sorted.
std::vector<std::array<VertexIndex, 2>> attachSeamTriangles(FinishedSurface &surface,
                                                            const std::vector<Triangle> &seam,
                                                            const std::vector<Triangle> &greedy);

} // namespace pcl_ms
