// SPDX-License-Identifier: GPL-3.0-or-later
// The pipeline of stages 2 and 3 (docs/algorithm.md, "Code layout"). In:
// distinct points, the scaffold's options and the parameters. Out: the
// greedy's triangles, the local scale and the two stages' figures.
#include <pcl_ms/mesh_points.h>

#include <chrono>
#include <utility>

namespace pcl_ms {

MeshedPoints meshPoints(const std::vector<Eigen::Vector3d> &points, const ScaffoldOptions &options,
                        const Parameters &parameters, const Deadline *deadline,
                        bool with_fixed_triangles,
                        const std::function<void(const MedialScaffold &)> &scaffold_built) {
  using Clock = std::chrono::steady_clock;
  const auto secondsSince = [](Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  MeshedPoints meshed;
  const Clock::time_point start = Clock::now();
  MedialScaffold scaffold = buildMedialScaffold(points, options);
  meshed.delaunay_seconds = scaffold.delaunay_seconds;
  meshed.scaffold_seconds = secondsSince(start) - scaffold.delaunay_seconds;
  if (scaffold_built)
    scaffold_built(scaffold);

  meshed.d_med = scaffold.d_med;
  meshed.local_scale = std::move(scaffold.local_scale); // the greedy does not read it
  const Clock::time_point greedy_start = Clock::now();
  GreedyMesher mesher(std::move(scaffold), points, parameters, deadline);
  mesher.run();
  meshed.triangles = mesher.triangles(with_fixed_triangles);
  meshed.seam_triangles = mesher.seamTriangles();
  meshed.greedy = mesher.statistics();
  meshed.greedy_seconds = secondsSince(greedy_start);
  return meshed;
}

} // namespace pcl_ms
