// SPDX-License-Identifier: GPL-3.0-or-later
// The circumcentre of a Delaunay cell, and the cells that CGAL's exact
// predicates accept but whose circumcentre cannot be constructed in double.
// Internal to the library: not installed.
#pragma once

#include "corner_order.h"

#include <array>

#include <CGAL/constructions/kernel_ftC3.h>

namespace pcl_ms {
namespace detail {

/// The circumcentre of `cell`'s corners taken in ascending index order,
/// computed as CGAL's circumcenterC3 (behind Delaunay_triangulation_3::dual)
/// computes it from corners in that order, with its determinants computed
/// once; false where that construction would divide by zero. That happens
/// when the corners lie many orders of magnitude apart and the volume rounds
/// to zero: CGAL then asserts where its assertions are on, and returns a
/// non-finite point where they are off.
template <typename CellHandle> bool circumcentre(CellHandle cell, double centre[3]) {
  // The same centre, bit for bit, whatever order the triangulation stores
  // the corners in.
  const auto corners =
      byIndex(std::array{cell->vertex(0), cell->vertex(1), cell->vertex(2), cell->vertex(3)});
  const auto &p = corners[0]->point(), &q = corners[1]->point(), &r = corners[2]->point(),
             &s = corners[3]->point();
  double num_x, num_y, num_z, den;
  CGAL::determinants_for_circumcenterC3(p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), r.x(), r.y(),
                                        r.z(), s.x(), s.y(), s.z(), num_x, num_y, num_z, den);
  if (den == 0)
    return false;
  const double inverse = 1.0 / (2.0 * den);
  centre[0] = p.x() + num_x * inverse;
  centre[1] = p.y() - num_y * inverse;
  centre[2] = p.z() + num_z * inverse;
  return true;
}

} // namespace detail
} // namespace pcl_ms
