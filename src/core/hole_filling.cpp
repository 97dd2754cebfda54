// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4, hole filling (docs/algorithm.md section 4, "Holes"). In: a
// triangle list, its boundary loops and the points. Out: the list with the
// small simple loops closed by minimum-cost triangulations that put no third
// triangle on an edge.
#include "finish_steps.h"
#include "huge_page_allocator.h"

#include <pcl_ms/costs.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <functional>
#include <limits>
#include <set>

namespace pcl_ms {
namespace detail {
namespace {

// Holes of at most this many edges are filled without the size limit.
constexpr std::size_t max_unlimited_loop_edges = 4;

/// Minimum-cost triangulation of one boundary loop, or nothing. With
/// delaunay_only, its triangles are facets of the loop's own Delaunay
/// triangulation, which keeps the filling from folding; a noisy loop that
/// twists in 3-D often has no such triangulation.
std::vector<Triangle> triangulateLoop(const std::vector<VertexIndex> &loop,
                                      const std::vector<Eigen::Vector3d> &points,
                                      const std::vector<EdgeKey> &mesh_edges,
                                      const SideLimit &limit, bool delaunay_only) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<std::size_t, Kernel>;
  using DataStructure = CGAL::Triangulation_data_structure_3<VertexBase>;
  using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, DataStructure>;

