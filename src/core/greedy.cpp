// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 3, greedy gap transforms (docs/algorithm.md section 3). In: the
// scaffold's candidates and the points. Out: an edge-manifold triangle list,
// accepted cheapest first, with the passes' statistics. Here the passes; the
// repairs after them in greedy_repair.cpp, opt-in seams in greedy_seams.cpp.
#include "greedy_impl.h"
#include "populate_pages.h"

#include <pcl_ms/costs.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

namespace pcl_ms {
namespace {

// How far along the sorted run the pass fetches candidates ahead of use.
constexpr std::size_t queue_prefetch_distance = 16;

// Outdated entries may grow the heap to twice the queued candidates plus
// this before it is compacted.
constexpr std::size_t compaction_slack = 1 << 16;

// An undone triangle is re-queued at most this often, so that two candidates
// whose costs keep crossing cannot undo each other forever.
constexpr std::uint8_t max_undos = 3;

} // namespace

GreedyMesher::Impl::Impl(MedialScaffold &&scaffold, const std::vector<Eigen::Vector3d> &points,
                         const Parameters &parameters, const Deadline *deadline,
                         GreedyStatistics &statistics)
    : graph_(std::move(scaffold)), scaffold_(graph_.scaffold()), candidates_(graph_.candidates()),
      points_(points), parameters_(parameters), deadline_(deadline), statistics_(statistics),
      mesh_(scaffold_, points.size()), is_fixed_(candidates_.size(), false),
      is_preferred_(candidates_.size(), false), multi_fan_vertex_(points.size(), false),
      may_have_several_fans_(points.size(), false) {
  detail::resizeForWriting(states_, candidates_.size());
  for (CandidateIndex t : scaffold_.fixed)
    is_fixed_[t] = true;
  for (CandidateIndex t : scaffold_.preferred)
    is_preferred_[t] = !is_fixed_[t];
  delay_multiplier_.resize(2 * static_cast<std::size_t>(parameters.max_delays) + 1);
  for (std::size_t k = 0; k < delay_multiplier_.size(); ++k)
    delay_multiplier_[k] = std::pow(parameters.delay_factor, static_cast<double>(k));
}

void GreedyMesher::Impl::run() {
  acceptFixedTriangles();
  rankPreferredTriangles();
  if (parameters_.allow_non_manifold)
    detectSeams();
  for (CandidateIndex t = 0; t < candidates_.size(); ++t) {
    if (is_fixed_[t] || states_[t].state != State::idle || mesh_.contains(t))
      continue;
    if (!bridges_seam_.empty() && bridges_seam_[t]) {
      states_[t].state = State::dropped;
      continue;
    }
    states_[t].cost = static_cast<float>(freshCost(t));
    push(t, candidates_[t].type == CandidateType::ambiguous && !is_preferred_[t] ? State::queue2
                                                                                 : State::queue1);
  }
  runPass(State::queue1, statistics_.pass1);
  removeFlapsAndIsolatedTriangles();
  buildQueue2(statistics_.pass2);
  runPass(State::queue2, statistics_.pass2);
  swapNonDelaunayDiagonals();
  enforceManifoldVertices();
  if (parameters_.allow_non_manifold) {
    runSeamPass();
    setSeamFansApart();
  }
}

std::vector<Triangle> GreedyMesher::Impl::seamTriangles() const {
  std::vector<Triangle> result;
  result.reserve(seam_list_.size() + set_apart_.size());
  for (CandidateIndex t : seam_list_)
    result.push_back(candidates_[t].vertices);
  for (CandidateIndex t : set_apart_)
    result.push_back(candidates_[t].vertices);
  return result;
}

std::vector<Triangle> GreedyMesher::Impl::triangles(bool with_fixed) const {
  std::vector<Triangle> result;
  result.reserve(mesh_.size());
  for (CandidateIndex t = 0; t < candidates_.size(); ++t)
    if (mesh_.contains(t) && (with_fixed || !is_fixed_[t]) &&
        (is_set_apart_.empty() || !is_set_apart_[t]))
      result.push_back(candidates_[t].vertices);
  return result;
}

/// Fixed triangles are in the surface before anything is ranked, so their
/// context counts from the start; nothing ever undoes them. A triangle
/// that would overfill an edge is left out (callers pass edge-manifold sets).
void GreedyMesher::Impl::acceptFixedTriangles() {
  for (CandidateIndex t : scaffold_.fixed) {
    if (mesh_.contains(t) || hasFullEdge(t)) {
      is_fixed_[t] = mesh_.contains(t);
      continue;
    }
    mesh_.add(t);
    states_[t].state = State::accepted;
    propagateContext(t, +1.0);
    // Fixed pieces may meet at a vertex without forming one fan yet.
    for (VertexIndex v : candidates_[t].vertices)
      may_have_several_fans_[v] = true;
  }
}

/// Preferred triangles (docs/algorithm.md, "Initial triangles") go first,
/// alone in Q1, in four rounds: those whose three edges the soup agrees on
/// (each shared with exactly one other preferred triangle), then two, one,
/// none; within a round by their own costs. A wrong triangle overlapping
/// right ones puts a third triangle on their edges, so it comes after them
/// and finds its edges full. From then on the base cost of the accepted
/// ones is 0: an ordinary candidate undoes one only where its context (how
/// sharply it bends against its accepted neighbours) makes it costlier.
/// Those not accepted in these rounds are ordinary candidates.
void GreedyMesher::Impl::rankPreferredTriangles() {
  if (scaffold_.preferred.empty())
    return;
  // How many preferred triangles each edge has: an edge with exactly two is
  // one the soup agrees on.
  std::vector<std::uint8_t> on_edge(scaffold_.numberOfEdges(), 0);
  for (CandidateIndex t : scaffold_.preferred)
    if (is_preferred_[t])
      for (EdgeIndex e : candidates_[t].edges)
        on_edge[e] = static_cast<std::uint8_t>(std::min(on_edge[e] + 1, 3));
  std::vector<CandidateIndex> tiers[4];
  for (CandidateIndex t : scaffold_.preferred) {
    if (!is_preferred_[t])
      continue;
    int agreed = 0;
    for (EdgeIndex e : candidates_[t].edges)
      agreed += on_edge[e] == 2;
    tiers[3 - agreed].push_back(t);
  }
  for (const auto &tier : tiers) {
    for (CandidateIndex t : tier) {
      states_[t].cost = static_cast<float>(freshCost(t));
      push(t, State::queue1);
    }
    runPass(State::queue1, statistics_.pass1);
  }
  preferred_ranked_ = true;
  for (CandidateIndex t : scaffold_.preferred) {
    if (states_[t].state != State::accepted) {
      is_preferred_[t] = false;
      continue;
    }
    states_[t].cost = static_cast<float>(freshCost(t));
  }
}

/// eps2 that accepted triangle `from` adds to candidate `to` across edge
/// slot k of `from`.
double GreedyMesher::Impl::contextTerm(CandidateIndex from, int k, CandidateIndex to) const {
  return ContextAcross(*this, from, k).termFor(to);
}

/// Adds (sign +1) or removes (sign -1) accepted triangle t's context from
/// every candidate sharing one of its edges, accepted ones included: their
/// current cost is what error recovery compares against.
void GreedyMesher::Impl::propagateContext(CandidateIndex t, double sign) {
  // The neighbours' records and apexes lie all over memory: listing them and
  // fetching each as it is listed, before any is computed, overlaps their
  // cache misses (docs/algorithm.md, section 3).
  const Candidate &accepted = candidates_[t];
  std::array<std::size_t, 4> first_on_edge{};
  neighbours_.clear();
  for (int k = 0; k < 3; ++k) {
    first_on_edge[k] = neighbours_.size();
    forEachCandidateOn(accepted.edges[k], [&](CandidateIndex s) {
      if (s != t) {
        __builtin_prefetch(&states_[s]);
        __builtin_prefetch(&candidates_[s]);
        neighbours_.push_back({s, 0});
      }
      return false;
    });
  }
  first_on_edge[3] = neighbours_.size();
  for (int k = 0; k < 3; ++k)
    for (std::size_t i = first_on_edge[k]; i < first_on_edge[k + 1]; ++i) {
      Neighbour &neighbour = neighbours_[i];
      neighbour.apex =
          apexOf(neighbour.candidate, accepted.vertices[k], accepted.vertices[(k + 1) % 3]);
      __builtin_prefetch(&points_[neighbour.apex]);
    }
  for (int k = 0; k < 3; ++k) {
    const ContextAcross across(*this, t, k);
    for (std::size_t i = first_on_edge[k]; i < first_on_edge[k + 1]; ++i) {
      const CandidateIndex s = neighbours_[i].candidate;
      // Dropped candidates never return; waiting Q2 members get their
      // context recomputed when Q2 is built.
      if (states_[s].state == State::dropped || isWaitingForQueue2(s))
        continue;
      states_[s].context += sign * across.termFor(s, neighbours_[i].apex);
      refreshCost(s);
    }
  }
}

/// Context of t from scratch: the sum over accepted triangles on its edges.
double GreedyMesher::Impl::contextFromScratch(CandidateIndex t) const {
  double context = 0;
  for (EdgeIndex e : candidates_[t].edges)
    for (CandidateIndex u : mesh_.edgeTriangles(e)) {
      if (u == no_candidate || u == t)
        continue;
      for (int k = 0; k < 3; ++k)
        if (candidates_[u].edges[k] == e)
          context += contextTerm(u, k, t);
    }
  return context;
}

void GreedyMesher::Impl::refreshCost(CandidateIndex t) {
  const float cost = static_cast<float>(freshCost(t));
  if (cost == states_[t].cost)
    return;
  states_[t].cost = cost;
  if (isQueued(t) && !isWaitingForQueue2(t) && cost < states_[t].queued_cost)
    enqueue(t, states_[t].state);
}

/// Puts t's current cost in the queue of `queue` (its state already).
void GreedyMesher::Impl::enqueue(CandidateIndex t, State queue, Arrival arrival) {
  CandidateQueue &heap = queues_[queueNumber(queue)];
  states_[t].queued_cost = states_[t].cost;
  if (arrival == Arrival::delayed)
    heap.pushDelayed(QueueEntry(states_[t].cost, t));
  else
    heap.push(QueueEntry(states_[t].cost, t));
  if (heap.size() > 2 * queued_[queueNumber(queue)] + compaction_slack)
    heap.compact([&](const QueueEntry &entry) { return isLive(entry, queue); });
}

void GreedyMesher::Impl::push(CandidateIndex t, State queue, Arrival arrival) {
  states_[t].state = queue;
  if (queue == State::queue2 && !queue2_built_)
    return; // queued when pass 2 starts
  ++queued_[queueNumber(queue)];
  enqueue(t, queue, arrival);
}

/// Q2 waits through pass 1 untouched (most of it is type III far from the
/// surface); its context is computed once, here, from the accepted mesh.
/// The closed-vertex rule is applied now rather than at each pop: after
/// pass 1 most type III candidates touch a closed vertex.
void GreedyMesher::Impl::buildQueue2(PassStatistics &statistics) {
  std::vector<CandidateIndex> members;
  for (CandidateIndex t = 0; t < candidates_.size(); ++t) {
    if (states_[t].state != State::queue2)
      continue;
    if (touchesClosedVertex(t)) {
      states_[t].state = State::dropped;
      ++statistics.rejected;
      continue;
    }
    members.push_back(t);
  }
  graph_.addLateCandidates(members);
  mesh_.growEdges(edgeCount());
  queue2_built_ = true;
  for (CandidateIndex t : members) {
    states_[t].context = contextFromScratch(t);
    states_[t].cost = static_cast<float>(freshCost(t));
    ++queued_[1];
    enqueue(t, State::queue2);
  }
}

void GreedyMesher::Impl::runPass(State queue_state, PassStatistics &statistics) {
  CandidateQueue &queue = queues_[queueNumber(queue_state)];
  while (!queue.empty()) {
    const QueueEntry entry = queue.top();
    queue.pop();
    if (const QueueEntry *ahead = queue.sortedAhead(queue_prefetch_distance)) {
      __builtin_prefetch(&states_[ahead->candidate()]);
      __builtin_prefetch(&candidates_[ahead->candidate()]);
    }
    if (const QueueEntry *next = queue.pushedTop()) {
      __builtin_prefetch(&states_[next->candidate()]);
      __builtin_prefetch(&candidates_[next->candidate()]);
    }
    if (!isLive(entry, queue_state))
      continue;
    const CandidateIndex t = entry.candidate();
    if (states_[t].queued_cost != states_[t].cost) { // it rose: queue it at its cost
      enqueue(t, queue_state);
      continue;
    }
    if (deadline_)
      deadline_->checkEvery(deadline_counter_, "the greedy passes");
    --queued_[queueNumber(queue_state)];
    states_[t].state = State::idle;
    ++statistics.popped;
    decide(t, queue_state, statistics);
    if (const QueueEntry *next = queue.pushedTop()) {
      mesh_.prefetchAround(next->candidate());
      graph_.prefetchListStarts(next->candidate());
    }
  }
}

/// Error recovery: on each full edge of t, undo the accepted triangles that
/// have become costlier than t.
void GreedyMesher::Impl::undoCostlierOnFullEdges(CandidateIndex t, PassStatistics &statistics) {
  for (EdgeIndex e : candidates_[t].edges) {
    if (mesh_.edgeTriangleCount(e) < 2)
      continue;
    const auto occupants = mesh_.edgeTriangles(e);
    for (CandidateIndex u : occupants)
      if (u != no_candidate && !is_fixed_[u] && states_[u].cost > states_[t].cost) {
        undo(u);
        ++statistics.undone;
      }
  }
}

void GreedyMesher::Impl::decide(CandidateIndex t, State from, PassStatistics &statistics) {
  graph_.prefetchLists(t); // for the close-ranking rule, after the edge and vertex rules
  // 1. Edge rule: at most two triangles per edge.
  if (hasFullEdge(t)) {
    if (parameters_.error_recovery)
      undoCostlierOnFullEdges(t, statistics);
    if (hasFullEdge(t)) {
      if (from == State::queue1) {
        push(t, State::queue2);
        ++statistics.demoted;
      } else {
        states_[t].state = State::dropped;
        ++statistics.rejected;
      }
      return;
    }
  }
  // 2. Vertex rules.
  if (touchesClosedVertex(t)) {
    states_[t].state = State::dropped;
    ++statistics.rejected;
    return;
  }
  bool vertex_face_incidence = false;
  for (VertexIndex v : candidates_[t].vertices) {
    if (mesh_.vertexTriangleCount(v) > 0) {
      const auto edges = mesh_.edgesAt(t, v);
      if (mesh_.edgeTriangleCount(edges[0]) == 0 && mesh_.edgeTriangleCount(edges[1]) == 0)
        vertex_face_incidence = true;
    }
  }
  if (vertex_face_incidence && states_[t].incidence_delays < parameters_.max_delays) {
    ++states_[t].incidence_delays;
    delay(t, from, statistics);
    return;
  }
  // 3. Close-ranking delay: wait for context when a competitor is as cheap.
  if (closeCompetitorDelayed(t, from)) {
    delay(t, from, statistics);
    return;
  }
  accept(t, vertex_face_incidence);
  ++statistics.accepted;
}

void GreedyMesher::Impl::delay(CandidateIndex t, State from, PassStatistics &statistics) {
  states_[t].cost = static_cast<float>(freshCost(t));
  push(t, from, Arrival::delayed);
  ++statistics.delayed;
}

/// A competitor is a candidate of the same queue on an edge of t that can
/// take only one more triangle. If one is within the tolerance, both are
/// delayed. (Q2 members are not decided in pass 1, so they do not compete.)
bool GreedyMesher::Impl::closeCompetitorDelayed(CandidateIndex t, State queue) {
  if (parameters_.close_ranking_tolerance <= 0 ||
      states_[t].ranking_delays >= parameters_.max_delays)
    return false;
  const double tolerance = parameters_.close_ranking_tolerance * states_[t].cost;
  for (EdgeIndex e : candidates_[t].edges) {
    if (mesh_.edgeTriangleCount(e) != 1)
      continue;
    const bool delayed = forEachCandidateOn(e, [&](CandidateIndex s) {
      if (s == t || states_[s].state != queue ||
          states_[s].ranking_delays >= parameters_.max_delays ||
          std::abs(states_[s].cost - states_[t].cost) > tolerance)
        return false;
      ++states_[s].ranking_delays;
      refreshCost(s);
      ++states_[t].ranking_delays;
      return true;
    });
    if (delayed)
      return true;
  }
  return false;
}

void GreedyMesher::Impl::accept(CandidateIndex t, bool created_second_fan) {
  mesh_.add(t);
  states_[t].state = State::accepted;
  propagateContext(t, +1.0);
  for (VertexIndex v : candidates_[t].vertices) {
    const bool was_multi_fan = multi_fan_vertex_[v];
    if (created_second_fan && mesh_.edgeTriangleCount(mesh_.edgesAt(t, v)[0]) == 1 &&
        mesh_.edgeTriangleCount(mesh_.edgesAt(t, v)[1]) == 1 && mesh_.vertexTriangleCount(v) > 1) {
      multi_fan_vertex_[v] = true;
      may_have_several_fans_[v] = true;
    }
    // Every acceptance at a marked vertex is followed by this check and
    // only an acceptance closes a ring, so a new one holds t inside it; an
    // undo at t's other corners may have taken t out. A vertex marked just
    // now may hold an older ring anywhere (docs/algorithm.md, section 3).
    if (multi_fan_vertex_[v])
      keepClosedFanOnly(v,
                        !was_multi_fan                               ? RingSearch::all_triangles
                        : mesh_.contains(t) && mesh_.isInnerAt(t, v) ? RingSearch::through_accepted
                                                                     : RingSearch::none,
                        t);
  }
}

/// A vertex whose triangles form a closed ring plus other fans: the ring
/// wins and the extras are undone. `search` says where a ring may have
/// closed since the last check; with none, only the mark is updated.
void GreedyMesher::Impl::keepClosedFanOnly(VertexIndex v, RingSearch search,
                                           CandidateIndex accepted) {
  // One fan: nothing to undo. The mark stays while fewer than three
  // triangles are inside it (a closed fan has at least three).
  int inner_triangles = 0;
  if (mesh_.isSingleFan(v, inner_triangles)) {
    if (inner_triangles >= 3)
      multi_fan_vertex_[v] = false;
    return;
  }
  const bool has_closed_fan = search == RingSearch::all_triangles ? mesh_.hasClosedFan(v)
                              : search == RingSearch::through_accepted
                                  ? mesh_.isInClosedFan(accepted, v)
                                  : false;
  if (!has_closed_fan) // the common case: no need to build the fans
    return;
  const auto fans = mesh_.fansAround(v);
  const std::vector<CandidateIndex> *closed = nullptr;
  for (const auto &fan : fans)
    if (std::all_of(fan.begin(), fan.end(),
                    [&](CandidateIndex u) { return mesh_.isInnerAt(u, v); }))
      closed = &fan;
  assert(closed && "hasClosedFan walked a ring of inner triangles: that fan");
  for (const auto &fan : fans)
    if (&fan != closed)
      for (CandidateIndex u : fan)
        if (!is_fixed_[u])
          undo(u);
  multi_fan_vertex_[v] = false;
}

/// Takes t out of the mesh together with the context it gave its
/// neighbours. Removing a triangle from the middle of a fan splits it in
/// two: its corners are checked again by the final manifold sweep.
void GreedyMesher::Impl::removeFromMesh(CandidateIndex t) {
  mesh_.remove(t);
  propagateContext(t, -1.0);
  for (VertexIndex v : candidates_[t].vertices)
    may_have_several_fans_[v] = true;
}

/// Takes t out of the mesh and sends it to Q2 with a fresh cost.
void GreedyMesher::Impl::undo(CandidateIndex t) {
  removeFromMesh(t);
  states_[t].cost = static_cast<float>(freshCost(t));
  if (++states_[t].undos > max_undos) {
    states_[t].state = State::dropped;
    return;
  }
  push(t, State::queue2);
}
/// Between the passes: triangles with at most one shared edge (flaps,
/// isolated triangles) go back to Q2.
void GreedyMesher::Impl::removeFlapsAndIsolatedTriangles() {
  std::vector<CandidateIndex> loose;
  for (CandidateIndex t = 0; t < candidates_.size(); ++t) {
    if (!mesh_.contains(t) || is_fixed_[t])
      continue;
    int shared_edges = 0;
    for (EdgeIndex e : candidates_[t].edges)
      shared_edges += mesh_.edgeTriangleCount(e) == 2;
    if (shared_edges <= 1)
      loose.push_back(t);
  }
  for (CandidateIndex t : loose)
    undo(t);
  statistics_.cleanup_undone += loose.size();
}

GreedyMesher::GreedyMesher(MedialScaffold &&scaffold, const std::vector<Eigen::Vector3d> &points,
                           const Parameters &parameters, const Deadline *deadline)
    : impl_(
          std::make_unique<Impl>(std::move(scaffold), points, parameters, deadline, statistics_)) {}

GreedyMesher::~GreedyMesher() = default;

void GreedyMesher::run() { impl_->run(); }

std::vector<Triangle> GreedyMesher::triangles(bool with_fixed) const {
  return impl_->triangles(with_fixed);
}

std::vector<Triangle> GreedyMesher::seamTriangles() const { return impl_->seamTriangles(); }

} // namespace pcl_ms
