// SPDX-License-Identifier: GPL-3.0-or-later
// Delaunay cells that CGAL's exact predicates accept but whose circumcentre
// cannot be constructed in double. Internal to the library: not installed.
#pragma once

#include <CGAL/constructions/kernel_ftC3.h>

namespace pcl_ms {
namespace detail {

/// Whether the circumcentre construction of `cell` (CGAL's circumcenterC3,
/// behind Delaunay_triangulation_3::dual) would divide by zero. It runs the
/// same determinants on the same corners, so the answer is exact for that
/// construction. This happens when the corners lie many orders of magnitude
/// apart and the volume rounds to zero: CGAL then asserts where its
/// assertions are on, and returns a non-finite point where they are off.
template <typename CellHandle> bool hasNoCircumcentre(CellHandle cell) {
  const auto &p = cell->vertex(0)->point(), &q = cell->vertex(1)->point(),
             &r = cell->vertex(2)->point(), &s = cell->vertex(3)->point();
  double num_x, num_y, num_z, den;
  CGAL::determinants_for_circumcenterC3(p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), r.x(), r.y(),
                                        r.z(), s.x(), s.y(), s.z(), num_x, num_y, num_z, den);
  return den == 0;
}

} // namespace detail
} // namespace pcl_ms
