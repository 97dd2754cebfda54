// SPDX-License-Identifier: GPL-3.0-or-later
// Stage 3, greedy gap transforms (docs/algorithm.md section 3). In: the
// scaffold's candidates and the points. Out: an edge-manifold triangle list,
// accepted cheapest first, with the passes' statistics.
#include <pcl_ms/costs.h>
#include <pcl_ms/greedy.h>

#include <boost/heap/d_ary_heap.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <unordered_map>

namespace pcl_ms {
namespace {

enum class State : std::uint8_t { idle, queue1, queue2, accepted, dropped };

/// A queued cost and its candidate packed into one integer that orders them
/// cheapest first, ties by candidate index: the cost's bits form the high
/// word, and costs are never negative (freshCost clamps at +0, NaN included),
/// so their IEEE bit patterns sort like the values. One integer comparison
/// per heap step instead of two float tests and a tie-break.
class QueueEntry {
public:
  QueueEntry(float cost, CandidateIndex candidate)
      : key_(std::uint64_t{bitsOf(cost)} << 32 | candidate) {}
  float cost() const {
    const auto bits = static_cast<std::uint32_t>(key_ >> 32);
    float cost;
    std::memcpy(&cost, &bits, sizeof cost);
    return cost;
  }
  CandidateIndex candidate() const { return static_cast<CandidateIndex>(key_); }
  // Boost's heaps keep the greatest element on top: "greater" puts the
  // cheapest first.
  bool operator>(const QueueEntry &other) const { return key_ > other.key_; }
  bool operator<(const QueueEntry &other) const { return key_ < other.key_; }

private:
  static std::uint32_t bitsOf(float cost) {
    std::uint32_t bits;
    std::memcpy(&bits, &cost, sizeof bits);
    return bits;
  }

  std::uint64_t key_;
};

struct CheaperFirst {
  bool operator()(const QueueEntry &a, const QueueEntry &b) const { return a > b; }
};

/// The queue of one pass. Most entries arrive together before the pass
/// pops any (the pass's initial costs): those are sorted once and read in
/// order, which costs far less than sifting each through a heap of millions
/// of entries, the greedy's main cost at 300,000 points. Entries pushed while
/// the pass runs (changed costs) go to a small heap. Boost's contiguous d-ary
/// heap has no handles: a candidate whose cost changes is pushed again and
/// its outdated entry skipped when it surfaces (lazy deletion). Entries are
/// totally ordered, so the pops come in the same order as from one heap.
class CandidateQueue {
public:
  void push(const QueueEntry &entry) { arrived_.push_back(entry); }
  bool empty() const { return size() == 0; }
  const QueueEntry &top() {
    settleArrivals();
    return sortedRunFirst() ? sorted_[next_] : heap_.top();
  }
  void pop() {
    settleArrivals();
    if (sortedRunFirst())
      ++next_;
    else
      heap_.pop();
  }
  std::size_t size() const { return sorted_.size() - next_ + heap_.size() + arrived_.size(); }
  /// The candidate `steps` places further along the sorted run, if any: the
  /// pass fetches its data early, as the run visits candidates in no order
  /// of memory.
  const QueueEntry *sortedAhead(std::size_t steps) const {
    return next_ + steps < sorted_.size() ? &sorted_[next_ + steps] : nullptr;
  }

  /// Drops the outdated entries.
  template <typename IsCurrent> void compact(const IsCurrent &is_current) {
    settleArrivals();
    std::vector<QueueEntry> current;
    std::copy_if(sorted_.begin() + static_cast<std::ptrdiff_t>(next_), sorted_.end(),
                 std::back_inserter(current), is_current);
    sorted_ = std::move(current);
    next_ = 0;
    std::vector<QueueEntry> in_heap;
    for (auto it = heap_.begin(); it != heap_.end(); ++it)
      if (is_current(*it))
        in_heap.push_back(*it);
    heap_.clear();
    heap_.reserve(in_heap.size());
    for (const QueueEntry &entry : in_heap)
      heap_.push(entry);
  }

private:
  // A batch at least this large is sorted and merged into the sorted run
  // rather than pushed onto the heap one by one.
  static constexpr std::size_t min_sorted_batch = 1024;

  bool sortedRunFirst() const {
    return next_ < sorted_.size() && (heap_.empty() || !(heap_.top() < sorted_[next_]));
  }

  void settleArrivals() {
    if (arrived_.empty())
      return;
    if (arrived_.size() < min_sorted_batch) {
      for (const QueueEntry &entry : arrived_)
        heap_.push(entry);
    } else {
      std::sort(arrived_.begin(), arrived_.end());
      std::vector<QueueEntry> merged;
      merged.reserve(sorted_.size() - next_ + arrived_.size());
      std::merge(sorted_.begin() + static_cast<std::ptrdiff_t>(next_), sorted_.end(),
                 arrived_.begin(), arrived_.end(), std::back_inserter(merged));
      sorted_ = std::move(merged);
      next_ = 0;
    }
    arrived_.clear();
  }

