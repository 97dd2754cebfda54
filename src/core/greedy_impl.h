// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 3's state (docs/algorithm.md sections 3, 4a). In: the scaffold's
// candidates, the points, the parameters. Out: GreedyMesher::Impl, defined in
// greedy.cpp (passes), greedy_repair.cpp (diagonal swaps, manifold sweep) and
// greedy_seams.cpp (seam detection, seam pass). Internal: not installed.
#pragma once

#include "candidate_graph.h"
#include "candidate_queue.h"

#include <pcl_ms/costs.h>
#include <pcl_ms/greedy.h>

#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace pcl_ms {
namespace detail {

/// Where a candidate is: not queued, waiting in Q1 or Q2, in the mesh, or
/// out for good.
enum class GreedyState : std::uint8_t { idle, queue1, queue2, accepted, dropped };

/// A likely seam edge: its axis (unit, from its lower to its higher end),
/// a frame across it, and the directions of its sheets in that frame.
struct SeamAxis {
  VertexIndex low = 0, high = 0;
  Eigen::Vector3d axis, across1, across2;
  std::vector<double> sheets; // angles in [-pi, pi], in cyclic order
  std::vector<float> costs;   // while detecting: each group's cheapest candidate
};

} // namespace detail

class GreedyMesher::Impl {
public:
  Impl(MedialScaffold &&scaffold, const std::vector<Eigen::Vector3d> &points,
       const Parameters &parameters, const Deadline *deadline, GreedyStatistics &statistics);

  void run();
  std::vector<Triangle> seamTriangles() const;
  std::vector<Triangle> triangles(bool with_fixed) const;

private:
  using State = detail::GreedyState;
  using SeamAxis = detail::SeamAxis;
  using QueueEntry = detail::QueueEntry;
  using CandidateQueue = detail::CandidateQueue;

  // ---- the passes (greedy.cpp) ---------------------------------------------

  void acceptFixedTriangles();
  void rankPreferredTriangles();
  void runPass(State queue_state, PassStatistics &statistics);

  // ---- costs (greedy.cpp) --------------------------------------------------

  double rankingBaseCost(CandidateIndex t) const {
    return preferred_ranked_ && is_preferred_[t] ? 0.0 : candidates_[t].base_cost;
  }

  double freshCost(CandidateIndex t) const {
    const double undelayed = std::max(0.0, rankingBaseCost(t) + states_[t].context);
    return undelayed * delay_multiplier_[states_[t].incidence_delays + states_[t].ranking_delays];
  }

  /// The context an accepted triangle gives across one of its edges: what
  /// depends on that edge alone, computed once for all its candidates.
  class ContextAcross {
  public:
    ContextAcross(const Impl &greedy, CandidateIndex from, int k)
        : greedy_(greedy), p_(greedy.candidates_[from].vertices[k]),
          q_(greedy.candidates_[from].vertices[(k + 1) % 3]),
          edge_length_((greedy.points_[q_] - greedy.points_[p_]).norm()),
          bending_(greedy.points_[p_], greedy.points_[q_],
                   greedy.points_[greedy.candidates_[from].vertices[(k + 2) % 3]]) {}
    /// eps2 it adds to candidate `to`, on the same edge.
    double termFor(CandidateIndex to) const { return termFor(to, greedy_.apexOf(to, p_, q_)); }
    /// The same, given the candidate's vertex off the edge.
    double termFor(CandidateIndex to, VertexIndex apex) const {
      return contextCost(edge_length_, greedy_.candidates_[to].inverse_shock_compactness,
                         bending_.angleTo(greedy_.points_[apex]));
    }

  private:
    const Impl &greedy_;
    VertexIndex p_, q_;
    double edge_length_;
    BendingAcrossEdge bending_;
  };

  double contextTerm(CandidateIndex from, int k, CandidateIndex to) const;
  void propagateContext(CandidateIndex t, double sign);
  double contextFromScratch(CandidateIndex t) const;
  void refreshCost(CandidateIndex t);

  // ---- queues (greedy.cpp) -------------------------------------------------

