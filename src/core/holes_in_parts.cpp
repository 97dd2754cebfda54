// SPDX-License-Identifier: GPL-3.0-or-later
// Hole filling over a triangle list held in parts (holes_in_parts.h;
// docs/algorithm.md, "Finishing in parts").
#include "holes_in_parts.h"

#include "finish_steps.h"
#include "numbering.h"
#include "points_from_homes.h"
#include "process_bytes.h"
#include "sort_unique.h"

#include <algorithm>
#include <iterator>
#include <stdexcept>
#include <utility>

namespace pcl_ms {
namespace detail {
namespace {

/// A point's position and local scale, on its way to process 0.
struct LoopPoint {
  double position[3];
  float scale;
};

/// The boundary of the list with `filling` appended, from the boundary
/// before (sorted) as addFilling() updates it: a boundary edge the filling
/// uses goes, a filling edge used once and not on the boundary comes.
std::vector<EdgeKey> boundaryWithFilling(const std::vector<EdgeKey> &boundary,
                                         const std::vector<Triangle> &filling) {
  std::vector<EdgeKey> uses;
  for (const Triangle &t : filling)
    for (int k = 0; k < 3; ++k)
      uses.push_back(edgeKey(t[k], t[(k + 1) % 3]));
  std::sort(uses.begin(), uses.end());
  std::vector<EdgeKey> used, opened;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j] == uses[i])
      ++j;
    used.push_back(uses[i]);
    if (j - i == 1 && !std::binary_search(boundary.begin(), boundary.end(), uses[i]))
      opened.push_back(uses[i]);
    i = j;
  }
  std::vector<EdgeKey> kept, merged;
  std::set_difference(boundary.begin(), boundary.end(), used.begin(), used.end(),
                      std::back_inserter(kept));
  std::merge(kept.begin(), kept.end(), opened.begin(), opened.end(), std::back_inserter(merged));
  return merged;
}

} // namespace

HolesPart fillHolesInParts(const std::vector<Triangle> &mine, const MeshEdgesPart &edges,
                           const std::vector<Eigen::Vector3d> &home_points,
                           const std::vector<float> &home_scales, std::uint64_t home_first,
                           int max_edges, double rho, const std::vector<VertexIndex> *around,
                           ProcessGroup &group) {
  const auto processes = static_cast<std::size_t>(group.processes());
  const bool on_zero = group.process() == 0;
  const std::vector<std::uint64_t> firsts =
      runFirsts(home_points.size(), home_first, group, "fillHolesInParts (points)");
  if (totalOver(home_scales.size() != home_points.size() ? 1 : 0, group) > 0)
    throw std::invalid_argument("fillHolesInParts: a slice's points and scales differ in number");

  // Process 0: every boundary edge and every marked vertex.
  std::vector<EdgeKey> boundary;
  gatherAtZero<EdgeKey>(
      edges.boundary.size(), [&](std::size_t e) { return edges.boundary[e]; },
      [&](std::size_t, EdgeKey key) { boundary.push_back(key); }, group);
  std::sort(boundary.begin(), boundary.end());
  const std::uint64_t any_around = totalOver(around ? 1 : 0, group);
  std::vector<VertexIndex> marked;
  if (any_around > 0) {
    const std::size_t mine_marked = around ? around->size() : 0;
    gatherAtZero<VertexIndex>(
        mine_marked, [&](std::size_t i) { return (*around)[i]; },
        [&](std::size_t, VertexIndex v) { marked.push_back(v); }, group);
    detail::sortUnique(marked);
  }

  // Process 0: the loops and those to fill; their vertices to everyone.
  HolesPart part;
  std::vector<std::vector<VertexIndex>> chosen;
  std::vector<VertexIndex> loop_vertices;
  if (on_zero) {
    part.loops = boundaryLoops(boundary);
    std::function<bool(VertexIndex)> isMarked;
    if (any_around > 0)
      isMarked = [&](VertexIndex v) { return std::binary_search(marked.begin(), marked.end(), v); };
    chosen = fillableLoops(part.loops, max_edges, isMarked);
    for (const std::vector<VertexIndex> &loop : chosen)
      loop_vertices.insert(loop_vertices.end(), loop.begin(), loop.end());
  }
  if (totalOver(loop_vertices.size(), group) == 0)
    return part;
  fromZeroToAll(loop_vertices, group);
  const Numbering<VertexIndex> on_loops(std::move(loop_vertices));

  // To process 0: the edges and triangles among those vertices, and the
  // vertices' points and scales, in the vertices' numbers: they keep the
  // vertices' order, so every order and key the filling compares is one
  // process's.
  std::vector<EdgeKey> mesh_edges;
  std::vector<Triangle> existing;
  {
    std::vector<EdgeKey> my_edges;
    std::vector<Triangle> my_triangles;
    edgesAndTrianglesAmong(
        mine, [&](VertexIndex v) { return on_loops.contains(v); }, my_edges, my_triangles);
    std::vector<std::vector<EdgeKey>> edges_out(processes);
    std::vector<std::vector<Triangle>> triangles_out(processes);
    for (EdgeKey key : my_edges)
      edges_out[0].push_back(edgeKey(on_loops(lowVertex(key)), on_loops(highVertex(key))));
    for (const Triangle &t : my_triangles)
      triangles_out[0].push_back({on_loops(t[0]), on_loops(t[1]), on_loops(t[2])});
    deliver(edges_out, group, [&](EdgeKey key) { mesh_edges.push_back(key); });
    deliver(triangles_out, group, [&](const Triangle &t) { existing.push_back(t); });
  }
  const std::vector<LoopPoint> loop_points = valuesFromHomes<LoopPoint>(
      on_zero ? on_loops.ids() : std::vector<VertexIndex>(), firsts, home_first,
      [&](std::size_t i) {
        return LoopPoint{{home_points[i].x(), home_points[i].y(), home_points[i].z()},
                         home_scales[i]};
      },
      group);

  // Process 0 fills the loops in its own numbers; the filling goes to the
  // last process in the list's numbers.
  std::vector<std::vector<Triangle>> filling_out(processes);
  if (on_zero) {
    detail::sortUnique(mesh_edges);
    detail::sortUnique(existing);
    std::vector<Eigen::Vector3d> points;
    std::vector<float> scales;
    points.reserve(loop_points.size());
    scales.reserve(loop_points.size());
    for (const LoopPoint &point : loop_points) {
      points.emplace_back(point.position[0], point.position[1], point.position[2]);
      scales.push_back(point.scale);
    }
    for (std::vector<VertexIndex> &loop : chosen)
      for (VertexIndex &v : loop)
        v = on_loops(v);
    std::vector<Triangle> filling;
    part.filled = fillChosenLoops(chosen, points, SideLimit{&scales, rho}, std::move(mesh_edges),
                                  existing, filling);
    for (Triangle &t : filling)
      for (VertexIndex &v : t)
        v = on_loops.id(v);
    part.loops = boundaryLoops(boundaryWithFilling(boundary, filling));
    filling_out[processes - 1] = std::move(filling);
  }
  deliver(filling_out, group, [&](const Triangle &t) { part.filling.push_back(t); });
  part.filled = totalOver(part.filled, group);
  return part;
}

} // namespace detail
} // namespace pcl_ms