  std::vector<QueueEntry> arrived_; // pushed, not yet placed
  std::vector<QueueEntry> sorted_;  // ascending from next_
  std::size_t next_ = 0;
  boost::heap::d_ary_heap<QueueEntry, boost::heap::arity<4>, boost::heap::compare<CheaperFirst>>
      heap_;
};

// How far along the sorted run the pass fetches candidates ahead of use.
constexpr std::size_t queue_prefetch_distance = 16;

// Outdated entries may grow the heap to twice the queued candidates plus
// this before it is compacted.
constexpr std::size_t compaction_slack = 1 << 16;

// An undone triangle is re-queued at most this often, so that two candidates
// whose costs keep crossing cannot undo each other forever.
constexpr std::uint8_t max_undos = 3;

// A swap must improve the angle sum by more than rounding noise, or
// co-circular quads would flip back and forth.
constexpr double swap_angle_tolerance = 1e-9;

// Swaps may bend a quad up to this much (20 degrees) even when it was flatter
// before: smooth surfaces bend a little either way.
constexpr double smooth_bending_angle = 0.35;

// Seam pass (docs/algorithm.md, "Seams (opt-in)"): a triangle joins a likely
// seam edge that holds two already only in a sheet of that edge (found
// before the passes) that no triangle there occupies yet.
// Sheets: a point is in a sheet of a seam edge when its direction around the
// edge is within this (about 29 degrees) of the sheet's, two neighbouring
// seam edges have the same sheets when these agree within it, and the third
// sheet grows from a rim whose triangles lie within it of its plane.
constexpr double max_sheet_bending = 0.5;
// Across an edge with one triangle, a seam-pass triangle may bend up to
// this much (about 92 degrees): where a seam ends at a box corner, the
// third sheet's triangle meets the box's crease. Triangles bridging two
// sheets are left out by seam detection instead.
constexpr double max_attached_bending = 1.6;
// A seam triangle's longest side is at most this times the longest side of
// the triangles on its full edge: on the test clouds the right ones measured
// 0.78-1.14 times, triangles bridging the wedge between two sheets 1.6-2.2.
constexpr double max_seam_size_ratio = 1.4;
// Seam detection (docs/algorithm.md, "Seams (opt-in)"): around an edge, the
// apexes of its Gabriel candidates fall into groups (sheets) separated by
// gaps of at least this much (about 34 degrees); three or more groups make
// the edge a likely seam edge.
constexpr double min_sheet_gap = 0.6;
// A point is along a seam edge's axis (in no sheet in particular) when its
// direction from the seam vertex is within this angle of the axis.
constexpr double max_axis_angle = 0.35;
// A group is a sheet when its cheapest candidate costs at most this times
// the cheapest around the edge: on the test clouds the sheets' cheapest
// measured within 1.9 times of each other, groups of triangles bridging two
// sheets or reaching across a thin part 2.4 times and far more.
constexpr double max_sheet_cost_ratio = 2.5;
// Seams are curves: a likely seam edge is kept when it is in a chain of at
// least this many, each continuing the next within about 37 degrees
// (cosine 0.8) with the same sheets. On the manifold test surfaces (bunny,
// camel, camel head, fandisk, anchor, noisy sphere) such chains of three
// sheets were 4 edges long at most (across creases, where a fold gives a
// third group); the test seams are chains of 20 and 52.
constexpr std::size_t min_seam_chain = 6;
constexpr double min_chain_cosine = 0.8;

} // namespace

class GreedyMesher::Impl {
public:
  Impl(MedialScaffold &scaffold, const std::vector<Eigen::Vector3d> &points,
       const Parameters &parameters, const Deadline *deadline, GreedyStatistics &statistics)
      : scaffold_(scaffold), candidates_(scaffold.candidates), points_(points),
        parameters_(parameters), deadline_(deadline), statistics_(statistics),
        mesh_(scaffold, points.size()), states_(candidates_.size()),
        is_fixed_(candidates_.size(), false), is_preferred_(candidates_.size(), false),
        multi_fan_vertex_(points.size(), false), may_have_several_fans_(points.size(), false) {
    for (CandidateIndex t : scaffold.fixed)
      is_fixed_[t] = true;
    for (CandidateIndex t : scaffold.preferred)
      is_preferred_[t] = !is_fixed_[t];
    delay_multiplier_.resize(2 * static_cast<std::size_t>(parameters.max_delays) + 1);
    for (std::size_t k = 0; k < delay_multiplier_.size(); ++k)
      delay_multiplier_[k] = std::pow(parameters.delay_factor, static_cast<double>(k));
  }

