// SPDX-License-Identifier: GPL-3.0-or-later
// The 3-D Delaunay triangulation the core reads its scaffolds from: CGAL's
// exact predicates, each vertex holding its point's index and each cell a
// number of its own. Internal to the library: not installed.
#pragma once

#include <pcl_ms/types.h>

#include "huge_page_allocator.h"
#include "populate_pages.h"

#include <CGAL/Bbox_3.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Spatial_lock_grid_3.h>
#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>
#include <Eigen/Core>
#include <boost/range/irange.hpp>

#include <cstdint>
#include <iterator>
#include <utility>
#include <vector>

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
using IndexedPoint = std::pair<KernelPoint, VertexIndex>;

/// The same triangulation built by CGAL's parallel insertion, as its
/// documentation sets it up: concurrent containers and a grid of locks over
/// the points' bounding box. The grid does not block: a thread that meets a
/// locked cell gives its point back and retries it later, where a blocking
/// one would wait on a lock holder that the machine may have descheduled.
using ParallelDataStructure =
    CGAL::Triangulation_data_structure_3<VertexBase, CellBase, CGAL::Parallel_tag>;
using LockGrid = CGAL::Spatial_lock_grid_3<CGAL::Tag_non_blocking>;
using ParallelDelaunay =
    CGAL::Delaunay_triangulation_3<Kernel, ParallelDataStructure, CGAL::Default, LockGrid>;
/// Cells per axis of the lock grid: the value of CGAL's examples.
inline constexpr int lock_grid_cells_per_axis = 50;

/// The smallest box holding every point: what the lock grid covers.
inline CGAL::Bbox_3 boundingBox(const std::vector<Eigen::Vector3d> &points) {
  CGAL::Bbox_3 box;
  for (const Eigen::Vector3d &point : points)
    box += CGAL::Bbox_3(point.x(), point.y(), point.z(), point.x(), point.y(), point.z());
  return box;
}

/// A triangulation for CGAL's parallel insertion together with the lock grid
/// over the points' bounding box that it needs and must not outlive.
struct ParallelTriangulation {
  explicit ParallelTriangulation(const std::vector<Eigen::Vector3d> &points)
      : locks(boundingBox(points), lock_grid_cells_per_axis), delaunay(&locks) {}
  ParallelTriangulation(const ParallelTriangulation &) = delete;
  ParallelTriangulation &operator=(const ParallelTriangulation &) = delete;

  /// Inserts `input` with CGAL's range insertion, which sorts indices into a
  /// copy of the points spatially and shares them among the threads of the
  /// calling task arena (withThreads).
  void insert(const std::vector<IndexedPoint> &input) {
    delaunay.insert(input.begin(), input.end());
  }

  LockGrid locks; // declared first: built before the triangulation, freed after it
  ParallelDelaunay delaunay;
};

/// (points[i], i) for every i of `chosen` (any range of indices), in that
/// order: insertIndexed's input.
template <typename Indices>
std::vector<IndexedPoint> indexedPoints(const std::vector<Eigen::Vector3d> &points,
                                        const Indices &chosen) {
  std::vector<IndexedPoint> input;
  input.reserve(static_cast<std::size_t>(std::distance(std::begin(chosen), std::end(chosen))));
  populateCapacity(input);
  for (VertexIndex i : chosen)
    input.emplace_back(KernelPoint(points[i].x(), points[i].y(), points[i].z()), i);
  return input;
}

/// (points[i], i) for every point.
inline std::vector<IndexedPoint> indexedPoints(const std::vector<Eigen::Vector3d> &points) {
  return indexedPoints(points,
                       boost::irange<VertexIndex>(0, static_cast<VertexIndex>(points.size())));
}

/// Inserts the points of `input`, each vertex holding its index, in the
/// order CGAL's range insertion uses: its spatial sort, applied to the pairs
/// themselves. CGAL's own insertion of pairs sorts indices into a copy of the
/// points instead, whose scattered reads made the triangulation 4-7 % slower
/// than one of bare points; the sort moves the same positions either way, so
/// the triangulation is the same (docs/algorithm.md, "The triangulation's
/// insertion").
/// Reorders `input`.
inline void insertIndexed(Delaunay &delaunay, std::vector<IndexedPoint> &input) {
  using SortTraits =
      CGAL::Spatial_sort_traits_adapter_3<Kernel, CGAL::First_of_pair_property_map<IndexedPoint>>;
  CGAL::spatial_sort(input.begin(), input.end(), SortTraits());
  VertexHandle hint;
  for (const auto &[point, index] : input) {
    hint = delaunay.insert(point, hint);
    if (hint != VertexHandle())
      hint->info() = index;
  }
}

} // namespace detail
} // namespace pcl_ms
