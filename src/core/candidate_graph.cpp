// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 3's candidate graph (docs/algorithm.md section 2, "Candidate graph"):
// the edges numbered after the scaffold was built. In: type III candidates
// that reach pass 2 or a diagonal swap. Out: their edge ids and their places
// on the edges' lists.
#include "candidate_graph.h"

#include <algorithm>
#include <numeric>

namespace pcl_ms {
namespace detail {

EdgeIndex CandidateGraph::findEdge(VertexIndex a, VertexIndex b) const {
  const EdgeIndex e = scaffold_.findEdge(a, b);
  if (e != no_edge || new_edges_.empty())
    return e;
  const auto found = new_edges_.find(edgeKey(a, b));
  return found == new_edges_.end() ? no_edge : found->second;
}

/// Gives candidate t the ids of its edges, numbering the edges that no
/// pass-1 candidate has.
void CandidateGraph::numberEdges(CandidateIndex t) {
  Candidate &candidate = scaffold_.candidates[t];
  for (int k = 0; k < 3; ++k) {
    const VertexIndex a = candidate.vertices[k], b = candidate.vertices[(k + 1) % 3];
    EdgeIndex e = findEdge(a, b);
    if (e == no_edge) {
      e = static_cast<EdgeIndex>(edgeCount());
      new_edges_.emplace(edgeKey(a, b), e);
    }
    candidate.edges[k] = e;
  }
}

void CandidateGraph::addLateCandidates(const std::vector<CandidateIndex> &members) {
  std::vector<CandidateIndex> late;
  for (CandidateIndex t : members)
    if (!hasEdges(t)) {
      numberEdges(t);
      late.push_back(t);
    }
  // Listed per edge as the scaffold lists the pass-1 candidates (CSR).
  late_offsets_.assign(edgeCount() + 1, 0);
  for (CandidateIndex t : late)
    for (EdgeIndex e : scaffold_.candidates[t].edges)
      ++late_offsets_[e + 1];
  std::partial_sum(late_offsets_.begin(), late_offsets_.end(), late_offsets_.begin());
  late_candidates_.resize(late_offsets_.back());
  std::vector<std::uint32_t> cursor(late_offsets_.begin(), late_offsets_.end() - 1);
  for (CandidateIndex t : late)
    for (EdgeIndex e : scaffold_.candidates[t].edges)
      late_candidates_[cursor[e]++] = t;
}

void CandidateGraph::listUnnumbered(std::size_t vertex_count) {
  const std::vector<Candidate> &candidates = scaffold_.candidates;
  unnumbered_offsets_.assign(vertex_count + 1, 0);
  for (CandidateIndex t = 0; t < candidates.size(); ++t)
    if (!hasEdges(t))
      ++unnumbered_offsets_[candidates[t].vertices[0] + 1];
  std::partial_sum(unnumbered_offsets_.begin(), unnumbered_offsets_.end(),
                   unnumbered_offsets_.begin());
  unnumbered_.resize(unnumbered_offsets_.back());
  std::vector<std::uint32_t> cursor(unnumbered_offsets_.begin(), unnumbered_offsets_.end() - 1);
  for (CandidateIndex t = 0; t < candidates.size(); ++t)
    if (!hasEdges(t))
      unnumbered_[cursor[candidates[t].vertices[0]]++] = t;
}

CandidateIndex CandidateGraph::unnumberedWith(const Triangle &vertices) const {
  if (unnumbered_offsets_.empty())
    return no_candidate;
  for (std::uint32_t i = unnumbered_offsets_[vertices[0]]; i < unnumbered_offsets_[vertices[0] + 1];
       ++i)
    if (scaffold_.candidates[unnumbered_[i]].vertices == vertices)
      return unnumbered_[i];
  return no_candidate;
}

void CandidateGraph::bringIn(CandidateIndex t) {
  numberEdges(t);
  for (EdgeIndex e : scaffold_.candidates[t].edges)
    swapped_in_[e].push_back(t);
}

} // namespace detail
} // namespace pcl_ms