  bool isWaitingForQueue2(CandidateIndex t) const {
    return !queue2_built_ && states_[t].state == State::queue2;
  }

  bool isQueued(CandidateIndex t) const {
    return states_[t].state == State::queue1 || states_[t].state == State::queue2;
  }
  int queueNumber(State state) const { return state == State::queue1 ? 0 : 1; }

  /// Whether `entry` is its candidate's one live entry in `queue`; the
  /// others are outdated and skipped.
  bool isLive(const QueueEntry &entry, State queue) const {
    const CandidateState &state = states_[entry.candidate()];
    return state.state == queue && state.queued_cost == entry.cost();
  }

  /// How a candidate comes to be queued: a delayed one's cost rises with
  /// the pass (CandidateQueue::pushDelayed).
  enum class Arrival { ordinary, delayed };
  void enqueue(CandidateIndex t, State queue, Arrival arrival = Arrival::ordinary);
  void push(CandidateIndex t, State queue, Arrival arrival = Arrival::ordinary);
  void buildQueue2(PassStatistics &statistics);

  // ---- the candidate graph (candidate_graph.h) -----------------------------

  template <typename Visit> bool forEachCandidateOn(EdgeIndex e, const Visit &visit) const {
    return graph_.forEachCandidateOn(e, visit);
  }
  bool hasEdges(CandidateIndex t) const { return graph_.hasEdges(t); }
  std::size_t edgeCount() const { return graph_.edgeCount(); }
  EdgeIndex findEdge(VertexIndex a, VertexIndex b) const { return graph_.findEdge(a, b); }

  VertexIndex apexOf(CandidateIndex t, VertexIndex a, VertexIndex c) const {
    for (VertexIndex v : candidates_[t].vertices)
      if (v != a && v != c)
        return v;
    return a;
  }

  // ---- decisions and undo (greedy.cpp) -------------------------------------

  bool touchesClosedVertex(CandidateIndex t) const {
    for (VertexIndex v : candidates_[t].vertices)
      if (mesh_.isClosedVertex(v))
        return true;
    return false;
  }

  bool hasFullEdge(CandidateIndex t) const {
    for (EdgeIndex e : candidates_[t].edges)
      if (mesh_.edgeTriangleCount(e) >= 2)
        return true;
    return false;
  }

  void undoCostlierOnFullEdges(CandidateIndex t, PassStatistics &statistics);
  void decide(CandidateIndex t, State from, PassStatistics &statistics);
  void delay(CandidateIndex t, State from, PassStatistics &statistics);
  bool closeCompetitorDelayed(CandidateIndex t, State queue);
  void accept(CandidateIndex t, bool created_second_fan);
  /// Where keepClosedFanOnly looks for a ring that closed since the last
  /// check at the vertex.
  enum class RingSearch { none, through_accepted, all_triangles };
  void keepClosedFanOnly(VertexIndex v, RingSearch search, CandidateIndex accepted);
  void removeFromMesh(CandidateIndex t);
  void undo(CandidateIndex t);
  void removeFlapsAndIsolatedTriangles();

  // ---- after pass 2: diagonal swaps, manifold sweep (greedy_repair.cpp) ----

  EdgeIndex edgeBetween(CandidateIndex t, VertexIndex a, VertexIndex b) const;
  CandidateIndex candidateWith(EdgeIndex e, VertexIndex a, VertexIndex b, VertexIndex apex) const;
  bool oppositeAnglesExceedPi(VertexIndex b, VertexIndex d, VertexIndex a, VertexIndex c) const;
  void swapNonDelaunayDiagonals();
  void enforceManifoldVertices();
  std::size_t fixedCount(const std::vector<CandidateIndex> &fan) const;
  std::size_t preferredCount(const std::vector<CandidateIndex> &fan) const;
  double fanCost(const std::vector<CandidateIndex> &fan) const;

  // ---- seams, opt-in (greedy_seams.cpp) ------------------------------------

