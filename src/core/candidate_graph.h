// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 3's candidate graph (docs/algorithm.md section 2, "Candidate graph").
// In: a scaffold, taken over from its builder. Out: each candidate's edges,
// edge ids by end points, and the candidates on each edge. The one owner of
// that graph: the scaffold's pass-1 edges, the edges numbered here for the
// type III candidates that reach pass 2, and the candidates that diagonal
// swaps bring in. Internal: not installed.
#pragma once

#include "edge_key.h"

#include <pcl_ms/scaffold.h>

#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace pcl_ms {
namespace detail {

class CandidateGraph {
public:
  explicit CandidateGraph(MedialScaffold &&scaffold) : scaffold_(std::move(scaffold)) {}

  /// The scaffold as built, except that the candidates numbered here carry
  /// their edge ids. Nothing else in it changes.
  const MedialScaffold &scaffold() const { return scaffold_; }
  const std::vector<Candidate> &candidates() const { return scaffold_.candidates; }

  /// The scaffold's edges and those numbered here, which follow them.
  std::size_t edgeCount() const { return scaffold_.numberOfEdges() + new_edges_.size(); }
  /// Whether candidate t has edge ids (every candidate but the type III ones
  /// not numbered yet).
  bool hasEdges(CandidateIndex t) const { return scaffold_.candidates[t].edges[0] != no_edge; }
  /// The edge joining a and b: the scaffold's, one numbered here, or no_edge.
  EdgeIndex findEdge(VertexIndex a, VertexIndex b) const;

  /// Visits the candidates on edge e, in ascending order within each group:
  /// the scaffold's (types I and II, fixed, preferred), the type III ones
  /// numbered for pass 2, then those brought in by swaps. Stops when visit
  /// returns true, and says whether it did.
  template <typename Visit> bool forEachCandidateOn(EdgeIndex e, const Visit &visit) const {
    if (e < scaffold_.numberOfEdges())
      for (const CandidateIndex *s = scaffold_.edgeBegin(e); s != scaffold_.edgeEnd(e); ++s)
        if (visit(*s))
          return true;
    if (e + std::size_t{1} < late_offsets_.size())
      for (std::uint32_t i = late_offsets_[e]; i < late_offsets_[e + 1]; ++i)
        if (visit(late_candidates_[i]))
          return true;
    if (!swapped_in_.empty()) {
      const auto found = swapped_in_.find(e);
      if (found != swapped_in_.end())
        for (CandidateIndex s : found->second)
          if (visit(s))
            return true;
    }
    return false;
  }

  /// Asks the processor for where the scaffold's lists of candidate t's
  /// edges start (step 1) or for the lists' first entries (step 2, once the
  /// starts are in cache). Inlined by force: GCC drops the calls to a
  /// function whose only effect is a prefetch.
  [[gnu::always_inline]] void prefetchListStarts(CandidateIndex t) const {
    for (EdgeIndex e : scaffold_.candidates[t].edges)
      if (e < scaffold_.numberOfEdges())
        __builtin_prefetch(&scaffold_.edge_offsets[e]);
  }
  [[gnu::always_inline]] void prefetchLists(CandidateIndex t) const {
    for (EdgeIndex e : scaffold_.candidates[t].edges)
      if (e < scaffold_.numberOfEdges())
        __builtin_prefetch(scaffold_.edgeBegin(e));
  }

  /// Numbers the edges of the members without edges (the type III ones in
  /// Q2) and lists them on those edges. Called once, when Q2 is built.
  void addLateCandidates(const std::vector<CandidateIndex> &members);

  /// Lists the candidates still without edges by lowest vertex, so that
  /// unnumberedWith can find them during the diagonal swaps.
  void listUnnumbered(std::size_t vertex_count);
  /// The unnumbered candidate with these corners (ascending), or
  /// no_candidate when there is none or no list was made.
  CandidateIndex unnumberedWith(const Triangle &vertices) const;
  void forgetUnnumbered() {
    unnumbered_offsets_ = {};
    unnumbered_ = {};
  }
  /// Numbers the edges of an unnumbered candidate that a swap brings into
  /// the mesh and lists it on them.
  void bringIn(CandidateIndex t);

private:
  void numberEdges(CandidateIndex t);

  MedialScaffold scaffold_;
  // Edges numbered here: their ids by end points, and who is on them.
  std::unordered_map<EdgeKey, EdgeIndex> new_edges_;
  std::vector<std::uint32_t> late_offsets_;
  std::vector<CandidateIndex> late_candidates_;
  std::unordered_map<EdgeIndex, std::vector<CandidateIndex>> swapped_in_;
  std::vector<std::uint32_t> unnumbered_offsets_; // by lowest vertex, during swaps
  std::vector<CandidateIndex> unnumbered_;
};

} // namespace detail
} // namespace pcl_ms
