// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 4, finishing (docs/algorithm.md section 4). In: the greedy's
// triangles and the points. Out: a FinishedSurface: small holes filled, folds
// cut, bow-ties split, components oriented, boundary loops traced. The steps
// are in hole_filling.cpp, orientation.cpp, bow_ties.cpp; this file drives them.
#include "finish_steps.h"

#include <algorithm>

namespace pcl_ms {
namespace detail {

EdgeUses edgeUses(const std::vector<Triangle> &triangles) {
  VertexIndex vertex_count = 0;
  for (const Triangle &triangle : triangles)
    for (VertexIndex v : triangle)
      vertex_count = std::max(vertex_count, v + 1);
  EdgeUses result;
  std::vector<std::uint32_t> &offsets = result.offsets;
  offsets.assign(static_cast<std::size_t>(vertex_count) + 1, 0);
  for (const Triangle &triangle : triangles)
    for (int k = 0; k < 3; ++k)
      ++offsets[lowVertex(edgeKey(triangle[k], triangle[(k + 1) % 3])) + 1];
  for (std::size_t v = 0; v < vertex_count; ++v)
    offsets[v + 1] += offsets[v];
  result.uses.resize(3 * triangles.size());
  std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const EdgeKey key = edgeKey(triangles[t][k], triangles[t][(k + 1) % 3]);
      result.uses[cursor[lowVertex(key)]++] = {highVertex(key), t};
    }
  forEachIndex(vertex_count, [&](std::size_t v) {
    std::sort(result.uses.begin() + offsets[v], result.uses.begin() + offsets[v + 1]);
  });
  return result;
}

std::vector<std::vector<VertexIndex>> boundaryLoops(const EdgeUses &uses) {
  // Boundary edges in both directions, sorted: a CSR of boundary neighbours.
  struct HalfEdge {
    VertexIndex from, to;
    std::uint32_t edge;
    bool operator<(const HalfEdge &other) const {
      return from < other.from || (from == other.from && to < other.to);
    }
  };
  std::vector<HalfEdge> half_edges;
  std::uint32_t boundary_edges = 0;
  forEachEdge(uses, [&](EdgeKey key, std::size_t, std::size_t count) {
    if (count != 1)
      return;
    half_edges.push_back({lowVertex(key), highVertex(key), boundary_edges});
    half_edges.push_back({highVertex(key), lowVertex(key), boundary_edges});
    ++boundary_edges;
  });
  std::sort(half_edges.begin(), half_edges.end());
  std::vector<bool> used(boundary_edges, false);
  auto nextFrom = [&](VertexIndex v) -> const HalfEdge * {
    HalfEdge probe{v, 0, 0};
    for (auto it = std::lower_bound(half_edges.begin(), half_edges.end(), probe);
         it != half_edges.end() && it->from == v; ++it)
      if (!used[it->edge])
        return &*it;
    return nullptr;
  };
  std::vector<std::vector<VertexIndex>> loops;
  // Half-edges are sorted by start vertex, so each loop is met first at its
  // smallest vertex.
  for (const HalfEdge &start : half_edges) {
    if (used[start.edge] || start.from > start.to)
      continue;
    std::vector<VertexIndex> loop = {start.from};
    used[start.edge] = true;
    VertexIndex current = start.to;
    while (current != start.from) {
      loop.push_back(current);
      const HalfEdge *next = nextFrom(current);
      if (!next)
        break;
      used[next->edge] = true;
      current = next->to;
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

std::vector<ManifoldPair> manifoldPairs(const EdgeUses &uses) {
  std::size_t count_of_pairs = 0;
  forEachEdge(uses, [&](EdgeKey, std::size_t, std::size_t count) { count_of_pairs += count == 2; });
  std::vector<ManifoldPair> pairs;
  pairs.reserve(count_of_pairs);
  forEachEdge(uses, [&](EdgeKey key, std::size_t first, std::size_t count) {
    if (count == 2)
      pairs.push_back({uses.uses[first].triangle, uses.uses[first + 1].triangle, lowVertex(key),
                       highVertex(key)});
  });
  return pairs;
}

} // namespace detail

namespace {

// Twists are cut and the opened loops refilled at most this many times.
constexpr int max_untwist_rounds = 3;
// Loops opened by cutting twists are closed again up to this size.
constexpr int max_untwist_loop_edges = 16;

} // namespace

std::vector<std::vector<VertexIndex>> traceBoundaryLoops(const std::vector<Triangle> &triangles) {
  return detail::boundaryLoops(detail::edgeUses(triangles));
}

FinishedSurface finishSurface(std::vector<Triangle> triangles,
                              const std::vector<Eigen::Vector3d> &points, int fill_holes_max_edges,
                              const SideLimit &limit, const std::vector<bool> *anchored_vertices,
                              const Eigen::Vector3d *viewpoint) {
  FinishedSurface surface;
  // Edge uses are built once per set of triangles. Orienting keeps the set,
  // so the boundary loops are traced before it and the uses freed: the
  // orientation's own arrays are as large.
  auto fillThenOrient = [&](int max_edges, const std::vector<bool> *only_around) {
    detail::EdgeUses uses = detail::edgeUses(triangles);
    surface.boundary_loops = detail::boundaryLoops(uses);
    const std::size_t filled =
        detail::fillLoops(triangles, surface.boundary_loops, points, max_edges, limit, only_around);
    if (filled > 0) {
      uses = detail::edgeUses(triangles);
      surface.boundary_loops = detail::boundaryLoops(uses);
    }
    surface.holes_filled += filled;
    const std::vector<detail::ManifoldPair> pairs = detail::manifoldPairs(uses);
    uses = detail::EdgeUses();
    return detail::orientPairs(triangles, pairs, points, surface.triangle_component,
                               surface.component_orientable, viewpoint);
  };
  std::vector<std::uint32_t> to_cut = fillThenOrient(fill_holes_max_edges, nullptr);
  for (int round = 0; round < max_untwist_rounds && !to_cut.empty(); ++round) {
    // Only the triangles at the inconsistent edges go, never whole fans:
    // cutting the most crumpled corner's fan at sharp folds split sparse
    // scans and the camel head apart (car6: 80 pieces instead of 52).
    std::vector<bool> drop(triangles.size(), false);
    for (std::uint32_t t : to_cut)
      drop[t] = !anchored_vertices ||
                std::none_of(triangles[t].begin(), triangles[t].end(),
                             [&](VertexIndex v) { return (*anchored_vertices)[v]; });
    const std::size_t before = triangles.size();
    std::vector<bool> touched(points.size(), false);
    detail::dropTriangles(triangles, drop, touched);
    splitBowTies(triangles, points.size(), touched);
    surface.twist_triangles_removed += before - triangles.size();
    // The loops that removal opened are ours to close, whatever the user's limit.
    to_cut = fillThenOrient(max_untwist_loop_edges, &touched);
  }
  surface.triangles = std::move(triangles);
  return surface;
}

} // namespace pcl_ms