  double angleAround(const SeamAxis &seam, VertexIndex v, VertexIndex p) const;
  void detectSeams();
  void keepSeamChains(const std::vector<EdgeIndex> &found);
  bool bridgesSeam(CandidateIndex t) const;

  /// Calls visit(u) for every triangle on edge e: the mesh's, then the seam
  /// pass's, which are kept outside MeshTopology (it holds two per edge).
  template <typename Visit> void forEachOccupant(EdgeIndex e, const Visit &visit) const {
    for (CandidateIndex u : mesh_.edgeTriangles(e))
      if (u != no_candidate)
        visit(u);
    const auto found = seam_on_edge_.find(e);
    if (found != seam_on_edge_.end())
      for (CandidateIndex u : found->second)
        visit(u);
  }

  std::size_t edgeUses(EdgeIndex e) const {
    const auto found = seam_on_edge_.find(e);
    return static_cast<std::size_t>(mesh_.edgeTriangleCount(e)) +
           (found == seam_on_edge_.end() ? 0 : found->second.size());
  }

  enum class SeamFit { none, seam, filler };

  SeamFit seamFit(CandidateIndex t) const;
  double longestSide(CandidateIndex t) const;
  double longestOnEdge(EdgeIndex e) const;
  bool continuesSheetAt(CandidateIndex t, VertexIndex v) const;
  float seamCost(CandidateIndex t) const;
  void runSeamPass();
  void setSeamFansApart();

  // ---- state ---------------------------------------------------------------

  detail::CandidateGraph graph_; // owns the scaffold from here on
  const MedialScaffold &scaffold_;
  const std::vector<Candidate> &candidates_;
  const std::vector<Eigen::Vector3d> &points_;
  const Parameters &parameters_;
  const Deadline *deadline_; // null: no time limit
  GreedyStatistics &statistics_;
  MeshTopology mesh_;

  // Everything the greedy keeps per candidate, in one record: candidates
  // are visited in cost order, i.e. all over memory, so one cache line each.
  struct CandidateState {
    double context = 0; // sum of eps2 from accepted neighbours
    float cost = 0;     // current cost: (base + context) clamped at 0, times delays
    // The cost of its live queue entry, at most `cost`: a rise waits until
    // that entry surfaces (docs/algorithm.md, section 3).
    float queued_cost = 0;
    State state = State::idle;
    std::uint8_t incidence_delays = 0, ranking_delays = 0, undos = 0;
  };
  std::vector<CandidateState> states_;
  std::vector<bool> is_fixed_;
  std::vector<bool> is_preferred_;
  bool preferred_ranked_ = false; // from then on preferred base costs are 0
  std::vector<bool> multi_fan_vertex_;
  std::vector<bool> may_have_several_fans_;
  std::vector<double> delay_multiplier_;
  // The candidates on an accepted triangle's edges and their apexes, listed
  // by propagateContext before it computes any (kept to spare allocations).
  struct Neighbour {
    CandidateIndex candidate;
    VertexIndex apex;
  };
  std::vector<Neighbour> neighbours_;
  // Seam pass: its triangles in order, per edge, and flags.
  std::vector<CandidateIndex> seam_list_;
  std::unordered_map<EdgeIndex, std::vector<CandidateIndex>> seam_on_edge_;
  std::vector<bool> is_seam_;
  // Mesh triangles on seam edges, handed over with the seam triangles.
  std::vector<CandidateIndex> set_apart_;
  std::vector<bool> is_set_apart_;
  // Seam detection: likely seam edges, those at each vertex, and the
  // candidates that bridge two sheets (all empty unless seams were found).
  std::unordered_map<EdgeIndex, SeamAxis> seam_axes_;
  std::unordered_map<VertexIndex, std::vector<EdgeIndex>> seams_at_;
  std::vector<bool> bridges_seam_;
  CandidateQueue queues_[2];       // Q1, Q2
  std::size_t queued_[2] = {0, 0}; // candidates whose state is that queue
  bool queue2_built_ = false;
  std::uint32_t deadline_counter_ = 0;
};

} // namespace pcl_ms
