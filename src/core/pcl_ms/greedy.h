// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 3: greedy gap transforms (paper §3; docs/algorithm.md section 3). Candidates
// are accepted cheapest first under 2-manifold rules; accepted neighbours
// change the costs; conflicts undo costlier earlier choices.
#pragma once

#include <pcl_ms/deadline.h>
#include <pcl_ms/mesh_topology.h>
#include <pcl_ms/scaffold.h>
#include <pcl_ms/types.h>

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace pcl_ms {

struct GreedyStatistics {
  PassStatistics pass1, pass2;
  /// Flaps and isolated triangles undone between the passes, plus triangles
  /// undone by the final manifold sweep.
  std::size_t cleanup_undone = 0;
  /// Pairs of triangles replaced by the other diagonal's pair.
  std::size_t swapped_pairs = 0;
  /// Triangles the seam pass accepted (Parameters::allow_non_manifold).
  std::size_t seam_triangles = 0;
};

class GreedyMesher {
public:
  /// The mesher takes the scaffold over: its candidate graph
  /// (candidate_graph.h) owns it and numbers the edges of the type III
  /// candidates that reach pass 2. The points and parameters must outlive
  /// the mesher. With a deadline, run() throws TimeLimitExceeded once it
  /// has passed.
  GreedyMesher(MedialScaffold &&scaffold, const std::vector<Eigen::Vector3d> &points,
               const Parameters &parameters, const Deadline *deadline = nullptr);
  ~GreedyMesher();
  GreedyMesher(const GreedyMesher &) = delete;
  GreedyMesher &operator=(const GreedyMesher &) = delete;

  /// Pass 1 (types I, II), clean-up, pass 2 (type III and demoted), then
  /// the final sweep that guarantees a 2-manifold result; then, with
  /// Parameters::allow_non_manifold, the seam pass (seamTriangles). The scaffold's
  /// fixed triangles are in the mesh from the start and never undone.
  void run();

  /// Accepted triangles as distinct-point indices, in candidate order;
  /// without the scaffold's fixed triangles when `with_fixed` is false.
  std::vector<Triangle> triangles(bool with_fixed = true) const;
  /// With Parameters::allow_non_manifold, the triangles of the seam pass
  /// and the mesh's triangles on seam edges (docs/algorithm.md, "Seams
  /// (opt-in)"), kept apart from triangles(): the 2-manifold rest is
  /// finished first and these join it afterwards.
  std::vector<Triangle> seamTriangles() const;
  const GreedyStatistics &statistics() const { return statistics_; }

private:
  class Impl;
  std::unique_ptr<Impl> impl_;
  GreedyStatistics statistics_;
};

} // namespace pcl_ms