  void run() {
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

  std::vector<Triangle> seamTriangles() const {
    std::vector<Triangle> result;
    result.reserve(seam_list_.size() + set_apart_.size());
    for (CandidateIndex t : seam_list_)
      result.push_back(candidates_[t].vertices);
    for (CandidateIndex t : set_apart_)
      result.push_back(candidates_[t].vertices);
    return result;
  }

  std::vector<Triangle> triangles(bool with_fixed) const {
    std::vector<Triangle> result;
    result.reserve(mesh_.size());
    for (CandidateIndex t = 0; t < candidates_.size(); ++t)
      if (mesh_.contains(t) && (with_fixed || !is_fixed_[t]) &&
          (is_set_apart_.empty() || !is_set_apart_[t]))
        result.push_back(candidates_[t].vertices);
    return result;
  }

private:
  /// Fixed triangles are in the surface before anything is ranked, so their
  /// context counts from the start; nothing ever undoes them. A triangle
  /// that would overfill an edge is left out (callers pass edge-manifold sets).
  void acceptFixedTriangles() {
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
  void rankPreferredTriangles() {
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

  // ---- costs -------------------------------------------------------------

  double rankingBaseCost(CandidateIndex t) const {
    return preferred_ranked_ && is_preferred_[t] ? 0.0 : candidates_[t].base_cost;
  }

  double freshCost(CandidateIndex t) const {
    const double undelayed = std::max(0.0, rankingBaseCost(t) + states_[t].context);
    return undelayed * delay_multiplier_[states_[t].incidence_delays + states_[t].ranking_delays];
  }

  /// eps2 that accepted triangle `from` adds to candidate `to` across edge
  /// slot k of `from`.
  double contextTerm(CandidateIndex from, int k, CandidateIndex to) const {
    const Candidate &source = candidates_[from];
    const Candidate &target = candidates_[to];
    const VertexIndex p = source.vertices[k], q = source.vertices[(k + 1) % 3];
    const VertexIndex source_apex = source.vertices[(k + 2) % 3];
    VertexIndex target_apex = target.vertices[0];
    for (VertexIndex v : target.vertices)
      if (v != p && v != q)
        target_apex = v;
    const double edge_length = (points_[q] - points_[p]).norm();
    const double angle =
        bendingAngle(points_[p], points_[q], points_[source_apex], points_[target_apex]);
    return contextCost(edge_length, target.inverse_shock_compactness, angle);
  }

  /// Adds (sign +1) or removes (sign -1) accepted triangle t's context from
  /// every candidate sharing one of its edges, accepted ones included: their
  /// current cost is what error recovery compares against.
  void propagateContext(CandidateIndex t, double sign) {
    const Candidate &candidate = candidates_[t];
    for (int k = 0; k < 3; ++k)
      forEachCandidateOn(candidate.edges[k], [&](CandidateIndex s) {
        // Dropped candidates never return; waiting Q2 members get their
        // context recomputed when Q2 is built.
        if (s == t || states_[s].state == State::dropped || isWaitingForQueue2(s))
          return false;
        states_[s].context += sign * contextTerm(t, k, s);
        refreshCost(s);
        return false;
      });
  }

  /// Context of t from scratch: the sum over accepted triangles on its edges.
  double contextFromScratch(CandidateIndex t) const {
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

  void refreshCost(CandidateIndex t) {
    const float cost = static_cast<float>(freshCost(t));
    if (cost == states_[t].cost)
      return;
    states_[t].cost = cost;
    if (isQueued(t) && !isWaitingForQueue2(t))
      enqueue(t, states_[t].state);
  }

  // ---- queues ------------------------------------------------------------

  bool isWaitingForQueue2(CandidateIndex t) const {
    return !queue2_built_ && states_[t].state == State::queue2;
  }

  bool isQueued(CandidateIndex t) const {
    return states_[t].state == State::queue1 || states_[t].state == State::queue2;
  }
  int queueNumber(State state) const { return state == State::queue1 ? 0 : 1; }

  bool isCurrent(const QueueEntry &entry, State queue) const {
    const CandidateState &state = states_[entry.candidate()];
    return state.state == queue && state.cost == entry.cost();
  }

  /// Puts t's current cost on the heap of `queue` (its state already).
  void enqueue(CandidateIndex t, State queue) {
    CandidateQueue &heap = queues_[queueNumber(queue)];
    heap.push(QueueEntry(states_[t].cost, t));
    if (heap.size() > 2 * queued_[queueNumber(queue)] + compaction_slack)
      heap.compact([&](const QueueEntry &entry) { return isCurrent(entry, queue); });
  }

  void push(CandidateIndex t, State queue) {
    states_[t].state = queue;
    if (queue == State::queue2 && !queue2_built_)
      return; // queued when pass 2 starts
    ++queued_[queueNumber(queue)];
    enqueue(t, queue);
  }

  /// Q2 waits through pass 1 untouched (most of it is type III far from the
  /// surface); its context is computed once, here, from the accepted mesh.
  /// The closed-vertex rule is applied now rather than at each pop: after
  /// pass 1 most type III candidates touch a closed vertex.
  void buildQueue2(PassStatistics &statistics) {
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
    listLateCandidates(members);
    queue2_built_ = true;
    for (CandidateIndex t : members) {
      states_[t].context = contextFromScratch(t);
      states_[t].cost = static_cast<float>(freshCost(t));
      ++queued_[1];
      enqueue(t, State::queue2);
    }
  }

  // ---- edges of type III candidates --------------------------------------

  /// Visits the candidates on edge e, in ascending order within each group:
  /// the scaffold's (types I and II, fixed), the type III ones that reached
  /// pass 2, then any that a diagonal swap brought in. Stops when visit
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

  bool hasEdges(CandidateIndex t) const { return candidates_[t].edges[0] != no_edge; }

  /// The scaffold's edges and those numbered here, which follow them.
  std::size_t edgeCount() const { return scaffold_.numberOfEdges() + new_edges_.size(); }

  /// The edge joining a and b: the scaffold's, one numbered here, or no_edge.
  EdgeIndex findEdge(VertexIndex a, VertexIndex b) const {
    const EdgeIndex e = scaffold_.findEdge(a, b);
    if (e != no_edge || new_edges_.empty())
      return e;
    const auto found = new_edges_.find(vertexPairKey(a, b));
    return found == new_edges_.end() ? no_edge : found->second;
  }

  static std::uint64_t vertexPairKey(VertexIndex a, VertexIndex b) {
    return a < b ? std::uint64_t{a} << 32 | b : std::uint64_t{b} << 32 | a;
  }

  /// Gives a type III candidate the ids of its edges, numbering the edges
  /// that no pass-1 candidate has.
  void numberEdges(CandidateIndex t) {
    Candidate &candidate = candidates_[t];
    for (int k = 0; k < 3; ++k) {
      const VertexIndex a = candidate.vertices[k], b = candidate.vertices[(k + 1) % 3];
      EdgeIndex e = findEdge(a, b);
      if (e == no_edge) {
        e = static_cast<EdgeIndex>(edgeCount());
        new_edges_.emplace(vertexPairKey(a, b), e);
      }
      candidate.edges[k] = e;
    }
    mesh_.growEdges(edgeCount());
  }

  /// Numbers the edges of the type III members of Q2 and lists them per
  /// edge, as the scaffold lists the pass-1 candidates.
  void listLateCandidates(const std::vector<CandidateIndex> &members) {
    std::vector<CandidateIndex> late;
    for (CandidateIndex t : members)
      if (!hasEdges(t)) {
        numberEdges(t);
        late.push_back(t);
      }
    late_offsets_.assign(edgeCount() + 1, 0);
    for (CandidateIndex t : late)
      for (EdgeIndex e : candidates_[t].edges)
        ++late_offsets_[e + 1];
    std::partial_sum(late_offsets_.begin(), late_offsets_.end(), late_offsets_.begin());
    late_candidates_.resize(late_offsets_.back());
    std::vector<std::uint32_t> cursor(late_offsets_.begin(), late_offsets_.end() - 1);
    for (CandidateIndex t : late)
      for (EdgeIndex e : candidates_[t].edges)
        late_candidates_[cursor[e]++] = t;
  }

  void runPass(State queue_state, PassStatistics &statistics) {
    CandidateQueue &queue = queues_[queueNumber(queue_state)];
    while (!queue.empty()) {
      const QueueEntry entry = queue.top();
      queue.pop();
      if (const QueueEntry *ahead = queue.sortedAhead(queue_prefetch_distance)) {
        __builtin_prefetch(&states_[ahead->candidate()]);
        __builtin_prefetch(&candidates_[ahead->candidate()]);
      }
      if (!isCurrent(entry, queue_state))
        continue;
      if (deadline_)
        deadline_->checkEvery(deadline_counter_, "the greedy passes");
      const CandidateIndex t = entry.candidate();
      --queued_[queueNumber(queue_state)];
      states_[t].state = State::idle;
      ++statistics.popped;
      decide(t, queue_state, statistics);
    }
  }

  // ---- decisions ---------------------------------------------------------

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

  /// Error recovery: on each full edge of t, undo the accepted triangles that
  /// have become costlier than t.
  void undoCostlierOnFullEdges(CandidateIndex t, PassStatistics &statistics) {
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

  void decide(CandidateIndex t, State from, PassStatistics &statistics) {
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

  void delay(CandidateIndex t, State from, PassStatistics &statistics) {
    states_[t].cost = static_cast<float>(freshCost(t));
    push(t, from);
    ++statistics.delayed;
  }

  /// A competitor is a candidate of the same queue on an edge of t that can
  /// take only one more triangle. If one is within the tolerance, both are
  /// delayed. (Q2 members are not decided in pass 1, so they do not compete.)
  bool closeCompetitorDelayed(CandidateIndex t, State queue) {
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

  void accept(CandidateIndex t, bool created_second_fan) {
    mesh_.add(t);
    states_[t].state = State::accepted;
    propagateContext(t, +1.0);
    for (VertexIndex v : candidates_[t].vertices) {
      if (created_second_fan && mesh_.edgeTriangleCount(mesh_.edgesAt(t, v)[0]) == 1 &&
          mesh_.edgeTriangleCount(mesh_.edgesAt(t, v)[1]) == 1 &&
          mesh_.vertexTriangleCount(v) > 1) {
        multi_fan_vertex_[v] = true;
        may_have_several_fans_[v] = true;
      }
      if (multi_fan_vertex_[v])
        keepClosedFanOnly(v);
    }
  }

  /// A vertex whose triangles form a closed ring plus other fans: the ring
  /// wins and the extras are undone.
  void keepClosedFanOnly(VertexIndex v) {
    // A closed fan has at least three triangles whose both edges at v are
    // full: without them there is nothing to do, and no fans to build.
    int inner_triangles = 0;
    for (CandidateIndex u : mesh_.vertexTriangles(v)) {
      const auto edges = mesh_.edgesAt(u, v);
      inner_triangles +=
          mesh_.edgeTriangleCount(edges[0]) == 2 && mesh_.edgeTriangleCount(edges[1]) == 2;
    }
    if (inner_triangles < 3)
      return;
    if (mesh_.isSingleFan(v)) {
      multi_fan_vertex_[v] = false;
      return;
    }
    const auto fans = mesh_.fansAround(v);
    const std::vector<CandidateIndex> *closed = nullptr;
    for (const auto &fan : fans)
      if (isClosedFan(fan, v))
        closed = &fan;
    if (!closed)
      return;
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
  void removeFromMesh(CandidateIndex t) {
    mesh_.remove(t);
    propagateContext(t, -1.0);
    for (VertexIndex v : candidates_[t].vertices)
      may_have_several_fans_[v] = true;
  }

  bool isClosedFan(const std::vector<CandidateIndex> &fan, VertexIndex v) const {
    for (CandidateIndex u : fan)
      for (EdgeIndex e : mesh_.edgesAt(u, v))
        if (mesh_.edgeTriangleCount(e) != 2)
          return false;
    return true;
  }

  /// Takes t out of the mesh and sends it to Q2 with a fresh cost.
  void undo(CandidateIndex t) {
    removeFromMesh(t);
    states_[t].cost = static_cast<float>(freshCost(t));
    if (++states_[t].undos > max_undos) {
      states_[t].state = State::dropped;
      return;
    }
    push(t, State::queue2);
  }

  // ---- diagonal swaps -------------------------------------------------------

  /// The edge of candidate t joining a and b (both vertices of t).
  EdgeIndex edgeBetween(CandidateIndex t, VertexIndex a, VertexIndex b) const {
    const Candidate &candidate = candidates_[t];
    for (int k = 0; k < 3; ++k) {
      const VertexIndex p = candidate.vertices[k], q = candidate.vertices[(k + 1) % 3];
      if ((p == a && q == b) || (p == b && q == a))
        return candidate.edges[k];
    }
    return candidate.edges[0];
  }

  /// The candidate (a, b, apex), where a and b are the ends of edge e, or
  /// no_candidate: on e's lists, else among the type III candidates without
  /// edges (unnumbered_, by lowest vertex). Vertex sets are unique, so where
  /// it is found does not matter.
  CandidateIndex candidateWith(EdgeIndex e, VertexIndex a, VertexIndex b, VertexIndex apex) const {
    CandidateIndex found = no_candidate;
    forEachCandidateOn(e, [&](CandidateIndex s) {
      const auto &v = candidates_[s].vertices;
      if (v[0] == apex || v[1] == apex || v[2] == apex)
        found = s;
      return found != no_candidate;
    });
    if (found != no_candidate || unnumbered_offsets_.empty())
      return found;
    Triangle vertices = {a, b, apex};
    std::sort(vertices.begin(), vertices.end());
    for (std::uint32_t i = unnumbered_offsets_[vertices[0]];
         i < unnumbered_offsets_[vertices[0] + 1]; ++i)
      if (candidates_[unnumbered_[i]].vertices == vertices)
        return unnumbered_[i];
    return no_candidate;
  }

  /// Lists the type III candidates still without edges by lowest vertex.
  void listUnnumberedCandidates() {
    unnumbered_offsets_.assign(points_.size() + 1, 0);
    for (CandidateIndex t = 0; t < candidates_.size(); ++t)
      if (!hasEdges(t))
        ++unnumbered_offsets_[candidates_[t].vertices[0] + 1];
    std::partial_sum(unnumbered_offsets_.begin(), unnumbered_offsets_.end(),
                     unnumbered_offsets_.begin());
    unnumbered_.resize(unnumbered_offsets_.back());
    std::vector<std::uint32_t> cursor(unnumbered_offsets_.begin(), unnumbered_offsets_.end() - 1);
    for (CandidateIndex t = 0; t < candidates_.size(); ++t)
      if (!hasEdges(t))
        unnumbered_[cursor[candidates_[t].vertices[0]]++] = t;
  }

  /// Numbers the edges of a type III candidate that a swap brings into the
  /// mesh (pass 2 had dropped it) and lists it on them.
  void bringInBySwap(CandidateIndex t) {
    numberEdges(t);
    for (EdgeIndex e : candidates_[t].edges)
      swapped_in_[e].push_back(t);
  }

  VertexIndex apexOf(CandidateIndex t, VertexIndex a, VertexIndex c) const {
    for (VertexIndex v : candidates_[t].vertices)
      if (v != a && v != c)
        return v;
    return a;
  }

  /// Whether the angles at b and d opposite edge ac sum to more than pi
  /// (plus the tolerance): the sine of the sum is negative then. Sines and
  /// cosines come from cross and dot products, without any arctangent.
  bool oppositeAnglesExceedPi(VertexIndex b, VertexIndex d, VertexIndex a, VertexIndex c) const {
    const Eigen::Vector3d ub = points_[a] - points_[b], wb = points_[c] - points_[b];
    const Eigen::Vector3d ud = points_[a] - points_[d], wd = points_[c] - points_[d];
    const double sine_b = ub.cross(wb).norm(), sine_d = ud.cross(wd).norm();
    const double scale =
        std::sqrt(ub.squaredNorm() * wb.squaredNorm() * ud.squaredNorm() * wd.squaredNorm());
    return sine_b * ud.dot(wd) + ub.dot(wb) * sine_d < -swap_angle_tolerance * scale;
  }

  /// Error recovery after the passes: two accepted triangles (a, c, b) and
  /// (a, c, d) whose quad is not locally Delaunay on the surface (the angles
  /// at b and d sum to more than pi) are replaced by the other pair of
  /// Delaunay candidates (a, b, d), (b, c, d), when that pair exists, its
  /// diagonal is not a mesh edge yet and it bends the surface no more (so
  /// ridges stay). On curved surfaces the 3-D empty-sphere test alone often
  /// picks the diagonal a surface triangulation would not.
  void swapNonDelaunayDiagonals() {
    listUnnumberedCandidates();
    std::vector<EdgeIndex> work;
    std::vector<bool> queued(edgeCount(), false);
    auto enqueue = [&](EdgeIndex e) {
      if (e >= queued.size()) // numbered by a swap
        queued.resize(edgeCount(), false);
      if (!queued[e] && mesh_.edgeTriangleCount(e) == 2) {
        queued[e] = true;
        work.push_back(e);
      }
    };
    for (CandidateIndex t = 0; t < candidates_.size(); ++t)
      if (mesh_.contains(t))
        for (EdgeIndex e : candidates_[t].edges)
          enqueue(e);
    // Flips on a curved surface change its geometry, so unlike in the plane
    // termination is not guaranteed: bound the work.
    std::size_t budget = 4 * work.size() + 16;
    for (std::size_t head = 0; head < work.size() && budget > 0; ++head, --budget) {
      const EdgeIndex e = work[head];
      queued[e] = false;
      if (mesh_.edgeTriangleCount(e) != 2)
        continue;
      const auto [first, second] = mesh_.edgeTriangles(e);
      if (is_fixed_[first] || is_fixed_[second] || is_preferred_[first] || is_preferred_[second])
        continue;
      if (seam_axes_.count(e)) // a likely seam edge stays (docs/algorithm.md, "Seams")
        continue;
      VertexIndex a = 0, c = 0;
      for (int k = 0; k < 3; ++k)
        if (candidates_[first].edges[k] == e) {
          a = candidates_[first].vertices[k];
          c = candidates_[first].vertices[(k + 1) % 3];
        }
      const VertexIndex b = apexOf(first, a, c), d = apexOf(second, a, c);
      if (!oppositeAnglesExceedPi(b, d, a, c))
        continue;
      const CandidateIndex abd = candidateWith(edgeBetween(first, a, b), a, b, d);
      const CandidateIndex bcd = candidateWith(edgeBetween(first, b, c), b, c, d);
      if (abd == no_candidate || bcd == no_candidate || states_[abd].state == State::accepted ||
          states_[bcd].state == State::accepted)
        continue;
      if (!bridges_seam_.empty() && (bridges_seam_[abd] || bridges_seam_[bcd]))
        continue;
      const EdgeIndex diagonal = findEdge(b, d);
      if (diagonal != no_edge && mesh_.edgeTriangleCount(diagonal) != 0)
        continue;
      const double bending_before = bendingAngle(points_[a], points_[c], points_[b], points_[d]);
      const double bending_after = bendingAngle(points_[b], points_[d], points_[a], points_[c]);
      if (bending_after > std::max(bending_before, smooth_bending_angle))
        continue;
      for (CandidateIndex old : {first, second}) {
        removeFromMesh(old);
        states_[old].state = State::dropped;
      }
      for (CandidateIndex replacement : {abd, bcd})
        if (!hasEdges(replacement))
          bringInBySwap(replacement);
      for (CandidateIndex replacement : {abd, bcd}) {
        if (isQueued(replacement)) // its heap entry is outdated from now on
          --queued_[queueNumber(states_[replacement].state)];
        mesh_.add(replacement);
        states_[replacement].state = State::accepted;
        propagateContext(replacement, +1.0);
        for (EdgeIndex outer : candidates_[replacement].edges)
          enqueue(outer);
      }
      ++statistics_.swapped_pairs;
    }
    unnumbered_offsets_ = {};
    unnumbered_ = {};
  }

  // ---- seams (opt-in) --------------------------------------------------------

  /// A likely seam edge: its axis (unit, from its lower to its higher end),
  /// a frame across it, and the directions of its sheets in that frame.
  struct SeamAxis {
    VertexIndex low = 0, high = 0;
    Eigen::Vector3d axis, across1, across2;
    std::vector<double> sheets; // angles in [-pi, pi], in cyclic order
    std::vector<float> costs;   // while detecting: each group's cheapest candidate
  };

  /// The angle of point p around edge `seam`, seen from its vertex v; or
  /// nothing (NaN) when p lies along the axis.
  double angleAround(const SeamAxis &seam, VertexIndex v, VertexIndex p) const {
    const Eigen::Vector3d offset = points_[p] - points_[v];
    const double along = offset.dot(seam.axis);
    const Eigen::Vector3d across = offset - along * seam.axis;
    if (across.norm() <= std::tan(max_axis_angle) * std::abs(along))
      return std::numeric_limits<double>::quiet_NaN();
    return std::atan2(across.dot(seam.across2), across.dot(seam.across1));
  }

  /// The sheet of `seam` within half the smallest gap between sheets (and
  /// max_sheet_bending) of `angle`, or -1 (also for NaN: along the axis).
  static int sheetAt(const SeamAxis &seam, double angle) {
    const std::size_t n = seam.sheets.size();
    double tolerance = M_PI;
    for (std::size_t i = 0; i < n; ++i) {
      double gap = seam.sheets[(i + 1) % n] - seam.sheets[i];
      if (gap <= 0)
        gap += 2 * M_PI;
      tolerance = std::min(tolerance, gap / 2);
    }
    tolerance = std::min(tolerance, max_sheet_bending);
    for (std::size_t i = 0; i < n; ++i) {
      const double difference = std::remainder(angle - seam.sheets[i], 2 * M_PI);
      if (std::abs(difference) <= tolerance)
        return static_cast<int>(i);
    }
    return -1;
  }

  /// Before the passes (docs/algorithm.md, "Seams (opt-in)"): the scaffold
  /// edges whose Gabriel candidates fan out into three or more sheets, and
  /// the candidates that would bridge the wedge between two sheets at one
  /// of their ends: those are left out of every pass.
  void detectSeams() {
    std::vector<std::pair<double, CandidateIndex>> angles;
    std::vector<EdgeIndex> found; // ascending
    for (EdgeIndex e = 0; e < scaffold_.numberOfEdges(); ++e) {
      const CandidateIndex *begin = scaffold_.edgeBegin(e), *end = scaffold_.edgeEnd(e);
      if (end - begin < 3)
        continue;
      SeamAxis seam;
      VertexIndex high = 0;
      {
        const Candidate &first = candidates_[*begin];
        for (int k = 0; k < 3; ++k)
          if (first.edges[k] == e) {
            seam.low = std::min(first.vertices[k], first.vertices[(k + 1) % 3]);
            high = std::max(first.vertices[k], first.vertices[(k + 1) % 3]);
          }
      }
      seam.axis = (points_[high] - points_[seam.low]).normalized();
      seam.across1 = seam.axis.unitOrthogonal();
      seam.across2 = seam.axis.cross(seam.across1);
      angles.clear();
      for (const CandidateIndex *s = begin; s != end; ++s) {
        if (candidates_[*s].type == CandidateType::ambiguous)
          continue;
        const Eigen::Vector3d offset = points_[apexOf(*s, seam.low, high)] - points_[seam.low];
        angles.emplace_back(std::atan2(offset.dot(seam.across2), offset.dot(seam.across1)), *s);
      }
      if (angles.size() < 3)
        continue;
      std::sort(angles.begin(), angles.end());
      // Groups: runs of angles with gaps below min_sheet_gap, cyclically;
      // each sheet's direction is its group's mean.
      std::size_t start = 0; // a group starts after the largest gap
      double widest = 0;
      for (std::size_t i = 0; i < angles.size(); ++i) {
        double gap = angles[i].first - angles[(i + angles.size() - 1) % angles.size()].first;
        if (gap <= 0)
          gap += 2 * M_PI;
        if (gap > widest) {
          widest = gap;
          start = i;
        }
      }
      if (widest < min_sheet_gap)
        continue;
      double sum = 0, previous = 0;
      float cheapest = std::numeric_limits<float>::max();
      std::size_t members = 0;
      for (std::size_t j = 0; j < angles.size(); ++j) {
        const std::size_t i = (start + j) % angles.size();
        const double angle = angles[i].first + (i < start ? 2 * M_PI : 0.0);
        if (members > 0 && angle - previous >= min_sheet_gap) {
          seam.sheets.push_back(std::remainder(sum / static_cast<double>(members), 2 * M_PI));
          seam.costs.push_back(cheapest);
          sum = 0;
          members = 0;
          cheapest = std::numeric_limits<float>::max();
        }
        cheapest = std::min(cheapest, candidates_[angles[i].second].base_cost);
        sum += angle;
        ++members;
        previous = angle;
      }
      seam.sheets.push_back(std::remainder(sum / static_cast<double>(members), 2 * M_PI));
      seam.costs.push_back(cheapest);
      // Only groups with a cheap candidate are sheets.
      const float cheapest_all = *std::min_element(seam.costs.begin(), seam.costs.end());
      std::vector<double> sheets;
      for (std::size_t i = 0; i < seam.sheets.size(); ++i)
        if (seam.costs[i] <= max_sheet_cost_ratio * cheapest_all)
          sheets.push_back(seam.sheets[i]);
      if (sheets.size() < 3)
        continue;
      seam.sheets = std::move(sheets);
      seam.high = high;
      found.push_back(e);
      seam_axes_.emplace(e, std::move(seam));
    }
    keepSeamChains(found);
    if (seam_axes_.empty())
      return;
    bridges_seam_.assign(candidates_.size(), false);
    for (CandidateIndex t = 0; t < candidates_.size(); ++t)
      bridges_seam_[t] = !is_fixed_[t] && !is_preferred_[t] && bridgesSeam(t);
  }

  static Eigen::Vector3d sheetDirection(const SeamAxis &seam, double angle) {
    return std::cos(angle) * seam.across1 + std::sin(angle) * seam.across2;
  }

  /// Whether two neighbouring likely seam edges have the same sheets: as
  /// many, each within max_sheet_bending of one of the other's.
  static bool sameSheets(const SeamAxis &a, const SeamAxis &b) {
    if (a.sheets.size() != b.sheets.size())
      return false;
    for (double angle : a.sheets) {
      const Eigen::Vector3d direction = sheetDirection(a, angle);
      bool matched = false;
      for (double other : b.sheets)
        matched |= direction.dot(sheetDirection(b, other)) >= std::cos(max_sheet_bending);
      if (!matched)
        return false;
    }
    return true;
  }

  /// Keeps the likely seam edges (`found`, ascending) that form chains of
  /// min_seam_chain or more, and lists them at their ends.
  void keepSeamChains(const std::vector<EdgeIndex> &found) {
    std::unordered_map<VertexIndex, std::vector<std::uint32_t>> at; // positions in found
    for (std::uint32_t i = 0; i < found.size(); ++i) {
      const SeamAxis &seam = seam_axes_.at(found[i]);
      at[seam.low].push_back(i);
      at[seam.high].push_back(i);
    }
    std::vector<std::uint32_t> parent(found.size());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](std::uint32_t i) {
      while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
      return i;
    };
    for (const auto &[v, edges] : at)
      for (std::size_t i = 0; i < edges.size(); ++i)
        for (std::size_t j = i + 1; j < edges.size(); ++j) {
          const SeamAxis &a = seam_axes_.at(found[edges[i]]), &b = seam_axes_.at(found[edges[j]]);
          // Axes run from low to high: away from v, one of them is reversed.
          const double sign = (a.low == v) == (b.low == v) ? 1.0 : -1.0;
          if (sign * a.axis.dot(b.axis) <= -min_chain_cosine && sameSheets(a, b))
            parent[root(edges[i])] = root(edges[j]);
        }
    std::vector<std::size_t> size(found.size(), 0);
    for (std::uint32_t i = 0; i < found.size(); ++i)
      ++size[root(i)];
    for (std::uint32_t i = 0; i < found.size(); ++i) {
      if (size[root(i)] < min_seam_chain) {
        seam_axes_.erase(found[i]);
        continue;
      }
      const SeamAxis &seam = seam_axes_.at(found[i]);
      seams_at_[seam.low].push_back(found[i]);
      seams_at_[seam.high].push_back(found[i]);
    }
  }

  /// Whether t, at one of its corners on a likely seam edge, reaches from
  /// one sheet to another (or off all of them) for every seam edge there.
  bool bridgesSeam(CandidateIndex t) const {
    const Triangle &corners = candidates_[t].vertices;
    for (int k = 0; k < 3; ++k) {
      const auto found = seams_at_.find(corners[k]);
      if (found == seams_at_.end())
        continue;
      const VertexIndex v = corners[k], a = corners[(k + 1) % 3], b = corners[(k + 2) % 3];
      bool fits_one = false;
      for (EdgeIndex e : found->second) {
        const SeamAxis &seam = seam_axes_.at(e);
        const double angle_a = angleAround(seam, v, a), angle_b = angleAround(seam, v, b);
        const int sheet_a = std::isnan(angle_a) ? -2 : sheetAt(seam, angle_a);
        const int sheet_b = std::isnan(angle_b) ? -2 : sheetAt(seam, angle_b);
        if (sheet_a == -1 || sheet_b == -1)
          continue;
        if (sheet_a == -2 || sheet_b == -2 || sheet_a == sheet_b) {
          fits_one = true;
          break;
        }
      }
      if (!fits_one)
        return true;
    }
    return false;
  }

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

  /// Whether t may join in the seam pass: as a *seam* triangle, on one or
  /// two likely seam edges that hold two or more triangles, in a sheet of
  /// each that is still free, and attached to a sheet (an edge with one
  /// triangle, or its apex on a sheet's rim along that sheet: the third
  /// sheet grows from its rim); or as a *filler* that closes the gap between
  /// a seam triangle and a sheet (two edges with one triangle each, one of
  /// them a seam triangle's). It must not bridge a seam, and across edges
  /// with one triangle it bends at most max_attached_bending.
  SeamFit seamFit(CandidateIndex t) const {
    const Candidate &candidate = candidates_[t];
    // Only Gabriel triangles (types I, II): type III ones bridged the wedge
    // between sheets on the test clouds.
    if (mesh_.contains(t) || is_seam_[t] || candidate.type == CandidateType::ambiguous ||
        bridges_seam_.empty() || bridges_seam_[t])
      return SeamFit::none;
    int full = 0, attached = 0, full_slot = 0;
    bool next_to_seam_triangle = false;
    for (int k = 0; k < 3; ++k) {
      const EdgeIndex e = candidate.edges[k];
      const std::size_t uses = edgeUses(e);
      const VertexIndex p = candidate.vertices[k], q = candidate.vertices[(k + 1) % 3];
      const VertexIndex apex = candidate.vertices[(k + 2) % 3];
      bool fits = true;
      if (uses >= 2) {
        // On a likely seam edge, one triangle per sheet: t's apex must lie
        // in a sheet that none of the triangles there occupies.
        const auto seam = seam_axes_.find(e);
        if (seam == seam_axes_.end())
          return SeamFit::none;
        const VertexIndex low = seam->second.low;
        const int sheet = sheetAt(seam->second, angleAround(seam->second, low, apex));
        fits = sheet >= 0;
        forEachOccupant(e, [&](CandidateIndex u) {
          fits &= sheetAt(seam->second, angleAround(seam->second, low, apexOf(u, p, q))) != sheet;
          next_to_seam_triangle |= is_seam_[u];
        });
      } else {
        forEachOccupant(e, [&](CandidateIndex u) {
          fits &= bendingAngle(points_[p], points_[q], points_[apex], points_[apexOf(u, p, q)]) <=
                  max_attached_bending;
          next_to_seam_triangle |= is_seam_[u];
        });
      }
      if (!fits)
        return SeamFit::none;
      if (uses >= 2) {
        ++full;
        full_slot = k;
      }
      attached += uses == 1;
    }
    // On each full edge (a likely seam edge: checked above) up to one
    // triangle per sheet, and no larger than the triangles there. Two full
    // edges: a corner where the seam turns, attached to its sheet.
    for (int k = 0; k < 3; ++k) {
      const EdgeIndex e = candidate.edges[k];
      if (edgeUses(e) < 2)
        continue;
      if (edgeUses(e) >= seam_axes_.at(e).sheets.size() ||
          longestSide(t) > max_seam_size_ratio * longestOnEdge(e))
        return SeamFit::none;
    }
    if (full == 2)
      return attached > 0 ? SeamFit::seam : SeamFit::none;
    if (full == 1)
      return attached > 0 || continuesSheetAt(t, candidate.vertices[(full_slot + 2) % 3])
                 ? SeamFit::seam
                 : SeamFit::none;
    return attached >= 2 && next_to_seam_triangle ? SeamFit::filler : SeamFit::none;
  }

  double longestSide(CandidateIndex t) const {
    const auto &v = candidates_[t].vertices;
    return std::sqrt(std::max({(points_[v[0]] - points_[v[1]]).squaredNorm(),
                               (points_[v[1]] - points_[v[2]]).squaredNorm(),
                               (points_[v[2]] - points_[v[0]]).squaredNorm()}));
  }

  /// The longest side among the triangles on edge e.
  double longestOnEdge(EdgeIndex e) const {
    double longest = 0;
    forEachOccupant(e, [&](CandidateIndex u) { longest = std::max(longest, longestSide(u)); });
    return longest;
  }

  /// Whether t lies along a sheet whose rim passes through its corner v: v
  /// is on a boundary edge of the mesh and one of its triangles is within
  /// max_sheet_bending of t's plane.
  bool continuesSheetAt(CandidateIndex t, VertexIndex v) const {
    if (mesh_.vertexBoundaryEdges(v) == 0)
      return false;
    const auto normal = [&](const Triangle &corners) {
      return (points_[corners[1]] - points_[corners[0]])
          .cross(points_[corners[2]] - points_[corners[0]])
          .normalized();
    };
    const Eigen::Vector3d own = normal(candidates_[t].vertices);
    for (CandidateIndex u : mesh_.vertexTriangles(v))
      if (std::abs(own.dot(normal(candidates_[u].vertices))) >= std::cos(max_sheet_bending))
        return true;
    return false;
  }

  /// Base cost plus the context of every triangle already on t's edges.
  float seamCost(CandidateIndex t) const {
    double context = 0;
    for (EdgeIndex e : candidates_[t].edges)
      forEachOccupant(e, [&](CandidateIndex u) {
        for (int k = 0; k < 3; ++k)
          if (candidates_[u].edges[k] == e)
            context += contextTerm(u, k, t);
      });
    return static_cast<float>(std::max(0.0, candidates_[t].base_cost + context));
  }

  /// The third queue (paper Fig. 18): after pass 2 and the manifold sweep,
  /// candidates that fit (seamFit) are accepted cheapest first; each one
  /// accepted brings the candidates at its corners in again.
  void runSeamPass() {
    const std::size_t count = candidates_.size();
    is_seam_.assign(count, false);
    // Candidates by corner, to find those a new seam triangle affects: the
    // Gabriel ones (seamFit), which all have their edges numbered.
    auto listed = [&](CandidateIndex t) {
      return !mesh_.contains(t) && candidates_[t].type != CandidateType::ambiguous;
    };
    std::vector<std::uint32_t> offsets(points_.size() + 1, 0);
    for (CandidateIndex t = 0; t < count; ++t)
      if (listed(t))
        for (VertexIndex v : candidates_[t].vertices)
          ++offsets[v + 1];
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    std::vector<CandidateIndex> at_vertex(offsets.back());
    std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (CandidateIndex t = 0; t < count; ++t)
      if (listed(t))
        for (VertexIndex v : candidates_[t].vertices)
          at_vertex[cursor[v]++] = t;

    using Entry = std::pair<float, CandidateIndex>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
    for (CandidateIndex t = 0; t < count; ++t)
      if (listed(t) && seamFit(t) != SeamFit::none)
        heap.emplace(seamCost(t), t);
    while (!heap.empty()) {
      const auto [cost, t] = heap.top();
      heap.pop();
      if (deadline_)
        deadline_->checkEvery(deadline_counter_, "the seam pass");
      if (is_seam_[t] || seamFit(t) == SeamFit::none)
        continue;
      const float current = seamCost(t);
      if (current != cost) { // its context changed since it was queued
        heap.emplace(current, t);
        continue;
      }
      is_seam_[t] = true;
      seam_list_.push_back(t);
      ++statistics_.seam_triangles;
      for (EdgeIndex e : candidates_[t].edges)
        seam_on_edge_[e].push_back(t);
      for (VertexIndex v : candidates_[t].vertices)
        for (std::uint32_t i = offsets[v]; i < offsets[v + 1]; ++i)
          if (seamFit(at_vertex[i]) != SeamFit::none)
            heap.emplace(seamCost(at_vertex[i]), at_vertex[i]);
    }
  }

  /// After the seam pass: the mesh's triangles on edges that now hold three
  /// or more join the seam triangles, so that the finish sees each sheet
  /// ending at the seam rather than two sheets joined across it (orienting
  /// those twisted them; docs/algorithm.md, "Seams (opt-in)").
  void setSeamFansApart() {
    if (seam_list_.empty())
      return;
    is_set_apart_.assign(candidates_.size(), false);
    for (CandidateIndex t = 0; t < candidates_.size(); ++t) {
      if (!mesh_.contains(t) || is_fixed_[t])
        continue;
      for (EdgeIndex e : candidates_[t].edges)
        if (edgeUses(e) >= 3) {
          is_set_apart_[t] = true;
          set_apart_.push_back(t);
          break;
        }
    }
  }

  // ---- clean-up ------------------------------------------------------------

  void removeFlapsAndIsolatedTriangles() {
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

  /// Final guarantee: every vertex's triangles form one fan. At a bow-tie the
  /// fan with the most fixed triangles, then the most triangles (ties: the
  /// cheaper one) stays and the others are undone, except fixed triangles; removals can split fans
  /// at neighbouring vertices, so those are checked again. A vertex gets a second fan only when a
  /// triangle at it was removed or accepted against the vertex-face incidence rule: only those
  /// vertices are looked at.
  void enforceManifoldVertices() {
    std::vector<VertexIndex> pending;
    std::vector<bool> is_pending(points_.size(), false);
    for (VertexIndex v = 0; v < points_.size(); ++v)
      if (may_have_several_fans_[v] && mesh_.vertexTriangleCount(v) > 0) {
        pending.push_back(v);
        is_pending[v] = true;
      }
    while (!pending.empty()) {
      const VertexIndex v = pending.back();
      pending.pop_back();
      is_pending[v] = false;
      if (deadline_)
        deadline_->checkEvery(deadline_counter_, "the manifold sweep");
      if (mesh_.isSingleFan(v))
        continue;
      const auto fans = mesh_.fansAround(v);
      std::size_t best = 0;
      for (std::size_t f = 1; f < fans.size(); ++f) {
        const std::size_t fixed = fixedCount(fans[f]), best_fixed = fixedCount(fans[best]);
        const std::size_t preferred = preferredCount(fans[f]),
                          best_preferred = preferredCount(fans[best]);
        if (fixed != best_fixed) {
          if (fixed > best_fixed)
            best = f;
        } else if (preferred != best_preferred) {
          if (preferred > best_preferred)
            best = f;
        } else if (fans[f].size() > fans[best].size() || (fans[f].size() == fans[best].size() &&
                                                          fanCost(fans[f]) < fanCost(fans[best]))) {
          best = f;
        }
      }
      for (std::size_t f = 0; f < fans.size(); ++f) {
        if (f == best)
          continue;
        for (CandidateIndex u : fans[f]) {
          if (is_fixed_[u])
            continue;
          removeFromMesh(u);
          states_[u].state = State::dropped;
          ++statistics_.cleanup_undone;
          for (VertexIndex w : candidates_[u].vertices)
            if (w != v && !is_pending[w]) {
              is_pending[w] = true;
              pending.push_back(w);
            }
        }
      }
    }
  }

  std::size_t fixedCount(const std::vector<CandidateIndex> &fan) const {
    return static_cast<std::size_t>(
        std::count_if(fan.begin(), fan.end(), [&](CandidateIndex u) { return is_fixed_[u]; }));
  }

  std::size_t preferredCount(const std::vector<CandidateIndex> &fan) const {
    return static_cast<std::size_t>(
        std::count_if(fan.begin(), fan.end(), [&](CandidateIndex u) { return is_preferred_[u]; }));
  }

  double fanCost(const std::vector<CandidateIndex> &fan) const {
    double total = 0;
    for (CandidateIndex u : fan)
      total += states_[u].cost;
    return total;
  }

  MedialScaffold &scaffold_;
  std::vector<Candidate> &candidates_;
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
  // Edges numbered here (type III candidates): their ids by end points, and
  // who is on them.
  std::unordered_map<std::uint64_t, EdgeIndex> new_edges_;
  std::vector<std::uint32_t> late_offsets_;
  std::vector<CandidateIndex> late_candidates_;
  std::unordered_map<EdgeIndex, std::vector<CandidateIndex>> swapped_in_;
  std::vector<std::uint32_t> unnumbered_offsets_; // by lowest vertex, during swaps
  std::vector<CandidateIndex> unnumbered_;
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

GreedyMesher::GreedyMesher(MedialScaffold &scaffold, const std::vector<Eigen::Vector3d> &points,
                           const Parameters &parameters, const Deadline *deadline)
    : impl_(std::make_unique<Impl>(scaffold, points, parameters, deadline, statistics_)) {}

GreedyMesher::~GreedyMesher() = default;

void GreedyMesher::run() { impl_->run(); }

std::vector<Triangle> GreedyMesher::triangles(bool with_fixed) const {
  return impl_->triangles(with_fixed);
}

std::vector<Triangle> GreedyMesher::seamTriangles() const { return impl_->seamTriangles(); }

} // namespace pcl_ms
