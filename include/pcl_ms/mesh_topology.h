// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 3: the growing surface mesh over the scaffold's candidates, with the
// per-edge and per-vertex counts the manifold rules ask about in O(1).
#pragma once

#include <pcl_ms/scaffold.h>

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace pcl_ms {

constexpr CandidateIndex no_candidate = std::numeric_limits<CandidateIndex>::max();

class MeshTopology {
public:
  MeshTopology(const MedialScaffold &scaffold, std::size_t vertex_count);

  /// Adds an accepted triangle. Precondition: each of its edges has fewer
  /// than two triangles (the 2-manifold edge rule).
  void add(CandidateIndex t);
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

  const std::vector<CandidateIndex> &vertexTriangles(VertexIndex v) const {
    return vertex_triangles_[v];
  }
  /// Edges at v with exactly one triangle.
  int vertexBoundaryEdges(VertexIndex v) const { return vertex_boundary_edges_[v]; }
  /// A vertex whose triangles close around it: nothing more may be added.
  bool isClosedVertex(VertexIndex v) const {
    return !vertex_triangles_[v].empty() && vertex_boundary_edges_[v] == 0;
  }

  /// The triangles at v grouped into fans (connected through edges at v),
  /// each fan in ascending triangle order, fans ordered by first triangle.
  std::vector<std::vector<CandidateIndex>> fansAround(VertexIndex v) const;

  /// The two edges of candidate t that contain vertex v.
  std::array<EdgeIndex, 2> edgesAt(CandidateIndex t, VertexIndex v) const;

  std::size_t size() const { return triangle_count_; }
  const MedialScaffold &scaffold() const { return scaffold_; }

private:
  const MedialScaffold &scaffold_;
  std::vector<std::array<CandidateIndex, 2>> edge_slots_;
  std::vector<std::vector<CandidateIndex>> vertex_triangles_;
  std::vector<std::uint16_t> vertex_boundary_edges_;
  std::vector<bool> in_mesh_;
  std::size_t triangle_count_ = 0;
};

} // namespace pcl_ms
