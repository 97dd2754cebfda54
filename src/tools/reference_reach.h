// SPDX-License-Identifier: GPL-3.0-or-later
//
// Where the triangles of a reference mesh lie in the medial scaffold of its
// own vertices: how many the method ranks in its first pass (Gabriel
// triangles, types I and II), how many it meets only in its second pass
// (type III), and how many it never meets (a side of at least d_max, or not a
// Delaunay triangle at all). This bounds the exact-triangle recall that any
// method preferring Gabriel triangles can reach on that reference.
#pragma once

#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace pcl_ms_tools {

struct ReferenceReach {
  std::size_t reference_triangles = 0;
  std::size_t gabriel = 0;      // type I or II candidates
  std::size_t ambiguous = 0;    // type III candidates
  std::size_t oversize = 0;     // Delaunay triangles with a side >= d_max
  std::size_t not_delaunay = 0; // not a triangle of the Delaunay tetrahedralisation
  /// Of each group, the triangles that `mesh` contains too.
  std::size_t gabriel_recovered = 0, ambiguous_recovered = 0, oversize_recovered = 0,
              not_delaunay_recovered = 0;

  static double share(std::size_t part, std::size_t whole) {
    return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
  }
};

/// `reference` and `mesh` index `vertices` (distinct points). Throws
/// std::invalid_argument when two vertices coincide or an index is out of range.
ReferenceReach referenceReach(const std::vector<Eigen::Vector3d> &vertices,
                              const std::vector<pcl_ms::Triangle> &reference,
                              const std::vector<pcl_ms::Triangle> &mesh, double rho);

} // namespace pcl_ms_tools
