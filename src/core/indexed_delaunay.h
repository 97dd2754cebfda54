// SPDX-License-Identifier: GPL-3.0-or-later
// The 3-D Delaunay triangulation the core reads its scaffolds from: CGAL's
// exact predicates, each vertex holding its point's index and each cell a
// number of its own. Internal to the library: not installed.
#pragma once

#include <pcl_ms/types.h>

#include "huge_page_allocator.h"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <cstdint>

namespace pcl_ms {
namespace detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using KernelPoint = Kernel::Point_3;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<VertexIndex, Kernel>;
using CellBase =
    CGAL::Triangulation_cell_base_with_info_3<std::uint32_t, Kernel,
                                              CGAL::Delaunay_triangulation_cell_base_3<Kernel>>;
using DataStructure = CGAL::Triangulation_data_structure_3<VertexBase, CellBase>;
using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, DataStructure>;
using CellHandle = Delaunay::Cell_handle;
using VertexHandle = Delaunay::Vertex_handle;

} // namespace detail
} // namespace pcl_ms
