// SPDX-License-Identifier: GPL-3.0-or-later
#include <pcl_ms/mesh_topology.h>

#include <algorithm>
#include <numeric>

namespace pcl_ms {

MeshTopology::MeshTopology(const MedialScaffold &scaffold, std::size_t vertex_count)
    : scaffold_(scaffold), edge_slots_(scaffold.numberOfEdges(), {no_candidate, no_candidate}),
      vertex_triangles_(vertex_count), vertex_boundary_edges_(vertex_count, 0),
      in_mesh_(scaffold.candidates.size(), false) {}

std::array<EdgeIndex, 2> MeshTopology::edgesAt(CandidateIndex t, VertexIndex v) const {
  const Candidate &candidate = scaffold_.candidates[t];
  // edges[k] joins vertices[k] and vertices[k + 1]: vertex k lies on edges k and k - 1.
  for (int k = 0; k < 3; ++k)
    if (candidate.vertices[k] == v)
      return {candidate.edges[k], candidate.edges[(k + 2) % 3]};
  return {0, 0};
}

void MeshTopology::add(CandidateIndex t) {
  const Candidate &candidate = scaffold_.candidates[t];
  for (int k = 0; k < 3; ++k) {
    auto &slots = edge_slots_[candidate.edges[k]];
    const int before = (slots[0] != no_candidate) + (slots[1] != no_candidate);
    (slots[0] == no_candidate ? slots[0] : slots[1]) = t;
    // An edge with one triangle is a boundary edge of both its vertices.
    const int delta = before == 0 ? 1 : -1;
    vertex_boundary_edges_[candidate.vertices[k]] += delta;
    vertex_boundary_edges_[candidate.vertices[(k + 1) % 3]] += delta;
  }
  for (VertexIndex v : candidate.vertices)
    vertex_triangles_[v].push_back(t);
  in_mesh_[t] = true;
  ++triangle_count_;
}

void MeshTopology::remove(CandidateIndex t) {
  const Candidate &candidate = scaffold_.candidates[t];
  for (int k = 0; k < 3; ++k) {
    auto &slots = edge_slots_[candidate.edges[k]];
    (slots[0] == t ? slots[0] : slots[1]) = no_candidate;
    const int after = (slots[0] != no_candidate) + (slots[1] != no_candidate);
    const int delta = after == 0 ? -1 : 1;
    vertex_boundary_edges_[candidate.vertices[k]] += delta;
    vertex_boundary_edges_[candidate.vertices[(k + 1) % 3]] += delta;
  }
  for (VertexIndex v : candidate.vertices) {
    auto &list = vertex_triangles_[v];
    list.erase(std::find(list.begin(), list.end(), t));
  }
  in_mesh_[t] = false;
  --triangle_count_;
}

std::vector<std::vector<CandidateIndex>> MeshTopology::fansAround(VertexIndex v) const {
  std::vector<CandidateIndex> triangles = vertex_triangles_[v];
  std::sort(triangles.begin(), triangles.end());
  const std::size_t count = triangles.size();
  // Union-find over the few triangles at v, joined through shared edges at v.
  std::vector<std::size_t> parent(count);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::size_t i) {
    while (parent[i] != i)
      i = parent[i] = parent[parent[i]];
    return i;
  };
  for (std::size_t i = 0; i < count; ++i)
    for (EdgeIndex e : edgesAt(triangles[i], v)) {
      const CandidateIndex other = otherTriangle(e, triangles[i]);
      if (other == no_candidate)
        continue;
      const std::size_t j =
          std::lower_bound(triangles.begin(), triangles.end(), other) - triangles.begin();
      parent[find(i)] = find(j);
    }
  std::vector<std::vector<CandidateIndex>> fans;
  std::vector<std::size_t> fan_of_root(count, count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t root = find(i);
    if (fan_of_root[root] == count) {
      fan_of_root[root] = fans.size();
      fans.emplace_back();
    }
    fans[fan_of_root[root]].push_back(triangles[i]);
  }
  return fans;
}

} // namespace pcl_ms
