// SPDX-License-Identifier: GPL-3.0-or-later
// The growing mesh that stage 3 edits (docs/algorithm.md section 3). In:
// triangle insertions and removals. Out: per-edge and per-vertex counts and
// the manifold checks the greedy asks about.
#include <pcl_ms/mesh_topology.h>

#include <algorithm>
#include <cassert>
#include <stdexcept>
#include <string>

namespace pcl_ms {

MeshTopology::MeshTopology(const MedialScaffold &scaffold, std::size_t vertex_count)
    : scaffold_(scaffold), edge_slots_(scaffold.numberOfEdges(), {no_candidate, no_candidate}),
      vertex_triangles_(vertex_count), vertex_counts_(vertex_count),
      in_mesh_(scaffold.candidates.size(), false) {}

void MeshTopology::notACorner(CandidateIndex t, VertexIndex v) {
  throw std::logic_error("MeshTopology::edgesAt: vertex " + std::to_string(v) +
                         " is not a corner of candidate " + std::to_string(t));
}

void MeshTopology::add(CandidateIndex t) {
  assert(t < in_mesh_.size() && !in_mesh_[t]);
  const Candidate &candidate = scaffold_.candidates[t];
  for (int k = 0; k < 3; ++k) {
    // Edges numbered after construction must have been made room for.
    assert(candidate.edges[k] < edge_slots_.size() && "growEdges after the graph numbered edges");
    auto &slots = edge_slots_[candidate.edges[k]];
    // A removal may leave an edge's one triangle in either slot.
    assert((slots[0] == no_candidate || slots[1] == no_candidate) &&
           "the 2-manifold edge rule: a third triangle on an edge");
    const int before = (slots[0] != no_candidate) + (slots[1] != no_candidate);
    (slots[0] == no_candidate ? slots[0] : slots[1]) = t;
    // An edge with one triangle is a boundary edge of both its vertices.
    const int delta = before == 0 ? 1 : -1;
    vertex_counts_[candidate.vertices[k]].boundary_edges += delta;
    vertex_counts_[candidate.vertices[(k + 1) % 3]].boundary_edges += delta;
  }
  for (VertexIndex v : candidate.vertices) {
    vertex_triangles_[v].push_back(t);
    ++vertex_counts_[v].triangles;
  }
  in_mesh_[t] = true;
  ++triangle_count_;
}

void MeshTopology::remove(CandidateIndex t) {
  assert(t < in_mesh_.size() && in_mesh_[t]);
  const Candidate &candidate = scaffold_.candidates[t];
  for (int k = 0; k < 3; ++k) {
    auto &slots = edge_slots_[candidate.edges[k]];
    assert((slots[0] == t || slots[1] == t) && "a mesh triangle missing from its edge");
    (slots[0] == t ? slots[0] : slots[1]) = no_candidate;
    const int after = (slots[0] != no_candidate) + (slots[1] != no_candidate);
    const int delta = after == 0 ? -1 : 1;
    vertex_counts_[candidate.vertices[k]].boundary_edges += delta;
    vertex_counts_[candidate.vertices[(k + 1) % 3]].boundary_edges += delta;
  }
  for (VertexIndex v : candidate.vertices) {
    auto &list = vertex_triangles_[v];
    list.erase(std::find(list.begin(), list.end(), t));
    --vertex_counts_[v].triangles;
  }
  in_mesh_[t] = false;
  --triangle_count_;
}

std::vector<std::vector<CandidateIndex>> MeshTopology::fansAround(VertexIndex v) const {
  std::vector<CandidateIndex> triangles(vertex_triangles_[v].begin(), vertex_triangles_[v].end());
  std::sort(triangles.begin(), triangles.end());
  // Triangles at v are joined through the edges they share at v.
  const auto groups = connectedGroups(triangles.size(), [&](const auto &join) {
    for (std::size_t i = 0; i < triangles.size(); ++i)
      for (EdgeIndex e : edgesAt(triangles[i], v)) {
        const CandidateIndex other = otherTriangle(e, triangles[i]);
        if (other != no_candidate)
          join(i, std::lower_bound(triangles.begin(), triangles.end(), other) - triangles.begin());
      }
  });
  std::vector<std::vector<CandidateIndex>> fans(groups.size());
  for (std::size_t f = 0; f < groups.size(); ++f)
    for (std::size_t i : groups[f])
      fans[f].push_back(triangles[i]);
  return fans;
}

bool MeshTopology::isSingleFan(VertexIndex v) const {
  int inner_triangles = 0;
  return isSingleFan(v, inner_triangles);
}

bool MeshTopology::isSingleFan(VertexIndex v, int &inner_triangles) const {
  const VertexTriangles &around = vertex_triangles_[v];
  inner_triangles = 0;
  if (around.empty())
    return true;
  // More than two boundary edges: at least two fans that are not rings. Most
  // of the greedy's marked vertices are such; no walk for them
  // (docs/algorithm.md, section 3).
  if (vertex_counts_[v].boundary_edges > 2)
    return false;
  // With at most two triangles per edge, the triangles at v chained through
  // their edges at v form paths and cycles: walk both ways from the first.
  const CandidateIndex start = around[0];
  const auto start_edges = edgesAt(start, v);
  inner_triangles = isInner(start_edges);
  std::size_t reached = 1;
  for (EdgeIndex first_edge : start_edges) {
    CandidateIndex current = start;
    EdgeIndex through = first_edge;
    for (;;) {
      const CandidateIndex next = otherTriangle(through, current);
      if (next == no_candidate)
        break;
      if (next == start) // a closed fan: walking the other way finds nothing new
        return reached == around.size();
      ++reached;
      const auto edges = edgesAt(next, v);
      inner_triangles += isInner(edges);
      through = edges[0] == through ? edges[1] : edges[0];
      current = next;
    }
  }
  return reached == around.size();
}

bool MeshTopology::hasClosedFan(VertexIndex v) const {
  return std::any_of(vertex_triangles_[v].begin(), vertex_triangles_[v].end(),
                     [&](CandidateIndex start) { return isInClosedFan(start, v); });
}

bool MeshTopology::isInClosedFan(CandidateIndex t, VertexIndex v) const {
  // Inner triangles link to two others at v: a walk from one returns to it
  // exactly when its fan is a ring of inner triangles.
  if (!isInnerAt(t, v))
    return false;
  CandidateIndex current = t;
  EdgeIndex through = edgesAt(t, v)[0];
  for (;;) {
    const CandidateIndex next = otherTriangle(through, current);
    if (next == t)
      return true;
    if (!isInnerAt(next, v))
      return false;
    const auto edges = edgesAt(next, v);
    through = edges[0] == through ? edges[1] : edges[0];
    current = next;
  }
}

} // namespace pcl_ms
