// SPDX-License-Identifier: GPL-3.0-or-later
// For stage 3: the growing surface mesh over the scaffold's candidates, with the
// per-edge and per-vertex counts the manifold rules ask about in O(1).
#pragma once

#include <pcl_ms/disjoint_sets.h>
#include <pcl_ms/scaffold.h>

#include <boost/container/small_vector.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace pcl_ms {

/// Groups items 0..count-1 into connected sets by union-find; joins(join)
/// calls join(i, j) for every pair known to be connected. Groups come in
/// order of their smallest item, each ascending. Used to split the few
/// triangles around a vertex into fans.
template <typename Joins>
std::vector<std::vector<std::size_t>> connectedGroups(std::size_t count, const Joins &joins) {
  detail::DisjointSets sets(count);
  joins([&](std::size_t i, std::size_t j) { sets.union_set(i, j); });
  std::vector<std::vector<std::size_t>> groups;
  std::vector<std::size_t> group_of_root(count, count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t root = sets.find_set(i);
    if (group_of_root[root] == count) {
      group_of_root[root] = groups.size();
      groups.emplace_back();
    }
    groups[group_of_root[root]].push_back(i);
  }
  return groups;
}

class MeshTopology {
public:
  MeshTopology(const MedialScaffold &scaffold, std::size_t vertex_count);

  /// Adds an accepted triangle. Precondition: each of its edges has fewer
  /// than two triangles (the 2-manifold edge rule).
  void add(CandidateIndex t);
  /// Makes room for edges numbered after construction (ids below edge_count).
  void growEdges(std::size_t edge_count) {
    if (edge_count > edge_slots_.size())
      edge_slots_.resize(edge_count, {no_candidate, no_candidate});
  }
  void remove(CandidateIndex t);
  bool contains(CandidateIndex t) const { return in_mesh_[t]; }

  int edgeTriangleCount(EdgeIndex e) const {
    return (edge_slots_[e][0] != no_candidate) + (edge_slots_[e][1] != no_candidate);
  }
  /// The accepted triangles on edge e (no_candidate for empty slots).
  const std::array<CandidateIndex, 2> &edgeTriangles(EdgeIndex e) const { return edge_slots_[e]; }
  /// The other accepted triangle on edge e, or no_candidate.
  CandidateIndex otherTriangle(EdgeIndex e, CandidateIndex t) const {
    return edge_slots_[e][0] == t ? edge_slots_[e][1] : edge_slots_[e][0];
  }

  /// A vertex of a surface mesh has six triangles on average: up to eight
  /// are kept inline, so the greedy's many small updates allocate nothing.
  using VertexTriangles = boost::container::small_vector<CandidateIndex, 8>;

  const VertexTriangles &vertexTriangles(VertexIndex v) const { return vertex_triangles_[v]; }
  /// Accepted triangles at v.
  std::size_t vertexTriangleCount(VertexIndex v) const { return vertex_counts_[v].triangles; }
  /// Edges at v with exactly one triangle.
  int vertexBoundaryEdges(VertexIndex v) const {
    return static_cast<int>(vertex_counts_[v].boundary_edges);
  }
  /// A vertex whose triangles close around it: nothing more may be added.
  bool isClosedVertex(VertexIndex v) const {
    return vertex_counts_[v].triangles > 0 && vertex_counts_[v].boundary_edges == 0;
  }

  /// The triangles at v grouped into fans (connected through edges at v),
  /// each fan in ascending triangle order, fans ordered by first triangle.
  std::vector<std::vector<CandidateIndex>> fansAround(VertexIndex v) const;
  /// Whether v's triangles (if any) form one fan: fansAround(v).size() <= 1,
  /// found by walking the fan without building it, or without a walk where
  /// v has more than two boundary edges: each fan that is not a ring has
  /// two, so there are several.
  bool isSingleFan(VertexIndex v) const;
  /// The same; when it returns true the walk has seen every triangle at v,
  /// and `inner_triangles` counts those inside the fan (isInnerAt).
  bool isSingleFan(VertexIndex v, int &inner_triangles) const;
  /// Whether one of v's fans is closed (a ring of inner triangles, see
  /// isInnerAt), found by walking without building the fans.
  bool hasClosedFan(VertexIndex v) const;
  /// Whether t lies in a closed fan of v: one walk from t.
  bool isInClosedFan(CandidateIndex t, VertexIndex v) const;
  /// Whether both of t's edges at v hold two triangles: t is inside v's
  /// fan, not at its rim.
  bool isInnerAt(CandidateIndex t, VertexIndex v) const { return isInner(edgesAt(t, v)); }

  /// The two edges of candidate t that contain vertex v; std::logic_error
  /// when v is not a corner of t. Inline: the greedy's rules ask it on
  /// every decision.
  std::array<EdgeIndex, 2> edgesAt(CandidateIndex t, VertexIndex v) const {
    const Candidate &candidate = scaffold_.candidates[t];
    // edges[k] joins vertices[k] and vertices[k + 1]: vertex k lies on edges k and k - 1.
    for (int k = 0; k < 3; ++k)
      if (candidate.vertices[k] == v)
        return {candidate.edges[k], candidate.edges[(k + 2) % 3]};
    notACorner(t, v);
  }

  std::size_t size() const { return triangle_count_; }

  /// Asks the processor for what the edge and vertex rules read of
  /// candidate t's edges and corners, so that those cache misses overlap
  /// other work (t's own record should be in cache already).
  /// Inlined by force: GCC takes a function that only prefetches for one
  /// without effects (const) and drops the calls.
  [[gnu::always_inline]] void prefetchAround(CandidateIndex t) const {
    const Candidate &candidate = scaffold_.candidates[t];
    for (EdgeIndex e : candidate.edges)
      if (e < edge_slots_.size()) // not no_edge
        __builtin_prefetch(&edge_slots_[e]);
    for (VertexIndex v : candidate.vertices)
      __builtin_prefetch(&vertex_counts_[v]);
  }

private:
  /// Whether both edges of a triangle at a vertex hold two triangles.
  bool isInner(const std::array<EdgeIndex, 2> &edges_at_vertex) const {
    return edgeTriangleCount(edges_at_vertex[0]) == 2 && edgeTriangleCount(edges_at_vertex[1]) == 2;
  }

  /// Callers walk the triangles around v; anything else is a broken
  /// invariant, which must stop the run rather than quietly use some edge.
  [[noreturn]] static void notACorner(CandidateIndex t, VertexIndex v);

  const MedialScaffold &scaffold_;
  std::vector<std::array<CandidateIndex, 2>> edge_slots_;
  std::vector<VertexTriangles> vertex_triangles_;
  // What the vertex rules ask of every candidate, apart from the triangle
  // lists: eight bytes a vertex stay in cache far better than the lists.
  struct VertexCounts {
    std::uint32_t boundary_edges = 0;
    std::uint32_t triangles = 0;
  };
  std::vector<VertexCounts> vertex_counts_;
  std::vector<bool> in_mesh_;
  std::size_t triangle_count_ = 0;
};

} // namespace pcl_ms