  const std::size_t m = loop.size();
  // A loop is one hole: like a triangle against its largest corner scale,
  // its filling is held to the largest scale on its rim.
  float rim_scale = 0;
  for (VertexIndex v : loop)
    rim_scale = std::max(rim_scale, (*limit.point_scale)[v]);
  const double max_side = limit.rho * rim_scale;
  std::set<std::array<std::size_t, 3>> allowed;
  if (delaunay_only) {
    std::vector<std::pair<Kernel::Point_3, std::size_t>> input;
    for (std::size_t i = 0; i < m; ++i) {
      const Eigen::Vector3d &p = points[loop[i]];
      input.emplace_back(Kernel::Point_3(p.x(), p.y(), p.z()), i);
    }
    const Delaunay delaunay(input.begin(), input.end());
    if (delaunay.dimension() < 2)
      return {};
    for (auto facet = delaunay.finite_facets_begin(); facet != delaunay.finite_facets_end();
         ++facet) {
      std::array<std::size_t, 3> corners;
      for (int k = 0; k < 3; ++k)
        corners[k] = facet->first->vertex((facet->second + 1 + k) & 3)->info();
      if (delaunay.dimension() == 2)
        corners = {facet->first->vertex(0)->info(), facet->first->vertex(1)->info(),
                   facet->first->vertex(2)->info()};
      std::sort(corners.begin(), corners.end());
      allowed.insert(corners);
    }
  }
  auto isMeshEdge = [&](std::size_t i, std::size_t j) {
    return std::binary_search(mesh_edges.begin(), mesh_edges.end(), edgeKey(loop[i], loop[j]));
  };
  // Classic polygon DP: best[i][j] triangulates loop[i..j] above chord (i, j).
  const double infinity = std::numeric_limits<double>::infinity();
  std::vector<std::vector<double>> best(m, std::vector<double>(m, infinity));
  std::vector<std::vector<std::size_t>> split(m, std::vector<std::size_t>(m, 0));
  for (std::size_t i = 0; i + 1 < m; ++i)
    best[i][i + 1] = 0;
  for (std::size_t span = 2; span < m; ++span)
    for (std::size_t i = 0; i + span < m; ++i) {
      const std::size_t j = i + span;
      // A chord that is not a loop edge must be new, or the hole's filling
      // would put a third triangle on an existing edge.
      if (!(i == 0 && j == m - 1) && isMeshEdge(i, j))
        continue;
      for (std::size_t k = i + 1; k < j; ++k) {
        if (best[i][k] == infinity || best[k][j] == infinity ||
            (delaunay_only && !allowed.count({i, k, j})))
          continue;
        const TriangleShape shape =
            triangleShape(points[loop[i]], points[loop[k]], points[loop[j]]);
        // A hole of three or four edges takes its triangles whatever their
        // size (a missing triangle or quad between the greedy's triangles,
        // whose new sides are at most two of its edges long); larger loops
        // keep the greedy's size limit, or fillings would reach across
        // concave spots.
        if (shape.compactness <= 0 ||
            (m > max_unlimited_loop_edges && shape.longest_side >= max_side))
          continue;
        const double cost =
            best[i][k] + best[k][j] + shape.perimeter / (shape.compactness * shape.compactness);
        if (cost < best[i][j]) {
          best[i][j] = cost;
          split[i][j] = k;
        }
      }
    }
  if (best[0][m - 1] == infinity)
    return {};
  std::vector<Triangle> filling;
  std::vector<std::pair<std::size_t, std::size_t>> stack = {{0, m - 1}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (j < i + 2)
      continue;
    const std::size_t k = split[i][j];
    filling.push_back({loop[i], loop[k], loop[j]});
    stack.push_back({i, k});
    stack.push_back({k, j});
  }
  return filling;
}

} // namespace

std::vector<std::vector<VertexIndex>>
fillableLoops(std::vector<std::vector<VertexIndex>> loops, int max_edges,
              const std::function<bool(VertexIndex)> &around) {
  // Only simple loops: a vertex met twice is a pinch the polygon DP cannot
  // fill; with `around`, only loops that reach the marked vertices.
  loops.erase(std::remove_if(loops.begin(), loops.end(),
                             [&](const std::vector<VertexIndex> &loop) {
                               if (loop.size() < 3 ||
                                   loop.size() > static_cast<std::size_t>(std::max(max_edges, 0)))
                                 return true;
                               std::vector<VertexIndex> sorted = loop;
                               std::sort(sorted.begin(), sorted.end());
                               if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
                                 return true;
                               return around && std::none_of(loop.begin(), loop.end(), around);
                             }),
              loops.end());
  return loops;
}

std::size_t fillChosenLoops(const std::vector<std::vector<VertexIndex>> &loops,
                            const std::vector<Eigen::Vector3d> &points, const SideLimit &limit,
                            std::vector<EdgeKey> mesh_edges, const std::vector<Triangle> &existing,
                            std::vector<Triangle> &added) {
  std::size_t filled = 0;
  for (const auto &loop : loops) {
    // Any triangles where the loop's Delaunay facets cannot fill it: the
    // size limit still holds, and a fold the filling makes is repaired with
    // the others. Kinect frames kept a quarter of their loops without this
    // (office1.pcd: 691 loops, now 599).
    std::vector<Triangle> filling = triangulateLoop(loop, points, mesh_edges, limit, true);
    if (filling.empty())
      filling = triangulateLoop(loop, points, mesh_edges, limit, false);
    bool duplicates_existing = false;
    for (Triangle t : filling) {
      std::sort(t.begin(), t.end());
      duplicates_existing |= std::binary_search(existing.begin(), existing.end(), t);
    }
    if (filling.empty() || duplicates_existing)
      continue;
    for (const Triangle &t : filling)
      for (int k = 0; k < 3; ++k) {
        const EdgeKey key = edgeKey(t[k], t[(k + 1) % 3]);
        mesh_edges.insert(std::lower_bound(mesh_edges.begin(), mesh_edges.end(), key), key);
      }
    added.insert(added.end(), filling.begin(), filling.end());
    ++filled;
  }
  return filled;
}

std::size_t fillLoops(const std::vector<Triangle> &triangles,
                      std::vector<std::vector<VertexIndex>> loops,
                      const std::vector<Eigen::Vector3d> &points, int max_edges,
                      const SideLimit &limit, const std::vector<bool> *only_around,
                      std::vector<Triangle> &added) {
  std::function<bool(VertexIndex)> around;
  if (only_around)
    around = [only_around](VertexIndex v) { return bool((*only_around)[v]); };
  loops = fillableLoops(std::move(loops), max_edges, around);
  if (loops.empty())
    return 0;
  // Existing edges and triangles matter only where all their corners are
  // on a loop that may be filled: that keeps these lists short.
  std::vector<bool> on_loop(points.size(), false);
  for (const auto &loop : loops)
    for (VertexIndex v : loop)
      on_loop[v] = true;
  std::vector<EdgeKey> mesh_edges;
  std::vector<Triangle> existing;
  edgesAndTrianglesAmong(
      triangles, [&](VertexIndex v) { return bool(on_loop[v]); }, mesh_edges, existing);
  return fillChosenLoops(loops, points, limit, std::move(mesh_edges), existing, added);
}

} // namespace detail
} // namespace pcl_ms
