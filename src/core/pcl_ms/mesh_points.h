// SPDX-License-Identifier: GPL-3.0-or-later
// Stages 2 and 3 on one set of distinct points: the one pipeline that the
// one-piece path (reconstruct.cpp) and every bucket and seam zone
// (buckets.cpp) run (docs/algorithm.md, "Code layout").
#pragma once

#include <pcl_ms/deadline.h>
#include <pcl_ms/greedy.h>
#include <pcl_ms/scaffold.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <functional>
#include <vector>

namespace pcl_ms {

struct MeshedPoints {
  /// The greedy's triangles in distinct-point indices (GreedyMesher::triangles).
  std::vector<Triangle> triangles;
  /// GreedyMesher::seamTriangles (empty unless Parameters::allow_non_manifold).
  std::vector<Triangle> seam_triangles;
  /// The scaffold's local scale per point, and its d_med.
  std::vector<float> local_scale;
  double d_med = 0;
  GreedyStatistics greedy;
  double delaunay_seconds = 0, scaffold_seconds = 0, greedy_seconds = 0;
};

/// Builds the medial scaffold of `points` and runs the greedy passes on it.
/// `scaffold_built`, when given, is called between the two stages (to read
/// the scaffold's figures, check a deadline or record memory).
/// `with_fixed_triangles`: whether the result lists the scaffold's fixed
/// triangles too. Throws what the stages throw.
MeshedPoints meshPoints(const std::vector<Eigen::Vector3d> &points, const ScaffoldOptions &options,
                        const Parameters &parameters, const Deadline *deadline,
                        bool with_fixed_triangles,
                        const std::function<void(const MedialScaffold &)> &scaffold_built = {});

} // namespace pcl_ms
