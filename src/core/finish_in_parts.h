// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4, finishing, for a triangle list held in parts by the processes of
// a ProcessGroup (docs/algorithm.md, "Finishing in parts"): the steps in
// parts chained as finishSurface() chains one process's.
// Internal to the library: not installed.
#pragma once

#include <pcl_ms/process_group.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl_ms {
namespace detail {

/// What finishInParts() leaves each process.
struct FinishedPart {
  /// The process's run of the finished list, from whole-list number `first`
  /// on (fillings join the last process's run).
  std::vector<Triangle> triangles;
  std::uint64_t first = 0;
  /// Per triangle of the run: the whole-list number of its component's
  /// first triangle, and 1 where that component is orientable (finishSurface()
  /// numbers the components in the order of their first triangles).
  std::vector<std::uint64_t> component;
  std::vector<std::uint8_t> orientable;
  /// On process 0: the boundary loops, as finishSurface() traces them.
  std::vector<std::vector<VertexIndex>> boundary_loops;
  /// On every process: the whole list's figures.
  std::uint64_t holes_filled = 0;
  std::uint64_t twist_triangles_removed = 0;
};

/// Collective. `mine` is this process's run of the greedy's triangles, from
/// whole-list number `first` on (the runs follow each other in process
/// order); `home_points` and `home_scales` its slice of the points and
/// their local scales, from point `home_first` on. The same triangles, in
/// the same order and turned alike, the same loops and figures as
/// finishSurface() without fixed triangles, for any split.
FinishedPart finishInParts(const std::vector<Triangle> &mine, std::uint64_t first,
                           const std::vector<Eigen::Vector3d> &home_points,
                           const std::vector<float> &home_scales, std::uint64_t home_first,
                           int fill_holes_max_edges, double rho, const Eigen::Vector3d *viewpoint,
                           ProcessGroup &group);

} // namespace detail
} // namespace pcl_ms
